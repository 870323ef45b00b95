/* cn_api.c -- the cornea engine's table: the one exported symbol, cornea_get_api. */
#include "cn_int.h"

static const char *version(void) { return "lensmat-cornea 3"; }

static int zcurv(const cn_zfit *z, double x, double y, double *axial, double *tang)
{
    return cn_zlocal(z, x, y, axial, tang, NULL);
}

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
    .zfit = cn_zfit_run,
    .zsag = cn_zsag,
    .zcurv = zcurv,
    .zcovered = cn_zcovered,
    .zmap = cn_zmap,
    .kc = cn_kc_of,
    .kc_model = cn_kc_model,
    .kc_model_in = cn_kc_model_in,
};

__attribute__((visibility("default"))) const cornea_api *cornea_get_api(int abi)
{
    return abi == CORNEA_ABI ? &api : NULL;
}
