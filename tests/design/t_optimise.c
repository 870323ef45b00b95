/* t_optimise.c -- damped least squares against closed forms.
 *  - A thin singlet's bending for least spherical aberration (object at infinity):
 *    Hecht's / Welford's thin-lens third-order form, shape factor
 *    q = (c1 + c2)/(c1 - c2) = 2 (n^2 - 1)/(n + 2) (R1 : R2 = 1 : -6 at n = 1.5),
 *    reached both through the Seidel operand (spha; 0.01 mm thick: |dq| < 1e-4) and
 *    through real-ray RMS spots at f/20 with the image plane free (0.3 mm thick, so
 *    the edge stays positive: the thickness and the fifth order move q by ~1e-3).
 *  - A thin cemented achromat: phi1/V1 + phi2/V2 = 0 with phi1 + phi2 = 1/f, so
 *    phi1 = phi V1/(V1 - V2); with zero thicknesses this is exact paraxially (model
 *    glasses have nF - nC = (nd - 1)/Vd by construction).
 *  - The Gaussian-quadrature RMS spot of Sasian's triplet on axis at d against the
 *    trace engine's dense-grid figure (999 332 rays, README "Published triplet":
 *    12.286 um; a different sampling, a different code path).
 *  - Refusals name FILE:LINE. */
#include "dsu.h"

static double shape(ds_problem *p, double *c1, double *c2)
{
    ds_var_info a, b;
    ds->var_info(p, 0, &a);
    ds->var_info(p, 1, &b);
    *c1 = a.value;
    *c2 = b.value;
    return (a.value + b.value) / (a.value - b.value);
}

static void singlet(const char *op, double tol)
{
    char text[2048], err[DS_ERR_MAX];
    ds_opt_result r;
    double n = 1.5, q0 = 2 * (n * n - 1) / (n + 2), c1, c2;
    int sp = !strcmp(op, "spha"), rw = !strcmp(op, "rmsw");
    /* start: equi-convex f ~ 100; rms: the image plane free; spha, rmsw: at the
     * paraxial focus (thickness 0 after the last surface) */
    snprintf(text, sizeof text,
             "thickness\nwavelengths d\nepd %s\nfield angle 0\n"
             "100 %s 1.5 stop\n-100 %s air\n"
             "vary c 1\nvary c 2\n%s"
             "target efl 100 weight 1\n%s\n",
             sp ? "20" : "5", sp ? "0.01" : "0.3", sp || rw ? "0" : "100",
             sp || rw ? "" : "vary t 2\n",
             sp ? "target spha 0 weight 1" :
             rw ? "target rmsw 0 field 1 weight 1\ndesign rings 6 arms 6" :
                  "target rms 0 field 1 weight 1\ndesign rings 6 arms 6");
    ds_problem *p = dsu_problem(text, err, sizeof err);
    CHECK(p != NULL, "singlet (%s) read: %s", op, p ? "" : err);
    if (!p) return;
    int rc = ds->optimise(p, 200, NULL, NULL, NULL, &r, err, sizeof err);
    double q = shape(p, &c1, &c2);
    CHECK(rc == DS_OK, "singlet (%s) optimised: %d iterations, merit %.3g -> %.3g (reason %d)", op,
          r.iterations, r.merit0, r.merit, r.reason);
    CHECK(fabs(q - q0) < tol, "singlet (%s): shape factor %.6f, thin-lens closed form %.6f "
          "(R1 %.4f, R2 %.4f; |dq| %.2g < %g)", op, q, q0, 1 / c1, 1 / c2, fabs(q - q0), tol);
    CHECK(fabs(1 / c2 / (1 / c1) + 6) < 60 * tol, "singlet (%s): R2/R1 = %.5f (-6 at n 1.5)", op,
          c1 / c2);
    ds->free(p);
}

