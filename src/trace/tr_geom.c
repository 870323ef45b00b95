/* tr_geom.c -- the engine's analytic surfaces in double: plane (disc, annulus,
 * rectangle), axial conic + even asphere (section 33), closed sphere.  Closed-form
 * intersection for planes, spheres and conics (stable quadratic), safeguarded Newton
 * for aspheres, analytic normals, world bounds for Embree.  A ray leaving a surface
 * drops the root at t = 0 exactly (constant term set to zero), so there is no
 * self-intersection acne and no epsilon. */
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include "tr_int.h"

void tr_set_err(char *err, size_t cap, const char *fmt, ...)
{
    va_list ap;
    if (!err || !cap) return;
    va_start(ap, fmt);
    vsnprintf(err, cap, fmt, ap);
    va_end(ap);
}

static int finite3(const double a[3])
{
    return isfinite(a[0]) && isfinite(a[1]) && isfinite(a[2]);
}

static void frame(tr_shape *g, const double up[3])
{
    double v[3];
    v_set(v, up);
    double k = v_dot(v, g->w);
    v[0] -= k * g->w[0]; v[1] -= k * g->w[1]; v[2] -= k * g->w[2];
    if (!finite3(v) || v_norm(v) < 1e-9 * (v_norm(up) + 1e-300)) {
        /* any vector not parallel to w */
        double a[3] = {0, 1, 0};             /* w = z gives the world frame */
        if (fabs(g->w[1]) > 0.6) { a[0] = 1; a[1] = 0; }
        k = v_dot(a, g->w);
        v[0] = a[0] - k * g->w[0]; v[1] = a[1] - k * g->w[1]; v[2] = a[2] - k * g->w[2];
    }
    v_unit(v);
    v_set(g->v, v);
    v_cross(g->v, g->w, g->u);   /* u x v = w */
    v_unit(g->u);
}

/* Conic part of the sag and its derivative with respect to s^2. */
static int conic_sag(const tr_shape *g, double s2, double *z, double *dz)
{
    double q = 1.0 - (1.0 + g->k) * g->c * g->c * s2;
    if (q < 0) return -1;
    double r = sqrt(q);
    *z = g->c * s2 / (1.0 + r);
    if (dz) *dz = r > 0 ? 0.5 * g->c / r : INFINITY;
    return 0;
}

static int sag(const tr_shape *g, double s2, double *z, double *dz)
{
    double zc, dc;
    if (conic_sag(g, s2, &zc, &dc)) return -1;
    double p = s2, za = 0, da = 0, pp = 1;   /* s^(2i+2), s^(2i) */
    for (int i = 0; i < g->nasph; i++) {
        za += g->asph[i] * p;
        da += (i + 1) * g->asph[i] * pp;
        pp = p;
        p *= s2;
    }
    *z = zc + za;
    if (dz) *dz = dc + da;
    return 0;
}

/* Surfaces whose frame is the world's (lenses on the z axis) skip the rotation;
 * the results are the same bits (products by exact 1 and 0). */
static void to_local(const tr_shape *g, const double p[3], double l[3])
{
    double q[3] = {p[0] - g->at[0], p[1] - g->at[1], p[2] - g->at[2]};
    if (g->aligned) { l[0] = q[0]; l[1] = q[1]; l[2] = q[2]; return; }
    l[0] = v_dot(q, g->u); l[1] = v_dot(q, g->v); l[2] = v_dot(q, g->w);
}
static void dir_local(const tr_shape *g, const double d[3], double l[3])
{
    if (g->aligned) { l[0] = d[0]; l[1] = d[1]; l[2] = d[2]; return; }
    l[0] = v_dot(d, g->u); l[1] = v_dot(d, g->v); l[2] = v_dot(d, g->w);
}
static void to_world_dir(const tr_shape *g, const double l[3], double d[3])
{
    if (g->aligned) { d[0] = l[0]; d[1] = l[1]; d[2] = l[2]; return; }
    for (int i = 0; i < 3; i++)
        d[i] = l[0] * g->u[i] + l[1] * g->v[i] + l[2] * g->w[i];
}

static void grow(double lo[3], double hi[3], const double p[3])
{
    for (int i = 0; i < 3; i++) {
        if (p[i] < lo[i]) lo[i] = p[i];
        if (p[i] > hi[i]) hi[i] = p[i];
    }
}

