/* rg_cornea.c -- the cornea models of section 33 (sphere, conic, even asphere) and the
 * biconic (toric) of real corneas, in the eye frame (apex at the origin, +z into the
 * eye), placed in the rig by the eye's pose: sag and slopes, outward normal, ray hits,
 * target points (theta, phi about the apex centre of curvature, or height and
 * meridian), and the surface's curvatures on two tangent directions (the beam's
 * oblique reflection, rg_spotscan.c). */
#include <stdio.h>
#include "rig/rg_geom.h"
#include "rig/rg_vec.h"

/* Rotational sag (conic + even asphere) of height s: z and dz/ds / s (the slope
 * divided by s, finite at the apex). */
static int sag_rot(const rg_cornea *c, double s2, double *z, double *slope_s)
{
    double cv = 1 / c->R, k1 = c->model == RG_SPHERE ? 1 : 1 + c->Q;
    double u = 1 - k1 * cv * cv * s2;
    if (u <= 0) return -1;
    double w = sqrt(u);
    *z = cv * s2 / (1 + w);
    *slope_s = cv / w;
    if (c->model == RG_ASPHERE) {
        double p = s2;              /* s^(2+2i) for term i (s^(4+2i)) */
        for (int i = 0; i < c->nasph; i++) {
            *z += c->asph[i] * p * s2;
            *slope_s += c->asph[i] * (4 + 2 * i) * p;
            p *= s2;
        }
    }
    return 0;
}

int rg_sag(const rg_cornea *c, double x, double y, double *z, double *fx, double *fy)
{
    if (c->model != RG_BICONIC) {
        double sl;
        if (sag_rot(c, x * x + y * y, z, &sl)) return -1;
        *fx = x * sl;
        *fy = y * sl;
        return 0;
    }
    double ca = cos(c->axis), sa = sin(c->axis);
    double xp = ca * x + sa * y, yp = -sa * x + ca * y;
    double cx = 1 / c->R, cy = 1 / c->R2;
    double A = cx * xp * xp + cy * yp * yp;
    double kx = (1 + c->Q) * cx * cx, ky = (1 + c->Q2) * cy * cy;
    double u = 1 - kx * xp * xp - ky * yp * yp;
    if (u <= 0) return -1;
    double w = sqrt(u), d = (1 + w) * (1 + w);
    *z = A / (1 + w);
    double zx = (2 * cx * xp * (1 + w) + A * kx * xp / w) / d;
    double zy = (2 * cy * yp * (1 + w) + A * ky * yp / w) / d;
    *fx = zx * ca - zy * sa;
    *fy = zx * sa + zy * ca;
    return 0;
}

/* A plain conic (no aspheric terms, not biconic) is a quadric: closed-form hits. */
static int is_quadric(const rg_cornea *c)
{
    return c->model == RG_SPHERE || c->model == RG_CONIC ||
           (c->model == RG_ASPHERE && c->nasph == 0);
}

void rg_normal_eye(const rg_cornea *c, const double p[3], double n[3])
{
    if (is_quadric(c)) {
        /* gradient of c s^2 - 2 z + (1+k) c z^2: finite up to the conic's edge */
        double cv = 1 / c->R, k1 = c->model == RG_SPHERE ? 1 : 1 + c->Q;
        v3set(n, cv * p[0], cv * p[1], k1 * cv * p[2] - 1);
    } else {
        double z, fx, fy;
        if (rg_sag(c, p[0], p[1], &z, &fx, &fy)) { fx = fy = 0; }
        v3set(n, fx, fy, -1);
    }
    v3norm(n);
}

