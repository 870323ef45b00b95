/* tr_int.h -- private to the trace engine's own files (tr_*.c); callers use trace.h.
 * Analytic surfaces in double (tr_geom.c), optics (tr_optics.c), sources
 * (tr_source.c), the scene on Embree (tr_scene.c) and its next-hit query (tr_hit.c), the
 * trace loop (tr_trace.c, tr_lanes.c, tr_pool.c: tr_eng.h), the table (tr_engine.c),
 * sequential lenses (tr_lens.c). */
#ifndef TR_INT_H
#define TR_INT_H
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include "trace.h"

/* Everything declared below stays inside the module (only trace_get_api, declared in
 * trace.h above, is exported): calls between the engine's files then go direct, not
 * through the PLT, and may be inlined. */
#pragma GCC visibility push(hidden)

#define TR_PI 3.14159265358979323846

/* ---- small vector helpers ---- */
static inline double v_dot(const double a[3], const double b[3])
{ return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static inline void v_cross(const double a[3], const double b[3], double c[3])
{
    double x = a[1] * b[2] - a[2] * b[1];
    double y = a[2] * b[0] - a[0] * b[2];
    double z = a[0] * b[1] - a[1] * b[0];
    c[0] = x; c[1] = y; c[2] = z;
}
static inline double v_norm(const double a[3]) { return sqrt(v_dot(a, a)); }
/* A finite vector whose squared length under- or overflows is scaled by its largest
 * component first (dir 0 0 1e-170 is a direction); only zero and non-finite fail. */
static inline int v_unit(double a[3])
{
    double l = v_norm(a);
    if (!(l > 0) || !isfinite(l)) {
        double m = fmax(fabs(a[0]), fmax(fabs(a[1]), fabs(a[2])));
        if (!(m > 0) || !isfinite(m)) return -1;
        a[0] /= m; a[1] /= m; a[2] /= m;
        l = v_norm(a);
    }
    double r = 1.0 / l;
    a[0] *= r; a[1] *= r; a[2] *= r;
    return 0;
}

/* The one range of lengths and sizes (the scene reader's too): 0 where a size may be
 * absent, else 1e-30 <= |x| <= 1e30, so that their squares and products neither
 * underflow nor overflow. */
#define TR_LEN_MIN 1e-30
#define TR_LEN_MAX 1e30
static inline int tr_len_ok(double x)
{
    return x == 0 || (fabs(x) >= TR_LEN_MIN && fabs(x) <= TR_LEN_MAX);
}
static inline void v_set(double d[3], const double s[3]) { d[0] = s[0]; d[1] = s[1]; d[2] = s[2]; }

/* ---- analytic surfaces (tr_geom.c) ---- */
typedef struct tr_shape {
    int shape;                 /* enum trace_shape */
    double at[3];              /* vertex / point / centre */
    double u[3], v[3], w[3];   /* local frame, w = axis (unit) */
    double radius, c, k;       /* c = 1/radius (0: flat) */
    double asph[TRACE_MAXASPH];
    int nasph;
    int aperture;
    double r_outer2, r_inner2; /* squared; r_outer2 = 0: unbounded (sphere limit) */
    double hw, hh;             /* rectangle half width (along u), half height (v) */
    double scale;              /* size, for tolerances */
    double reach;              /* no point of the surface lies farther from at */
    double lo[3], hi[3];       /* world bounds */
    int aligned;               /* u, v, w are the world's x, y, z */
    double k1, ck1;            /* 1 + k and c (1 + k), as the formulas compute them */
    int fast;                  /* TR_FAST_*: an inline case of tr_shape_hit_t */
} tr_shape;

enum { TR_FAST_NONE, TR_FAST_CONIC, TR_FAST_PLANE };

/* A ray starting farther than TR_FAR reaches before its closest approach to a
 * surface's vertex is solved from an origin advanced, in double, to one reach before
 * that point (tr_advance: the advance, or 0 for a ray near enough).  The quadratic's
 * terms then cancel only as far as the surface's own size makes them, wherever the ray
 * started: the hit keeps the precision of a ray started next to the surface (about the
 * rounding of the start point itself), not one that falls with the square of the
 * distance.  Points of the ray before the advanced origin are farther than the reach
 * from the vertex, so no root is lost. */
#define TR_FAR 4.0
static inline double tr_advance(const tr_shape *g, const double lo[3], const double d[3])
{
    double t0 = -(lo[0] * d[0] + lo[1] * d[1] + lo[2] * d[2]) - g->reach;
    return t0 > TR_FAR * g->reach ? t0 : 0;
}

/* Inside the aperture at local (x, y)? */
static inline int tr_in_aperture(const tr_shape *g, double x, double y)
{
    if (g->aperture == TRACE_AP_RECT) return fabs(x) <= g->hw && fabs(y) <= g->hh;
    double s2 = x * x + y * y;
    if (g->r_outer2 > 0 && s2 > g->r_outer2) return 0;
    return s2 >= g->r_inner2;
}

/* On the vertex branch of the conic and inside the aperture (local point p)? */
static inline int tr_axial_ok(const tr_shape *g, const double p[3])
{
    if (g->c != 0 && 1.0 - g->ck1 * p[2] <= 0) return 0;
    if (g->r_outer2 == 0 && g->aperture == TRACE_AP_DISC && g->c != 0 &&
        1.0 - g->k1 * g->c * g->c * (p[0] * p[0] + p[1] * p[1]) < 0)
        return 0;
    return tr_in_aperture(g, p[0], p[1]);
}

/* Both real roots of A t^2 + 2B t + C = 0 (disc = B^2 - A C >= 0) in the stable form:
 * q = -(B + sign(B) sqrt(disc)), roots q/A and C/q (each only where it is defined),
 * ascending.  Returns how many.  Shared by every quadric intersection. */
static inline int tr_quad_roots(double A, double B, double C, double disc, double r[2])
{
    int nr = 0;
    double q = -(B + copysign(sqrt(disc), B));
    if (A != 0) r[nr++] = q / A;
    if (q != 0) r[nr++] = C / q;
    if (nr == 2 && r[0] > r[1]) { double x = r[0]; r[0] = r[1]; r[1] = x; }
    return nr;
}

/* The hot cases of tr_shape_hit_t, inline (the trace loop calls them per segment):
 * TR_FAST_CONIC, an axial conic without aspheric terms whose frame is the world's
 * (lens surfaces): stable quadratic, and a ray leaving the surface drops the root
 * t = 0 exactly (roots 0 and -2B/A); p = the hit in local coordinates. */
static inline int tr_conic_hit(const tr_shape *g, const double o[3], const double d[3],
                               int leaving, double *t, double p[3])
{
    double lo[3] = {o[0] - g->at[0], o[1] - g->at[1], o[2] - g->at[2]};
    double c = g->c, k1 = g->k1, r[2], t0 = 0;
    int nr = 0;
    if (!leaving && (t0 = tr_advance(g, lo, d)) > 0)
        for (int j = 0; j < 3; j++) lo[j] += t0 * d[j];
    double A = c * (d[0] * d[0] + d[1] * d[1] + k1 * d[2] * d[2]);
    double B = c * (lo[0] * d[0] + lo[1] * d[1] + k1 * lo[2] * d[2]) - d[2];
    if (leaving) {
        if (A == 0) return 0;
        r[nr++] = -2 * B / A;
    } else {
        double C = c * (lo[0] * lo[0] + lo[1] * lo[1] + k1 * lo[2] * lo[2]) - 2 * lo[2];
        double disc = B * B - A * C;
        if (disc < 0) return 0;
        nr = tr_quad_roots(A, B, C, disc, r);
    }
    for (int i = 0; i < nr; i++) {
        double tt = r[i];
        if (!(tt > 0)) continue;
        for (int j = 0; j < 3; j++) p[j] = lo[j] + tt * d[j];
        if (!tr_axial_ok(g, p)) continue;
        *t = t0 + tt;
        return t0 > 0 ? 2 : 1;
    }
    return 0;
}

/* Unit normal (toward back) of a conic at local point p. */
static inline void tr_conic_normal_local(const tr_shape *g, const double p[3], double nl[3])
{
    nl[0] = -g->c * p[0];
    nl[1] = -g->c * p[1];
    nl[2] = 1.0 - g->ck1 * p[2];
    double l = 1.0 / sqrt(nl[0] * nl[0] + nl[1] * nl[1] + nl[2] * nl[2]);
    nl[0] *= l; nl[1] *= l; nl[2] *= l;
}

/* TR_FAST_PLANE: a plane whose frame is the world's; p = the hit in local
 * coordinates (z = 0). */
static inline int tr_plane_hit(const tr_shape *g, const double o[3], const double d[3],
                               int leaving, double *t, double p[3])
{
    if (leaving || d[2] == 0) return 0;
    double lo[3] = {o[0] - g->at[0], o[1] - g->at[1], o[2] - g->at[2]};
    double tt = -lo[2] / d[2];
    if (!(tt > 0)) return 0;
    p[0] = lo[0] + tt * d[0];
    p[1] = lo[1] + tt * d[1];
    p[2] = 0;
    if (!tr_in_aperture(g, p[0], p[1])) return 0;
    *t = tt;
    return tr_advance(g, lo, d) > 0 ? 2 : 1;
}

/* The hit functions below return 1 for a hit, and 2 for a hit of a ray that started
 * far away (tr_advance): the caller then takes the hit point from the surface's own
 * frame (tr_shape_world of the local point p), which holds it to the rounding of the
 * surface's size, instead of o + t d, which rounds to that of the start point. */
/* Validates and prepares; 0, or -1 with a message in err. */
int tr_shape_init(tr_shape *g, const trace_surface *s, char *err, size_t cap);
/* Nearest intersection with t > 0 of the ray o + t d (d unit).  `leaving`: the
 * origin lies on this surface (the root at t = 0 is excluded exactly).  Returns 1
 * with *t and the unit normal n (pointing to the back side), 0 for none. */
int tr_shape_hit(const tr_shape *g, const double o[3], const double d[3], int leaving,
                 double *t, double n[3]);
/* The same in two steps: the root (*t) and a point p that tr_shape_hit_normal turns
 * into the normal, so a caller choosing among candidates computes one normal. */
int tr_shape_hit_t(const tr_shape *g, const double o[3], const double d[3], int leaving,
                   double *t, double p[3]);
void tr_shape_hit_normal(const tr_shape *g, const double p[3], double n[3]);
/* The world point of the local hit point p that tr_shape_hit_t returned with 2. */
void tr_shape_world(const tr_shape *g, const double p[3], double q[3]);
/* The same computed in single precision (to compare with a float-only tracer). */
int tr_shape_hit_float(const tr_shape *g, const double o[3], const double d[3],
                       int leaving, double *t, double n[3]);
/* Unit normal (toward back) at a point near the surface. */
void tr_shape_normal(const tr_shape *g, const double p[3], double n[3]);
/* Newton on the implicit function from t0: 1 with *t, or 0. */
int tr_shape_refine(const tr_shape *g, const double o[3], const double d[3], double t0,
                    double *t);

/* ---- optics (tr_optics.c) ---- */
/* Coherency state of a ray in the basis (e, d x e). */
typedef struct tr_pol {
    double e[3];
    double jss, jpp, jre, jim;   /* <Es Es*>, <Ep Ep*>, <Es Ep*> */
} tr_pol;

void tr_fresnel(double n1, double n2, double cos_i, trace_fresnel_coef *f);
int tr_refract(const double d[3], const double nrm[3], double n1, double n2,
               double out[3]);
/* Rotate the state of a ray with direction d into the s/p basis given by unit s.
 * New basis: s and d x s.  With f = d x e: s = c e + s f, so the components are
 * E_s = c E_e + s E_f and E_p = -s E_e + c E_f; J' = R J R^T. */
static inline void tr_pol_rotate(tr_pol *p, const double d[3], const double s[3])
{
    double f[3];
    if (p->jss == p->jpp && p->jre == 0 && p->jim == 0) {   /* isotropic: J = J */
        v_set(p->e, s);
        return;
    }
    v_cross(d, p->e, f);
    /* e, f and s are unit and perpendicular to d: c^2 + sn^2 = 1 to rounding */
    double c = v_dot(p->e, s), sn = v_dot(f, s);
    if (c == 1.0 && sn == 0.0) { v_set(p->e, s); return; }
    double a = p->jss, b = p->jpp, re = p->jre, im = p->jim;
    double cc = c * c, ss = sn * sn, cs = c * sn;
    p->jss = cc * a + 2 * cs * re + ss * b;
    p->jpp = ss * a - 2 * cs * re + cc * b;
    /* J'_sp = cs (J_pp - J_ss) + c^2 J_sp - s^2 conj(J_sp) */
    p->jre = cs * (b - a) + (cc - ss) * re;
    p->jim = (cc + ss) * im;
    if (p->jss < 0) p->jss = 0;   /* rounding of an exactly polarised state */
    if (p->jpp < 0) p->jpp = 0;
    v_set(p->e, s);
}

/* ---- sources (tr_source.c) ---- */
typedef struct tr_source {
    trace_source s;            /* copy; s.ray points to own copy */
    trace_ray *rays;
    double u[3], v[3];         /* frame about dir */
    long nrays;
    long *row_first;           /* GRID: first kept ray of each row (count+1) */
    int *row_i0;               /* GRID: first kept column of each row */
    double wsum;               /* GAUSSIAN: sum of weights */
    uint64_t first;            /* global number of its first ray */
    int has_grid0;             /* GRID: grid0 holds what its rays share */
    struct tr_ray0 {
        double o[3], d[3];
        double power, n;
        tr_pol pol;
        double lambda, alpha;    /* wavelength (um, 0: none); absorption of the medium */
    } grid0;                   /* GRID: every ray but its origin (made once, by the
                                  code that made each ray before: the same bits) */
} tr_source;

typedef struct tr_ray0 tr_ray0;

int tr_source_init(tr_source *ts, const trace_source *s, char *err, size_t cap);
void tr_source_free(tr_source *ts);
void tr_source_ray(const tr_source *ts, long i, tr_ray0 *r);
/* Rays i .. i+n-1 of the source, the same as n calls (a grid is walked, not searched). */
void tr_source_rays(const tr_source *ts, long i, long n, tr_ray0 *r);

/* ---- sequential lenses (tr_lens.c), through the public table ---- */
int tr_add_lens(trace_scene *sc, const trace_lens *lens);
int tr_lens_fan(const trace_lens *lens, double z_obj, double y_obj, double z_paraxial,
                int nrays, const double *h, trace_fan_ray *out, char *err, size_t cap);

/* ---- real rays aimed at the stop (tr_aim.c), the table's rx_trace and rx_aim ---- */
int tr_rx_trace(const trace_rx *rx, const double o[3], const double d[3], double *pts,
                trace_aim_ray *out, char *err, size_t cap);
int tr_rx_aim(const trace_rx *rx, const trace_aim_req *rq, trace_aim_ray *out, char *err,
              size_t cap);
int tr_rx_opd(const trace_rx *rx, const trace_aim_req *rq, int n, double z_xp, double lambda,
              double *w, int *st, trace_aim_ray *chief, double *R_ref, char *err,
              size_t errcap);

/* Lens hints (tr_scene.c): after refraction at surface id a forward ray can only
 * meet cand[0..n-1] (-1 entries skipped); valid until another surface is added. */
void tr_scene_set_seq(trace_scene *sc, int id, const int *cand, int n);
int tr_scene_nsurf(const trace_scene *sc);
/* ... and a forward ray starting at z < z meets cand[] first (or misses them). */
void tr_scene_set_entry(trace_scene *sc, const int *cand, int n, double z);
const tr_shape *tr_scene_shape(const trace_scene *sc, int id);

/* Set the scene's message; returns code. */
int tr_scene_fail(trace_scene *sc, int code, const char *msg);

void tr_set_err(char *err, size_t cap, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

#pragma GCC visibility pop
#endif
