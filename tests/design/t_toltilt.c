/* t_toltilt.c -- tilt and decentre tolerances, and folded lenses in the design engine,
 * against models of the test's own.
 *  - Closed form: the boresight (field 1's chief ray, on axis, on the image plane) of
 *    Sasian's triplet (indices at d as plain numbers) with each surface tilted about x
 *    and y and decentred in x and y, and two elements tilted and decentred, against
 *    this file's own first-order model: a sphere tilted by theta about its vertex is
 *    the sphere with its centre moved by -+R theta (an element: each vertex moved by
 *    -+z theta about the first), so the ray leaving surface j gains
 *    n'u' += e_j phi_j -+ (n' - n) theta_j (e_j the vertex's shift); the entering
 *    height is found so that the ray crosses the stop's own centre (the stop moves
 *    with its surface), and the image height follows by y-nu tracing.  The engine's
 *    half-difference at +-delta against it: the worst relative error is printed as
 *    "closed form: worst relative error" (scripts/bench_design.sh: tol_tilt_sens_rel_err).
 *  - Monte Carlo: 2000 triplets with every surface tilted and decentred (uniform): the
 *    boresight's sd against the RSS of the linear sensitivities, sqrt(sum s_i^2 / 3)
 *    (the sd of 2000 draws has a 1.6 % standard error), and the mean RMS^2 against
 *    the second-order prediction RMS0^2 + sum_i ((RMS_i+^2 + RMS_i-^2)/2 - RMS0^2)/3
 *    (independent zero-mean draws: cross terms average out), within 4 standard errors.
 *  - A 45-degree fold mirror after a singlet (breaks, mirror, negative thickness):
 *    tilting the mirror by theta about x turns the reflected beam by 2 theta, so the
 *    image moves by L tan(2 theta) (L mirror to image), about its own y by
 *    2 cos(45 deg) theta: against the engine's boresight.
 *  - Folded optimisation: a classical Cassegrain (primary a paraboloid, m = 5) whose
 *    secondary's conic varies for the least RMS spot finds k2 = -((m+1)/(m-1))^2 =
 *    -2.25; a singlet bent for f = 100 and the least spot reaches through a 45-degree
 *    fold the same curvatures and merit as straight; its tolerances too. */
#include "dsu.h"

static void (*const keep_dsu)(int, const double *, const double *, const double *, double *,
                              double *) __attribute__((unused)) = dsu_yn;

#define PI_ 3.14159265358979323846

static const char *triplet =
    "thickness\nwavelengths d\nepd 12.5\nfield angle 0 14.14 20\n"
    "23.713     4.831    1.691002\n"
    "7331.288   5.86     air\n"
    "-24.456    0.975    1.672707 stop\n"
    "21.896     4.822    air\n"
    "86.759     3.127    1.691002\n"
    "-20.4942   41.2365  air\n";
static const double R[6] = {23.713, 7331.288, -24.456, 21.896, 86.759, -20.4942};
static const double T[6] = {4.831, 5.86, 0.975, 4.822, 3.127, 41.2365};
static const double N[6] = {1.691002, 1, 1.672707, 1, 1.691002, 1};

/* The closed form: surfaces s0..s1 moved together (axis 0 x, 1 y; tilt theta radians
 * about that axis, decentre d): the image height of the on-axis chief ray. */
static double own_bore(int s0, int s1, int tilt, int axis, double v)
{
    double z[6], e[6] = {0}, th[6] = {0}, zz = 0;
    for (int i = 0; i < 6; i++) { z[i] = zz; zz += T[i]; }
    /* tilt about x turns +z toward -y (right-handed): vertex at z moves by -z theta in y,
     * a centre of curvature by -R theta; about y toward +x: +z theta, +R theta */
    double sgn = tilt && axis == 0 ? -1 : 1;
    for (int j = s0; j <= s1; j++) {
        if (tilt) { e[j] = sgn * (z[j] - z[s0]) * v; th[j] = v; }
        else e[j] = v;
    }
    /* the ray for entering height y0: linear in y0 */
    double ys[2], yi[2];
    for (int pass = 0; pass < 2; pass++) {
        double y = pass, nu = 0, n0 = 1;
        for (int i = 0; i < 6; i++) {
            double phi = (N[i] - n0) / R[i];
            if (i == 2) ys[pass] = y - e[i];         /* stop: its own centre */
            nu = nu - y * phi + e[i] * phi + sgn * (N[i] - n0) * th[i];
            n0 = N[i];
            y += T[i] * nu / n0;
        }
        yi[pass] = y;
    }
    /* y_stop(y0) = ys0 + (ys1 - ys0) y0 = 0 */
    double y0 = -ys[0] / (ys[1] - ys[0]);
    return yi[0] + (yi[1] - yi[0]) * y0;
}

