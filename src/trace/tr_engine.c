/* tr_engine.c -- the function table the trace module exports (trace_get_api): the
 * scene (tr_scene.c), the run (tr_pool.c, tr_lanes.c, tr_trace.c), optics
 * (tr_optics.c), lenses (tr_lens.c), aimed rays (tr_aim.c) and their wave aberration
 * (tr_opd.c) behind one ABI-checked table. */
#include "tr_eng.h"

/* ---------------- the table ---------------- */

static const char *version(void)
{
    return "lensmat trace engine (ABI " "1" "), Embree " RTC_VERSION_STRING;
}

static int refract(const double d[3], const double nrm[3], double n1, double n2,
                   double out[3])
{
    return tr_refract(d, nrm, n1, n2, out);
}

static void fresnel(double n1, double n2, double cos_i, trace_fresnel_coef *out)
{
    tr_fresnel(n1, n2, cos_i, out);
}

static const trace_api api = {
    TRACE_ABI,
    version,
    tr_scene_new,
    tr_scene_free,
    tr_scene_error,
    tr_add_surface,
    tr_add_mesh,
    tr_add_source,
    tr_options_default,
    tr_build,
    tr_run,
    refract,
    fresnel,
    tr_add_lens,
    tr_lens_fan,
    tr_set_absorption,
    tr_rx_trace,
    tr_rx_aim,
    tr_rx_opd,
    tr_polarization,
    tr_set_polar,
    tr_prt_interface,
    tr_run_batches,
};

const trace_api *trace_get_api(int abi)
{
    return abi == TRACE_ABI ? &api : NULL;
}
