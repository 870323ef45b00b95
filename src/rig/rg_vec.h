/* rg_vec.h -- inside the rig module: the 3-vector arithmetic the geometry is written
 * in (static inline, doubles, no allocation). */
#ifndef RG_VEC_H
#define RG_VEC_H
#include <math.h>

static inline void v3set(double o[3], double x, double y, double z)
{ o[0] = x; o[1] = y; o[2] = z; }
static inline void v3copy(double o[3], const double a[3])
{ o[0] = a[0]; o[1] = a[1]; o[2] = a[2]; }
static inline double v3dot(const double a[3], const double b[3])
{ return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static inline double v3len(const double a[3]) { return sqrt(v3dot(a, a)); }
static inline void v3add(double o[3], const double a[3], const double b[3])
{ o[0] = a[0] + b[0]; o[1] = a[1] + b[1]; o[2] = a[2] + b[2]; }
static inline void v3sub(double o[3], const double a[3], const double b[3])
{ o[0] = a[0] - b[0]; o[1] = a[1] - b[1]; o[2] = a[2] - b[2]; }
static inline void v3scale(double o[3], const double a[3], double s)
{ o[0] = a[0] * s; o[1] = a[1] * s; o[2] = a[2] * s; }
/* o = a + s b */
static inline void v3axpy(double o[3], const double a[3], double s, const double b[3])
{ o[0] = a[0] + s * b[0]; o[1] = a[1] + s * b[1]; o[2] = a[2] + s * b[2]; }
static inline void v3cross(double o[3], const double a[3], const double b[3])
{
    double x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2],
           z = a[0] * b[1] - a[1] * b[0];
    o[0] = x; o[1] = y; o[2] = z;
}
static inline double v3dist(const double a[3], const double b[3])
{ double d[3]; v3sub(d, a, b); return v3len(d); }
/* Normalise in place; returns the old length (0: left as it was). */
static inline double v3norm(double a[3])
{
    double l = v3len(a);
    if (l > 0) { a[0] /= l; a[1] /= l; a[2] /= l; }
    return l;
}
/* Mirror reflection of direction d at unit normal n (either orientation). */
static inline void v3reflect(double o[3], const double d[3], const double n[3])
{ v3axpy(o, d, -2 * v3dot(d, n), n); }
/* Row-major 3x3 times vector, and its transpose. */
static inline void m3mul(double o[3], const double m[9], const double a[3])
{
    double x = m[0] * a[0] + m[1] * a[1] + m[2] * a[2];
    double y = m[3] * a[0] + m[4] * a[1] + m[5] * a[2];
    double z = m[6] * a[0] + m[7] * a[1] + m[8] * a[2];
    o[0] = x; o[1] = y; o[2] = z;
}
static inline void m3tmul(double o[3], const double m[9], const double a[3])
{
    double x = m[0] * a[0] + m[3] * a[1] + m[6] * a[2];
    double y = m[1] * a[0] + m[4] * a[1] + m[7] * a[2];
    double z = m[2] * a[0] + m[5] * a[1] + m[8] * a[2];
    o[0] = x; o[1] = y; o[2] = z;
}
/* Rodrigues: v turned by angle about unit axis. */
static inline void v3rot(double o[3], const double axis[3], double ang, const double v[3])
{
    double c = cos(ang), s = sin(ang), k[3], t[3];
    v3cross(k, axis, v);
    double ad = v3dot(axis, v) * (1 - c);
    for (int i = 0; i < 3; i++) t[i] = v[i] * c + k[i] * s + axis[i] * ad;
    v3copy(o, t);
}
/* Two unit vectors completing unit n to a right-handed basis (e1, e2, n); e1 is the
 * part of `hint` across n when hint is not along n. */
static inline void v3basis(const double n[3], const double hint[3], double e1[3],
                           double e2[3])
{
    double h[3];
    v3axpy(h, hint, -v3dot(hint, n), n);
    if (v3len(h) < 1e-6) {
        double alt[3] = {1, 0, 0};
        if (fabs(n[0]) > 0.9) v3set(alt, 0, 1, 0);
        v3axpy(h, alt, -v3dot(alt, n), n);
    }
    v3norm(h);
    v3copy(e1, h);
    v3cross(e2, n, e1);
}
#endif
