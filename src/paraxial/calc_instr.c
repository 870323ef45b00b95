/* calc_instr.c -- instruments and measurements as pure functions: the magnifier and
 * microscopes (31.7-31.10, 58), telescopes (31.11-31.13), the lens matrix from
 * measurements (14), from cardinal points (24) and from nodal and focal points (26),
 * spectacles (41, 57) and the cornea (37).  Declared in paraxial.h; no I/O. */
#include <float.h>
#include <math.h>
#include "paraxial.h"

int px_magnify(double f, double nearpoint, double d_o, px_magnifier *out)
{
    if (!(f > 0) || !(nearpoint > 0) || !(d_o > 0) || isinf(d_o)) return PX_BAD;
    out->angular = nearpoint / d_o;
    out->angular_limit = nearpoint / f;
    out->best_alpha = nearpoint / (nearpoint + f);
    out->best_d_o = out->best_alpha * f;
    out->best_angular = nearpoint / out->best_d_o;
    if (d_o == f) { out->d_i = -INFINITY; out->lateral = INFINITY; return PX_AT_INFINITY; }
    out->d_i = f * d_o / (d_o - f);
    out->lateral = -out->d_i / d_o;
    return PX_OK;
}

int px_compound_microscope(double fo, double fe, double tube, double nearpoint,
                           px_compound *out)
{
    if (!(fo > 0) || !(fe > 0) || !(tube > 0) || !(nearpoint > 0)) return PX_BAD;
    out->d_o = fo * (fo + tube) / tube;     /* 1/fo - 1/(fo + T), inverted */
    out->m_objective = -tube / fo;
    out->m_eyepiece = nearpoint / fe;
    out->total = out->m_objective * out->m_eyepiece;
    out->length = fo + tube + fe;
    return PX_OK;
}

static px_mat lens(double f) { px_mat m = {1.0, 0.0, -1.0 / f, 1.0}; return m; }

/* m = step * m, keeping the rounding scale */
static void chain(px_mat *m, px_mat *abs, px_mat step)
{
    *m = px_mul(step, *m);
    *abs = px_mul_abs(step, *abs);
}

int px_telescope_make(double fo, double fe, double erector, px_telescope *out)
{
    px_mat abs = px_identity();
    if (!(fo > 0) || fe == 0.0 || !isfinite(fe) || !(erector >= 0) || !isfinite(erector))
        return PX_BAD;
    out->length = fo + fe + erector;
    if (!(out->length > 0) || (erector > 0 && !(fe > 0))) return PX_BAD;
    out->m = lens(fo);
    abs = px_mul_abs(out->m, abs);
    out->erector_f = erector / 4.0;
    if (erector > 0) {
        chain(&out->m, &abs, px_translation(fo + erector / 2));
        chain(&out->m, &abs, lens(out->erector_f));
        chain(&out->m, &abs, px_translation(erector / 2 + fe));
    } else {
        chain(&out->m, &abs, px_translation(fo + fe));
    }
    chain(&out->m, &abs, lens(fe));
    out->afocal = fabs(out->m.c) <= 16 * DBL_EPSILON * abs.c;
    out->angular = out->m.d;    /* C = 0: n theta_out = D n theta_in */
    return out->afocal ? PX_OK : PX_AT_INFINITY;
}