static void local_box(tr_shape *g, double x, double y, double z0, double z1)
{
    for (int i = 0; i < 3; i++) { g->lo[i] = INFINITY; g->hi[i] = -INFINITY; }
    for (int c = 0; c < 8; c++) {
        double l[3] = {(c & 1) ? x : -x, (c & 2) ? y : -y, (c & 4) ? z1 : z0}, p[3];
        to_world_dir(g, l, p);
        p[0] += g->at[0]; p[1] += g->at[1]; p[2] += g->at[2];
        grow(g->lo, g->hi, p);
    }
}

static void pad_box(tr_shape *g)
{
    for (int i = 0; i < 3; i++) {
        double m = 1e-6 * g->scale + 1e-6 * fmax(fabs(g->lo[i]), fabs(g->hi[i]));
        g->lo[i] -= m;
        g->hi[i] += m;
    }
}

static int init_aperture(tr_shape *g, const trace_surface *s, char *err, size_t cap)
{
    g->aperture = s->aperture;
    if (!tr_len_ok(s->width) || !tr_len_ok(s->height) || !tr_len_ok(s->r_outer) ||
        !tr_len_ok(s->r_inner)) {
        tr_set_err(err, cap, "aperture sizes must be 0 or %g to %g", TR_LEN_MIN, TR_LEN_MAX);
        return -1;
    }
    if (s->aperture == TRACE_AP_RECT) {
        if (!(s->width > 0 && s->height > 0 && isfinite(s->width) && isfinite(s->height))) {
            tr_set_err(err, cap, "rectangle needs a positive width and height");
            return -1;
        }
        g->hw = s->width / 2;
        g->hh = s->height / 2;
        return 0;
    }
    if (s->aperture != TRACE_AP_DISC) {
        tr_set_err(err, cap, "unknown aperture type %d", s->aperture);
        return -1;
    }
    if (!(s->r_outer >= 0 && isfinite(s->r_outer)) ||
        !(s->r_inner >= 0 && isfinite(s->r_inner)) ||
        (s->r_outer > 0 && s->r_inner >= s->r_outer)) {
        tr_set_err(err, cap, "bad aperture radii (outer %g, inner %g)", s->r_outer,
                   s->r_inner);
        return -1;
    }
    g->r_outer2 = s->r_outer * s->r_outer;
    g->r_inner2 = s->r_inner * s->r_inner;
    return 0;
}

static int init_axial(tr_shape *g, const trace_surface *s, char *err, size_t cap)
{
    double smax, zlo, zhi, extra = 0;
    g->c = (s->radius == 0 || isinf(s->radius)) ? 0.0 : 1.0 / s->radius;
    g->k = s->conic;
    if (!isfinite(g->k)) { tr_set_err(err, cap, "conic constant is not finite"); return -1; }
    if (s->nasph < 0 || s->nasph > TRACE_MAXASPH) {
        tr_set_err(err, cap, "%d aspheric coefficients (at most %d)", s->nasph,
                   TRACE_MAXASPH);
        return -1;
    }
    g->nasph = s->nasph;
    for (int i = 0; i < s->nasph; i++) {
        if (!isfinite(s->asph[i])) {
            tr_set_err(err, cap, "aspheric coefficient %d is not finite", i);
            return -1;
        }
        g->asph[i] = s->asph[i];
    }
    if (init_aperture(g, s, err, cap)) return -1;
    if (g->aperture == TRACE_AP_RECT) smax = sqrt(g->hw * g->hw + g->hh * g->hh);
    else smax = sqrt(g->r_outer2);
    if (smax == 0) {
        if (g->c == 0 || g->k <= -1 || g->nasph) {
            tr_set_err(err, cap, "this surface is unbounded: give it a semi-diameter");
            return -1;
        }
        smax = 1.0 / (fabs(g->c) * sqrt(1.0 + g->k));
    }
    if (1.0 - (1.0 + g->k) * g->c * g->c * smax * smax < -1e-12) {
        tr_set_err(err, cap, "the conic (radius %g, k %g) has no real surface at the "
                   "aperture (%g)", s->radius, g->k, smax);
        return -1;
    }
    double z0 = 0, z1;
    if (conic_sag(g, g->r_inner2, &z0, NULL)) z0 = 0;
    if (conic_sag(g, smax * smax, &z1, NULL)) z1 = 1.0 / (g->c * (1.0 + g->k));
    for (int i = 0; i < g->nasph; i++) extra += fabs(g->asph[i]) * pow(smax, 2 * i + 2);
    zlo = fmin(z0, z1) - extra;
    zhi = fmax(z0, z1) + extra;
    g->scale = fmax(smax, zhi - zlo);
    g->reach = hypot(smax, fmax(fabs(zlo), fabs(zhi))) * (1 + 1e-9);
    local_box(g, smax, smax, zlo, zhi);
    return 0;
}

