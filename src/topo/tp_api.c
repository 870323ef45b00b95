/* tp_api.c -- the topography pipeline's table: the one exported symbol,
 * topo_get_api. */
#include "tp_int.h"

static const char *version(void) { return "lensmat-topo 1"; }

static const topo_api api = {
    .abi = TOPO_ABI,
    .version = version,
    .pattern = tp_pattern,
    .measure = tp_measure,
    .counts = tp_counts,
};

__attribute__((visibility("default"))) const topo_api *topo_get_api(int abi)
{
    return abi == TOPO_ABI ? &api : NULL;
}
