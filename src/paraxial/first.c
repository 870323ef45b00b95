/* first.c -- the accurate first-order results of a system (cardinal points, focal
 * lengths, power, object/image planes, magnifications), each with its sensitivity
 * to the inputs and its condition number; media by name.  Cancellation-prone sums
 * (1 - D, C d1 + D, A d1 + B, n_o D - n_i) are formed in double-double from the
 * double-double matrix; every quotient is then one rounding. */
#include <float.h>
#include <math.h>
#include <string.h>
#include <strings.h>
#include "paraxial.h"
#include "dd.h"

/* A result v with absolute sensitivity sens.  Its condition is that of the part
 * `rel` (sensitivity rel_sens) that matters: a position's offset from its reference
 * plane, a distance, a ratio; measured against `scale`, the system's length scale,
 * for lengths that may vanish (a principal plane on the surface is not
 * ill-conditioned), 0 for ratios. */
static px_value value_rel(double v, double sens, double rel, double rel_sens, double scale)
{
    px_value r;
    double den = fmax(fabs(rel), scale);
    r.v = v + 0.0;
    r.sens = sens;
    r.cond = rel_sens == 0 ? 0 : (den == 0 ? INFINITY : rel_sens / den);
    return r;
}

static px_value value(double v, double sens) { return value_rel(v, sens, v, sens, 0); }
static px_value length(double v, double sens, double scale)
{
    return value_rel(v, sens, v, sens, scale);
}

/* The system's length scale: its length and focal lengths. */
static double system_scale(const px_system *s, double c)
{
    double l = fabs(s->z_last - s->z_first), f = fmax(s->n_obj, s->n_img) / fabs(c);
    return isfinite(f) ? fmax(l, f) : l;
}

int px_ill_conditioned(px_value v) { return v.cond > PX_ILL_CONDITIONED; }

int px_digits_meaningful(px_value v, int digits)
{
    return DBL_EPSILON * v.cond <= pow(10, -digits);
}

static dd entry(const px_system *s, int i)
{
    dd r = {(&s->hi.a)[i], (&s->lo.a)[i]};
    return r;
}

/* z + num/c as a position, with its sensitivity: z's own, the quotient's through the
 * matrix (gradient g), and `extra` (indices). */
static px_value position(const px_system *s, double z, dd num, double c, const double g[4],
                         double extra, double scale)
{
    double q = dd_val(num) / c, sq = px_sensitivity(s, g[0], g[1], g[2], g[3]) + extra;
    return value_rel(z + q, fabs(z) + sq, q, sq, scale);
}

int px_first_order(const px_system *s, px_first *out)
{
    double no = s->n_obj, ni = s->n_img, z1 = s->z_first, z2 = s->z_last;
    dd A = entry(s, 0), D = entry(s, 3);
    double a, c, d, sc, l;

    memset(out, 0, sizeof *out);
    if (s->err) return s->err;
    out->m.a = dd_val(A);
    out->m.b = dd_val(entry(s, 1));
    out->m.c = dd_val(entry(s, 2));
    out->m.d = dd_val(D);
    out->det = px_det_accurate(out->m);
    a = out->m.a; c = out->m.c; d = out->m.d;
    if (px_is_afocal(s)) {
        out->afocal = 1;
        out->angular = value(d * no / ni, px_sensitivity(s, 0, 0, 0, no / ni) +
                             2 * fabs(d * no / ni));
        return PX_OK;
    }
    sc = px_sensitivity(s, 0, 0, 1, 0);
    l = system_scale(s, c);
    out->power = value(-c, sc);
    out->efl = value(-1 / c, sc / (c * c));
    out->f_front = value(-no / c, no * sc / (c * c) + fabs(no / c));
    out->f_back = value(-ni / c, ni * sc / (c * c) + fabs(ni / c));
    out->ffd = length(-no * d / c, px_sensitivity(s, 0, 0, no * d / (c * c), -no / c) +
                      fabs(no * d / c), l);
    out->bfd = length(-ni * a / c, px_sensitivity(s, -ni / c, 0, ni * a / (c * c), 0) +
                      fabs(ni * a / c), l);
    out->z_f1 = value_rel(z1 - out->ffd.v, fabs(z1) + out->ffd.sens, out->ffd.v,
                          out->ffd.sens, l);
    out->z_f2 = value_rel(z2 + out->bfd.v, fabs(z2) + out->bfd.sens, out->bfd.v,
                          out->bfd.sens, l);
    {
        dd q1 = dd_mul_d(dd_sub(dd_of(1), D), -no);        /* -n_o (1 - D) */
        dd q2 = dd_mul_d(dd_sub(dd_of(1), A), ni);         /* n_i (1 - A) */
        dd q3 = dd_sub(dd_mul_d(D, no), dd_of(ni));        /* n_o D - n_i */
        dd q4 = dd_sub(dd_of(no), dd_mul_d(A, ni));        /* n_o - n_i A */
        double g1[4] = {0, 0, -dd_val(q1) / (c * c), no / c};
        double g2[4] = {-ni / c, 0, -dd_val(q2) / (c * c), 0};
        double g3[4] = {0, 0, -dd_val(q3) / (c * c), no / c};
        double g4[4] = {-ni / c, 0, -dd_val(q4) / (c * c), 0};
        out->z_h1 = position(s, z1, q1, c, g1, fabs(dd_val(q1) / c), l);
        out->z_h2 = position(s, z2, q2, c, g2, fabs(dd_val(q2) / c), l);
        out->z_n1 = position(s, z1, q3, c, g3, (fabs(no * d) + ni) / fabs(c), l);
        out->z_n2 = position(s, z2, q4, c, g4, (no + fabs(ni * a)) / fabs(c), l);
    }
    return PX_OK;
}