int tr_shape_init(tr_shape *g, const trace_surface *s, char *err, size_t cap)
{
    memset(g, 0, sizeof *g);
    g->shape = s->shape;
    if (!finite3(s->at) || !finite3(s->axis) || !finite3(s->up)) {
        tr_set_err(err, cap, "surface position or axis is not finite");
        return -1;
    }
    v_set(g->at, s->at);
    g->radius = s->radius;
    if (!isinf(s->radius) && !tr_len_ok(s->radius)) {
        tr_set_err(err, cap, "radius %g is out of range (0, or %g to %g)", s->radius,
                   TR_LEN_MIN, TR_LEN_MAX);
        return -1;
    }
    for (int i = 0; i < 3; i++)
        if (fabs(s->at[i]) > TR_LEN_MAX) {
            tr_set_err(err, cap, "surface position beyond |x| <= %g", TR_LEN_MAX);
            return -1;
        }
    switch (s->shape) {
    case TRACE_SPHERE:
        if (!(s->radius > 0 && isfinite(s->radius))) {
            tr_set_err(err, cap, "sphere radius must be positive (got %g)", s->radius);
            return -1;
        }
        g->w[2] = 1; frame(g, s->up);
        g->scale = s->radius;
        g->reach = s->radius;
        for (int i = 0; i < 3; i++) {
            g->lo[i] = s->at[i] - s->radius;
            g->hi[i] = s->at[i] + s->radius;
        }
        break;
    case TRACE_PLANE:
    case TRACE_AXIAL:
        v_set(g->w, s->axis);
        if (v_unit(g->w)) {
            tr_set_err(err, cap, "surface axis (normal) is zero");
            return -1;
        }
        frame(g, s->up);
        if (s->shape == TRACE_AXIAL) {
            if (!isfinite(s->radius) && !isinf(s->radius)) {
                tr_set_err(err, cap, "radius is not a number");
                return -1;
            }
            if (init_axial(g, s, err, cap)) return -1;
        } else {
            if (init_aperture(g, s, err, cap)) return -1;
            double x = g->aperture == TRACE_AP_RECT ? g->hw : sqrt(g->r_outer2);
            double y = g->aperture == TRACE_AP_RECT ? g->hh : x;
            if (x == 0) {
                tr_set_err(err, cap, "a plane needs an aperture (radius or rectangle)");
                return -1;
            }
            g->scale = fmax(x, y);
            g->reach = hypot(x, y) * (1 + 1e-9);
            local_box(g, x, y, 0, 0);
        }
        break;
    default:
        tr_set_err(err, cap, "unknown surface shape %d", s->shape);
        return -1;
    }
    pad_box(g);
    g->aligned = g->u[0] == 1 && g->u[1] == 0 && g->u[2] == 0 && g->v[0] == 0 &&
                 g->v[1] == 1 && g->v[2] == 0 && g->w[0] == 0 && g->w[1] == 0 &&
                 g->w[2] == 1;
    g->k1 = 1.0 + g->k;
    g->ck1 = g->c * g->k1;
    g->fast = !g->aligned ? TR_FAST_NONE :
              s->shape == TRACE_PLANE ? TR_FAST_PLANE :
              s->shape == TRACE_AXIAL && g->nasph == 0 ? TR_FAST_CONIC : TR_FAST_NONE;
    return 0;
}

/* ---- intersection ---- */

