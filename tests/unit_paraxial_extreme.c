/* unit_paraxial_extreme.c -- the paraxial engine on extreme prescriptions, one table
 * row each with its asserted outcome: afocal or not, the effective focal length, the
 * image of an object plane and its magnification, which results must be flagged
 * ill-conditioned, and |det - 1| at rounding level for every system.  Expected values
 * come from independent arithmetic: closed forms (thick-lens formulas of section 9,
 * lens maker's equation, Newton's x x' = -F1 F2, ball lens) and a vergence trace
 * (Gauss's formula of section 4 applied surface after surface in long double), never
 * from the engine itself. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "unit.h"
#include "paraxial/paraxial.h"

#define MAXS 8
#define NOVAL NAN
enum { ANY = -1 };

typedef struct surf { double r, z, n; } surf;    /* radius, position, index right */

typedef struct xcase {
    const char *name;
    double n_obj;
    int ns;
    surf s[MAXS];
    void (*build)(px_system *s, double param);   /* instead of s[]: generated systems */
    double param;
    double z_obj;        /* NOVAL: no object */
    int want_afocal;     /* 0, 1 */
    double efl;          /* expected -1/C (NOVAL: by vergence trace; INFINITY: skip) */
    double efl_tol;      /* relative */
    double z_img;        /* expected image (NOVAL: by vergence trace; INFINITY: at inf) */
    double mag;          /* expected lateral magnification (NOVAL: by vergence trace) */
    double img_tol;      /* relative to max(|z_img|, |z_obj|, 1) and to |mag| */
    int want_ill;        /* some checked result flagged ill-conditioned: 0, 1, ANY */
} xcase;

/* ---- independent references -------------------------------------------------- */

/* Vergence trace (section 4, Gauss: n2/z2 = n1/z1 + (n2 - n1)/R, z relative to the
 * surface): reduced vergence V = n/z of the axial image point, in long double.
 * Returns the final image z (INFINITY when V = 0) and the lateral magnification. */
static long double vergence_trace(const xcase *x, long double *mag)
{
    long double n1 = x->n_obj, v, z_img_rel, m = 1;
    long double zo = x->z_obj - x->s[0].z;       /* object relative to surface 1 */
    v = n1 / zo;
    for (int i = 0; i < x->ns; i++) {
        long double n2 = x->s[i].n, p = 0, v2;
        if (isfinite(x->s[i].r) && x->s[i].r != 0) p = (n2 - n1) / (long double)x->s[i].r;
        v2 = v + p;
        m *= v / v2;
        if (i + 1 < x->ns) {
            long double t = (long double)x->s[i + 1].z - x->s[i].z;
            v = v2 / (1 - t * v2 / n2);         /* V' = n2/(z2 - t) */
        } else {
            v = v2;
        }
        n1 = n2;
    }
    *mag = m;
    z_img_rel = n1 / v;
    return x->s[x->ns - 1].z + z_img_rel;
}

/* Section 9: thick lens in air, n, R1, R2, t: -1/C. */
static double thick_efl(double n, double r1, double r2, double t)
{
    return n * r1 * r2 / ((n - 1) * (n * (r2 - r1) + t * (n - 1)));
}

/* -1/C from a y-nu ray trace of the ray (1, 0) in long double (section 9's closed
 * form for a lens in air). */
static double ref_efl(const xcase *x)
{
    long double y = 1, nu = 0, n = x->n_obj;
    if (x->ns == 2 && x->n_obj == 1 && x->s[1].n == 1)
        return thick_efl(x->s[0].n, x->s[0].r, x->s[1].r, x->s[1].z - x->s[0].z);
    for (int i = 0; i < x->ns; i++) {
        if (i) y += ((long double)x->s[i].z - x->s[i - 1].z) / n * nu;
        if (isfinite(x->s[i].r) && x->s[i].r != 0)
            nu += y * (n - x->s[i].n) / (long double)x->s[i].r;
        n = x->s[i].n;
    }
    return (double)(-1 / nu);
}