int px_fit_matrix(const double *x, const double *y, const double *mag, int n,
                  px_linfit fit, px_fit *out)
{
    double alpha[PX_FIT_MAX], beta[PX_FIT_MAX];
    px_mat m;
    if (n < 2 || n > PX_FIT_MAX || !fit) return PX_BAD;
    for (int i = 0; i < n; i++) {
        if (mag[i] == 0.0 || !isfinite(x[i]) || !isfinite(y[i])) return PX_BAD;
        alpha[i] = 1.0 / mag[i];           /* 1/m = C x + D */
    }
    if (fit(x, alpha, n, &m.d, &m.c, &out->rss_cd)) return PX_BAD;
    for (int i = 0; i < n; i++) beta[i] = -y[i] * (m.c * x[i] + m.d);  /* A x + B */
    if (fit(x, beta, n, &m.b, &m.a, &out->rss_ab)) return PX_BAD;
    out->m = m;
    out->det = px_det_accurate(m);
    out->max_condition = 0.0;
    for (int i = 0; i < n; i++) {
        double r = fabs((m.a * x[i] + m.b) + y[i] * (m.c * x[i] + m.d));
        if (r > out->max_condition) out->max_condition = r;
    }
    return PX_OK;
}

/* A, D from the focal points, B from det = 1, given the power p = -C. */
static void from_focal(double n1, double n2, double z1, double z2, double zf1, double zf2,
                       double p, px_mat *m)
{
    m->c = -p;
    m->a = m->c * (z2 - zf2) / n2;     /* zf2 = z2 - n2 A/C */
    m->d = m->c * (zf1 - z1) / n1;     /* zf1 = z1 + n1 D/C */
    m->b = (m->a * m->d - 1.0) / m->c;
}

static double rel_diff(double a, double b)
{
    double s = fmax(fabs(a), fabs(b));
    return s == 0.0 ? 0.0 : fabs(a - b) / s;
}

int px_matrix_from_cardinal(double n1, double n2, double z1, double z2, double zf1,
                            double zf2, double zh1, double zh2, px_mat *out,
                            double *mismatch)
{
    double p, p1;
    if (!(n1 > 0) || !(n2 > 0) || zf2 == zh2 || zh1 == zf1) return PX_BAD;
    p = n2 / (zf2 - zh2);              /* second focal length F2 = n2/P */
    p1 = n1 / (zh1 - zf1);             /* first focal length F1 = n1/P */
    *mismatch = rel_diff(p, p1);
    from_focal(n1, n2, z1, z2, zf1, zf2, p, out);
    return PX_OK;
}

int px_matrix_from_nodal(double n1, double n2, double z1, double z2, double zn1,
                         double zn2, double ffl, double bfl, px_mat *out,
                         double *zh1, double *zh2, double *mismatch)
{
    double zf1 = z1 - ffl, zf2 = z2 + bfl, p, p1;
    if (!(n1 > 0) || !(n2 > 0) || zn1 == zf1 || zf2 == zn2) return PX_BAD;
    p = n2 / (zn1 - zf1);              /* F1 to N1 is the second focal length */
    p1 = n1 / (zf2 - zn2);             /* N2 to F2 is the first */
    *mismatch = rel_diff(p, p1);
    from_focal(n1, n2, z1, z2, zf1, zf2, p, out);
    *zh1 = zf1 + n1 / p;
    *zh2 = zf2 - n2 / p;
    return PX_OK;
}

/* The lens images the object at `target` as a virtual image at the near point:
 * 1/f = 1/do + 1/di with do = target, di = -nearpoint (section 57, Example 4). */
double px_vision_near(double nearpoint, double target)
{
    return (isinf(target) ? 0.0 : 1.0 / target) - (isinf(nearpoint) ? 0.0 : 1.0 / nearpoint);
}
/* Object at infinity, virtual image at the far point (Example 5). */
double px_vision_far(double farpoint) { return isinf(farpoint) ? 0.0 : -1.0 / farpoint; }

double px_cornea_power(double radius, double n) { return (n - 1.0) / radius; }
double px_cornea_radius(double power, double n) { return (n - 1.0) / power; }
double px_cornea_dradius(double power, double dpower, double n)
{
    return fabs((n - 1.0) * dpower / (power * power));
}
double px_cornea_doc_radius(double p, double n) { return (n - 1.0) / (n * p); }
double px_cornea_doc_dradius(double p, double dp, double n)
{
    return fabs(dp / (n / (n - 1.0) * p * p));
}
