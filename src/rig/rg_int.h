/* rg_int.h -- inside the rig module only (never included outside src/rig/): the seam
 * between the two halves of the engine's table.  rg_api.c owns rig_get_api and fills
 * the geometry block; the machine half fills its own block in rg_machine_fill(),
 * defined in the machine's file (a weak do-nothing default lives in rg_api.c, so the
 * geometry half builds and tests alone). */
#ifndef RG_INT_H
#define RG_INT_H
#include "rig/rig.h"

/* Called once, before rig_get_api returns the table for the first time. */
void rg_machine_fill(rig_api *api);

/* The geometry half's fill (rg_api.c). */
void rg_geometry_fill(rig_api *api);

#define RG_HIDDEN __attribute__((visibility("hidden")))
#endif