/* ---- generated systems ------------------------------------------------------- */

/* Thin lenses of focal length f (r = +-f, n = 1.5) spaced 2f: a relay; param lenses. */
static void build_relay(px_system *s, double nlens)
{
    double f = 37.3;
    for (int i = 0; i < (int)nlens; i++) {
        px_system_translate(s, i * 2 * f);
        px_system_refract(s, f, 1.5);
        px_system_refract(s, -f, 1.0);
    }
}

/* Random surfaces: entries grow without bound (1e58 after 10 000 surfaces). */
static void build_random(px_system *s, double nsurf)
{
    double z = 0;
    srand(7);
    for (int i = 0; i < (int)nsurf; i++) {
        double r = (50 + 450 * (rand() / (double)RAND_MAX)) * (rand() % 2 ? 1 : -1);
        px_system_translate(s, z);
        px_system_refract(s, r, 1 + rand() / (double)RAND_MAX);
        z += 0.1 + 2 * (rand() / (double)RAND_MAX);
    }
}

/* ---- the table ------------------------------------------------------------------ */

#define N15 1.5
static const xcase cases[] = {
    {"thin convex lens, object at -2 (virtual image, section 13)", 1, 2,
     {{3, 0, N15}, {-3, 0, 1}}, 0, 0, -2, 0, 3, 1e-14, -6, 3, 1e-14, 0},
    {"thin convex lens, object at -4 (real image)", 1, 2,
     {{3, 0, N15}, {-3, 0, 1}}, 0, 0, -4, 0, 3, 1e-14, 12, -3, 1e-14, 0},
    {"object exactly in the first focal plane", 1, 2,
     {{3, 0, N15}, {-3, 0, 1}}, 0, 0, -3, 0, 3, 1e-14, INFINITY, NOVAL, 0, ANY},
    {"object 1e-9 from the focal plane: finite, flagged", 1, 2,
     {{3, 0, N15}, {-3, 0, 1}}, 0, 0, -3 - 1e-9, 0, 3, 1e-14, NOVAL, NOVAL, 1e-5, 1},
    {"object 1e-3 from the focal plane: accurate", 1, 2,
     {{3, 0, N15}, {-3, 0, 1}}, 0, 0, -3.001, 0, 3, 1e-14, NOVAL, NOVAL, 1e-11, 0},
    {"object at the first surface (d1 = 0)", 1, 2,
     {{3, 0, N15}, {-3, 0, 1}}, 0, 0, 0, 0, 3, 1e-14, 0, 1, 1e-14, 0},
    {"object 1e15 away: image at the focal point", 1, 2,
     {{3, 0, N15}, {-3, 0, 1}}, 0, 0, -1e15, 0, 3, 1e-14, NOVAL, NOVAL, 1e-12, 0},
    {"Figure 4: thick lens r1 = 3, r2 = 4, t = 5, n = 1.4", 1, 2,
     {{3, 0, 1.4}, {4, 5, 1}}, 0, 0, -10, 0, NOVAL, 1e-13, NOVAL, NOVAL, 1e-12, 0},
    {"Figure 5: diverging r1 = -3, r2 = 3, t = 1", 1, 2,
     {{-3, 0, 1.4}, {3, 1, 1}}, 0, 0, -10, 0, NOVAL, 1e-13, NOVAL, NOVAL, 1e-12, 0},
    {"Figure 6: reversed principal planes r1 = 1, r2 = -3, t = 8", 1, 2,
     {{1, 0, 1.4}, {-3, 8, 1}}, 0, 0, -10, 0, NOVAL, 1e-13, NOVAL, NOVAL, 1e-12, 0},
    {"exactly afocal thick lens (t = n(R1-R2)/(n-1)), decimal data", 1, 2,
     {{10.3, 0, 1.517}, {4.7, 1.517 * 5.6 / 0.517, 1}}, 0, 0, -20, 1, INFINITY, 0,
     NOVAL, NOVAL, 1e-12, 0},
    {"afocal Kepler telescope of two thin lenses f = 3 at 0 and 6", 1, 4,
     {{3, 0, N15}, {-3, 0, 1}, {3, 6, N15}, {-3, 6, 1}}, 0, 0, -10, 1, INFINITY, 0,
     2, -1, 1e-14, 0},
    {"nearly afocal telescope f = 100, 10, gap 110.001", 1, 4,
     {{100, 0, N15}, {-100, 0, 1}, {10, 110.001, N15}, {-10, 110.001, 1}}, 0, 0, -1000,
     0, NOVAL, 1e-8, NOVAL, NOVAL, 1e-9, 0},
    {"nearly afocal telescope, gap 110 + 1e-9: focal, flagged", 1, 4,
     {{100, 0, N15}, {-100, 0, 1}, {10, 110 + 1e-9, N15}, {-10, 110 + 1e-9, 1}}, 0, 0,
     NOVAL, 0, INFINITY, 0, INFINITY, NOVAL, 0, 1},
    {"telescope detuned below double's resolution (1e-14): afocal", 1, 4,
     {{100, 0, N15}, {-100, 0, 1}, {10, 110 + 1e-14, N15}, {-10, 110 + 1e-14, 1}}, 0, 0,
     -1000, 1, INFINITY, 0, NOVAL, NOVAL, 1e-10, 0},
    {"total thickness 1e-9 (by position)", 1, 2,
     {{3, 0, N15}, {-3, 1e-9, 1}}, 0, 0, -7, 0, NOVAL, 1e-12, NOVAL, NOVAL, 1e-12, 0},
    {"total thickness 1e6, radii 5e5", 1, 2,
     {{5e5, 0, N15}, {-5e5, 1e6, 1}}, 0, 0, -2e6, 0, NOVAL, 1e-12, NOVAL, NOVAL, 1e-11, 0},
    {"mixed-sign radii: doublet plus meniscus", 1, 6,
     {{12.5, 0, 1.62}, {-8, 1.2, 1.52}, {40, 2.0, 1}, {-6, 5, 1.7}, {-9, 6.5, 1.33},
      {25, 8, 1}}, 0, 0, -30, 0, NOVAL, 1e-13, NOVAL, NOVAL, 1e-11, 0},
    {"identical indices: no surface refracts", N15, 3,
     {{3, 0, N15}, {-7, 2, N15}, {11, 5, N15}}, 0, 0, -10, 1, INFINITY, 0, -10, 1, 1e-14,
     0},
    {"identical indices 1 in air, one plane", 1, 2,
     {{3, 0, 1}, {INFINITY, 4, 1}}, 0, 0, -1, 1, INFINITY, 0, -1, 1, 1e-14, 0},
    {"R = 1e12 single surface", 1, 1,
     {{1e12, 0, N15}}, 0, 0, -1e13, 0, 2e12, 1e-14, NOVAL, NOVAL, 1e-12, 0},
    {"R = 1e12 thin lens", 1, 2,
     {{1e12, 0, N15}, {-1e12, 0, 1}}, 0, 0, -5e11, 0, 1e12, 1e-14, NOVAL, NOVAL, 1e-12,
     0},
    {"glass window of planes: afocal, image shifted by t(1 - 1/n)", 1, 2,
     {{INFINITY, 0, N15}, {0, 10, 1}}, 0, 0, -10, 1, INFINITY, 0, -10 + 10 / 3.0, 1,
     1e-14, 0},
    {"single plane air to water: afocal, apparent depth", 1, 1,
     {{INFINITY, 0, 1.333}}, 0, 0, -10, 1, INFINITY, 0, -13.33, 1, 1e-14, 0},
    {"silicon n = 4.01 single surface (Gauss, unequal media)", 1, 1,
     {{10, 0, 4.01}}, 0, 0, -50, 0, NOVAL, 1e-14, NOVAL, NOVAL, 1e-13, 0},
    {"silicon n = 4.01 thick lens in air", 1, 2,
     {{20, 0, 4.01}, {-20, 5, 1}}, 0, 0, -40, 0, NOVAL, 1e-13, NOVAL, NOVAL, 1e-12, 0},
    {"ball lens n = 2 (back focus on the surface)", 1, 2,
     {{5, 0, 2}, {-5, 10, 1}}, 0, 0, -25, 0, 5, 1e-14, NOVAL, NOVAL, 1e-12, 0},
    {"cemented thin triplet (t = 0 everywhere)", 1, 4,
     {{7, 0, 1.6}, {-5, 0, 1.5}, {9, 0, 1.7}, {-11, 0, 1}}, 0, 0, -40, 0, NOVAL, 1e-13,
     NOVAL, NOVAL, 1e-12, 0},
    {"eye-like: cornea, aqueous, lens, vitreous (unequal media)", 1, 4,
     {{7.7, 0, 1.376}, {6.8, 0.5, 1.336}, {10, 3.6, 1.406}, {-6, 7.2, 1.337}}, 0, 0,
     -250, 0, INFINITY, 0, NOVAL, NOVAL, 1e-12, 0},
    {"water on the left, air on the right", 1.333, 2,
     {{-5, 0, 1.5}, {8, 2, 1}}, 0, 0, -30, 0, NOVAL, 1e-13, NOVAL, NOVAL, 1e-12, 0},
    {"10 000-surface periodic relay (5000 thin lenses 2f apart): afocal", 1, 0, {{0, 0, 0}},
     build_relay, 5000, -10, 1, INFINITY, 0, NOVAL, 1, 1e-10, 0},
    {"1001-surface relay (odd number of cells): focal, f = -37.3", 1, 0, {{0, 0, 0}},
     build_relay, 501, NOVAL, 0, 37.3, 1e-9, NOVAL, NOVAL, 0, 0},
    {"10 000 random surfaces, entries past 1e50", 1, 0, {{0, 0, 0}},
     build_random, 10000, NOVAL, ANY, INFINITY, 0, NOVAL, NOVAL, 0, ANY},
};

