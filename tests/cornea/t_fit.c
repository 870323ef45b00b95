/* t_fit.c -- the cornea fit against synthetic truth: the analytic forward model
 * against rig_api.forward, noise-free recovery, noisy recovery within the reported
 * uncertainty, the reported uncertainty against the scatter of repeated scans,
 * outlier and missing spots, the clinical numbers. */
#include "ct.h"

static const rig_api *rg;
static const cornea_api *cn;
static rg_geometry g;

static void test_forward(void)
{
    rg_cornea eye = ct_eye12(rg, &g);
    rg_geometry gt = g;
    gt.cornea = eye;
    cn_plane pl;
    cn->plane(&gt, &pl);               /* rig_api.forward's plane (true apex) */
    cn_params tp;
    cn->params_from_cornea(&eye, g.cornea.trans, 2 * CT_DEG, 0, &tp);
    cn_scan_opts so = {.npoints = 300, .theta_max = 12 * CT_DEG, .quantise = 1};
    cn_spot sp[300];
    char err[256];
    int n = cn->simulate(rg, &g, &eye, &so, sp, 300, err, sizeof err);
    double worst = 0;
    int cmp = 0;
    for (int i = 0; i < n; i++) {     /* every simulated spot is a hit for the model */
        double u, v;
        if (sp[i].status == CN_S_OK &&
            !cn->forward(CN_BICONIC, &tp, g.cornea.trans, &pl, &sp[i].ray, &u, &v, NULL, NULL))
            cmp++;
    }
    /* direct comparison with rig_api.forward on solved poses */
    for (int k = 0; k < 200; k++) {
        rg_target t = {RG_T_ANGLES, 12 * CT_DEG * sqrt((k + 0.5) / 200), k * 2.39996};
        rg_solution s;
        if (rg->solve(&g, &t, NULL, &s, err, sizeof err)) continue;
        rg_beam b;
        if (rg->forward(&gt, &s.pose, &b, err, sizeof err) && !isfinite(b.det[0])) continue;
        cn_ray r;
        if (cn->ray_of_pose(rg, &g, &s.pose, &r, err, sizeof err)) continue;
        double u, v, spot[3], nrm[3];
        if (cn->forward(CN_BICONIC, &tp, g.cornea.trans, &pl, &r, &u, &v, spot, nrm)) {
            worst = INFINITY;
            continue;
        }
        double h[3], du, dv, ds = 0;
        for (int i = 0; i < 3; i++) h[i] = b.det[i] - pl.at[i];
        du = h[0] * pl.e1[0] + h[1] * pl.e1[1] + h[2] * pl.e1[2] - u;
        dv = h[0] * pl.e2[0] + h[1] * pl.e2[1] + h[2] * pl.e2[2] - v;
        for (int i = 0; i < 3; i++) ds = fmax(ds, fabs(spot[i] - b.spot[i]));
        worst = fmax(worst, fmax(hypot(du, dv), ds));
    }
    ct_check(cmp > 250 && worst < 1e-9,
             "analytic forward model = rig_api.forward (decentred tilted biconic): "
             "%d spots, worst difference %.2g mm on cornea and detector", cmp, worst);
}

static int fit_threads;             /* cn_fit_opts.threads of fit_eye's fits */

static int fit_eye(const rg_cornea *eye, double rx, double ry, int model, int npts,
                   double theta, double sigma, unsigned long long seed, cn_result *res,
                   cn_params *truth, cn_spot *sp, int cap)
{
    cn_scan_opts so = {.npoints = npts, .theta_max = theta, .sigma = sigma, .seed = seed,
                       .quantise = 1};
    char err[256];
    int n = cn->simulate(rg, &g, eye, &so, sp, cap, err, sizeof err);
    cn->params_from_cornea(eye, g.cornea.trans, rx, ry, truth);
    cn_fit_opts fo = {.model = model, .threads = fit_threads};
    if (cn->fit(&g, sp, n, NULL, &fo, res, err, sizeof err)) {
        printf("# fit failed: %s\n", err);
        return -1;
    }
    return n;
}