static void closed_form(void)
{
    char text[4096], err[DS_ERR_MAX];
    snprintf(text, sizeof text, "%s%s", triplet,
             "tol tx all 0.005\ntol ty all 0.005\ntol dx all 0.001\ntol dy all 0.001\n"
             "tol tx 1-2 0.005\ntol ty 5-6 0.005\ntol dy 3-4 0.001\ntol tedx 1-2 0.001\n");
    ds_problem *p = dsu_problem(text, err, sizeof err);
    CHECK(p != NULL, "triplet with tilts read: %s", p ? "" : err);
    if (!p) return;
    ds_tol_opts o;
    ds->tol_defaults(p, &o);
    o.compensate = 0;
    int nt = ds->ntol(p), n = 0;
    double big = 0, worst = 0, a_eng[64], a_own[64];
    CHECK(nt == 24 + 4, "28 tolerances: tx ty dx dy of 6 surfaces and 4 element ones (got %d)", nt);
    for (int i = 0; i < nt && i < 64; i++) {
        ds_tol_info ti;
        ds_crit a, b;
        ds->tol_info(p, i, &ti);
        int tilt = ti.name[0] == 't', axis = ti.name[1] == 'y', s0 = 0, s1 = 0;
        if (sscanf(ti.name + 3, "%d-%d", &s0, &s1) < 2) s1 = s0;
        s0--; s1--;
        ds->tol_one(p, &o, i, -1, &a);
        ds->tol_one(p, &o, i, 1, &b);
        double v = tilt ? ti.delta * PI_ / 180 : ti.delta;
        int moved = tilt ? !axis : axis;          /* a tilt about x moves the image in y */
        double eng = (b.bore[moved] - a.bore[moved]) / 2, other = (b.bore[!moved] - a.bore[!moved]) / 2;
        double own = (own_bore(s0, s1, tilt, axis, v) - own_bore(s0, s1, tilt, axis, -v)) / 2;
        a_eng[n] = eng;
        a_own[n++] = own;
        big = fmax(big, fabs(own));
        if (fabs(other) > 1e-12) printf("FAIL %s: the other coordinate moved %g\n", ti.name, other);
        CHECK(a.ok && b.ok && fabs(other) <= 1e-12, "%s: boresight %+.9f um at +%g (own %+.9f)",
              ti.name, eng * 1e3, ti.delta, own * 1e3);
    }
    for (int i = 0; i < n; i++)
        if (fabs(a_own[i]) > 0.05 * big) worst = fmax(worst, fabs(a_eng[i] / a_own[i] - 1));
        else worst = fmax(worst, fabs(a_eng[i] - a_own[i]) / (0.05 * big));
    printf("closed form: worst relative error %.3g\n", worst);
    CHECK(worst < 1e-5, "boresight sensitivities of %d tilts and decentres against the "
          "first-order closed form: worst relative error %.3g", n, worst);
    ds->free(p);
}