/* ---- the runner -------------------------------------------------------------------- */

static int build(const xcase *x, px_system *s)
{
    px_system_init(s, x->n_obj);
    if (x->build) { x->build(s, x->param); return s->err; }
    for (int i = 0; i < x->ns; i++) {
        if (px_system_translate(s, x->s[i].z) < 0) return s->err;
        px_system_refract(s, x->s[i].r, x->s[i].n);
        if (s->err) return s->err;
    }
    return PX_OK;
}

static int rel_ok(double got, double want, double tol, double scale)
{
    return fabs(got - want) <= tol * fmax(fabs(want), scale);
}

static void check_image(const xcase *x, const px_system *s)
{
    px_conj cj;
    int rc = px_conjugate(s, x->z_obj, &cj);
    double want_z = x->z_img, want_m = x->mag;
    long double lm = 0;
    if (isnan(want_z) || isnan(want_m)) {
        long double lz = x->build ? 0 : vergence_trace(x, &lm);
        if (isnan(want_z)) want_z = (double)lz;
        if (isnan(want_m)) want_m = (double)lm;
    }
    if (x->z_img == INFINITY) {
        CHECK(rc == PX_AT_INFINITY && cj.at_infinity, "%s: image at infinity (rc %d)",
              x->name, rc);
        return;
    }
    CHECK(rc == PX_OK, "%s: finite image (rc %d)", x->name, rc);
    if (rc != PX_OK) return;
    if (x->build && isnan(x->z_img)) {
        /* relay: M = [1 -2f; 0 1] from the first to the last lens (see build_relay) */
        double f = 37.3, d1 = s->z_first - x->z_obj;
        want_z = s->z_last - d1 + 2 * f;
    }
    if (isfinite(want_z))
        CHECK(rel_ok(cj.z_img.v, want_z, x->img_tol,
                     fmax(fabs(x->z_obj), fmax(1, fabs(s->z_last)))),
              "%s: image z = %.17g, want %.17g", x->name, cj.z_img.v, want_z);
    if (isfinite(want_m))
        CHECK(rel_ok(cj.lateral.v, want_m, x->img_tol, 0),
              "%s: lateral magnification %.17g, want %.17g", x->name, cj.lateral.v, want_m);
    if (x->want_ill != ANY)
        CHECK(px_ill_conditioned(cj.d2) == x->want_ill,
              "%s: image distance %s ill-conditioned (cond %.3g)", x->name,
              x->want_ill ? "is" : "is not", cj.d2.cond);
    /* Newton's relation x x' = -F1 F2 holds whenever the system is focal */
    if (!px_is_afocal(s) && !x->build) {
        px_first f;
        px_first_order(s, &f);
        double xo = x->z_obj - f.z_f1.v, xi = cj.z_img.v - f.z_f2.v;
        /* what the rounding of the positions allows, then a 1e-12 margin */
        double tol = 8 * DBL_EPSILON * (fabs(xo) * (cj.z_img.sens + f.z_f2.sens) +
                                        fabs(xi) * (f.z_f1.sens + fabs(x->z_obj))) +
                     1e-12 * fabs(f.f_front.v * f.f_back.v);
        CHECK(fabs(xo * xi + f.f_front.v * f.f_back.v) <= tol,
              "%s: Newton x x' = -F1 F2 (%.6g vs %.6g)", x->name, xo * xi,
              -f.f_front.v * f.f_back.v);
    }
}

