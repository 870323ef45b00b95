/* rt.h -- shared by the rig geometry's tests and bench (tests/rig/): the engine
 * tables, and an independent model of the rig written from the textbook formulas
 * (rotation matrices instead of Rodrigues, the sag formulas typed again, ray hits by
 * bracketing and bisection) to check the engine against. */
#ifndef RT_H
#define RT_H
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "rig/rig.h"
#include "trace/trace.h"

#pragma GCC diagnostic ignored "-Wunused-function"
#define RT_PI 3.14159265358979323846
#define RT_DEG (RT_PI / 180)

static const rig_api *rt_rig(void)
{
    const rig_api *a = rig_get_api(RIG_ABI);
    if (!a || !a->solve) { printf("FAIL no rig engine table\n"); exit(1); }
    return a;
}
static const trace_api *rt_trace(void)
{
    const trace_api *t = trace_get_api(TRACE_ABI);
    if (!t) { printf("FAIL no trace engine table\n"); exit(1); }
    return t;
}

static double rt_dot(const double a[3], const double b[3])
{ return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static double rt_dist(const double a[3], const double b[3])
{ return sqrt((a[0]-b[0])*(a[0]-b[0]) + (a[1]-b[1])*(a[1]-b[1]) + (a[2]-b[2])*(a[2]-b[2])); }
static void rt_unit(double a[3])
{ double l = sqrt(rt_dot(a, a)); a[0] /= l; a[1] /= l; a[2] /= l; }

/* Rotation matrix about unit axis k by angle t: I + sin t K + (1 - cos t) K^2. */
static void rt_rotmat(const double k[3], double t, double M[9])
{
    double K[9] = {0, -k[2], k[1], k[2], 0, -k[0], -k[1], k[0], 0}, K2[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            K2[i * 3 + j] = 0;
            for (int l = 0; l < 3; l++) K2[i * 3 + j] += K[i * 3 + l] * K[l * 3 + j];
        }
    for (int i = 0; i < 9; i++)
        M[i] = (i % 4 == 0) + sin(t) * K[i] + (1 - cos(t)) * K2[i];
}
static void rt_mv(const double M[9], const double v[3], double o[3])
{
    double t[3];
    for (int i = 0; i < 3; i++) t[i] = M[i * 3] * v[0] + M[i * 3 + 1] * v[1] + M[i * 3 + 2] * v[2];
    memcpy(o, t, sizeof t);
}
/* Gimbal normal: outer rotation (fixed axis1) after the inner one (axis2 at zero). */
static void rt_gimbal(const rg_gimbal *m, double a, double b, double n[3])
{
    double A[9], B[9];
    rt_rotmat(m->axis1, a, A);
    rt_rotmat(m->axis2, b, B);
    rt_mv(B, m->normal0, n);
    rt_mv(A, n, n);
}

/* Sag in the eye frame, typed from the formulas (NaN outside the surface). */
static double rt_sag(const rg_cornea *c, double x, double y)
{
    if (c->model == RG_BICONIC) {
        double xp = cos(c->axis) * x + sin(c->axis) * y, yp = -sin(c->axis) * x + cos(c->axis) * y;
        double u = 1 - (1 + c->Q) * xp * xp / (c->R * c->R) - (1 + c->Q2) * yp * yp / (c->R2 * c->R2);
        if (u < 0) return NAN;
        return (xp * xp / c->R + yp * yp / c->R2) / (1 + sqrt(u));
    }
    double s2 = x * x + y * y, k = c->model == RG_SPHERE ? 0 : c->Q;
    double u = 1 - (1 + k) * s2 / (c->R * c->R);
    if (u < 0) return NAN;
    double z = s2 / c->R / (1 + sqrt(u));
    if (c->model == RG_ASPHERE)
        for (int i = 0; i < c->nasph; i++) z += c->asph[i] * pow(s2, 2 + i);
    return z;
}
static void rt_to_eye(const rg_cornea *c, const double p[3], double e[3])
{
    double r[3] = {p[0] - c->trans[0], p[1] - c->trans[1], p[2] - c->trans[2]};
    for (int i = 0; i < 3; i++) e[i] = c->rot[i] * r[0] + c->rot[3 + i] * r[1] + c->rot[6 + i] * r[2];
}
static void rt_dir_to_rig(const rg_cornea *c, const double e[3], double p[3])
{
    for (int i = 0; i < 3; i++) p[i] = c->rot[i * 3] * e[0] + c->rot[i * 3 + 1] * e[1] + c->rot[i * 3 + 2] * e[2];
}
/* Height of a rig point above the surface along the eye axis (>0: outside). */
static double rt_above(const rg_cornea *c, const double p[3])
{
    double e[3];
    rt_to_eye(c, p, e);
    return rt_sag(c, e[0], e[1]) - e[2];
}
/* Outward normal by central differences of the sag (rig frame). */
static void rt_normal(const rg_cornea *c, const double p[3], double n[3])
{
    double e[3], h = 1e-5;
    rt_to_eye(c, p, e);
    double fx = (rt_sag(c, e[0] + h, e[1]) - rt_sag(c, e[0] - h, e[1])) / (2 * h);
    double fy = (rt_sag(c, e[0], e[1] + h) - rt_sag(c, e[0], e[1] - h)) / (2 * h);
    double ne[3] = {fx, fy, -1};
    rt_unit(ne);
    rt_dir_to_rig(c, ne, n);
}

/* Independent forward: plane hits, reflections, the cornea by marching to a sign
 * change of rt_above and bisecting.  Returns 0 and fills the points. */
typedef struct rt_path { double h1[3], h2[3], spot[3], d1[3], d2[3], d3[3], n1[3], n2[3], nc[3]; } rt_path;
static int rt_plane(const double o[3], const double d[3], const double p0[3], const double n[3], double h[3])
{
    double r[3] = {p0[0] - o[0], p0[1] - o[1], p0[2] - o[2]};
    double t = rt_dot(r, n) / rt_dot(d, n);
    if (!(t > 0)) return -1;
    for (int i = 0; i < 3; i++) h[i] = o[i] + t * d[i];
    return 0;
}
static void rt_reflect(const double d[3], const double n[3], double o[3])
{ double k = 2 * rt_dot(d, n); for (int i = 0; i < 3; i++) o[i] = d[i] - k * n[i]; }
static int rt_forward(const rg_geometry *g, const rg_pose *p, rt_path *r)
{
    double p0[3], c2[3];
    rt_gimbal(&g->m1, p->j[RG_J_M1A], p->j[RG_J_M1B], r->n1);
    for (int i = 0; i < 3; i++) p0[i] = g->m1.center[i] + g->m1.offset * r->n1[i];
    if (rt_plane(g->laser_at, g->laser_dir, p0, r->n1, r->h1)) return -1;
    rt_reflect(g->laser_dir, r->n1, r->d1);
    rt_gimbal(&g->m2, p->j[RG_J_M2A], p->j[RG_J_M2B], r->n2);
    for (int i = 0; i < 3; i++) {
        c2[i] = g->m2.center[i] + p->j[RG_J_U] * g->p2_u[i] + p->j[RG_J_V] * g->p2_v[i];
        p0[i] = c2[i] + g->m2.offset * r->n2[i];
    }
    if (rt_plane(r->h1, r->d1, p0, r->n2, r->h2)) return -1;
    rt_reflect(r->d1, r->n2, r->d2);
    /* march in 0.01 mm steps (300 mm: more than any leg in these rigs) to where the
     * ray goes from outside (sag above the point) to inside */
    double lo = 0, hi = -1, prev = NAN;
    for (double t = 0; t < 300; t += 0.01) {
        double q[3] = {r->h2[0] + t * r->d2[0], r->h2[1] + t * r->d2[1], r->h2[2] + t * r->d2[2]};
        double a = rt_above(&g->cornea, q);
        if (isfinite(a) && isfinite(prev) && prev > 0 && a <= 0) { lo = t - 0.01; hi = t; break; }
        prev = a;
    }
    if (hi < 0) return -1;
    for (int k = 0; k < 200; k++) {
        double m = 0.5 * (lo + hi);
        double q[3] = {r->h2[0] + m * r->d2[0], r->h2[1] + m * r->d2[1], r->h2[2] + m * r->d2[2]};
        if (rt_above(&g->cornea, q) > 0) lo = m; else hi = m;
    }
    for (int i = 0; i < 3; i++) r->spot[i] = r->h2[i] + hi * r->d2[i];
    rt_normal(&g->cornea, r->spot, r->nc);
    rt_reflect(r->d2, r->nc, r->d3);
    return 0;
}
/* Distance of point x from the line o + t d (d unit). */
static double rt_line_dist(const double o[3], const double d[3], const double x[3])
{
    double r[3] = {x[0] - o[0], x[1] - o[1], x[2] - o[2]};
    double t = rt_dot(r, d);
    double q[3] = {r[0] - t * d[0], r[1] - t * d[1], r[2] - t * d[2]};
    return sqrt(rt_dot(q, q));
}
/* Scan targets: a Fermat spiral of n points up to theta_max. */
static rg_target rt_scan(int i, int n, double theta_max)
{
    rg_target t = {RG_T_ANGLES, theta_max * sqrt((i + 0.5) / n), fmod(i * 2.39996322972865332, 2 * RT_PI)};
    return t;
}
/* The same disc walked as a scan would: an equal-area spiral of `turns` turns,
 * consecutive points close together. */
static rg_target rt_scan_path(int i, int n, double theta_max, double turns)
{
    double f = sqrt((i + 0.5) / n);
    rg_target t = {RG_T_ANGLES, theta_max * f, fmod(2 * RT_PI * turns * f, 2 * RT_PI)};
    return t;
}
#endif