static void monte_carlo(void)
{
    char text[4096], err[DS_ERR_MAX];
    snprintf(text, sizeof text, "%s%s", triplet,
             "tol tx all 0.03\ntol ty all 0.03\ntol dx all 0.015\ntol dy all 0.015\n");
    ds_problem *p = dsu_problem(text, err, sizeof err);
    CHECK(p != NULL, "triplet with tilt tolerances read: %s", p ? "" : err);
    if (!p) return;
    ds_tol_opts o;
    ds->tol_defaults(p, &o);
    o.compensate = 1;
    o.dist = 0;
    ds_crit c0;
    ds->tol_nominal(p, &o, &c0);
    double vx = 0, vy = 0, r2 = c0.rms * c0.rms;
    for (int i = 0; i < ds->ntol(p); i++) {
        ds_crit a, b;
        ds->tol_one(p, &o, i, -1, &a);
        ds->tol_one(p, &o, i, 1, &b);
        vx += pow((b.bore[0] - a.bore[0]) / 2, 2) / 3;
        vy += pow((b.bore[1] - a.bore[1]) / 2, 2) / 3;
        r2 += ((a.rms * a.rms + b.rms * b.rms) / 2 - c0.rms * c0.rms) / 3;
    }
    int M = 2000, bad = 0;
    double sx = 0, sx2 = 0, sy = 0, sy2 = 0, q = 0, q2 = 0;
    for (int k = 1; k <= M; k++) {
        ds_crit c;
        ds->tol_mc(p, &o, 11, k, &c);
        if (!c.ok) { bad++; continue; }
        sx += c.bore[0]; sx2 += c.bore[0] * c.bore[0];
        sy += c.bore[1]; sy2 += c.bore[1] * c.bore[1];
        q += c.rms * c.rms; q2 += pow(c.rms, 4);
    }
    int m = M - bad;
    double mx = sx / m, my = sy / m, mq = q / m;
    double sdx = sqrt((sx2 - m * mx * mx) / (m - 1)), sdy = sqrt((sy2 - m * my * my) / (m - 1));
    double seq = sqrt((q2 - m * mq * mq) / (m - 1) / m);
    CHECK(bad == 0, "Monte Carlo of %d tilted and decentred triplets: every ray traced", M);
    printf("monte carlo: bore sd x %.6g y %.6g um, linear %.6g %.6g um; mean rms^2 %.6g, "
           "second order %.6g um^2 (se %.3g)\n", sdx * 1e3, sdy * 1e3, sqrt(vx) * 1e3,
           sqrt(vy) * 1e3, mq * 1e6, r2 * 1e6, seq * 1e6);
    CHECK(fabs(sdx / sqrt(vx) - 1) < 0.05 && fabs(sdy / sqrt(vy) - 1) < 0.05,
          "Monte Carlo boresight sd x %.5g, y %.5g um against the RSS of the sensitivities "
          "%.5g, %.5g um (ratios %.4f, %.4f; 5 %%: 3 standard errors)", sdx * 1e3, sdy * 1e3,
          sqrt(vx) * 1e3, sqrt(vy) * 1e3, sdx / sqrt(vx), sdy / sqrt(vy));
    CHECK(fabs(mx) < 4 * sdx / sqrt(m) && fabs(my) < 4 * sdy / sqrt(m),
          "Monte Carlo boresight mean (%.4g, %.4g) um: zero within 4 standard errors", mx * 1e3,
          my * 1e3);
    CHECK(fabs(mq - r2) < 4 * seq, "Monte Carlo mean RMS^2 %.6g um^2 against the second-order "
          "prediction %.6g um^2 (standard error %.3g)", mq * 1e6, r2 * 1e6, seq * 1e6);
    ds->free(p);
}

/* A singlet (f about 100) then 30 mm to a flat mirror at 45 degrees, L to the image. */
static const char *folded =
    "thickness\nwavelengths d\nepd 10\nfield angle 0 3\n"
    "%s    4     1.5168 stop\n"
    "%s    30    air\n"
    "coordbrk 0 tilt 45 0 0\n"
    "plane 0 air mirror\n"
    "coordbrk %s tilt 45 0 0\n";
static const char *straight =
    "thickness\nwavelengths d\nepd 10\nfield angle 0 3\n"
    "%s    4     1.5168 stop\n"
    "%s    %s    air\n";