static int plane_hit(const tr_shape *g, const double o[3], const double d[3],
                     int leaving, double *t, double p[3])
{
    double lo[3], ld[3];
    if (leaving) return 0;
    to_local(g, o, lo);
    dir_local(g, d, ld);
    if (ld[2] == 0) return 0;
    double tt = -lo[2] / ld[2];
    if (!(tt > 0)) return 0;
    p[0] = lo[0] + tt * ld[0];
    p[1] = lo[1] + tt * ld[1];
    p[2] = 0;
    if (!tr_in_aperture(g, p[0], p[1])) return 0;
    *t = tt;
    return tr_advance(g, lo, ld) > 0 ? 2 : 1;
}

/* p: the hit relative to the centre */
static int sphere_hit(const tr_shape *g, const double o[3], const double d[3],
                      int leaving, double *t, double p[3])
{
    double q[3] = {o[0] - g->at[0], o[1] - g->at[1], o[2] - g->at[2]}, t0 = 0;
    if (!leaving && (t0 = tr_advance(g, q, d)) > 0)     /* a far start: see tr_int.h */
        for (int i = 0; i < 3; i++) q[i] += t0 * d[i];
    double A = v_dot(d, d), B = v_dot(q, d), R = g->radius;
    double l[3] = {q[0] - B / A * d[0], q[1] - B / A * d[1], q[2] - B / A * d[2]};
    double h2 = R * R - v_dot(l, l);
    double C = leaving ? 0.0 : v_dot(q, q) - R * R;
    double r[2], tt = -1;
    if (h2 < 0) return 0;
    double qq = -(B + copysign(sqrt(A * h2), B));
    r[0] = qq / A;
    r[1] = qq != 0 ? C / qq : 0;
    if (r[0] > r[1]) { double x = r[0]; r[0] = r[1]; r[1] = x; }
    if (r[0] > 0) tt = r[0];
    else if (r[1] > 0) tt = r[1];
    if (!(tt > 0)) return 0;
    for (int i = 0; i < 3; i++) p[i] = q[i] + tt * d[i];
    *t = t0 + tt;
    return t0 > 0 ? 2 : 1;
}

static void axial_normal_local(const tr_shape *g, const double p[3], double nl[3])
{
    if (g->nasph == 0) {
        tr_conic_normal_local(g, p, nl);
        return;
    }
    double z, dz;
    if (sag(g, p[0] * p[0] + p[1] * p[1], &z, &dz)) dz = 0;
    nl[0] = -2 * p[0] * dz;
    nl[1] = -2 * p[1] * dz;
    nl[2] = 1.0;
    double l = 1.0 / sqrt(nl[0] * nl[0] + nl[1] * nl[1] + nl[2] * nl[2]);
    nl[0] *= l; nl[1] *= l; nl[2] *= l;
}

/* Newton on h(t) = z(t) - sag(s(t)^2) in local coordinates, from t. */
static int asph_newton(const tr_shape *g, const double lo[3], const double ld[3],
                       double *t)
{
    double tt = *t, step = INFINITY;
    for (int it = 0; it < 60; it++) {
        double x = lo[0] + tt * ld[0], y = lo[1] + tt * ld[1], zz = lo[2] + tt * ld[2];
        double z, dz;
        if (sag(g, x * x + y * y, &z, &dz)) {
            if (!isfinite(step)) return 0;
            step *= 0.5;             /* stepped off the surface: go back half way */
            tt -= step;
            continue;
        }
        double h = zz - z, hp = ld[2] - 2 * dz * (x * ld[0] + y * ld[1]);
        if (hp == 0 || !isfinite(hp)) return 0;
        step = -h / hp;
        tt += step;
        if (fabs(step) <= 4 * DBL_EPSILON * fmax(fabs(tt), g->scale)) {
            *t = tt;
            return 1;
        }
    }
    return 0;
}