static void achromat(void)
{
    char err[DS_ERR_MAX];
    const char *text =
        "thickness\nwavelengths d F C\nepd 5\nfield angle 0\n"
        "50 0 1.5168/64.17 stop\n-40 0 1.62/36.37\n-300 0 air\n"
        "vary c 2\nvary c 3\ntarget efl 100\ntarget axcl 0\n";
    ds_opt_result r;
    ds_problem *p = dsu_problem(text, err, sizeof err);
    CHECK(p != NULL, "achromat read: %s", p ? "" : err);
    if (!p) return;
    int rc = ds->optimise(p, 200, NULL, NULL, NULL, &r, err, sizeof err);
    ds_var_info a, b;
    ds->var_info(p, 0, &a);
    ds->var_info(p, 1, &b);
    double V1 = 64.17, V2 = 36.37, phi = 0.01, c1 = 1 / 50.0;
    double phi1 = phi * V1 / (V1 - V2), phi2 = -phi * V2 / (V1 - V2);
    double c2 = c1 - phi1 / 0.5168, c3 = c2 - phi2 / 0.62;
    CHECK(rc == DS_OK && r.merit < 1e-9, "achromat: merit %.3g after %d iterations (reason %d)", r.merit,
          r.iterations, r.reason);
    CHECK(fabs(a.value - c2) < 1e-9 * fabs(c2) + 1e-13, "achromat: c2 %.12g, closed form %.12g",
          a.value, c2);
    CHECK(fabs(b.value - c3) < 1e-9 * fabs(c3) + 1e-13, "achromat: c3 %.12g, closed form %.12g",
          b.value, c3);
    /* the test's own y-nu trace at F and C (model glass: n = A + B/l^2 through nd with
     * nF - nC = (nd - 1)/Vd) agrees that the focus does not move */
    double cc[3] = {c1, a.value, b.value}, t[3] = {0, 0, 0}, nF[3], nC[3], e, bF, bC;
    double lF = 0.4861327, ld = 0.5875618, lC = 0.6562725, nd[2] = {1.5168, 1.62}, Vd[2] = {V1, V2};
    for (int i = 0; i < 2; i++) {
        double B = (nd[i] - 1) / Vd[i] / (1 / (lF * lF) - 1 / (lC * lC)), A = nd[i] - B / (ld * ld);
        nF[i] = A + B / (lF * lF);
        nC[i] = A + B / (lC * lC);
    }
    nF[2] = nC[2] = 1;
    dsu_yn(3, cc, t, nF, &e, &bF);
    dsu_yn(3, cc, t, nC, &e, &bC);
    CHECK(fabs(bF - bC) < 1e-9, "achromat: the test's own trace: bfd(F) - bfd(C) = %.3g", bF - bC);
    ds->free(p);
}

static void quadrature(void)
{
    char err[DS_ERR_MAX], *s = dsu_slurp("doc/design/sasian-triplet.rx");
    CHECK(s != NULL, "doc/design/sasian-triplet.rx read");
    if (!s) return;
    /* only the lens: the merit replaced by one operand, d only, 16 rings */
    char *cut = strstr(s, "# the merit:");
    if (cut) *cut = '\0';
    strcat(s, "target rms 0 field 1 wave 1\ndesign rings 16 arms 8 aim paraxial\n");
    ds_problem *p = dsu_problem(s, err, sizeof err);
    CHECK(p != NULL, "sasian read: %s", p ? "" : err);
    if (p) {
        double m;
        ds_op_info o;
        CHECK(ds->merit(p, &m, err, sizeof err) == DS_OK, "sasian merit");
        ds->op_info(p, 0, &o);
        CHECK(fabs(o.value * 1000 - 12.286) < 0.0015,
              "sasian on axis at d: RMS %.4f um by 16-ring quadrature, 12.286 by the dense grid",
              o.value * 1000);
        ds->free(p);
    }
    free(s);
}