static void test_noise_free(void)
{
    static cn_spot sp[400];
    rg_cornea eye = ct_eye12(rg, &g);
    cn_result r;
    cn_params t;
    fit_eye(&eye, 2 * CT_DEG, 0, CN_BICONIC, 400, 12 * CT_DEG, 0, 1, &r, &t, sp, 400);
    double worst = 0;
    for (int k = 0; k < CN_NPARAM; k++) {
        double e = fabs(r.par.p[k] - t.p[k]);
        if (k == CN_QF || k == CN_QS) e *= 1e-2;    /* Q: dimensionless, 100x looser */
        worst = fmax(worst, e);
    }
    ct_check(worst < 1e-7 && r.undetermined == 0,
             "noise-free biconic recovered: worst parameter error %.2g (R %.9f true %.9f), "
             "%d iterations, rms %.2g mm", worst, r.par.p[CN_R], t.p[CN_R], r.iterations,
             r.rms);
}

static void test_noisy(void)
{
    static cn_spot sp[1000];
    static char buf[4096];
    rg_cornea eye = ct_eye12(rg, &g);
    cn_result r;
    cn_params t;
    fit_eye(&eye, 2 * CT_DEG, 0, CN_BICONIC, 1000, 12 * CT_DEG, CT_SIGMA, 42, &r, &t, sp, 1000);
    printf("%s", cn->report(&r, buf, sizeof buf));
    int ok = r.undetermined == 0;
    for (int k = 0; k < CN_NPARAM; k++) {
        if (!r.free[k]) continue;          /* the asphere's terms in a biconic fit */
        double sd = sqrt(r.cov[k * CN_NPARAM + k]), e = r.par.p[k] - t.p[k];
        printf("#   %-8s fit %.8g true %.8g err %.3g sd %.3g (%.2f sd)\n",
               cn->param_name(k), r.par.p[k], t.p[k], e, sd, e / sd);
        if (!(fabs(e) < 4 * sd)) ok = 0;
    }
    ct_check(ok, "noisy scan (1000 points, sigma %.2g um): every parameter within 4 sd",
             CT_SIGMA * 1000);
    ct_check(r.chi2_dof > 0.85 && r.chi2_dof < 1.15, "chi2/dof %.3f near 1", r.chi2_dof);
    double km = 337.5 / 7.8;
    ct_check(fabs(r.k.Km - km) < 4 * r.k.sd_Km && fabs(r.k.cyl - 0.75) < 4 * r.k.sd_cyl &&
             ct_axis_err(r.k.K1_axis, 0) < 4 * r.k.sd_axis + 1e-9 &&
             fabs(r.k.K2_axis - 90) < 4 * r.k.sd_axis + 1e-9,
             "Sim K: mean K %.4f +- %.4f D (true %.4f), cyl %.4f +- %.4f D (0.75) @ %.2f "
             "(90) axis sd %.3f deg", r.k.Km, r.k.sd_Km, km, r.k.cyl, r.k.sd_cyl,
             r.k.K2_axis, r.k.sd_axis);
    ct_check(fabs(r.k.P - r.k.Km * 0.376 / 0.3375) < 1e-9 && r.k.sd_P > r.k.sd_Km,
             "corneal power (n 1.376) %.4f +- %.4f D", r.k.P, r.k.sd_P);
    ct_check(fabs(r.k.R_flat - eye.R) < 4 * r.k.sd_R_flat &&
             fabs(r.k.R_steep - eye.R2) < 4 * r.k.sd_R_steep,
             "R flat %.6f +- %.6f (true %.6f), R steep %.6f +- %.6f (true %.6f)",
             r.k.R_flat, r.k.sd_R_flat, eye.R, r.k.R_steep, r.k.sd_R_steep, eye.R2);
    /* the prediction at the truth gives the same uncertainties as the fit */
    cn_predict pr;
    char err[256];
    int rc = cn->predict(&g, sp, 1000, CN_BICONIC, 0, &t, CT_SIGMA, &pr, err, sizeof err);
    double ratio = pr.sd[CN_R] / sqrt(r.cov[0]);
    ct_check(rc == 0 && fabs(ratio - 1) < 0.05 && pr.undetermined == 0,
             "predicted sd(R) %.3g um = fit's %.3g um (cond %.3g)", pr.sd[CN_R] * 1e3,
             sqrt(r.cov[0]) * 1e3, pr.cond);
}

