/* matrix.c -- 2x2 ray-transfer matrices.  The products follow the original listing's
 * order of operations exactly (c_ij = (0 + a_i1*b_1j) + a_i2*b_2j), so the classic
 * dialogue prints the same round-off as the original; build with -ffp-contract=off.
 * px_mul_fma and px_det_accurate are the careful versions (explicit fma). */
#include <math.h>
#include "paraxial.h"

px_mat px_identity(void) { px_mat m = {1.0, 0.0, 0.0, 1.0}; return m; }

px_mat px_translation(double reduced)
{
    px_mat m = {1.0, reduced, 0.0, 1.0};
    return m;
}

px_mat px_refraction(double n1, double n2, double r)
{
    px_mat m = {1.0, 0.0, 0.0, 1.0};
    if (isfinite(r) && r != 0.0)   /* a plane (r = 0 or inf) does not refract */
        m.c = (n1 - n2) / r;
    return m;
}

/* The "0.0 +" is deliberate: it is what the listing's matm does, and it turns a
 * product of -0 into +0 exactly as the original did. */
px_mat px_mul(px_mat l, px_mat r)
{
    px_mat m;
    m.a = (0.0 + l.a * r.a) + l.b * r.c;
    m.b = (0.0 + l.a * r.b) + l.b * r.d;
    m.c = (0.0 + l.c * r.a) + l.d * r.c;
    m.d = (0.0 + l.c * r.b) + l.d * r.d;
    return m;
}

/* a*b + c*d with one rounding of the exact product sum (fma recovers a*b's error). */
static double dot2(double a, double b, double c, double d)
{
    double p = a * b, e = fma(a, b, -p);
    return fma(c, d, p) + e;
}

px_mat px_mul_fma(px_mat l, px_mat r)
{
    px_mat m;
    m.a = dot2(l.a, r.a, l.b, r.c);
    m.b = dot2(l.a, r.b, l.b, r.d);
    m.c = dot2(l.c, r.a, l.d, r.c);
    m.d = dot2(l.c, r.b, l.d, r.d);
    return m;
}

px_mat px_mul_abs(px_mat l, px_mat r)
{
    px_mat m;
    m.a = fabs(l.a) * fabs(r.a) + fabs(l.b) * fabs(r.c);
    m.b = fabs(l.a) * fabs(r.b) + fabs(l.b) * fabs(r.d);
    m.c = fabs(l.c) * fabs(r.a) + fabs(l.d) * fabs(r.c);
    m.d = fabs(l.c) * fabs(r.b) + fabs(l.d) * fabs(r.d);
    return m;
}

double px_det(px_mat m) { return m.a * m.d - m.c * m.b; }

/* Kahan's 2x2 determinant: the fma recovers the rounding error of b*c exactly. */
double px_det_accurate(px_mat m)
{
    double w = m.b * m.c;
    double e = fma(-m.b, m.c, w);
    double f = fma(m.a, m.d, -w);
    return f + e;
}