/* The RMS wavefront of pure third-order spherical aberration at the paraxial focus:
 * W = W040 rho^4 with W040 = SI/8 (Welford), piston removed: RMS = W040 sqrt(1/5 -
 * 1/9) = W040 sqrt(4/45).  An f/20 singlet, where the fifth order is ~1e-3 of it. */
static void wavefront(void)
{
    char err[DS_ERR_MAX];
    const char *text = "thickness\nwavelengths d\nepd 5\nfield angle 0\n58.33 0.3 1.5 stop\n"
                       "-350 0 air\ntarget spha 0\ntarget rmsw 0 field 1\ndesign rings 8 arms 6\n";
    ds_problem *p = dsu_problem(text, err, sizeof err);
    CHECK(p != NULL, "wavefront singlet read: %s", p ? "" : err);
    if (!p) return;
    double m;
    ds_op_info si, w;
    CHECK(ds->merit(p, &m, err, sizeof err) == DS_OK, "wavefront singlet merit");
    ds->op_info(p, 0, &si);
    ds->op_info(p, 1, &w);
    double pred = sqrt(4.0 / 45) * fabs(si.value) / 8 / 0.5875618e-3;
    CHECK(fabs(w.value / pred - 1) < 0.01, "RMS wavefront %.6g waves, third order SI/8 sqrt(4/45) "
          "= %.6g waves (ratio %.5f)", w.value, pred, w.value / pred);
    ds->free(p);
}

/* A plano-convex lens, plane side to a collimated beam: the beam meets the curved exit
 * surface undeviated and is focused without aberration by a hyperboloid of conic
 * k = -n^2 (the Cartesian oval from glass into air).  Varying k alone (image at the
 * paraxial focus) must find it; an even asphere on the sphere instead must find the
 * hyperboloid's r^4 term, a4 = k c^3 / 8 (with a6 free to take the next order). */
static void conic(void)
{
    char err[DS_ERR_MAX];
    const char *tk = "thickness\nwavelengths d\nepd 10\nfield angle 0\nplane 4 1.5 stop\n"
                     "-25 0 air\nvary k 2\ntarget rms 0 field 1\ndesign rings 6 arms 6\n";
    const char *ta = "thickness\nwavelengths d\nepd 4\nfield angle 0\nplane 4 1.5 stop\n"
                     "-25 0 air\nvary a4 2\nvary a6 2\ntarget rms 0 field 1\ndesign rings 8 arms 6\n";
    ds_opt_result r;
    ds_var_info v;
    ds_problem *p = dsu_problem(tk, err, sizeof err);
    CHECK(p != NULL, "plano-hyperbolic read: %s", p ? "" : err);
    if (!p) return;
    ds->optimise(p, 200, NULL, NULL, NULL, &r, err, sizeof err);
    ds->var_info(p, 0, &v);
    CHECK(fabs(v.value + 2.25) < 1e-6 && r.merit < 1e-9, "conic found %.9f, -n^2 = -2.25 "
          "(merit %.3g)", v.value, r.merit);
    ds->free(p);
    p = dsu_problem(ta, err, sizeof err);
    CHECK(p != NULL, "aspheric read: %s", p ? "" : err);
    if (!p) return;
    ds->optimise(p, 200, NULL, NULL, NULL, &r, err, sizeof err);
    ds->var_info(p, 0, &v);
    double c = -1 / 25.0, a4 = -2.25 * c * c * c / 8;
    CHECK(fabs(v.value / a4 - 1) < 0.01, "a4 found %.6g, the hyperboloid's k c^3/8 = %.6g "
          "(merit %.3g -> %.3g)", v.value, a4, r.merit0, r.merit);
    ds->free(p);
}

/* A model glass pushed off the glass map: efl 10 from R +-50 needs nd 3.5; the
 * glass map (the convex hull of the catalogue's glasses) holds nd at its edge for
 * Vd 64.17: on the map, and below 2.1 (no crown of Vd 64 in any catalogue comes near). */
