/* tr_hit.c -- the one question the trace loop asks of the scene: which surface does
 * this ray meet next, and where (in double).  Embree's callbacks for analytic surfaces
 * and meshes, its float ray started where the double one enters its box, the surfaces
 * outside its range tested in double, the second chance at shared vertices of closed
 * meshes, hits near a mesh's edges and vertices decided in double (tr_wt.c),
 * coincident surfaces taken in order, and the lens shortcut's candidates. */
#include <float.h>
#include <math.h>
#include "tr_eng.h"

/* The context handed to rtcIntersect1: Embree passes it on to our callbacks. */
typedef struct tr_ctx {
    struct RTCIntersectContext ec;   /* must be first */
    const trace_scene *sc;
    double o[3], d[3];
    int last_surf;
    long last_prim;
    int float_hits;
    double ta;                       /* Embree's ray starts at o + ta d */
    int best_surf;                   /* nearest analytic hit so far */
    double best_t, best_n[3];
    int best_far;                    /* ... from a far start: its point best_q */
    double best_q[3];
    const tr_surf *xs;               /* triangles xp[0..nx) of mesh xs: the double */
    const uint32_t *xp;              /* test said the ray misses them */
    int nx;
} tr_ctx;

/* Embree's query; a hit in a mesh's chunk (tr_meshbvh.c) told as the mesh's own:
 * its surface and triangle number. */
