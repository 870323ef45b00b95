/* t_trace.c -- a scan's final parameters checked through the trace engine: the
 * fitted cornea placed in the rig, each commanded pose traced by rig_api.verify
 * (mirrors, cornea with its Fresnel reflection, detector) and the traced detector
 * hit compared with the fit's analytic model at the same parameters. */
#include "ct.h"
#include "trace/trace.h"

int main(void)
{
    const rig_api *rg = ct_rig();
    const cornea_api *cn = ct_cn();
    const trace_api *tr = trace_get_api(TRACE_ABI);
    if (!tr) { printf("FAIL no trace table\n"); return 1; }
    rg_geometry g;
    rg->geometry_default(&g);
    int models[] = {CN_CONIC, CN_BICONIC};
    for (int mi = 0; mi < 2; mi++) {
        int model = models[mi];
        rg_cornea eye = ct_eye12(rg, &g);
        if (model == CN_CONIC) {
            eye = ct_eye(rg, &g, 7.7, -0.3, 0, 0, 0.1, -0.1, 1 * CT_DEG, 0);
            eye.model = RG_CONIC;
        }
        static cn_spot sp[300];
        char err[256];
        cn_scan_opts so = {.npoints = 300, .theta_max = 12 * CT_DEG, .sigma = CT_SIGMA,
                           .seed = 9, .quantise = 1};
        int n = cn->simulate(rg, &g, &eye, &so, sp, 300, err, sizeof err);
        cn_fit_opts fo = {.model = model};
        cn_result r;
        if (cn->fit(&g, sp, n, NULL, &fo, &r, err, sizeof err)) { printf("FAIL fit: %s\n", err); return 1; }
        rg_geometry gf = g;
        cn->cornea_from_params(rg, model, &r.par, g.cornea.trans, &gf.cornea);
        cn_plane pl;
        cn->plane(&gf, &pl);          /* the plane rig_api.verify's detector disc lies in */
        double worst = 0, refl = 0;
        int traced = 0;
        for (int k = 0; k < 100; k++) {
            rg_target t = {RG_T_ANGLES, 12 * CT_DEG * sqrt((k + 0.5) / 100), k * 2.39996};
            rg_solution s;
            rg_quantised q;
            if (rg->solve(&g, &t, NULL, &s, err, sizeof err) ||
                rg->quantise(&g, &t, &s, &q, err, sizeof err))
                continue;
            rg_beam b;
            rg->forward(&gf, &q.pose, &b, err, sizeof err);
            if (!isfinite(b.spot[0])) continue;
            rg_verify v;
            if (rg->verify(tr, &gf, &q.pose, b.spot, &v, err, sizeof err) || !v.hit) continue;
            cn_ray ray;
            double u, w;
            if (cn->ray_of_pose(rg, &g, &q.pose, &ray, err, sizeof err) ||
                cn->forward(model, &r.par, g.cornea.trans, &pl, &ray, &u, &w, NULL, NULL))
                continue;
            double h[3];
            for (int i = 0; i < 3; i++) h[i] = v.det[i] - pl.at[i];
            double du = h[0] * pl.e1[0] + h[1] * pl.e1[1] + h[2] * pl.e1[2] - u;
            double dv = h[0] * pl.e2[0] + h[1] * pl.e2[1] + h[2] * pl.e2[2] - w;
            worst = fmax(worst, hypot(du, dv));
            refl = fmax(refl, v.reflect_err);
            traced++;
        }
        ct_check(traced > 80 && worst < 1e-6,
                 "%s fit's final parameters through the trace engine: %d poses traced, "
                 "detector hits agree with the fit's model to %.2g mm (reflection law %.2g)",
                 model == CN_CONIC ? "conic" : "biconic", traced, worst, refl);
    }
    return ct_fails != 0;
}