static void check_first(const xcase *x, const px_system *s)
{
    px_first f;
    int rc = px_first_order(s, &f);
    double scale = fabs(f.m.a * f.m.d) + fabs(f.m.b * f.m.c);
    CHECK(rc == PX_OK, "%s: first-order analysis (rc %d)", x->name, rc);
    CHECK(fabs(f.det - 1) <= 4 * DBL_EPSILON * scale,
          "%s: |det - 1| = %.3g <= 4 eps (|AD| + |BC|) = %.3g", x->name, fabs(f.det - 1),
          4 * DBL_EPSILON * scale);
    if (x->want_afocal != ANY)
        CHECK(f.afocal == x->want_afocal, "%s: %s (C = %.3g)", x->name,
              x->want_afocal ? "afocal" : "focal", f.m.c);
    if (f.afocal) {
        CHECK(isfinite(f.angular.v) && f.angular.v != 0,
              "%s: afocal angular magnification %g", x->name, f.angular.v);
        return;
    }
    if (x->efl != INFINITY) {
        double want = isnan(x->efl) ? ref_efl(x) : x->efl;
        CHECK(rel_ok(f.efl.v, want, x->efl_tol, 0), "%s: efl %.17g, want %.17g", x->name,
              f.efl.v, want);
    }
    if (x->want_ill == 1 && isnan(x->z_obj))
        CHECK(px_ill_conditioned(f.efl), "%s: focal length flagged (cond %.3g)", x->name,
              f.efl.cond);
    if (x->want_ill == 0)
        CHECK(!px_ill_conditioned(f.efl) && !px_ill_conditioned(f.z_h1) &&
                  !px_ill_conditioned(f.z_n2) && !px_ill_conditioned(f.bfd),
              "%s: cardinal points well-conditioned (efl %.3g, h1 %.3g, n2 %.3g, bfd %.3g)",
              x->name, f.efl.cond, f.z_h1.cond, f.z_n2.cond, f.bfd.cond);
    /* identities that hold for any media: N - H = (n_i - n_o)/P on both sides */
    {
        double p = f.power.v, dn = (s->n_img - s->n_obj) / p;
        double tol = 1e-12 * (fabs(dn) + fabs(f.efl.v) + fabs(s->z_last) + 1) +
                     4 * DBL_EPSILON * (f.z_n1.sens + f.z_h1.sens);
        if (!x->build)
            CHECK(fabs((f.z_n1.v - f.z_h1.v) - dn) <= tol &&
                      fabs((f.z_n2.v - f.z_h2.v) - dn) <= tol,
                  "%s: N - H = (n_i - n_o)/P on both sides (%g, %g, want %g)", x->name,
                  f.z_n1.v - f.z_h1.v, f.z_n2.v - f.z_h2.v, dn);
    }
}