static void fold_tilt(void)
{
    char text[4096], err[DS_ERR_MAX];
    double L = 66.0;
    snprintf(text, sizeof text, folded, "102", "-102", "-66");
    strcat(text, "tol tx 4 0.01\ntol ty 4 0.01\ntol r 1 0.5\ntol t 2 0.1\n");
    ds_problem *p = dsu_problem(text, err, sizeof err);
    CHECK(p != NULL, "singlet with a 45-degree fold read: %s", p ? "" : err);
    if (!p) return;
    ds_tol_opts o;
    ds->tol_defaults(p, &o);
    o.compensate = 0;
    for (int i = 0; i < 2; i++) {
        ds_crit a, b;
        ds_tol_info ti;
        ds->tol_info(p, i, &ti);
        ds->tol_one(p, &o, i, -1, &a);
        ds->tol_one(p, &o, i, 1, &b);
        double th = ti.delta * PI_ / 180, eng = fabs(b.bore[!i] - a.bore[!i]) / 2;
        double own = i == 0 ? L * tan(2 * th) : L * tan(2 * cos(PI_ / 4) * th);
        /* about y the second order of the compound rotation is below 1e-6 relative */
        CHECK(a.ok && b.ok && fabs(eng / own - 1) < 2e-6, "fold mirror %s %g deg: image moves "
              "%.9f um, closed form %.9f um (%s)", ti.name, ti.delta, eng * 1e3, own * 1e3,
              i == 0 ? "L tan 2theta" : "L tan(2 cos45 theta)");
    }
    /* the folded lens's criteria are the straight one's */
    ds_crit f, s;
    o.compensate = 1;
    ds->tol_nominal(p, &o, &f);
    ds_problem *q;
    snprintf(text, sizeof text, straight, "102", "-102", "96");
    q = dsu_problem(text, err, sizeof err);
    CHECK(q != NULL, "the same singlet straight read: %s", q ? "" : err);
    if (!q) { ds->free(p); return; }
    ds->tol_nominal(q, &o, &s);
    CHECK(f.ok && s.ok && fabs(f.rms / s.rms - 1) < 1e-9 && fabs(f.efl - s.efl) < 1e-9 &&
          fabs(f.bfd - (s.bfd - 30)) < 1e-9 && fabs(f.focus - s.focus) < 1e-9,
          "folded = straight: RMS %.9g / %.9g um, efl %.9g / %.9g, bfd (from the mirror) %.9g / %.9g - 30, refocus "
          "%.9g / %.9g mm", f.rms * 1e3, s.rms * 1e3, f.efl, s.efl, f.bfd, s.bfd, f.focus, s.focus);
    ds->free(q);
    ds->free(p);
}

static double optimise(const char *text, double *vals, int nv, char *err, size_t cap)
{
    ds_problem *p = dsu_problem(text, err, cap);
    ds_opt_result r;
    double m = NAN;
    if (!p) return NAN;
    if (ds->optimise(p, 200, NULL, NULL, NULL, &r, err, cap) == DS_OK) m = r.merit;
    for (int i = 0; i < nv && i < ds->nvar(p); i++) {
        ds_var_info v;
        ds->var_info(p, i, &v);
        vals[i] = v.value;
    }
    ds->free(p);
    return m;
}

static void folded_opt(void)
{
    char err[DS_ERR_MAX];
    double k[1] = {0};
    /* classical Cassegrain (t_45's): primary R -400 k -1, secondary 150 in front */
    double m = optimise("thickness\nwavelengths d\nepd 100\nfield angle 0\nindex air\n"
                        "-400  -150  air  conic -1  mirror  stop\n"
                        "-125   250  air  conic 0   mirror\n"
                        "vary k 2\ntarget rms 0 field 1\n", k, 1, err, sizeof err);
    CHECK(isfinite(m) && fabs(k[0] + 2.25) < 1e-6, "Cassegrain: the secondary's conic for the "
          "least spot %.9f, closed form -((m+1)/(m-1))^2 = -2.25 (merit %.3g)", k[0], m);
    double a[3], b[3];
    char t1[4096], t2[4096];
    const char *mf = "vary c 1\nvary c 2\nvary t %d\ntarget efl 100\ntarget rms 0 field all\n";
    snprintf(t1, sizeof t1, folded, "90", "-150", "-60");
    snprintf(t1 + strlen(t1), sizeof t1 - strlen(t1), mf, 5);
    snprintf(t2, sizeof t2, straight, "90", "-150", "90");
    snprintf(t2 + strlen(t2), sizeof t2 - strlen(t2), mf, 2);
    double m1 = optimise(t1, a, 3, err, sizeof err), m2 = optimise(t2, b, 3, err, sizeof err);
    CHECK(isfinite(m1) && fabs(m1 - m2) <= 1e-9 * m2 && fabs(a[0] - b[0]) < 1e-8 &&
          fabs(a[1] - b[1]) < 1e-8 && fabs(-a[2] - (b[2] - 30)) < 1e-5,
          "singlet optimised through a 45-degree fold: merit %.9g (straight %.9g), c %.9g %.9g "
          "(straight %.9g %.9g), mirror to image %.6f (straight %.6f - 30)", m1, m2, a[0], a[1],
          b[0], b[1], -a[2], b[2]);
}

int main(void)
{
    dsu_init();
    closed_form();
    monte_carlo();
    fold_tilt();
    folded_opt();
    return unit_failed();
}
