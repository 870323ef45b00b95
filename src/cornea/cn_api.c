/* cn_api.c -- the cornea engine's table: the one exported symbol, cornea_get_api. */
#include "cn_int.h"

static const char *version(void) { return "lensmat-cornea 2"; }

static const cornea_api api = {
    .abi = CORNEA_ABI,
    .version = version,
    .param_name = cn_param_name,
    .plane = cn_plane_of,
    .params_from_cornea = cn_params_from_cornea,
    .forward = cn_forward,
    .cornea_from_params = cn_cornea_from_params,
    .ray_of_pose = cn_ray_of_pose,
    .simulate = cn_simulate,
    .fit = cn_fit,
    .predict = cn_predict_scan,
    .report = cn_report,
    .reimage = cn_reimage,
    .map = cn_map,
    .spot_xy = cn_spot_xy,
    .report_csv = cn_report_csv,
    .report_json = cn_report_json,
};

__attribute__((visibility("default"))) const cornea_api *cornea_get_api(int abi)
{
    return abi == CORNEA_ABI ? &api : NULL;
}