/* p: the hit in local coordinates */
static int axial_hit(const tr_shape *g, const double o[3], const double d[3],
                     int leaving, double *t, double p[3])
{
    double lo[3], ld[3], r[2];
    double c = g->c, k1 = 1.0 + g->k, tmin = 0, t0 = 0;
    int nr = 0;
    to_local(g, o, lo);
    dir_local(g, d, ld);
    if (!leaving && (t0 = tr_advance(g, lo, ld)) > 0)   /* a far start: see tr_int.h */
        for (int j = 0; j < 3; j++) lo[j] += t0 * ld[j];
    double A = c * (ld[0] * ld[0] + ld[1] * ld[1] + k1 * ld[2] * ld[2]);
    double B = c * (lo[0] * ld[0] + lo[1] * ld[1] + k1 * lo[2] * ld[2]) - ld[2];
    double C = c * (lo[0] * lo[0] + lo[1] * lo[1] + k1 * lo[2] * lo[2]) - 2 * lo[2];
    if (leaving) {
        if (g->nasph == 0) C = 0;
        else tmin = 1e-9 * g->scale;
    }
    double disc = B * B - A * C;
    if (leaving && !g->nasph) {
        /* roots 0 and -2B/A (what the general branch gives, sqrt(B^2) being |B|) */
        if (A == 0) return 0;
        r[nr++] = -2 * B / A;
    } else if (disc < 0) {
        if (!g->nasph) return 0;
        r[nr++] = ld[2] != 0 ? -lo[2] / ld[2] : 0;     /* start from the vertex plane */
    } else {
        nr = tr_quad_roots(A, B, C, disc, r);
    }
    for (int i = 0; i < nr; i++) {
        double tt = r[i];
        if (g->nasph) {
            if (tt <= tmin && i + 1 < nr) continue;
            if (!asph_newton(g, lo, ld, &tt)) continue;
        }
        if (!(tt > tmin)) continue;
        for (int j = 0; j < 3; j++) p[j] = lo[j] + tt * ld[j];
        if (!tr_axial_ok(g, p)) continue;
        *t = t0 + tt;
        return t0 > 0 ? 2 : 1;
    }
    return 0;
}

int tr_shape_hit_t(const tr_shape *g, const double o[3], const double d[3], int leaving,
                   double *t, double p[3])
{
    switch (g->fast) {
    case TR_FAST_CONIC: return tr_conic_hit(g, o, d, leaving, t, p);
    case TR_FAST_PLANE: return tr_plane_hit(g, o, d, leaving, t, p);
    default: break;
    }
    switch (g->shape) {
    case TRACE_PLANE: return plane_hit(g, o, d, leaving, t, p);
    case TRACE_SPHERE: return sphere_hit(g, o, d, leaving, t, p);
    default: return axial_hit(g, o, d, leaving, t, p);
    }
}

void tr_shape_hit_normal(const tr_shape *g, const double p[3], double n[3])
{
    double nl[3];
    switch (g->shape) {
    case TRACE_PLANE:
        v_set(n, g->w);
        break;
    case TRACE_SPHERE:
        for (int i = 0; i < 3; i++) n[i] = p[i] / g->radius;
        v_unit(n);
        break;
    default:
        axial_normal_local(g, p, nl);
        to_world_dir(g, nl, n);
    }
}

void tr_shape_world(const tr_shape *g, const double p[3], double q[3])
{
    if (g->shape == TRACE_SPHERE) {               /* p is relative to the centre */
        for (int i = 0; i < 3; i++) q[i] = g->at[i] + p[i];
        return;
    }
    to_world_dir(g, p, q);
    for (int i = 0; i < 3; i++) q[i] += g->at[i];
}

int tr_shape_hit(const tr_shape *g, const double o[3], const double d[3], int leaving,
                 double *t, double n[3])
{
    double p[3];
    int ok = tr_shape_hit_t(g, o, d, leaving, t, p);
    if (ok) tr_shape_hit_normal(g, p, n);
    return ok;
}