static inline void query(const trace_scene *sc, tr_ctx *x, struct RTCRayHit *rh)
{
    rtcIntersect1(sc->scn, &x->ec, rh);
    unsigned k = rh->hit.instID[0];
    if (k == RTC_INVALID_GEOMETRY_ID) return;
    rh->hit.primID = (unsigned)tr_mesh_prim(sc, k, rh->hit.primID);
    rh->hit.geomID = (unsigned)sc->ch_surf[k - (unsigned)sc->ch_base];
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

/* Front-facing unit normal of an analytic surface from tr_shape_hit's. */
static void front_normal(const tr_shape *g, double n[3])
{
    if (g->shape != TRACE_SPHERE) { n[0] = -n[0]; n[1] = -n[1]; n[2] = -n[2]; }
}

/* Does a ray that left surface `last` leave f too (f itself, or coincident with it)?
 * Its root at t = 0 is then excluded exactly. */
static inline int leaves(const trace_scene *sc, int last, const tr_surf *f)
{
    return last == f->id ||
           (last >= 0 && f->group >= 0 && sc->surf[last]->group == f->group);
}

/* Analytic surface f offered to the query: kept in x->best_* (and as rh's hit) if the
 * true ray meets it nearer than what rh holds. */
static void offer_analytic(tr_ctx *x, const tr_surf *f, struct RTCRayHit *rh,
                           unsigned geomID)
{
    double t, n[3], p[3];
    int leaving = leaves(x->sc, x->last_surf, f), ok;
    const tr_shape *g = &f->shape;
    if (x->float_hits) ok = tr_shape_hit_float(g, x->o, x->d, leaving, &t, n);
    else {
        /* tr_shape_hit_t's own cases, its inline ones called here directly */
        if (g->fast == TR_FAST_PLANE) ok = tr_plane_hit(g, x->o, x->d, leaving, &t, p);
        else if (g->fast == TR_FAST_CONIC) ok = tr_conic_hit(g, x->o, x->d, leaving, &t, p);
        else ok = tr_shape_hit_t(g, x->o, x->d, leaving, &t, p);
        if (ok) tr_shape_hit_normal(g, p, n);
    }
    /* at a tie the lower surface id, whatever order Embree visits them in: the lens
     * shortcut's candidates (seq_hit) are in id order and take the first */
    if (!ok || !(t < x->best_t || (t == x->best_t && f->id < x->best_surf))) return;
    float tf = (float)(t - x->ta);
    if (tf > rh->ray.tfar) return;          /* a triangle is clearly nearer */
    rh->ray.tfar = tf;
    rh->hit.geomID = geomID;
    rh->hit.primID = 0;
    rh->hit.u = rh->hit.v = 0;
    rh->hit.Ng_x = (float)n[0];
    rh->hit.Ng_y = (float)n[1];
    rh->hit.Ng_z = (float)n[2];
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    front_normal(&f->shape, n);
    x->best_surf = f->id;
    x->best_t = t;
    v_set(x->best_n, n);
    x->best_far = ok == 2 && !x->float_hits;
    if (x->best_far) tr_shape_world(&f->shape, p, x->best_q);
}

void tr_user_intersect(const struct RTCIntersectFunctionNArguments *a)
{
    if (a->N != 1 || !a->valid[0]) return;
    offer_analytic((tr_ctx *)a->context, a->geometryUserPtr, (struct RTCRayHit *)a->rayhit,
                   a->geomID);
}

/* The scene's inline analytic surfaces (TR_INLINE_MAX), before Embree's query: as if
 * Embree had visited them first, so its tfar already stops at the nearest. */
static inline void offer_inline(const trace_scene *sc, tr_ctx *x, struct RTCRayHit *rh)
{
    for (int i = 0; i < sc->ninline; i++)
        offer_analytic(x, sc->surf[sc->inl[i]], rh, (unsigned)sc->inl[i]);
}

void tr_user_occluded(const struct RTCOccludedFunctionNArguments *a)
{
    (void)a;   /* the engine never asks occlusion queries */
}

static void tri_normal(const tr_surf *f, long prim, double n[3])
{
    const uint32_t *ix = f->idx + 3 * prim;
    const double *a = f->vtx + 3 * ix[0], *b = f->vtx + 3 * ix[1], *c = f->vtx + 3 * ix[2];
    double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    v_cross(e1, e2, n);
}

/* Distance along the ray to the plane of triangle prim (its tri_normal n), in
 * double. */
static inline double plane_t_n(const tr_surf *f, long prim, const double n[3],
                               const double o[3], const double d[3])
{
    const double *a = f->vtx + 3 * f->idx[3 * prim];
    double den = v_dot(n, d);
    double q[3] = {a[0] - o[0], a[1] - o[1], a[2] - o[2]};
    return den != 0 ? v_dot(n, q) / den : INFINITY;
}

static double tri_plane_t(const tr_surf *f, long prim, const double o[3], const double d[3])
{
    double n[3];
    tri_normal(f, prim, n);
    return plane_t_n(f, prim, n, o, d);
}

/* Leaving a mesh: never its own triangle again, nor another one "here". */
void tr_mesh_filter(const struct RTCFilterFunctionNArguments *a)
{
    if (a->N != 1 || !a->valid[0]) return;
    const tr_ctx *x = (const tr_ctx *)a->context;
    const tr_surf *f = a->geometryUserPtr;
    const unsigned *hu = (const unsigned *)a->hit;  /* RTCHitN for N = 1: Ng, u, v, */
    long prim = tr_mesh_prim(x->sc, hu[7], hu[5]); /* primID, geomID, instID[0] */
    if (x->xs == f)
        for (int i = 0; i < x->nx; i++)
            if (x->xp[i] == (uint32_t)prim) { a->valid[0] = 0; return; }
    if (x->last_surf != f->id) return;
    if (prim == x->last_prim) { a->valid[0] = 0; return; }
    if (x->float_hits) return;
    if (x->sc->wt_all) goto exact;
    /* Embree's float distance (the ray's tfar, from o + ta d) to the grown triangle's
     * plane lies within 1.3 pad / |cos| of the double one (the float ray strays by at
     * most pad from the double one, the grown float plane by pad / 4 from the true one
     * over the triangle; cos between the ray and the float normal Ng): a hit clearly
     * beyond eps is kept without reading the triangle's double vertices.  Same
     * decisions as the test below, which takes the rest. */
    const float *r = (const float *)a->ray, *g = (const float *)a->hit;
    double ng = (double)g[0] * r[4] + (double)g[1] * r[5] + (double)g[2] * r[6];
    double nn = (double)g[0] * g[0] + (double)g[1] * g[1] + (double)g[2] * g[2];
    double tf = x->ta + r[8] - f->eps;     /* RTCRay.tfar for N = 1: the hit's */
    if (tf > 0 && tf * tf * ng * ng > 16 * f->pad * f->pad * nn) return;
exact:
    if (!(tri_plane_t(f, prim, x->o, x->d) > f->eps)) a->valid[0] = 0;
}

/* A ray that went into a closed mesh must meet it again, and one that meets a closed
 * mesh from inside must have gone in; but Embree's float test can let a ray through
 * exactly at a shared vertex or edge.  Then the same query is asked again with the
 * float direction turned by 1e-6 rad four ways; the first triangle of that mesh it
 * meets nearer than the hit in hand (not the one the ray left, nor the one in hand,
 * farther than the mesh's eps in double) is the hit, its distance taken in double
 * along the true ray. */
static void closed_retry(const trace_scene *sc, tr_ctx *x, struct RTCRayHit *rh,
                         const tr_surf *m, const double o[3], const double d[3], double ta)
{
    double u[3], v[3], a[3] = {1, 0, 0};
    if (fabs(d[0]) > 0.6) { a[0] = 0; a[1] = 1; }
    v_cross(d, a, u);
    v_unit(u);
    v_cross(d, u, v);
    for (int k = 0; k < 4; k++) {
        const double *w = k < 2 ? u : v;
        double s = k % 2 ? -1e-6 : 1e-6, dd[3];
        for (int j = 0; j < 3; j++) dd[j] = d[j] + s * w[j];
        struct RTCRayHit r2 = *rh;
        r2.ray.dir_x = (float)dd[0]; r2.ray.dir_y = (float)dd[1]; r2.ray.dir_z = (float)dd[2];
        r2.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        r2.hit.primID = RTC_INVALID_GEOMETRY_ID;
        r2.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        tr_ctx keep = *x;                   /* analytic hits are the true ray's already */
        query(sc, x, &r2);
        x->best_surf = keep.best_surf;
        x->best_t = keep.best_t;
        v_set(x->best_n, keep.best_n);
        x->best_far = keep.best_far;
        v_set(x->best_q, keep.best_q);
        if (r2.hit.geomID != (unsigned)m->id ||
            (rh->hit.geomID == (unsigned)m->id && r2.hit.primID == rh->hit.primID))
            continue;
        double t = tri_plane_t(m, r2.hit.primID, o, d);
        if (!(t > m->eps) || !((float)(t - ta) <= rh->ray.tfar)) continue;
        rh->hit = r2.hit;
        rh->ray.tfar = (float)(t - ta);
        return;
    }
}

/* Embree's hit on a mesh within its margin of an edge or vertex (tr_wt_margin) is
 * decided in double: the nearest of the triangles around the hit triangle's vertices
 * that the watertight test says the true ray meets (beyond the mesh's eps when it
 * leaves that mesh, never the triangle it left).  If none does, Embree's triangle
 * grew past the true one: the query is asked again without the triangles tested, a
 * few times.  Ties go to the lower triangle number, so the answer never depends on
 * Embree's order or on threads. */
#define WT_ROUNDS 4
#define WT_CAP 256
static void near_edge(const trace_scene *sc, tr_ctx *x, struct RTCRayHit *rh,
                      const double o[3], const double d[3], int last_surf,
                      long last_prim, double ta)
{
    uint32_t ex[WT_CAP];
    int nex = 0;
    for (int round = 0; round < WT_ROUNDS; round++) {
        if (rh->hit.geomID == RTC_INVALID_GEOMETRY_ID) return;
        const tr_surf *f = sc->surf[rh->hit.geomID];
        if (!f->is_mesh) return;
        long prim = rh->hit.primID, best;
        double u = rh->hit.u, v = rh->hit.v, w = 1 - u - v, t;
        double m = fmin(u, fmin(v, w));
        if (!sc->wt_all && !tr_wt_near(f, prim, m, 2 * f->pad)) return;   /* well inside */
        if (x->xs && x->xs != f) return;   /* one mesh's edges at a time: rare enough */
        int leaving = last_surf == f->id;
        if (tr_wt_ring(f, prim, o, d, leaving ? last_prim : -1, leaving ? f->eps : 0,
                       &best, &t, ex, &nex, WT_CAP)) {
            rh->hit.primID = (unsigned)best;
            rh->ray.tfar = (float)(t - ta);
            return;
        }
        /* the true ray misses them all: ask again without them */
        x->xs = f;
        x->xp = ex;
        x->nx = nex;
        x->best_surf = -1;
        x->best_t = INFINITY;
        x->best_far = 0;
        rh->ray.tfar = INFINITY;
        rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh->hit.primID = RTC_INVALID_GEOMETRY_ID;
        offer_inline(sc, x, rh);
        query(sc, x, rh);
    }
}

/* The analytic surface the intersection callbacks kept (x->best_*) as the hit: 1. */
static int analytic_hit(const tr_ctx *x, int surf, tr_hitrec *h)
{
    h->surf = surf;
    h->prim = -1;
    h->t = x->best_t;
    v_set(h->n, x->best_n);
    h->far = x->best_far;
    v_set(h->q, x->best_q);
    return 1;
}

/* Nearest hit among what Embree holds, its ray starting at o + ta d; 0 if none. */
static int embree_nearest(const trace_scene *sc, int float_hits, const double o[3],
                          const double d[3], int last_surf, long last_prim, double ta,
                          tr_hitrec *h)
{
    tr_ctx x;
    struct RTCRayHit rh;
    rtcInitIntersectContext(&x.ec);
    x.sc = sc;
    v_set(x.o, o);
    v_set(x.d, d);
    x.last_surf = last_surf;
    x.last_prim = last_prim;
    x.float_hits = float_hits;
    x.best_surf = -1;
    x.best_t = INFINITY;
    x.best_far = 0;
    x.ta = ta;
    x.xs = NULL;
    x.xp = NULL;
    x.nx = 0;
    rh.ray.org_x = (float)(o[0] + ta * d[0] - sc->eoff[0]);
    rh.ray.org_y = (float)(o[1] + ta * d[1] - sc->eoff[1]);
    rh.ray.org_z = (float)(o[2] + ta * d[2] - sc->eoff[2]);
    rh.ray.dir_x = (float)d[0]; rh.ray.dir_y = (float)d[1]; rh.ray.dir_z = (float)d[2];
    rh.ray.tnear = 0;
    rh.ray.tfar = INFINITY;
    rh.ray.time = 0;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    offer_inline(sc, &x, &rh);
    query(sc, &x, &rh);
    if (sc->nclosed && !float_hits && last_surf >= 0 && last_prim >= 0 &&
        rh.hit.geomID != (unsigned)last_surf) {
        const tr_surf *m = sc->surf[last_surf];
        double n[3];
        if (m->is_mesh && m->closed) {
            tri_normal(m, last_prim, n);
            if (v_dot(n, d) * m->closed < 0) closed_retry(sc, &x, &rh, m, o, d, ta);
        }
    }
    /* ... and one that leaves a closed mesh it never went into may have slipped in
     * through a shared vertex or edge: is there a nearer entry? */
    if (sc->nclosed && !float_hits && rh.hit.geomID != RTC_INVALID_GEOMETRY_ID &&
        rh.hit.geomID != (unsigned)last_surf) {
        const tr_surf *m = sc->surf[rh.hit.geomID];
        double n[3];
        if (m->is_mesh && m->closed) {
            tri_normal(m, rh.hit.primID, n);
            if (v_dot(n, d) * m->closed > 0) closed_retry(sc, &x, &rh, m, o, d, ta);
        }
    }
    if (!float_hits) near_edge(sc, &x, &rh, o, d, last_surf, last_prim, ta);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return 0;
    const tr_surf *f = sc->surf[rh.hit.geomID];
    if (!f->is_mesh) return analytic_hit(&x, f->id, h);
    long prim = rh.hit.primID;
    double n[3];
    tri_normal(f, prim, n);             /* once: the plane's distance and the normal */
    double t = float_hits ? ta + rh.ray.tfar : plane_t_n(f, prim, n, o, d);
    if (!(t > 0 && isfinite(t))) t = ta + rh.ray.tfar;
    v_unit(n);
    if (f->has_under && f->refine != TRACE_REFINE_NONE && !float_hits) {
        double tt, p[3], an[3];
        if (f->refine == TRACE_REFINE_FULL && tr_shape_refine(&f->shape, o, d, t, &tt) &&
            tt > 0)
            t = tt;
        for (int i = 0; i < 3; i++) p[i] = o[i] + t * d[i];
        tr_shape_normal(&f->shape, p, an);
        if (v_dot(an, n) < 0) { an[0] = -an[0]; an[1] = -an[1]; an[2] = -an[2]; }
        v_set(n, an);
    }
    if (x.best_surf >= 0 && x.best_t < t)         /* an analytic surface is nearer */
        return analytic_hit(&x, x.best_surf, h);
    h->surf = f->id;
    h->prim = prim;
    h->t = t;
    v_set(h->n, n);
    h->far = 0;
    return 1;
}

/* Where the ray (o, d) enters the box b (lo, hi) and leaves it: 0 if it never meets it
 * ahead (t >= 0). */
static int slab(const double lo[3], const double hi[3], const double o[3],
                const double d[3], double *tin)
{
    double a = 0, b = INFINITY;
    for (int j = 0; j < 3; j++) {
        if (d[j] == 0) {
            if (o[j] < lo[j] || o[j] > hi[j]) return 0;
            continue;
        }
        double t1 = (lo[j] - o[j]) / d[j], t2 = (hi[j] - o[j]) / d[j];
        if (t1 > t2) { double x = t1; t1 = t2; t2 = x; }
        if (t1 > a) a = t1;
        if (t2 < b) b = t2;
    }
    if (!(a <= b)) return 0;
    *tin = a;
    return 1;
}

/* Nearest hit of the ray (o, d) in double; 0 if none.  Embree's float ray starts where
 * the double one enters the box of what Embree holds (so neither a far start nor one
 * beyond single precision's range reaches it); the surfaces outside its range follow
 * in double. */
static int nearest(const trace_scene *sc, int float_hits, const double o[3],
                   const double d[3], int last_surf, long last_prim, tr_hitrec *h)
{
    double ta;
    int got = 0;
    /* (float_hits compares with a float-only tracer: its float ray starts at o) */
    int near = o[0] >= sc->nlo[0] && o[0] <= sc->nhi[0] && o[1] >= sc->nlo[1] &&
               o[1] <= sc->nhi[1] && o[2] >= sc->nlo[2] && o[2] <= sc->nhi[2];
    if (near) ta = 0;                      /* the usual case: no slab to clip */
    if (sc->nembree && (near || slab(sc->elo, sc->ehi, o, d, &ta)))
        got = embree_nearest(sc, float_hits, o, d, last_surf, last_prim,
                             float_hits ? 0 : ta, h);
    for (int i = 0; i < sc->nfar; i++) {
        const tr_surf *f = sc->surf[sc->far[i]];
        double t, n[3], p[3];
        int ok = tr_shape_hit_t(&f->shape, o, d, leaves(sc, last_surf, f), &t, p);
        if (!ok || (got && !(t < h->t))) continue;
        tr_shape_hit_normal(&f->shape, p, n);
        front_normal(&f->shape, n);
        h->surf = f->id;
        h->prim = -1;
        h->t = t;
        v_set(h->n, n);
        h->far = ok == 2;
        if (h->far) tr_shape_world(&f->shape, p, h->q);
        got = 1;
    }
    return got;
}

/* A ray refracted forward through a lens surface can only meet the candidates the
 * lens named (see tr_lens.c).  Does that hold for this ray?  Then cand[0..*nc-1]. */
static inline int seq_cands(const trace_scene *sc, const trace_options *o,
                            const double org[3], const double d[3], int last,
                            uint32_t hist, const int **cand,
                            const tr_shape *const **cg, int *nc)
{
    if (!(o->sequential && !o->float_hits && hist == 0 && d[2] > 0 &&
          sc->seq_nsurf == sc->nsurf))
        return 0;
    if (last >= 0) {
        const tr_surf *f = sc->surf[last];
        *cand = f->seq;
        *cg = f->seqg;
        *nc = f->nseq;
    } else {
        if (!(sc->nentry > 0 && org[2] < sc->entry_z && org[2] > sc->entry_zmin))
            return 0;
        *cand = sc->entry;
        *cg = sc->entryg;
        *nc = sc->nentry;
    }
    return *nc > 0;
}

/* The nearest of the candidates (ids cand, shapes cg) in double (the first one at a
 * tie); 0 if none is hit.  Its normal waits for seq_normal (from bp). */
static inline int seq_hit(const int *cand, const tr_shape *const *cg, int nc, int last,
                          const double org[3], const double d[3], tr_hitrec *h,
                          double bp[3])
{
    double best = INFINITY, t, p[3] = {0, 0, 0};
    int bs = -1, ok, far = 0;
    for (int k = 0; k < nc; k++) {
        const tr_shape *g = cg[k];
        int leaving = cand[k] == last;
        if (g->fast == TR_FAST_CONIC) ok = tr_conic_hit(g, org, d, leaving, &t, p);
        else if (g->fast == TR_FAST_PLANE) ok = tr_plane_hit(g, org, d, leaving, &t, p);
        else ok = tr_shape_hit_t(g, org, d, leaving, &t, p);
        if (ok && t < best) {
            best = t;
            bs = k;
            far = ok == 2;
            v_set(bp, p);
        }
    }
    if (bs < 0) return 0;
    h->surf = cand[bs];
    h->prim = -1;
    h->t = best;
    h->far = far;
    if (far) tr_shape_world(cg[bs], bp, h->q);
    return 1;
}

static inline void seq_normal(const trace_scene *sc, tr_hitrec *h, const double bp[3])
{
    const tr_shape *g = &sc->surf[h->surf]->shape;
    if (g->fast == TR_FAST_CONIC) tr_conic_normal_local(g, bp, h->n);  /* world frame */
    else tr_shape_hit_normal(g, bp, h->n);
    front_normal(g, h->n);
}

/* A ray leaving a member of a group of coincident surfaces at org meets the next
 * member in its direction there, at t = 0: going to the back side of the group's
 * first member, the one added after `last`, else the one before.  1 and the hit, or
 * 0 when it has passed them all. */
static int coincident_next(const trace_scene *sc, const double org[3], const double d[3],
                           int last, tr_hitrec *h)
{
    const tr_surf *f = sc->surf[last], *g0 = sc->surf[f->group];
    double nb[3];
    tr_shape_normal(&g0->shape, org, nb);
    if (g0->shape.shape == TRACE_SPHERE) { nb[0] = -nb[0]; nb[1] = -nb[1]; nb[2] = -nb[2]; }
    double dn = v_dot(d, nb);
    int next = dn > 0 ? f->gnext : dn < 0 ? f->gprev : -1;
    if (next < 0) return 0;
    const tr_surf *g = sc->surf[next];
    h->surf = next;
    h->prim = -1;
    h->t = 0;
    h->far = 0;
    tr_shape_normal(&g->shape, org, h->n);
    front_normal(&g->shape, h->n);
    return 1;
}

/* A ray that meets a group of coincident surfaces (any member: they tie) meets its
 * first member first when it goes to the group's back side, else its last. */
static void coincident_first(const trace_scene *sc, const double d[3], tr_hitrec *h)
{
    const tr_surf *f = sc->surf[h->surf], *g = sc->surf[f->group], *head = g;
    /* h->n is f's front normal; a plane may face the other way from the group's head */
    int opp_f = f->shape.shape == TRACE_PLANE && v_dot(f->shape.w, head->shape.w) < 0;
    double s = opp_f ? -1 : 1;
    int back = -s * v_dot(d, h->n) > 0;          /* toward the head's back side */
    if (!back) while (g->gnext >= 0) g = sc->surf[g->gnext];
    if (g == f) return;
    int opp_g = g->shape.shape == TRACE_PLANE && v_dot(g->shape.w, head->shape.w) < 0;
    if (opp_f != opp_g)
        for (int i = 0; i < 3; i++) h->n[i] = -h->n[i];
    h->surf = g->id;
}

/* The lens shortcut (the same hits, bit for bit), else Embree. */
int tr_find_hit(const trace_scene *sc, const trace_options *o, const double org[3],
                    const double d[3], int last, long last_prim, uint32_t hist,
                    tr_hitrec *h)
{
    const int *cand;
    const tr_shape *const *cg;
    int nc;
    double bp[3] = {0, 0, 0};
    if (last >= 0 && sc->ngroup && sc->surf[last]->group >= 0 &&
        coincident_next(sc, org, d, last, h))
        return 1;
    if (seq_cands(sc, o, org, d, last, hist, &cand, &cg, &nc) &&
        seq_hit(cand, cg, nc, last, org, d, h, bp)) {
        seq_normal(sc, h, bp);
        return 1;
    }
    if (!nearest(sc, o->float_hits, org, d, last, last_prim, h)) return 0;
    if (sc->ngroup && h->prim < 0 && sc->surf[h->surf]->group >= 0)
        coincident_first(sc, d, h);
    return 1;
}