/* Eye-frame hit of o + t d with the conic (R, k1 = 1 + Q) on its apex branch. */
static int conic_hit(double R, double k1, const double o[3], const double d[3],
                     double tmin, double *t)
{
    double cv = 1 / R;
    double a = cv * (d[0] * d[0] + d[1] * d[1]) + k1 * cv * d[2] * d[2];
    double b = 2 * (cv * (o[0] * d[0] + o[1] * d[1]) - d[2] + k1 * cv * o[2] * d[2]);
    double q = cv * (o[0] * o[0] + o[1] * o[1]) - 2 * o[2] + k1 * cv * o[2] * o[2];
    double r[2];
    int nr = 0;
    if (fabs(a) < 1e-300 || fabs(a) * fabs(q) < 1e-18 * b * b) {
        if (b == 0) return -1;
        /* nearly linear: one root -q/b refined with the quadratic's correction */
        double t0 = -q / b;
        r[nr++] = t0 - a * t0 * t0 / (b + 2 * a * t0);
    } else {
        double disc = b * b - 4 * a * q;
        if (disc < 0) return -1;
        double qq = -0.5 * (b + copysign(sqrt(disc), b));
        r[nr++] = qq / a;
        if (qq != 0) r[nr++] = q / qq;
    }
    double best = INFINITY;
    for (int i = 0; i < nr; i++) {
        double z = o[2] + r[i] * d[2];
        /* the apex branch: 0 <= z and (1+k) c z <= 1 */
        if (r[i] > tmin && r[i] < best && z >= -1e-12 * R && k1 * cv * z <= 1 + 1e-12)
            best = r[i];
    }
    if (!isfinite(best)) return -1;
    *t = best;
    return 0;
}

/* Newton on h(t) = z(t) - f(x(t), y(t)) from t0, safeguarded: a step that leaves the
 * domain is halved. */
static int newton_hit(const rg_cornea *c, const double o[3], const double d[3],
                      double t0, double *t)
{
    double tt = t0;
    for (int it = 0; it < 60; it++) {
        double p[3], z, fx, fy;
        v3axpy(p, o, tt, d);
        if (rg_sag(c, p[0], p[1], &z, &fx, &fy)) return -1;
        double h = p[2] - z, hp = d[2] - fx * d[0] - fy * d[1];
        if (hp == 0) return -1;
        double step = -h / hp, tn = tt + step;
        for (int k = 0; k < 40; k++) {
            double q[3], z2, gx, gy;
            v3axpy(q, o, tn, d);
            if (!rg_sag(c, q[0], q[1], &z2, &gx, &gy)) break;
            step *= 0.5;
            tn = tt + step;
        }
        tt = tn;
        if (fabs(step) <= 1e-15 * (fabs(tt) + 1)) { *t = tt; return 0; }
    }
    /* converged to rounding but the last steps oscillate at the last bit */
    double p[3], z, fx, fy;
    v3axpy(p, o, tt, d);
    if (!rg_sag(c, p[0], p[1], &z, &fx, &fy) && fabs(p[2] - z) < 1e-12) {
        *t = tt;
        return 0;
    }
    return -1;
}

static int hit_eye(const rg_cornea *c, const double o[3], const double d[3], double *t)
{
    const double tmin = 1e-9;
    if (is_quadric(c))
        return conic_hit(c->R, c->model == RG_SPHERE ? 1 : 1 + c->Q, o, d, tmin, t);
    /* start from the flat meridian's conic (a sphere when that misses) */
    double t0;
    if (conic_hit(c->R, 1 + c->Q, o, d, tmin, &t0) &&
        conic_hit(c->R, 1, o, d, tmin, &t0))
        return -1;
    if (newton_hit(c, o, d, t0, t)) return -1;
    return *t > tmin ? 0 : -1;
}

int rg_cornea_hit(const rg_cornea *c, const double o[3], const double d[3],
                  double q[3], double n[3], double *t)
{
    double oe[3], de[3], rel[3], pe[3], ne[3], tt;
    v3sub(rel, o, c->trans);
    m3tmul(oe, c->rot, rel);
    m3tmul(de, c->rot, d);
    if (hit_eye(c, oe, de, &tt)) return -1;
    v3axpy(pe, oe, tt, de);
    rg_normal_eye(c, pe, ne);
    m3mul(q, c->rot, pe);
    v3add(q, q, c->trans);
    m3mul(n, c->rot, ne);
    if (t) *t = tt;
    return 0;
}