/* Are the uncertainties honest?  The scatter of 24 scans against the reported sd. */
static void test_scatter(void)
{
    static cn_spot sp[300];
    rg_cornea eye = ct_eye12(rg, &g);
    double s2r = 0, s2k = 0, sdr = 0, sdk = 0;
    int m = 0;
    for (int s = 0; s < 24; s++) {
        cn_result r;
        cn_params t;
        if (fit_eye(&eye, 2 * CT_DEG, 0, CN_BICONIC, 300, 12 * CT_DEG, CT_SIGMA, 100 + s,
                    &r, &t, sp, 300) < 0) continue;
        s2r += pow(r.par.p[CN_R] - t.p[CN_R], 2);
        s2k += pow(r.k.Km - 337.5 / 7.8, 2);
        sdr += r.k.sd_R;
        sdk += r.k.sd_Km;
        m++;
    }
    double zr = sqrt(s2r / m) / (sdr / m), zk = sqrt(s2k / m) / (sdk / m);
    ct_check(m == 24 && zr > 0.6 && zr < 1.5 && zk > 0.6 && zk < 1.5,
             "24 scans: RMS error / reported sd = %.2f (R), %.2f (mean K)", zr, zk);
}

static void test_outliers(void)
{
    static cn_spot sp[500];
    rg_cornea eye = ct_eye12(rg, &g);
    cn_scan_opts so = {.npoints = 500, .theta_max = 12 * CT_DEG, .sigma = CT_SIGMA,
                       .seed = 7, .quantise = 1};
    char err[256];
    int n = cn->simulate(rg, &g, &eye, &so, sp, 500, err, sizeof err);
    int bad[] = {3, 50, 120, 333, 401, 477};
    for (int i = 0; i < 6; i++) sp[bad[i]].u += 0.01 * (i + 1);   /* 50..300 sigma */
    sp[10].status = CN_S_NONE;
    sp[11].status = CN_S_SEVERAL;
    sp[12].u = NAN;
    cn_result r;
    cn_params t;
    cn->params_from_cornea(&eye, g.cornea.trans, 2 * CT_DEG, 0, &t);
    cn_fit_opts fo = {.model = CN_BICONIC};
    int rc = cn->fit(&g, sp, n, NULL, &fo, &r, err, sizeof err);
    int out = 0, flagged = 1;
    for (int i = 0; i < n; i++) out += sp[i].status == CN_S_OUTLIER;
    for (int i = 0; i < 6; i++) flagged &= sp[bad[i]].status == CN_S_OUTLIER;
    ct_check(rc == 0 && flagged && out <= 7 && sp[10].status == CN_S_NONE &&
             sp[11].status == CN_S_SEVERAL && sp[12].status == CN_S_NONE &&
             r.nrejected == out + 3,
             "6 gross outliers rejected by the robust test (%d rejected as outliers), "
             "3 missing/ambiguous spots left out", out);
    ct_check(fabs(r.par.p[CN_R] - t.p[CN_R]) < 4 * sqrt(r.cov[0]) &&
             fabs(r.k.Km - 337.5 / 7.8) < 4 * r.k.sd_Km,
             "with outliers: R err %.3g um (sd %.3g)", (r.par.p[CN_R] - t.p[CN_R]) * 1e3,
             sqrt(r.cov[0]) * 1e3);
    /* without rejection the same data are far off */
    for (int i = 0; i < n; i++) if (sp[i].status == CN_S_OUTLIER) sp[i].status = CN_S_OK;
    cn_fit_opts nr = {.model = CN_BICONIC, .reject_rounds = -1};
    cn_result r2;
    cn->fit(&g, sp, n, NULL, &nr, &r2, err, sizeof err);
    ct_check(r2.chi2_dof > 10 * r.chi2_dof,
             "the same spots without rejection: chi2/dof %.3g (with: %.3g)", r2.chi2_dof,
             r.chi2_dof);
}