static void run_case(const xcase *x)
{
    px_system s;
    int rc = build(x, &s);
    CHECK(rc == PX_OK, "%s: builds (rc %d)", x->name, rc);
    if (rc == PX_OK) {
        check_first(x, &s);
        if (!isnan(x->z_obj)) check_image(x, &s);
    }
    px_system_free(&s);
}

/* ---- cases that are not a prescription with an outcome --------------------------- */

/* Negative thickness entered by mistake, non-positive or NaN index, NaN radius. */
static void test_bad_input(void)
{
    px_system s;
    px_mat before;
    px_system_init(&s, 1);
    px_system_translate(&s, 0);
    px_system_refract(&s, 3, 1.5);
    before = s.m;
    CHECK(px_system_translate(&s, -1) == -1 && s.err == PX_BAD,
          "negative thickness by position: error PX_BAD");
    CHECK(!memcmp(&before, &s.m, sizeof before) && s.z_last == 0 && s.nsteps == 1,
          "negative thickness leaves the system unchanged");
    s.err = 0;
    CHECK(px_system_gap(&s, -0.5) == PX_BAD, "negative thickness by gap: PX_BAD");
    CHECK(px_system_gap(&s, NAN) == PX_BAD, "NaN thickness: PX_BAD");
    CHECK(px_system_surface(&s, 3, 0) == PX_BAD, "index 0: PX_BAD");
    CHECK(px_system_surface(&s, 3, -1.5) == PX_BAD, "negative index: PX_BAD");
    CHECK(px_system_surface(&s, NAN, 1.5) == PX_BAD, "NaN radius: PX_BAD");
    CHECK(px_system_translate(&s, INFINITY) == -1, "infinite position: error");
    {
        px_first f;
        px_conj cj;
        CHECK(px_first_order(&s, &f) == PX_BAD, "an erroneous system reports its error");
        CHECK(px_conjugate(&s, -10, &cj) == PX_BAD, "... also when imaging");
    }
    px_system_free(&s);
}