double rg_cornea_height(const rg_cornea *c, const double p[3])
{
    double rel[3], pe[3];
    v3sub(rel, p, c->trans);
    m3tmul(pe, c->rot, rel);
    return hypot(pe[0], pe[1]);
}

int rg_cornea_point(const rg_cornea *c, const rg_target *t, double p[3], double n[3],
                    char *err, size_t errcap)
{
    double pe[3], ne[3];
    if (!(c->R > 0) || (c->model == RG_BICONIC && !(c->R2 > 0))) {
        snprintf(err, errcap, "cornea radius must be > 0");
        return RG_EINVAL;
    }
    if (!isfinite(t->a) || !isfinite(t->b)) {
        snprintf(err, errcap, "target is not a number");
        return RG_EINVAL;
    }
    if (t->kind == RG_T_ANGLES) {
        if (t->a < 0 || t->a >= RG_PI / 2) {
            snprintf(err, errcap, "target theta %.6g deg outside [0, 90)",
                     t->a * 180 / RG_PI);
            return RG_EUNREACH;
        }
        double o[3] = {0, 0, c->R}, w[3] = {sin(t->a) * cos(t->b),
                                           sin(t->a) * sin(t->b), -cos(t->a)};
        double tt;
        if (hit_eye(c, o, w, &tt)) {
            snprintf(err, errcap, "target theta %.6g deg phi %.6g deg is off the cornea",
                     t->a * 180 / RG_PI, t->b * 180 / RG_PI);
            return RG_EUNREACH;
        }
        v3axpy(pe, o, tt, w);
    } else if (t->kind == RG_T_HEIGHT) {
        double fx, fy;
        if (t->a < 0) {
            snprintf(err, errcap, "target height %.6g mm is negative", t->a);
            return RG_EINVAL;
        }
        pe[0] = t->a * cos(t->b);
        pe[1] = t->a * sin(t->b);
        if (rg_sag(c, pe[0], pe[1], &pe[2], &fx, &fy)) {
            snprintf(err, errcap, "target height %.6g mm is past the cornea's edge",
                     t->a);
            return RG_EUNREACH;
        }
    } else {
        snprintf(err, errcap, "unknown target kind %d", t->kind);
        return RG_EINVAL;
    }
    if (c->zone > 0 && hypot(pe[0], pe[1]) > c->zone * (1 + 1e-12)) {
        snprintf(err, errcap, "target at height %.6g mm is outside the cornea's zone "
                 "(%.6g mm)", hypot(pe[0], pe[1]), c->zone);
        return RG_EUNREACH;
    }
    rg_normal_eye(c, pe, ne);
    m3mul(p, c->rot, pe);
    v3add(p, p, c->trans);
    m3mul(n, c->rot, ne);
    return RG_OK;
}

void rg_eye_pose(rg_cornea *c, double rx, double ry, double rz, const double at[3])
{
    /* R = Rz Ry Rx: about x first, then y, then z (fixed axes) */
    double cx = cos(rx), sx = sin(rx), cy = cos(ry), sy = sin(ry), cz = cos(rz),
           sz = sin(rz);
    double m[9] = {cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx,
                   sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx,
                   -sy, cy * sx, cy * cx};
    for (int i = 0; i < 9; i++) c->rot[i] = m[i];
    v3copy(c->trans, at);
}

/* Second derivatives of the sag at (x, y) in the eye frame (hxx, hxy, hyy): analytic,
 * the rotational sag as z''(s) along the radius and z'(s)/s across it; the biconic's
 * z = N / (1 + S), S = sqrt(u), by the quotient rule in its own axes, then turned. */
