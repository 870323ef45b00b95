/* calc_lens.c -- the document's lens calculations as pure functions: length units
 * and diopters (23), Gauss's single-surface formula (4), the thick lens and the lens
 * maker's equation (8-10, 21), the thin lens equation (57), a pair of thin lenses
 * (56).  Declared in the "calculations" part of paraxial.h; no I/O. */
#include <float.h>
#include <math.h>
#include "paraxial.h"

double px_unit_meters(px_unit u) { return u == PX_MM ? 1e-3 : u == PX_CM ? 1e-2 : 1.0; }
double px_diopters(double power, px_unit u) { return power / px_unit_meters(u); }
double px_power_of_diopters(double dpt, px_unit u) { return dpt * px_unit_meters(u); }

/* 1/x with 1/inf = 0: vergences of distances that may be infinite. */
static double inv(double x) { return isinf(x) ? 0.0 : 1.0 / x; }
static double curvature(double r) { return (r == 0.0 || isinf(r)) ? 0.0 : 1.0 / r; }

int px_gauss_surface(double n1, double n2, double r, double z1, px_gauss *out)
{
    double v;
    if (!(n1 > 0) || !(n2 > 0) || z1 == 0.0) return PX_BAD;
    out->power = (n2 - n1) * curvature(r);
    out->focal_obj = out->power == 0.0 ? -INFINITY : -n1 / out->power;
    out->focal_img = out->power == 0.0 ? INFINITY : n2 / out->power;
    v = n1 * inv(z1) + out->power;           /* n2/z2 */
    if (v == 0.0 || fabs(v) <= 4 * DBL_EPSILON * (fabs(n1 * inv(z1)) + fabs(out->power))) {
        out->z2 = INFINITY;
        out->mag = INFINITY;
        return PX_AT_INFINITY;
    }
    out->z2 = n2 / v;
    /* m = n1 z2 / (n2 z1) = n1/(z1 v): finite also for z1 = -inf (then 0) */
    out->mag = isinf(z1) ? 0.0 : n1 / (z1 * v);
    return PX_OK;
}

int px_thick_lens(double n1, double r1, double t, double n, double r2, double n3,
                  px_lens *out)
{
    double c1 = curvature(r1), c2 = curvature(r2), p1, p2;
    int rc;
    if (!(n1 > 0) || !(n > 0) || !(n3 > 0) || !(t >= 0) || !isfinite(t)) return PX_BAD;
    px_system_init(&out->sys, n1);
    if ((rc = px_system_surface(&out->sys, r1, n)) || (rc = px_system_gap(&out->sys, t)) ||
        (rc = px_system_surface(&out->sys, r2, n3)) ||
        (rc = px_first_order(&out->sys, &out->first))) {
        px_system_free(&out->sys);
        return rc;
    }
    p1 = (n - n1) * c1;
    p2 = (n3 - n) * c2;
    out->maker_power = p1 + p2 - t * p1 * p2 / n;
    out->thin_power = p1 + p2;
    return out->first.afocal ? PX_AT_INFINITY : PX_OK;
}

int px_thin_equation(int unknown, double f, double d_o, double d_i, px_thin *out)
{
    double v;
    if ((unknown != PX_THIN_F && f == 0.0) || (unknown != PX_THIN_DO && d_o == 0.0) ||
        (unknown != PX_THIN_DI && d_i == 0.0) || unknown < 0 || unknown > PX_THIN_NONE)
        return PX_BAD;
    switch (unknown) {
    case PX_THIN_F:  v = inv(d_o) + inv(d_i); f = v == 0.0 ? INFINITY : 1.0 / v; break;
    case PX_THIN_DO: v = inv(f) - inv(d_i); d_o = v == 0.0 ? INFINITY : 1.0 / v; break;
    case PX_THIN_DI: v = inv(f) - inv(d_o); d_i = v == 0.0 ? INFINITY : 1.0 / v; break;
    default: {   /* the section's script: each from the other two */
        double fdi = 1.0 / (inv(f) - inv(d_o)), fdo = 1.0 / (inv(f) - inv(d_i));
        double ff = 1.0 / (inv(d_o) + inv(d_i));
        f = ff; d_o = fdo; d_i = fdi;
    }
    }
    out->f = f; out->d_o = d_o; out->d_i = d_i;
    out->power = inv(f);
    if (isinf(d_i) || (isinf(d_o) && isinf(d_i))) { out->mag = INFINITY; return PX_AT_INFINITY; }
    out->mag = isinf(d_o) ? 0.0 : -d_i / d_o;
    return isinf(f) || isinf(d_o) ? PX_AT_INFINITY : PX_OK;
}

static px_mat thin_lens(double power) { px_mat m = {1.0, 0.0, -power, 1.0}; return m; }

int px_thin_pair(double f1, double f2, double t, px_pair *out)
{
    px_mat l1, l2, tr, abs;
    double a, d;
    if (f1 == 0.0 || f2 == 0.0 || !(t >= 0) || !isfinite(t)) return PX_BAD;
    l1 = thin_lens(inv(f1)); l2 = thin_lens(inv(f2)); tr = px_translation(t);
    out->m = px_mul(l2, px_mul(tr, l1));
    abs = px_mul_abs(l2, px_mul_abs(tr, l1));
    /* the formula of section 56, in powers: P1 + P2 - t P1 P2 */
    out->power = inv(f1) + inv(f2) - t * inv(f1) * inv(f2);
    out->afocal = fabs(out->m.c) <= 8 * DBL_EPSILON * abs.c;
    if (out->afocal) return PX_AT_INFINITY;
    a = out->m.a; d = out->m.d;
    out->f = 1.0 / out->power;
    out->bfd = a / out->power;
    out->ffd = d / out->power;
    out->z_h1 = (1.0 - d) / out->power;
    out->z_h2 = t - (1.0 - a) / out->power;
    return PX_OK;
}
