/* bench_cornea.c -- the cornea measurement's figures (issue 12 section 3): the
 * synthetic eye (R 7.8, Q -0.26, 0.75 D with the rule, decentred 0.2 mm, tilted
 * 2 deg) scanned by the example rig (sunflower pattern, theta <= 12 deg, poses
 * quantised to its steps), spots from rig_api.forward plus Gaussian centroid noise
 * 0.04 px at a 5 um pitch, fitted as a biconic with the eye's pose.  Prints the table
 * of scan points against time and error, then BENCH lines.  argv[1] "quick": fewer
 * seeds.  Fixed seeds: the output is the same bit for bit on every run. */
#include <stdint.h>
#include <time.h>
#include "ct.h"
#include "bench_util.h"

int main(int argc, char **argv)
{
    int quick = argc > 1 && !strcmp(argv[1], "quick");
    const rig_api *rg = ct_rig();
    const cornea_api *cn = ct_cn();
    rg_geometry g;
    rg->geometry_default(&g);
    rg_cornea eye = ct_eye12(rg, &g);
    cn_params t;
    cn->params_from_cornea(&eye, g.cornea.trans, 2 * CT_DEG, 0, &t);
    double km = 337.5 / 7.8;
    static const int sizes[] = {10, 30, 100, 300, 1000, 3000, 10000};
    int nseeds = quick ? 3 : 10;
    cn_spot *sp = malloc(sizeof *sp * 10000);
    if (!sp) return 1;
    printf("# cornea: pitch %.1f um, centroid sigma %.2f px = %.2f um, theta <= 12 deg, "
           "%d seeds per row (RMS errors over them; sd: the fit's reported)\n",
           CT_PITCH * 1e3, CT_SIGMA / CT_PITCH, CT_SIGMA * 1e3, nseeds);
    printf("# %6s %6s %9s %9s %10s %9s %10s %9s %9s %8s %s\n", "points", "used",
           "plan_ms", "fit_ms", "R_err_um", "R_sd_um", "Km_err_D", "Km_sd_D", "axis_deg",
           "iters", "flags");
    double fig_r = 0, fig_k = 0, fig_ax = 0, fig_rf = 0, t1000 = 0, plan1000 = 0;
    uint64_t hash = 1469598103934665603ull;
    for (size_t si = 0; si < sizeof sizes / sizeof *sizes; si++) {
        int N = sizes[si];
        double er = 0, erf = 0, ek = 0, ea = 0, sdr = 0, sdk = 0, tp = 0, tf = 0;
        int used = 0, iters = 0, m = 0;
        unsigned flags = 0;
        for (int s = 0; s < nseeds; s++) {
            cn_scan_opts so = {.npoints = N, .theta_max = 12 * CT_DEG, .sigma = CT_SIGMA,
                               .seed = 1000 + s, .quantise = 1};
            char err[256];
            double t0 = now();
            int n = cn->simulate(rg, &g, &eye, &so, sp, 10000, err, sizeof err);
            double t1 = now();
            cn_fit_opts fo = {.model = CN_BICONIC};
            cn_result r;
            int rc = cn->fit(&g, sp, n, NULL, &fo, &r, err, sizeof err);
            double t2 = now();
            tp += t1 - t0;
            tf += t2 - t1;
            if (rc) { flags |= 1u << 31; continue; }
            m++;
            used += r.nused;
            iters += r.iterations;
            flags |= r.undetermined | (r.poor ? 1u << 30 : 0);
            er += pow(r.k.R - t.p[CN_R], 2);
            erf += pow(fmax(fabs(r.k.R_flat - eye.R), fabs(r.k.R_steep - eye.R2)), 2);
            ek += pow(r.k.Km - km, 2);
            ea += pow(ct_axis_err(r.k.K1_axis, 0), 2);
            sdr += r.k.sd_R;
            sdk += r.k.sd_Km;
            if (N == 1000 && s == 0)
                for (int k = 0; k < CN_NPARAM; k++) {
                    uint64_t b;
                    memcpy(&b, &r.par.p[k], 8);
                    hash = (hash ^ b) * 1099511628211ull;
                }
        }
        if (!m) { printf("  %6d  (no fit)\n", N); continue; }
        er = sqrt(er / m); erf = sqrt(erf / m); ek = sqrt(ek / m); ea = sqrt(ea / m);
        printf("  %6d %6d %9.2f %9.2f %10.3f %9.3f %10.5f %9.5f %9.4f %8d %#x\n", N,
               used / m, 1e3 * tp / nseeds, 1e3 * tf / nseeds, er * 1e3, sdr / m * 1e3,
               ek, sdk / m, ea, iters / m, flags);
        if (N == 1000) {
            fig_r = er; fig_rf = erf; fig_k = ek; fig_ax = ea;
            t1000 = (tp + tf) / nseeds;
            plan1000 = tp / nseeds;
        }
    }
    /* the accuracy the rig can have, asked before building: N = 1000 at the truth */
    {
        cn_scan_opts so = {.npoints = 1000, .theta_max = 12 * CT_DEG, .quantise = 1};
        char err[256];
        cn_predict pr;
        int n = cn->simulate(rg, &g, &eye, &so, sp, 10000, err, sizeof err);
        if (n > 0 && !cn->predict(&g, sp, n, CN_BICONIC, 0, &t, CT_SIGMA, &pr, err, sizeof err)) {
            printf("# predicted (1000 points, sigma %.2f um): singular values", CT_SIGMA * 1e3);
            for (int k = 0; k < pr.nfree; k++) printf(" %.3g", pr.sv[k]);
            printf(", condition %.3g\n# predicted sd:", pr.cond);
            for (int k = 0; k < CN_NPARAM; k++) printf(" %s %.3g", cn->param_name(k), pr.sd[k]);
            printf("\n# predicted sd: R %.3f um, mean K %.4f D, cylinder %.4f D, axis %.4f deg\n",
                   pr.k.sd_R * 1e3, pr.k.sd_Km, pr.k.sd_cyl, pr.k.sd_axis);
            printf("# weakest direction:");
            for (int c = 0; c < pr.nfree; c++)
                if (fabs(pr.vt[(pr.nfree - 1) * pr.nfree + c]) > 0.1)
                    printf(" %+.2f %s", pr.vt[(pr.nfree - 1) * pr.nfree + c],
                           cn->param_name(pr.idx[c]));
            printf("\n");
        }
    }
    printf("# result hash (N 1000, seed 1000): %016llx\n", (unsigned long long)hash);
    printf("BENCH cornea_radius_err_um %.3f um\n", fig_r * 1e3);
    printf("BENCH cornea_radius_flat_steep_err_um %.3f um\n", fig_rf * 1e3);
    printf("BENCH cornea_power_err_D %.5f D\n", fig_k);
    printf("BENCH cornea_cyl_axis_err_deg %.4f deg\n", fig_ax);
    printf("BENCH cornea_plan_fit1000_s %.3f s\n", t1000);
    printf("BENCH cornea_fit_vs_plan_ratio %.2f x\n", (t1000 - plan1000) / plan1000);
    free(sp);
    return 0;
}