static int sag_hessian(const rg_cornea *c, double x, double y, double h[3])
{
    if (c->model != RG_BICONIC) {
        double s2 = x * x + y * y, cv = 1 / c->R, k1 = c->model == RG_SPHERE ? 1 : 1 + c->Q;
        double u = 1 - k1 * cv * cv * s2;
        if (u <= 0) return -1;
        double w = sqrt(u), zs = cv / w, zss = cv / (u * w);   /* z'/s and z'' */
        if (c->model == RG_ASPHERE) {
            double p = s2;          /* s^(2+2i) */
            for (int i = 0; i < c->nasph; i++) {
                zs += c->asph[i] * (4 + 2 * i) * p;
                zss += c->asph[i] * (4 + 2 * i) * (3 + 2 * i) * p;
                p *= s2;
            }
        }
        h[0] = h[2] = zs;
        h[1] = 0;
        if (s2 > 0) {
            double d = (zss - zs) / s2;
            h[0] += d * x * x; h[1] += d * x * y; h[2] += d * y * y;
        }
        return 0;
    }
    double ca = cos(c->axis), sa = sin(c->axis);
    double xp = ca * x + sa * y, yp = -sa * x + ca * y;
    double cx = 1 / c->R, cy = 1 / c->R2;
    double kx = (1 + c->Q) * cx * cx, ky = (1 + c->Q2) * cy * cy;
    double u = 1 - kx * xp * xp - ky * yp * yp;
    if (u <= 0) return -1;
    double S = sqrt(u), D = 1 + S, N = cx * xp * xp + cy * yp * yp;
    double Ni[2] = {2 * cx * xp, 2 * cy * yp}, Nii[2] = {2 * cx, 2 * cy};
    double ui[2] = {-2 * kx * xp, -2 * ky * yp}, uii[2] = {-2 * kx, -2 * ky};
    double Si[2] = {ui[0] / (2 * S), ui[1] / (2 * S)}, hp[3];
    for (int k = 0; k < 3; k++) {       /* (i, j) = (0,0), (0,1), (1,1) */
        int i = k == 2, j = k > 0;
        double Nij = i == j ? Nii[i] : 0, uij = i == j ? uii[i] : 0;
        double Sij = uij / (2 * S) - ui[i] * ui[j] / (4 * S * S * S);
        hp[k] = Nij / D - (Ni[i] * Si[j] + Ni[j] * Si[i]) / (D * D) - N * Sij / (D * D) +
                2 * N * Si[i] * Si[j] / (D * D * D);
    }
    /* H = Rt H' R with (xp, yp) = R (x, y), R = [ca sa; -sa ca] */
    h[0] = ca * ca * hp[0] - 2 * ca * sa * hp[1] + sa * sa * hp[2];
    h[1] = ca * sa * (hp[0] - hp[2]) + (ca * ca - sa * sa) * hp[1];
    h[2] = sa * sa * hp[0] + 2 * ca * sa * hp[1] + ca * ca * hp[2];
    return 0;
}

int rg_cornea_curvature(const rg_cornea *c, const double p[3], const double e1[3],
                        const double e2[3], double K[3])
{
    double rel[3], pe[3], a[3], b[3], h[3], z, fx, fy;
    v3sub(rel, p, c->trans);
    m3tmul(pe, c->rot, rel);
    m3tmul(a, c->rot, e1);
    m3tmul(b, c->rot, e2);
    if (rg_sag(c, pe[0], pe[1], &z, &fx, &fy) || sag_hessian(c, pe[0], pe[1], h)) return RG_EUNREACH;
    /* II(a, b) = (a_xy)^T H (b_xy) / |(fx, fy, -1)|: a tangent vector's xy part is its
     * coordinate differential; the inward normal (-fx, -fy, 1)/|.| */
    double g = sqrt(1 + fx * fx + fy * fy);
#define II(u, v) ((u[0] * (h[0] * v[0] + h[1] * v[1]) + u[1] * (h[1] * v[0] + h[2] * v[1])) / g)
    K[0] = II(a, a);
    K[1] = II(b, b);
    K[2] = II(a, b);
#undef II
    return RG_OK;
}