static void glassmap(void)
{
    char err[DS_ERR_MAX];
    const char *t = "thickness\nwavelengths d\nepd 2\nfield angle 0\n50 3 1.5168/64.17 stop\n"
                    "-50 0 air\nvary nd 1\ntarget efl 10\n";
    ds_opt_result r;
    ds_var_info v;
    ds_op_info g;
    double m;
    ds_problem *p = dsu_problem(t, err, sizeof err);
    CHECK(p != NULL, "glass map read: %s", p ? "" : err);
    if (!p) return;
    ds->optimise(p, 300, NULL, NULL, NULL, &r, err, sizeof err);
    ds->merit(p, &m, err, sizeof err);
    ds->var_info(p, 0, &v);
    ds->op_info(p, 0, &g);
    CHECK(!strcmp(g.name, "max glassmap surface 1") && g.value < 2e-3 && v.value > 1.6 && v.value < 2.1,
          "nd %.5f at Vd 64.17: %.2g outside the catalogue's glass map (%s)", v.value, g.value, g.name);
    ds->free(p);
}

/* Edge and centre thickness against the sphere's sag at the semi-diameter, done
 * here: R +-50, semi 10: t - 2 (50 - sqrt(2500 - 100)). */
static void thickness_ops(void)
{
    char err[DS_ERR_MAX];
    const char *t = "thickness\nepd 2\n50 5 1.5 semi 10\n-50 0 air semi 8\n"
                    "target et 0 surface 1\ntarget ct 0 surface 1\n";
    double m;
    ds_op_info a, b;
    ds_problem *p = dsu_problem(t, err, sizeof err);
    CHECK(p != NULL, "et/ct read: %s", p ? "" : err);
    if (!p) return;
    ds->merit(p, &m, err, sizeof err);
    ds->op_info(p, 0, &a);
    ds->op_info(p, 1, &b);
    double et = 5 - 2 * (50 - sqrt(2500.0 - 100));
    CHECK(fabs(a.value - et) < 1e-12 && b.value == 5, "et %.15g (sags: %.15g), ct %g", a.value, et, b.value);
    ds->free(p);
}

static void refusals(void)
{
    char err[DS_ERR_MAX];
    static const struct { const char *text, *msg; } bad[] = {
        {"thickness\nepd 2\n50 2 1.5\n-50 0 air\nvary c 9\n", "test.rx:5: '9': give a surface number from 1 to 2"},
        {"thickness\nepd 2\n50 2 1.5\n-50 0 air\nvary q 1\n", "test.rx:5: 'q' is not a variable"},
        {"thickness\nepd 2\n50 2 1.5\n-50 0 air\ntarget efl x\n", "test.rx:5: 'x' is not a number"},
        {"thickness\nepd 2\n50 2 1.5\n-50 0 air\ntarget rms 0\n", "test.rx:5: rms needs the lens's fields"},
        {"thickness\nepd 2\n50 2 1.5\n-50 0 air\nvary t 1\nvary t 1\n", "test.rx:6: this variable is already varied (line 5)"},
        {"thickness\nepd 2\n50 2 1.5\n-50 0 air\nvary glass 2\n", "test.rx:5: surface 2: the medium to vary"},
        {"thickness\nepd 2\n50 2 1.5\n-50 0 air\ntol tilt 1 0.1\n", "test.rx:5: 'tilt' is not a tolerance"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
        ds_problem *p = dsu_problem(bad[i].text, err, sizeof err);
        CHECK(!p && strstr(err, bad[i].msg), "refused with '%s' (got '%s')", bad[i].msg, p ? "accepted" : err);
        if (p) ds->free(p);
    }
}

int main(void)
{
    dsu_init();
    refusals();
    achromat();
    singlet("spha", 1e-4);
    singlet("rms", 3e-3);
    singlet("rmsw", 3e-3);
    wavefront();
    conic();
    glassmap();
    thickness_ops();
    quadrature();
    return unit_failed();
}