int px_conjugate(const px_system *s, double z_obj, px_conj *out)
{
    double no = s->n_obj, ni = s->n_img, z1 = s->z_first, z2 = s->z_last;
    dd d1, den, num;
    double d1v, denv, numv, c, s_d1, s_den, s_d2, d2, l;

    memset(out, 0, sizeof *out);
    if (s->err) return s->err;
    if (!isfinite(z_obj)) return PX_BAD;
    d1 = dd_div_d(dd_two_sum(z1, -z_obj), no);
    d1v = dd_val(d1);
    s_d1 = (fabs(z1) + fabs(z_obj)) / no + fabs(d1v);
    /* length scale of the image side: the system's length, and the focal length or
     * the object distance, whichever is smaller (f alone is huge near afocal) */
    l = fmax(fabs(z2 - z1), fmin(fabs(z1 - z_obj), system_scale(s, s->hi.c + s->lo.c)));
    out->d1 = length(d1v, s_d1, l);
    c = s->hi.c + s->lo.c;
    den = dd_add(dd_mul(entry(s, 2), d1), entry(s, 3));        /* C d1 + D */
    num = dd_add(dd_mul(entry(s, 0), d1), entry(s, 1));        /* A d1 + B */
    denv = dd_val(den);
    numv = dd_val(num);
    s_den = px_sensitivity(s, 0, 0, d1v, 1) + fabs(c) * s_d1;
    out->angular = value(denv * no / ni, s_den * no / ni + 2 * fabs(denv * no / ni));
    if (fabs(denv) <= 2.0 * DBL_EPSILON * s_den) {
        out->at_infinity = 1;
        out->exit_slope = c / ni;
        return PX_AT_INFINITY;
    }
    d2 = -numv / denv;
    /* d(d2)/d(d1) = -1/den^2 (det = 1) */
    s_d2 = px_sensitivity(s, -d1v / denv, -1 / denv, numv * d1v / (denv * denv),
                          numv / (denv * denv)) + s_d1 / (denv * denv);
    out->d2 = length(d2, s_d2, l / ni);
    out->z_img = value_rel(fma(ni, d2, z2), fabs(z2) + ni * s_d2 + fabs(ni * d2), ni * d2,
                           ni * s_d2 + fabs(ni * d2), l);
    out->lateral = value(1 / denv, s_den / (denv * denv));
    return PX_OK;
}

double px_nearpoint_angmag(const px_system *s, double nearpoint, double z_obj,
                           const px_conj *c)
{
    double s1, s2;
    if (c->at_infinity) return -(s->hi.c + s->lo.c) * nearpoint / s->n_img;
    s1 = fmax(fabs(z_obj - s->z_first), nearpoint);
    s2 = fmax(fabs(c->z_img.v - s->z_last), nearpoint);
    return s1 * c->lateral.v / s2;
}

/* Indices near 589 nm (silicon: the value the project's tests use). */
static const struct { const char *name; double n; } media[] = {
    {"vacuum", 1.0}, {"air", 1.000293}, {"water", 1.333}, {"aqueous", 1.336},
    {"vitreous", 1.337}, {"keratometric", 1.3375}, {"cornea", 1.376},
    {"crystalline", 1.406}, {"crown", 1.5168}, {"bk7", 1.5168}, {"flint", 1.62},
    {"diamond", 2.417}, {"silicon", 4.01},
};

double px_medium_index(const char *name)
{
    for (size_t i = 0; i < sizeof media / sizeof *media; i++)
        if (!strcasecmp(name, media[i].name)) return media[i].n;
    return 0;
}