/* Object exactly in the principal plane H1: image in H2, magnification 1. */
static void test_principal_plane_object(void)
{
    static const double n[] = {1.4, 1.7, 4.01};
    for (int i = 0; i < 3; i++) {
        px_system s;
        px_first f;
        px_conj cj;
        px_system_init(&s, 1);
        px_system_translate(&s, 0);
        px_system_refract(&s, 3, n[i]);
        px_system_translate(&s, 5);
        px_system_refract(&s, 4, 1.2);
        px_first_order(&s, &f);
        px_conjugate(&s, f.z_h1.v, &cj);
        CHECK(fabs(cj.lateral.v - 1) < 1e-13 && fabs(cj.z_img.v - f.z_h2.v) < 1e-12,
              "object at H1 (n %g): image at H2 (%.15g vs %.15g), m = %.15g", n[i],
              cj.z_img.v, f.z_h2.v, cj.lateral.v);
        /* nodal points: unit angular magnification */
        px_conjugate(&s, f.z_n1.v, &cj);
        CHECK(fabs(cj.angular.v - 1) < 1e-13 && fabs(cj.z_img.v - f.z_n2.v) < 1e-12,
              "object at N1 (n %g): image at N2, angular magnification %.15g", n[i],
              cj.angular.v);
        px_system_free(&s);
    }
}

/* A 200-surface chain whose entries reach 1e6: the lateral magnification by
 * 1/(C d1 + D) keeps full accuracy where the equal A + d2 C (the listing's) loses
 * digits.  Reference: the same product and formula in long double. */