/* Single precision throughout (what a float-only tracer computes). */
int tr_shape_hit_float(const tr_shape *g, const double o[3], const double d[3],
                       int leaving, double *t, double n[3])
{
    float lo[3], ld[3], u[3][3];
    for (int i = 0; i < 3; i++) {
        u[0][i] = (float)g->u[i]; u[1][i] = (float)g->v[i]; u[2][i] = (float)g->w[i];
    }
    for (int a = 0; a < 3; a++) {
        lo[a] = 0; ld[a] = 0;
        for (int i = 0; i < 3; i++) {
            lo[a] += ((float)o[i] - (float)g->at[i]) * u[a][i];
            ld[a] += (float)d[i] * u[a][i];
        }
    }
    if (g->shape == TRACE_SPHERE || g->nasph) {
        return tr_shape_hit(g, o, d, leaving, t, n);   /* not needed in float */
    }
    float tt = -1, nl[3];
    if (g->shape == TRACE_PLANE || g->c == 0) {
        if (leaving || ld[2] == 0) return 0;
        tt = -lo[2] / ld[2];
        if (!(tt > 0) || !tr_in_aperture(g, lo[0] + tt * ld[0], lo[1] + tt * ld[1]))
            return 0;
        nl[0] = 0; nl[1] = 0; nl[2] = 1;
    } else {
        float c = (float)g->c, k1 = (float)(1.0 + g->k);
        float A = c * (ld[0] * ld[0] + ld[1] * ld[1] + k1 * ld[2] * ld[2]);
        float B = c * (lo[0] * ld[0] + lo[1] * ld[1] + k1 * lo[2] * ld[2]) - ld[2];
        float C = leaving ? 0.0f :
                  c * (lo[0] * lo[0] + lo[1] * lo[1] + k1 * lo[2] * lo[2]) - 2 * lo[2];
        float disc = B * B - A * C, r[2];
        if (disc < 0) return 0;
        float q = -(B + copysignf(sqrtf(disc), B));
        r[0] = A != 0 ? q / A : -1;
        r[1] = q != 0 ? C / q : -1;
        if (r[0] > r[1]) { float x = r[0]; r[0] = r[1]; r[1] = x; }
        int found = 0;
        for (int i = 0; i < 2 && !found; i++) {
            double p[3];
            if (!(r[i] > 0)) continue;
            for (int j = 0; j < 3; j++) p[j] = lo[j] + r[i] * ld[j];
            if (!tr_axial_ok(g, p)) continue;
            tt = r[i];
            nl[0] = -c * (float)p[0]; nl[1] = -c * (float)p[1];
            nl[2] = 1.0f - c * k1 * (float)p[2];
            found = 1;
        }
        if (!found) return 0;
    }
    float l = sqrtf(nl[0] * nl[0] + nl[1] * nl[1] + nl[2] * nl[2]);
    for (int i = 0; i < 3; i++)
        n[i] = (float)((nl[0] * u[0][i] + nl[1] * u[1][i] + nl[2] * u[2][i]) / l);
    *t = tt;
    return 1;
}

void tr_shape_normal(const tr_shape *g, const double p[3], double n[3])
{
    double l[3], nl[3];
    if (g->shape == TRACE_SPHERE) {
        for (int i = 0; i < 3; i++) n[i] = p[i] - g->at[i];
        v_unit(n);
        return;
    }
    if (g->shape == TRACE_PLANE) { v_set(n, g->w); return; }
    to_local(g, p, l);
    axial_normal_local(g, l, nl);
    to_world_dir(g, nl, n);
}

int tr_shape_refine(const tr_shape *g, const double o[3], const double d[3], double t0,
                    double *t)
{
    double lo[3], ld[3], tt = t0;
    to_local(g, o, lo);
    dir_local(g, d, ld);
    if (g->shape == TRACE_PLANE || (g->shape == TRACE_AXIAL && g->c == 0 && !g->nasph)) {
        if (ld[2] == 0) return 0;
        *t = -lo[2] / ld[2];
        return 1;
    }
    if (g->shape == TRACE_AXIAL) {
        if (!asph_newton(g, lo, ld, &tt)) return 0;
    } else {
        double q[3] = {o[0] - g->at[0], o[1] - g->at[1], o[2] - g->at[2]};
        int ok = 0;
        for (int it = 0; it < 60 && !ok; it++) {
            double p[3] = {q[0] + tt * d[0], q[1] + tt * d[1], q[2] + tt * d[2]};
            double f = v_dot(p, p) - g->radius * g->radius, fp = 2 * v_dot(p, d);
            if (fp == 0) return 0;
            double step = -f / fp;
            tt += step;
            ok = fabs(step) <= 4 * DBL_EPSILON * fmax(fabs(tt), g->scale);
        }
        if (!ok) return 0;
    }
    if (!(fabs(tt - t0) <= 0.1 * g->scale + 1e-6 * fabs(t0))) return 0;
    *t = tt;
    return 1;
}
