/* rg_gimbal.c -- two-axis mirror mounts: the normal a pair of joint angles gives,
 * n(a, b) = Rot(axis1, a) Rot(axis2, b) normal0 (the inner axis rides on the outer),
 * and back: the angles that give a wanted normal, in closed form. */
#include "rig/rg_geom.h"
#include "rig/rg_vec.h"

void rg_gimbal_normal(const rg_gimbal *m, double a, double b, double n[3])
{
    double w[3];
    v3rot(w, m->axis2, b, m->normal0);
    v3rot(n, m->axis1, a, w);
}

/* Angle turning w about unit axis k onto n (both seen across k). */
static double turn_angle(const double k[3], const double w[3], const double n[3])
{
    double wp[3], np[3], c[3];
    v3axpy(wp, w, -v3dot(w, k), k);
    v3axpy(np, n, -v3dot(n, k), k);
    v3cross(c, wp, np);
    return atan2(v3dot(k, c), v3dot(wp, np));
}

/* The outer rotation keeps the component along axis1, so b alone must give
 * (Rot(axis2, b) normal0) . axis1 = n . axis1:  A cos b + B sin b = C, two roots;
 * then a turns that vector onto n about axis1.  The root nearer the zero pose wins. */
int rg_gimbal_angles(const rg_gimbal *m, const double n[3], double *a, double *b)
{
    const double *k1 = m->axis1, *k2 = m->axis2, *n0 = m->normal0;
    double par = v3dot(n0, k2), perp[3], e[3];
    v3axpy(perp, n0, -par, k2);
    v3cross(e, k2, n0);
    double A = v3dot(perp, k1), B = v3dot(e, k1);
    double C = v3dot(n, k1) - par * v3dot(k2, k1);
    double r = hypot(A, B);
    double cand[2];
    int nc;
    if (r < 1e-12) {
        if (fabs(C) > 1e-9) return -1;      /* b cannot change n . axis1 */
        cand[0] = 0;
        nc = 1;
    } else {
        double x = C / r;
        if (x > 1 + 1e-12 || x < -1 - 1e-12) return -1;
        if (x > 1) x = 1;
        if (x < -1) x = -1;
        double beta = atan2(B, A), d = acos(x);
        cand[0] = beta + d;
        cand[1] = beta - d;
        nc = 2;
    }
    double best = INFINITY;
    for (int i = 0; i < nc; i++) {
        double bb = remainder(cand[i], 2 * RG_PI), w[3];
        v3rot(w, k2, bb, n0);
        double aa = turn_angle(k1, w, n);
        /* the root must reproduce n (not its mirror image about axis1) */
        double chk[3];
        v3rot(chk, k1, aa, w);
        if (v3dist(chk, n) > 1e-7) continue;
        double cost = aa * aa + bb * bb;
        if (cost < best) { best = cost; *a = aa; *b = bb; }
    }
    return isfinite(best) ? 0 : -1;
}