static void test_long_chain_magnification(void)
{
    px_system s;
    px_conj cj;
    long double a = 1, b = 0, c = 0, d = 1, n = 1, z = 0;
    double maxe, zo = -40, naive, ref, e_eng, e_naive;
    px_image im;
    srand(11);
    px_system_init(&s, 1);
    for (int i = 0; i < 200; i++) {
        double r = (4 + 8 * (rand() / (double)RAND_MAX)) * (i % 3 ? 1 : -1);
        double n2 = 1.3 + 0.4 * (rand() / (double)RAND_MAX);
        double zz = z + (i ? 0.8 + 4.5 * (rand() / (double)RAND_MAX) : 0);
        long double t = i ? ((long double)zz - z) / n : 0, p = (n - n2) / (long double)r;
        a += t * c; b += t * d;               /* translation */
        c += p * a; d += p * b;               /* refraction */
        px_system_translate(&s, zz);
        px_system_refract(&s, r, n2);
        n = n2; z = zz;
    }
    maxe = fmax(fmax(fabs(s.m.a), fabs(s.m.b)), fmax(fabs(s.m.c), fabs(s.m.d)));
    px_conjugate(&s, zo, &cj);
    px_image_plane(&s, zo, &im);
    naive = im.mag;                           /* A + d2 C, the listing's */
    {
        long double d1 = (0 - (long double)zo) / 1;
        ref = (double)(1 / (c * d1 + d));
    }
    e_eng = fabs(cj.lateral.v - ref) / fabs(ref);
    e_naive = fabs(naive - ref) / fabs(ref);
    CHECK(maxe > 1e5, "200-surface chain: entries reach %.3g", maxe);
    CHECK(e_eng < 1e-13, "1/(C d1 + D): relative error %.3g (condition %.3g)", e_eng,
          cj.lateral.cond);
    CHECK(e_naive > 100 * e_eng, "A + d2 C loses digits: relative error %.3g", e_naive);
    px_system_free(&s);
}

/* The relay's determinant after 10 000 surfaces; random chain's relative to scale. */
static void test_det_drift(void)
{
    px_system s;
    px_first f;
    px_system_init(&s, 1);
    build_relay(&s, 5000);
    px_first_order(&s, &f);
    CHECK(s.nsurf == 10000 && fabs(f.det - 1) < 1e-14,
          "10 000-surface relay: |det - 1| = %.3g (double-double product)", fabs(f.det - 1));
    CHECK(fabs(px_det(s.m) - 1) < 1e-11, "... listing-order product |det - 1| = %.3g",
          fabs(px_det(s.m) - 1));
    px_system_free(&s);
    px_system_init(&s, 1);
    build_random(&s, 10000);
    px_first_order(&s, &f);
    {
        double scale = fabs(f.m.a * f.m.d) + fabs(f.m.b * f.m.c);
        double sc = px_sensitivity(&s, 0, 0, 1, 0);
        CHECK(scale > 1e30 && fabs(f.det - 1) / scale < 4 * DBL_EPSILON,
              "random 10 000: |det - 1|/(|AD| + |BC|) = %.3g, scale %.3g",
              fabs(f.det - 1) / scale, scale);
        CHECK(isfinite(sc) && sc > 0, "random 10 000: sensitivity of C finite (%.3g)", sc);
    }
    px_system_free(&s);
}

/* The old bound (product of |matrices|) overflows on a long relay and calls every
 * long system afocal; the sensitivity bound does not. */
static void test_afocal_bound_scale(void)
{
    px_system s;
    px_system_init(&s, 1);
    build_relay(&s, 501);
    CHECK(!isfinite(s.abs.c) || s.abs.c > 1e100,
          "1002-surface relay: |M| product bound is useless (%.3g)", s.abs.c);
    CHECK(!px_is_afocal(&s), "1002-surface relay with an odd number of cells is focal");
    px_system_free(&s);
}

/* Media and the sensitivities' meaning: perturbing an input by a relative 1e-9 moves a
 * result by no more than 1e-9 * sens (first order, small margin). */