static void test_sphere_conic(void)
{
    static cn_spot sp[300];
    rg_cornea eye = ct_eye(rg, &g, 8.0, 0, 0, 0, 0.1, -0.05, 0, 0);
    eye.model = RG_SPHERE;
    cn_result r;
    cn_params t;
    fit_eye(&eye, 0, 0, CN_SPHERE, 300, 12 * CT_DEG, CT_SIGMA, 3, &r, &t, sp, 300);
    ct_check(fabs(r.par.p[CN_R] - 8.0) < 4 * sqrt(r.cov[0]) && r.undetermined == 0 &&
             fabs(r.par.p[CN_DX] - 0.1) < 4 * sqrt(r.cov[CN_DX * (CN_NPARAM + 1)]),
             "sphere R 8: %.6f +- %.6f mm, dx %.5f", r.par.p[CN_R], sqrt(r.cov[0]),
             r.par.p[CN_DX]);
    rg_cornea ec = ct_eye(rg, &g, 7.6, -0.3, 0, 0, -0.1, 0.1, 0, 1 * CT_DEG);
    ec.model = RG_CONIC;
    fit_eye(&ec, 0, 1 * CT_DEG, CN_CONIC, 300, 12 * CT_DEG, CT_SIGMA, 4, &r, &t, sp, 300);
    ct_check(fabs(r.par.p[CN_R] - 7.6) < 4 * sqrt(r.cov[0]) &&
             fabs(r.par.p[CN_QF] + 0.3) < 4 * sqrt(r.cov[CN_QF * (CN_NPARAM + 1)]) && r.undetermined == 0,
             "conic R 7.6 Q -0.3: R %.6f Q %.4f +- %.4f", r.par.p[CN_R], r.par.p[CN_QF],
             sqrt(r.cov[CN_QF * (CN_NPARAM + 1)]));
}

/* Same seed, same bits: the scan and the fit are deterministic. */
static void test_reproducible(void)
{
    static cn_spot a[300], b[300];
    rg_cornea eye = ct_eye12(rg, &g);
    cn_result ra, rb;
    cn_params t;
    fit_eye(&eye, 2 * CT_DEG, 0, CN_BICONIC, 300, 12 * CT_DEG, CT_SIGMA, 5, &ra, &t, a, 300);
    fit_eye(&eye, 2 * CT_DEG, 0, CN_BICONIC, 300, 12 * CT_DEG, CT_SIGMA, 5, &rb, &t, b, 300);
    int same = !memcmp(ra.par.p, rb.par.p, sizeof ra.par.p) && !memcmp(ra.cov, rb.cov, sizeof ra.cov);
    for (int i = 0; i < 300; i++) same &= a[i].u == b[i].u && a[i].v == b[i].v;
    fit_eye(&eye, 2 * CT_DEG, 0, CN_BICONIC, 300, 12 * CT_DEG, CT_SIGMA, 6, &rb, &t, b, 300);
    ct_check(same && memcmp(ra.par.p, rb.par.p, sizeof ra.par.p),
             "same seed: spots, parameters and covariance identical bit for bit; another "
             "seed differs");
    /* residuals and Jacobian split over 3 threads (100 spots each): the same bits */
    fit_threads = 3;
    fit_eye(&eye, 2 * CT_DEG, 0, CN_BICONIC, 300, 12 * CT_DEG, CT_SIGMA, 5, &rb, &t, b, 300);
    fit_threads = 0;
    ct_check(!memcmp(ra.par.p, rb.par.p, sizeof ra.par.p) && !memcmp(ra.cov, rb.cov, sizeof ra.cov) &&
             ra.iterations == rb.iterations,
             "fit on 3 threads: parameters, covariance and iterations identical to 1 thread's");
}

int main(void)
{
    rg = ct_rig();
    cn = ct_cn();
    rg->geometry_default(&g);
    test_forward();
    test_noise_free();
    test_noisy();
    test_scatter();
    test_outliers();
    test_sphere_conic();
    test_reproducible();
    return ct_fails != 0;
}
