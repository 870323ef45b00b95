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
    .measure_zone = tp_measure_zone,
    .iso = tp_iso_report,
    .truth_sag = tp_truth_sag,
};

__attribute__((visibility("default"))) const topo_api *topo_get_api(int abi)
{
    return abi == TOPO_ABI ? &api : NULL;
}