static double f2_of_thickness(double t, px_value *out)
{
    px_system s;
    px_first f;
    px_system_init(&s, 1);
    px_system_translate(&s, 0);
    px_system_refract(&s, 3, 1.4);
    px_system_translate(&s, t);
    px_system_refract(&s, 4, 1);
    px_first_order(&s, &f);
    px_system_free(&s);
    *out = f.z_f2;
    return f.z_f2.v;
}

static void test_sensitivity_bound(void)
{
    px_value v0, v1;
    double eps = 1e-9;
    CHECK(px_medium_index("Water") == 1.333 && px_medium_index("silicon") == 4.01 &&
              px_medium_index("unobtainium") == 0, "media by name");
    f2_of_thickness(5, &v0);
    f2_of_thickness(5 * (1 + eps), &v1);
    CHECK(v0.sens > 0 && fabs(v1.v - v0.v) <= 1.01 * eps * v0.sens,
          "moving surface 2 by a relative 1e-9 moves F2 by %.3g <= 1e-9 sens = %.3g",
          fabs(v1.v - v0.v), eps * v0.sens);
    CHECK(fabs(v1.v - v0.v) >= 0.01 * eps * v0.sens,
          "... and the sensitivity is not a gross overestimate");
}

/* The original's magnifier figure: f = 3, near point 25. */
static void test_nearpoint_angmag(void)
{
    px_system s;
    px_conj c;
    px_system_init(&s, 1);
    px_system_surface(&s, 3, 1.5);
    px_system_surface(&s, -3, 1);
    px_conjugate(&s, -2, &c);    /* virtual image at -6, m = 3: both inside 25 */
    CHECK(fabs(px_nearpoint_angmag(&s, 25, -2, &c) - 3) < 1e-14, "magnifier, image inside "
          "the near point: s1 m/s2 = 25*3/25 = 3");
    px_conjugate(&s, -2.9, &c);  /* virtual image at -87, m = 30 */
    CHECK(fabs(px_nearpoint_angmag(&s, 25, -2.9, &c) - 25 * 30 / 87.0) < 1e-12,
          "magnifier, image beyond the near point: 25*30/87");
    CHECK(px_conjugate(&s, -3, &c) == PX_AT_INFINITY &&
              fabs(px_nearpoint_angmag(&s, 25, -3, &c) - 25 / 3.0) < 1e-14,
          "object in the focal plane: b/f = 8.333");
    px_system_free(&s);
}

/* px_mul_fma against px_mul on a 10 000-matrix relay product: the fma product keeps
 * |det - 1| at least as small. */
static void test_mul_fma(void)
{
    px_mat p = px_identity(), q = px_identity(), t = px_translation(2 * 37.3),
           l = px_refraction(1, 1.5, 37.3), l2 = px_refraction(1.5, 1, -37.3);
    px_mat cell = px_mul(px_mul(t, l2), l);
    for (int i = 0; i < 5000; i++) {
        p = px_mul_fma(cell, p);
        q = px_mul(cell, q);
    }
    CHECK(fabs(px_det_accurate(p) - 1) < 1e-12 &&
              fabs(px_det_accurate(p) - 1) <= fabs(px_det_accurate(q) - 1) + 1e-15,
          "fma product of 5000 relay cells: |det - 1| = %.3g (plain %.3g)",
          fabs(px_det_accurate(p) - 1), fabs(px_det_accurate(q) - 1));
}

int main(void)
{
    test_nearpoint_angmag();
    test_mul_fma();
    size_t n = sizeof cases / sizeof *cases;
    for (size_t i = 0; i < n; i++) run_case(&cases[i]);
    CHECK(n >= 30, "%zu extreme prescriptions in the table", n);
    test_bad_input();
    test_principal_plane_object();
    test_long_chain_magnification();
    test_det_drift();
    test_afocal_bound_scale();
    test_sensitivity_bound();
    return unit_failed();
}
