/* rg_api.c -- the rig engine's one exported symbol, rig_get_api: the table of entry
 * points, filled once (geometry by rg_geometry_fill, the machine by rg_machine_fill). */
#include <pthread.h>
#include "rig/rg_int.h"

static rig_api api;
static pthread_once_t once = PTHREAD_ONCE_INIT;

static const char *rg_version(void) { return "lensmat-rig " LENSMAT_VERSION; }

/* The machine half defines the strong one; without it the block stays NULL. */
__attribute__((weak)) void rg_machine_fill(rig_api *a) { (void)a; }

static void fill(void)
{
    api.abi = RIG_ABI;
    api.version = rg_version;
    rg_geometry_fill(&api);
    rg_machine_fill(&api);
}

__attribute__((visibility("default"))) const rig_api *rig_get_api(int abi)
{
    if (abi != RIG_ABI) return NULL;
    pthread_once(&once, fill);
    return &api;
}
