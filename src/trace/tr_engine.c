/* tr_engine.c -- the trace engine's scene and trace loop on Embree 3, and the
 * function table the module exports (trace_get_api).  Owns: surfaces (analytic ones
 * as Embree user geometry, meshes as robust triangle geometry with double copies of
 * their vertices), the Embree device (created on the first build, never before),
 * the per-ray recursion with Fresnel s/p bookkeeping, and the batched, thread-count
 * independent run.  Nothing here prints. */
#include <embree3/rtcore.h>
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "tr_int.h"
#include "tr_packet.h"

typedef struct tr_surf {
    int id, is_mesh;
    trace_material mat;
    tr_shape shape;            /* analytic surface, or a mesh's underlying one */
    int has_under, refine;
    double *vtx;               /* mesh: nv*3 */
    uint32_t *idx;             /* mesh: ntri*3 */
    double *media;             /* mesh: ntri*2 or NULL */
    long nv, ntri;
    double eps;                /* mesh: plane distances below this are "here" */
    int seq[4], nseq;          /* lens: the only surfaces a forward ray can meet next */
    const tr_shape *seqg[4];   /* ... and their shapes */
    tr_pk_set pk;              /* ... laid out for the packet */
} tr_surf;

struct trace_scene {
    char err[512];
    tr_surf **surf;
    int nsurf, capsurf;
    tr_source *src;
    int nsrc, capsrc;
    uint64_t nrays;
    RTCDevice dev;
    RTCScene scn;
    int built;
    double build_ms;
    int seq_nsurf;             /* the lens hints hold while nsurf == seq_nsurf */
    int entry[4], nentry;      /* lens: what a forward ray from left of it meets first */
    const tr_shape *entryg[4];
    tr_pk_set entry_pk;
    double entry_z;            /* ... if it starts at z < entry_z */
};

/* The context handed to rtcIntersect1: Embree passes it on to our callbacks. */
typedef struct tr_ctx {
    struct RTCIntersectContext ec;   /* must be first */
    const trace_scene *sc;
    double o[3], d[3];
    int last_surf;
    long last_prim;
    int float_hits;
    int best_surf;                   /* nearest analytic hit so far */
    double best_t, best_n[3];
} tr_ctx;

typedef struct tr_hitrec {
    int surf;
    long prim;
    double t, n[3];                  /* n: unit normal pointing into the front side */
} tr_hitrec;

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

static int fail(trace_scene *sc, int code, const char *msg)
{
    if (sc && msg) {
        size_t n = strlen(msg);
        if (n >= sizeof sc->err) n = sizeof sc->err - 1;
        memmove(sc->err, msg, n);
        sc->err[n] = '\0';
    }
    return code;
}

int tr_scene_fail(trace_scene *sc, int code, const char *msg)
{
    return fail(sc, code, msg);
}

int tr_scene_nsurf(const trace_scene *sc) { return sc->nsurf; }

const tr_shape *tr_scene_shape(const trace_scene *sc, int id)
{
    return id >= 0 && id < sc->nsurf && !sc->surf[id]->is_mesh ? &sc->surf[id]->shape
                                                                 : NULL;
}

void tr_scene_set_entry(trace_scene *sc, const int *cand, int n, double z)
{
    sc->nentry = 0;
    tr_pk_set_clear(&sc->entry_pk);
    for (int i = 0; i < n && i < 4; i++)
        if (cand[i] >= 0) {
            const tr_surf *f = sc->surf[cand[i]];
            sc->entryg[sc->nentry] = &f->shape;
            sc->entry[sc->nentry++] = cand[i];
            tr_pk_set_add(&sc->entry_pk, cand[i], &f->shape, &f->mat, 0);
        }
    sc->entry_z = z;
}

void tr_scene_set_seq(trace_scene *sc, int id, const int *cand, int n)
{
    tr_surf *f = sc->surf[id];
    f->nseq = 0;
    tr_pk_set_clear(&f->pk);
    for (int i = 0; i < n && i < 4; i++)
        if (cand[i] >= 0) {
            const tr_surf *c = sc->surf[cand[i]];
            f->seqg[f->nseq] = &c->shape;
            f->seq[f->nseq++] = cand[i];
            tr_pk_set_add(&f->pk, cand[i], &c->shape, &c->mat, cand[i] == id);
        }
    sc->seq_nsurf = sc->nsurf;
}

/* ---------------- scene ---------------- */

static trace_scene *scene_new(void)
{
    return calloc(1, sizeof(trace_scene));
}

static void drop_embree(trace_scene *sc)
{
    if (sc->scn) rtcReleaseScene(sc->scn);
    if (sc->dev) rtcReleaseDevice(sc->dev);
    sc->scn = NULL;
    sc->dev = NULL;
    sc->built = 0;
}

static void scene_free(trace_scene *sc)
{
    if (!sc) return;
    drop_embree(sc);
    for (int i = 0; i < sc->nsurf; i++) {
        free(sc->surf[i]->vtx);
        free(sc->surf[i]->idx);
        free(sc->surf[i]->media);
        free(sc->surf[i]);
    }
    free(sc->surf);
    for (int i = 0; i < sc->nsrc; i++) tr_source_free(&sc->src[i]);
    free(sc->src);
    free(sc);
}

static const char *scene_error(const trace_scene *sc)
{
    return sc ? sc->err : "no scene (out of memory)";
}

static int check_material(trace_scene *sc, const trace_material *m)
{
    if (!m) return fail(sc, TRACE_EINVAL, "no material given");
    if (m->kind < TRACE_REFRACT || m->kind > TRACE_DETECT)
        return fail(sc, TRACE_EINVAL, "unknown surface kind");
    if (!(m->n_front > 0 && isfinite(m->n_front) && m->n_back > 0 && isfinite(m->n_back)))
        return fail(sc, TRACE_EINVAL, "indices of refraction must be positive numbers");
    return TRACE_OK;
}

static tr_surf *new_surf(trace_scene *sc)
{
    if (sc->nsurf == sc->capsurf) {
        int cap = sc->capsurf ? 2 * sc->capsurf : 16;
        tr_surf **p = realloc(sc->surf, (size_t)cap * sizeof *p);
        if (!p) return NULL;
        sc->surf = p;
        sc->capsurf = cap;
    }
    tr_surf *s = calloc(1, sizeof *s);
    if (!s) return NULL;
    s->id = sc->nsurf;
    return s;
}

static int add_surface(trace_scene *sc, const trace_surface *s, const trace_material *m)
{
    int rc;
    if (!sc) return TRACE_EINVAL;
    if (!s) return fail(sc, TRACE_EINVAL, "no surface given");
    if ((rc = check_material(sc, m))) return rc;
    tr_surf *f = new_surf(sc);
    if (!f) return fail(sc, TRACE_ENOMEM, "out of memory");
    if (tr_shape_init(&f->shape, s, sc->err, sizeof sc->err)) {
        free(f);
        return TRACE_EINVAL;
    }
    f->mat = *m;
    sc->surf[sc->nsurf++] = f;
    drop_embree(sc);
    return f->id;
}

/* Distance scale of how far a refined hit may sit off its triangle. */
static double under_gap(const tr_surf *f)
{
    double gap = 0;
    for (long i = 0; i < f->ntri; i++) {
        double c[3] = {0, 0, 0}, t, dir[3], o[3];
        const uint32_t *ix = f->idx + 3 * i;
        for (int k = 0; k < 3; k++)
            for (int j = 0; j < 3; j++) c[j] += f->vtx[3 * ix[k] + j] / 3;
        tr_shape_normal(&f->shape, c, dir);
        for (int j = 0; j < 3; j++) o[j] = c[j] - dir[j] * f->shape.scale;
        if (tr_shape_refine(&f->shape, o, dir, f->shape.scale, &t))
            gap = fmax(gap, fabs(t - f->shape.scale));
    }
    return gap;
}

static int add_mesh(trace_scene *sc, const trace_mesh *mesh, const trace_material *m)
{
    char msg[256];
    int rc;
    if (!sc) return TRACE_EINVAL;
    if (!mesh || !mesh->vertex || mesh->ntri < 1 || mesh->ntri > 200000000L)
        return fail(sc, TRACE_EINVAL, "a mesh needs vertices and 1..2e8 triangles");
    if ((rc = check_material(sc, m))) return rc;
    long nv = mesh->index ? mesh->nvertex : 3 * mesh->ntri;
    if (nv < 3 || nv > 600000000L) return fail(sc, TRACE_EINVAL, "bad vertex count");
    tr_surf *f = new_surf(sc);
    if (!f) return fail(sc, TRACE_ENOMEM, "out of memory");
    f->is_mesh = 1;
    f->mat = *m;
    f->nv = nv;
    f->ntri = mesh->ntri;
    f->vtx = malloc((size_t)nv * 3 * sizeof(double));
    f->idx = malloc((size_t)f->ntri * 3 * sizeof(uint32_t));
    if (mesh->media) f->media = malloc((size_t)f->ntri * 2 * sizeof(double));
    if (!f->vtx || !f->idx || (mesh->media && !f->media)) {
        rc = fail(sc, TRACE_ENOMEM, "out of memory for the mesh");
        goto bad;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (long i = 0; i < nv * 3; i++) {
        double x = mesh->vertex[i];
        if (!isfinite(x)) {
            snprintf(msg, sizeof msg, "vertex %ld is not finite", i / 3 + 1);
            rc = fail(sc, TRACE_EINVAL, msg);
            goto bad;
        }
        f->vtx[i] = x;
        if (x < lo[i % 3]) lo[i % 3] = x;
        if (x > hi[i % 3]) hi[i % 3] = x;
    }
    for (long i = 0; i < f->ntri * 3; i++) {
        uint32_t k = mesh->index ? mesh->index[i] : (uint32_t)i;
        if ((long)k >= nv) {
            snprintf(msg, sizeof msg, "triangle %ld: vertex index %u out of range",
                     i / 3 + 1, k);
            rc = fail(sc, TRACE_EINVAL, msg);
            goto bad;
        }
        f->idx[i] = k;
    }
    for (long i = 0; i < f->ntri; i++) {
        const double *a = f->vtx + 3 * f->idx[3 * i], *b = f->vtx + 3 * f->idx[3 * i + 1],
                     *c = f->vtx + 3 * f->idx[3 * i + 2];
        double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]}, n[3];
        v_cross(e1, e2, n);
        double l2 = fmax(v_dot(e1, e1), v_dot(e2, e2));
        if (!(v_norm(n) > 1e-12 * l2)) {
            snprintf(msg, sizeof msg, "triangle %ld is degenerate (zero area)", i + 1);
            rc = fail(sc, TRACE_EINVAL, msg);
            goto bad;
        }
        if (mesh->media) {
            double n1 = mesh->media[2 * i], n2 = mesh->media[2 * i + 1];
            if (!(n1 > 0 && n2 > 0 && isfinite(n1) && isfinite(n2))) {
                snprintf(msg, sizeof msg, "triangle %ld: indices must be positive "
                         "numbers", i + 1);
                rc = fail(sc, TRACE_EINVAL, msg);
                goto bad;
            }
            f->media[2 * i] = n1;
            f->media[2 * i + 1] = n2;
        }
    }
    double diag[3] = {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
    f->eps = 1e-9 * v_norm(diag);
    if (mesh->underlying) {
        if (tr_shape_init(&f->shape, mesh->underlying, sc->err, sizeof sc->err)) {
            rc = TRACE_EINVAL;
            goto bad;
        }
        f->has_under = 1;
        f->refine = mesh->refine;
        if (f->refine == TRACE_REFINE_FULL) f->eps = fmax(f->eps, 2.5 * under_gap(f));
    }
    sc->surf[sc->nsurf++] = f;
    drop_embree(sc);
    return f->id;
bad:
    free(f->vtx);
    free(f->idx);
    free(f->media);
    free(f);
    return rc;
}

static int add_source(trace_scene *sc, const trace_source *s, uint64_t *first)
{
    if (!sc) return TRACE_EINVAL;
    if (!s) return fail(sc, TRACE_EINVAL, "no source given");
    if (sc->nsrc == sc->capsrc) {
        int cap = sc->capsrc ? 2 * sc->capsrc : 8;
        tr_source *p = realloc(sc->src, (size_t)cap * sizeof *p);
        if (!p) return fail(sc, TRACE_ENOMEM, "out of memory");
        sc->src = p;
        sc->capsrc = cap;
    }
    tr_source *ts = &sc->src[sc->nsrc];
    if (tr_source_init(ts, s, sc->err, sizeof sc->err)) {
        tr_source_free(ts);
        return TRACE_EINVAL;
    }
    ts->first = sc->nrays;
    if (first) *first = ts->first;
    sc->nrays += (uint64_t)ts->nrays;
    sc->nsrc++;
    return TRACE_OK;
}

/* ---------------- Embree ---------------- */

static void embree_error(void *user, enum RTCError code, const char *str)
{
    trace_scene *sc = user;
    snprintf(sc->err, sizeof sc->err, "Embree error %d: %s", (int)code,
             str ? str : "(no message)");
}

static void user_bounds(const struct RTCBoundsFunctionArguments *a)
{
    const tr_surf *f = a->geometryUserPtr;
    struct RTCBounds *b = a->bounds_o;
    b->lower_x = nextafterf((float)f->shape.lo[0], -INFINITY);
    b->lower_y = nextafterf((float)f->shape.lo[1], -INFINITY);
    b->lower_z = nextafterf((float)f->shape.lo[2], -INFINITY);
    b->upper_x = nextafterf((float)f->shape.hi[0], INFINITY);
    b->upper_y = nextafterf((float)f->shape.hi[1], INFINITY);
    b->upper_z = nextafterf((float)f->shape.hi[2], INFINITY);
}

/* Front-facing unit normal of an analytic surface from tr_shape_hit's. */
static void front_normal(const tr_shape *g, double n[3])
{
    if (g->shape != TRACE_SPHERE) { n[0] = -n[0]; n[1] = -n[1]; n[2] = -n[2]; }
}

static void user_intersect(const struct RTCIntersectFunctionNArguments *a)
{
    if (a->N != 1 || !a->valid[0]) return;
    tr_ctx *x = (tr_ctx *)a->context;
    const tr_surf *f = a->geometryUserPtr;
    struct RTCRayHit *rh = (struct RTCRayHit *)a->rayhit;
    double t, n[3];
    int leaving = x->last_surf == f->id;
    int ok = x->float_hits ? tr_shape_hit_float(&f->shape, x->o, x->d, leaving, &t, n)
                           : tr_shape_hit(&f->shape, x->o, x->d, leaving, &t, n);
    if (!ok || !(t < x->best_t)) return;
    float tf = (float)t;
    if (tf > rh->ray.tfar) return;          /* a triangle is clearly nearer */
    rh->ray.tfar = tf;
    rh->hit.geomID = a->geomID;
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
}

static void user_occluded(const struct RTCOccludedFunctionNArguments *a)
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

/* Distance along the ray to the triangle's plane, in double. */
static double tri_plane_t(const tr_surf *f, long prim, const double o[3], const double d[3])
{
    double n[3];
    const double *a = f->vtx + 3 * f->idx[3 * prim];
    tri_normal(f, prim, n);
    double den = v_dot(n, d);
    double q[3] = {a[0] - o[0], a[1] - o[1], a[2] - o[2]};
    return den != 0 ? v_dot(n, q) / den : INFINITY;
}

/* Leaving a mesh: never its own triangle again, nor another one "here". */
static void mesh_filter(const struct RTCFilterFunctionNArguments *a)
{
    if (a->N != 1 || !a->valid[0]) return;
    const tr_ctx *x = (const tr_ctx *)a->context;
    const tr_surf *f = a->geometryUserPtr;
    if (x->last_surf != f->id) return;
    long prim = ((const unsigned *)a->hit)[5];    /* RTCHit.primID for N = 1 */
    if (prim == x->last_prim) { a->valid[0] = 0; return; }
    if (!x->float_hits && !(tri_plane_t(f, prim, x->o, x->d) > f->eps)) a->valid[0] = 0;
}

static int attach_mesh(trace_scene *sc, tr_surf *f)
{
    RTCGeometry g = rtcNewGeometry(sc->dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!g) return -1;
    float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                       3 * sizeof(float), (size_t)f->nv);
    unsigned *ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                           3 * sizeof(unsigned), (size_t)f->ntri);
    if (!v || !ix) { rtcReleaseGeometry(g); return -1; }
    for (long i = 0; i < 3 * f->nv; i++) v[i] = (float)f->vtx[i];
    memcpy(ix, f->idx, (size_t)f->ntri * 3 * sizeof(unsigned));
    rtcSetGeometryUserData(g, f);
    rtcSetGeometryIntersectFilterFunction(g, mesh_filter);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(sc->scn, g, (unsigned)f->id);
    rtcReleaseGeometry(g);
    return 0;
}

static int attach_user(trace_scene *sc, tr_surf *f)
{
    RTCGeometry g = rtcNewGeometry(sc->dev, RTC_GEOMETRY_TYPE_USER);
    if (!g) return -1;
    rtcSetGeometryUserPrimitiveCount(g, 1);
    rtcSetGeometryUserData(g, f);
    rtcSetGeometryBoundsFunction(g, user_bounds, NULL);
    rtcSetGeometryIntersectFunction(g, user_intersect);
    rtcSetGeometryOccludedFunction(g, user_occluded);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(sc->scn, g, (unsigned)f->id);
    rtcReleaseGeometry(g);
    return 0;
}

static int build(trace_scene *sc, double *ms)
{
    if (!sc) return TRACE_EINVAL;
    if (sc->built) { if (ms) *ms = sc->build_ms; return TRACE_OK; }
    double t0 = now_ms();
    sc->err[0] = '\0';
    if (!sc->dev) {
        sc->dev = rtcNewDevice(NULL);
        if (!sc->dev) return fail(sc, TRACE_EEMBREE, "cannot create the Embree device");
        rtcSetDeviceErrorFunction(sc->dev, embree_error, sc);
    }
    sc->scn = rtcNewScene(sc->dev);
    if (!sc->scn) { drop_embree(sc); return fail(sc, TRACE_EEMBREE, "no Embree scene"); }
    rtcSetSceneFlags(sc->scn, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(sc->scn, RTC_BUILD_QUALITY_MEDIUM);
    for (int i = 0; i < sc->nsurf; i++) {
        int rc = sc->surf[i]->is_mesh ? attach_mesh(sc, sc->surf[i])
                                      : attach_user(sc, sc->surf[i]);
        if (rc) {
            drop_embree(sc);
            return fail(sc, TRACE_EEMBREE, sc->err[0] ? NULL : "Embree geometry failed");
        }
    }
    rtcCommitScene(sc->scn);
    if (rtcGetDeviceError(sc->dev) != RTC_ERROR_NONE) {
        drop_embree(sc);
        return fail(sc, TRACE_EEMBREE, sc->err[0] ? NULL : "Embree build failed");
    }
    sc->built = 1;
    sc->build_ms = now_ms() - t0;
    if (ms) *ms = sc->build_ms;
    return TRACE_OK;
}

/* Nearest hit of the ray (o, d) in double; 0 if none. */
static int nearest(const trace_scene *sc, int float_hits, const double o[3],
                   const double d[3], int last_surf, long last_prim, tr_hitrec *h)
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
    rh.ray.org_x = (float)o[0]; rh.ray.org_y = (float)o[1]; rh.ray.org_z = (float)o[2];
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
    rtcIntersect1(sc->scn, &x.ec, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return 0;
    const tr_surf *f = sc->surf[rh.hit.geomID];
    if (!f->is_mesh) {
        h->surf = f->id;
        h->prim = -1;
        h->t = x.best_t;
        v_set(h->n, x.best_n);
        return 1;
    }
    long prim = rh.hit.primID;
    double t = float_hits ? (double)rh.ray.tfar : tri_plane_t(f, prim, o, d), n[3];
    if (!(t > 0 && isfinite(t))) t = rh.ray.tfar;
    tri_normal(f, prim, n);
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
    if (x.best_surf >= 0 && x.best_t < t) {      /* an analytic surface is nearer */
        h->surf = x.best_surf;
        h->prim = -1;
        h->t = x.best_t;
        v_set(h->n, x.best_n);
        return 1;
    }
    h->surf = f->id;
    h->prim = prim;
    h->t = t;
    v_set(h->n, n);
    return 1;
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
        if (!(sc->nentry > 0 && org[2] < sc->entry_z)) return 0;
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
    int bs = -1, ok;
    for (int k = 0; k < nc; k++) {
        const tr_shape *g = cg[k];
        int leaving = cand[k] == last;
        if (g->fast == TR_FAST_CONIC) ok = tr_conic_hit(g, org, d, leaving, &t, p);
        else if (g->fast == TR_FAST_PLANE) ok = tr_plane_hit(g, org, d, leaving, &t);
        else ok = tr_shape_hit_t(g, org, d, leaving, &t, p);
        if (ok && t < best) {
            best = t;
            bs = k;
            v_set(bp, p);
        }
    }
    if (bs < 0) return 0;
    h->surf = cand[bs];
    h->prim = -1;
    h->t = best;
    return 1;
}

static inline void seq_normal(const trace_scene *sc, tr_hitrec *h, const double bp[3])
{
    const tr_shape *g = &sc->surf[h->surf]->shape;
    if (g->fast == TR_FAST_CONIC) tr_conic_normal_local(g, bp, h->n);  /* world frame */
    else tr_shape_hit_normal(g, bp, h->n);
    front_normal(g, h->n);
}

/* The lens shortcut (the same hits, bit for bit), else Embree. */
static int find_hit(const trace_scene *sc, const trace_options *o, const double org[3],
                    const double d[3], int last, long last_prim, uint32_t hist,
                    tr_hitrec *h)
{
    const int *cand;
    const tr_shape *const *cg;
    int nc;
    double bp[3] = {0, 0, 0};
    if (seq_cands(sc, o, org, d, last, hist, &cand, &cg, &nc) &&
        seq_hit(cand, cg, nc, last, org, d, h, bp)) {
        seq_normal(sc, h, bp);
        return 1;
    }
    return nearest(sc, o->float_hits, org, d, last, last_prim, h);
}

/* ---------------- the trace ---------------- */

typedef struct tr_tally {
    double emitted, detected, absorbed, escaped, cutoff;
    uint32_t segments, interactions, tir, hits, cut_depth, cut_power, cut_reflection,
             mismatch, failures;
    int max_depth;
} tr_tally;

/* The powers of one ray's tally: summed ray by ray, in ray order, so that the sums
 * keep their bits whatever the thread count (the counts are summed in any order). */
typedef struct tr_power {
    double emitted, detected, absorbed, escaped, cutoff;
} tr_power;

typedef struct tr_wray {
    double o[3], d[3];
    double n, len, opl;
    tr_pol pol;
    int depth, last_surf;
    long last_prim;
    uint32_t hist;
} tr_wray;

typedef struct tr_buf {
    void *p;
    size_t n, cap, size;
} tr_buf;

/* Room for one more record at the end of b (NULL: out of memory). */
static void *buf_slot(tr_buf *b)
{
    if (b->n == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 1024;
        void *p = realloc(b->p, cap * b->size);
        if (!p) return NULL;
        b->p = p;
        b->cap = cap;
    }
    return (char *)b->p + b->n++ * b->size;
}

/* Append all of a's records to b and empty a. */
static int buf_move(tr_buf *b, tr_buf *a)
{
    if (a->n == 0) return 0;
    if (b->n + a->n > b->cap) {
        size_t cap = b->cap ? b->cap : 1024;
        while (cap < b->n + a->n) cap *= 2;
        void *p = realloc(b->p, cap * b->size);
        if (!p) return -1;
        b->p = p;
        b->cap = cap;
    }
    memcpy((char *)b->p + b->n * b->size, a->p, a->n * a->size);
    b->n += a->n;
    a->n = 0;
    return 0;
}

/* Where a ray's records go: the worker's buffers, or a lane's until its turn. */
typedef struct tr_out {
    tr_buf seg, hit;
} tr_out;

/* Rays traced side by side on the lens shortcut (tr_packet.c): TR_PK rays' arithmetic
 * in vector registers, one step at a time. */
#define TR_LANES TR_PK

typedef struct tr_lane {
    tr_wray r;                   /* its doubles live in the packet while it runs */
    tr_tally *ty;
    uint64_t ray;
    double p0;
    int sp, live;
    int state;                   /* LANE_RUN, LANE_DONE, LANE_SLOW */
    tr_wray *stack;
    tr_out out;
} tr_lane;
enum { LANE_RUN, LANE_DONE, LANE_SLOW };

typedef struct tr_worker {
    const trace_scene *sc;
    const trace_options *o;
    uint64_t first, count;       /* the batch in hand: global ray numbers */
    tr_tally tally[TR_LANES];    /* the rays in hand (trace_lanes: one per lane) */
    tr_power *power;             /* the batch's powers, one per ray (its slot's) */
    trace_summary *counts;       /* the batch's counts (its slot's) */
    int want_seg, want_hit;
    tr_out out;
    tr_wray *stack;
    tr_lane lane[TR_LANES];
    int nomem;
} tr_worker;

static void emit_segment(tr_worker *w, tr_out *out, const tr_wray *r, uint64_t ray,
                         const double p1[3], int end, int surf)
{
    if (!w->want_seg) return;
    trace_segment *s = buf_slot(&out->seg);
    if (!s) { w->nomem = 1; return; }
    memset(s, 0, sizeof *s);            /* padding too: records compare bytewise */
    s->ray = ray;
    s->depth = r->depth;
    s->end = end;
    s->surface = surf;
    v_set(s->p0, r->o);
    v_set(s->p1, p1);
    s->power = r->pol.jss + r->pol.jpp;
}

static void emit_hit(tr_worker *w, tr_out *out, const tr_wray *r, uint64_t ray,
                     const tr_hitrec *h, const double p[3])
{
    if (!w->want_hit) return;
    trace_hit *x = buf_slot(&out->hit);
    if (!x) { w->nomem = 1; return; }
    memset(x, 0, sizeof *x);
    x->ray = ray;
    x->depth = r->depth;
    x->history = r->hist;
    x->surface = h->surf;
    x->prim = h->prim;
    v_set(x->pos, p);
    v_set(x->dir, r->d);
    v_set(x->normal, h->n);
    v_set(x->s_dir, r->pol.e);
    x->power_s = r->pol.jss;
    x->power_p = r->pol.jpp;
    x->length = r->len;
    x->opl = r->opl;
}

/* s unit vector of the plane of incidence (d x n), or the ray's own e at normal
 * incidence. */
static void s_vector(const tr_wray *r, const double n[3], double s[3])
{
    v_cross(r->d, n, s);
    double l = v_norm(s);
    if (!(l >= 1e-12)) { v_set(s, r->pol.e); return; }
    l = 1.0 / l;
    s[0] *= l; s[1] *= l; s[2] *= l;
}

/* Does a ray of power p go on?  Else it is counted as cut off. */
static int strong(const tr_worker *w, tr_tally *ty, double p, double p0)
{
    if (p <= 0) return 0;
    if (p < w->o->cutoff * p0) {
        ty->cutoff += p;
        ty->cut_power++;
        return 0;
    }
    return 1;
}

static void keep(tr_worker *w, tr_tally *ty, int *sp, const tr_wray *c, double p0)
{
    if (strong(w, ty, c->pol.jss + c->pol.jpp, p0)) (*sp)++;
}

/* The interaction at h: a reflected ray that must wait is pushed on the stack; the
 * ray that goes on now (refracted, or reflected at a mirror or TIR) replaces *r.
 * Returns 1 if *r goes on. */
static int interact(tr_worker *w, tr_tally *ty, tr_wray *stack, int *sp, tr_wray *r,
                    const tr_hitrec *h, const tr_surf *f, double p0)
{
    double n1 = f->mat.n_front, n2 = f->mat.n_back, s[3], m[3];
    if (f->media && h->prim >= 0) { n1 = f->media[2 * h->prim]; n2 = f->media[2 * h->prim + 1]; }
    double dn = v_dot(r->d, h->n);
    if (dn > 0) { double x = n1; n1 = n2; n2 = x; }     /* arriving from the back */
    /* m: unit normal pointing back into the incident medium */
    for (int i = 0; i < 3; i++) m[i] = dn > 0 ? -h->n[i] : h->n[i];
    double ci = fabs(dn) < 1.0 ? fabs(dn) : 1.0;   /* fmin(1, |dn|) without the call */
    if (f->mat.kind == TRACE_REFRACT && fabs(r->n - n1) > 1e-9 * n1) ty->mismatch++;
    ty->interactions++;
    s_vector(r, h->n, s);
    tr_pol_rotate(&r->pol, r->d, s);
    r->depth++;
    r->last_surf = h->surf;
    r->last_prim = h->prim;

    if (f->mat.kind == TRACE_MIRROR) {          /* rs = -1, rp = +1 */
        if (r->depth <= 32) r->hist |= 1u << (r->depth - 1);
        for (int i = 0; i < 3; i++) r->d[i] += 2 * ci * m[i];
        v_unit(r->d);
        r->pol.jre = -r->pol.jre;
        r->pol.jim = -r->pol.jim;
        return strong(w, ty, r->pol.jss + r->pol.jpp, p0);
    }
    trace_fresnel_coef fc;
    tr_fresnel(n1, n2, ci, &fc);
    if (fc.tir) {
        double ph = fc.rs_phase - fc.rp_phase, re = r->pol.jre, im = r->pol.jim;
        if (r->depth <= 32) r->hist |= 1u << (r->depth - 1);
        for (int i = 0; i < 3; i++) r->d[i] += 2 * ci * m[i];
        v_unit(r->d);
        if (re != 0 || im != 0) {
            r->pol.jre = cos(ph) * re - sin(ph) * im;
            r->pol.jim = sin(ph) * re + cos(ph) * im;
        }
        ty->tir++;
        return strong(w, ty, r->pol.jss + r->pol.jpp, p0);
    }
    if (w->o->fresnel) {
        /* outside TIR the phases are 0 or pi: rs rp is the product of signed values */
        double rsp = fc.rs * fc.rp * (fc.rs_phase == fc.rp_phase ? 1.0 : -1.0);
        if (w->o->reflections) {
            /* the reflected ray waits on the stack; the refracted one goes first */
            tr_wray *c = &stack[*sp];
            *c = *r;
            if (r->depth <= 32) c->hist |= 1u << (r->depth - 1);
            for (int i = 0; i < 3; i++) c->d[i] = r->d[i] + 2 * ci * m[i];
            v_unit(c->d);
            c->n = n1;
            c->pol.jss = fc.Rs * r->pol.jss;
            c->pol.jpp = fc.Rp * r->pol.jpp;
            c->pol.jre = rsp * r->pol.jre;
            c->pol.jim = rsp * r->pol.jim;
            keep(w, ty, sp, c, p0);
        } else {
            double p = fc.Rs * r->pol.jss + fc.Rp * r->pol.jpp;
            if (p > 0) { ty->cutoff += p; ty->cut_reflection++; }
        }
    }
    double eta = n1 / n2, k = eta * ci - fc.cos_t;
    for (int i = 0; i < 3; i++) r->d[i] = eta * r->d[i] + k * m[i];
    v_unit(r->d);
    r->n = n2;
    if (w->o->fresnel) {
        double a = sqrt(fc.Ts * fc.Tp);
        r->pol.jss *= fc.Ts;
        r->pol.jpp *= fc.Tp;
        r->pol.jre *= a;
        r->pol.jim *= a;
    }
    return strong(w, ty, r->pol.jss + r->pol.jpp, p0);
}

/* A ray's state from its source ray; its tally starts. */
static void ray_start(tr_wray *r, const tr_ray0 *r0, tr_tally *ty, double *p0)
{
    memset(ty, 0, sizeof *ty);
    v_set(r->o, r0->o);
    v_set(r->d, r0->d);
    r->n = r0->n;
    r->len = r->opl = 0;
    r->pol = r0->pol;
    r->depth = 0;
    r->last_surf = -1;
    r->last_prim = -1;
    r->hist = 0;
    *p0 = r0->pol.jss + r0->pol.jpp;
    ty->emitted = *p0;
}

/* One step once the hit h of *r is known: the segment to it and what the surface
 * does.  Returns 1 if *r goes on. */
static inline int on_hit(tr_worker *w, tr_out *out, tr_tally *ty, tr_wray *stack, int *sp,
                         tr_wray *r, const tr_hitrec *h, uint64_t ray, double p0)
{
    double p = r->pol.jss + r->pol.jpp, q[3];
    for (int i = 0; i < 3; i++) q[i] = r->o[i] + h->t * r->d[i];
    if (!(isfinite(q[0]) && isfinite(q[1]) && isfinite(q[2]) && isfinite(h->n[0]))) {
        ty->failures++;
        ty->cutoff += p;
        return 0;
    }
    const tr_surf *f = w->sc->surf[h->surf];
    ty->segments++;
    r->len += h->t;
    r->opl += r->n * h->t;
    switch (f->mat.kind) {
    case TRACE_ABSORB:
        ty->absorbed += p;
        emit_segment(w, out, r, ray, q, TRACE_END_ABSORB, h->surf);
        return 0;
    case TRACE_DETECT: {
        double s[3];
        s_vector(r, h->n, s);
        tr_pol_rotate(&r->pol, r->d, s);
        ty->detected += p;
        ty->hits++;
        emit_segment(w, out, r, ray, q, TRACE_END_DETECT, h->surf);
        emit_hit(w, out, r, ray, h, q);
        return 0;
    }
    default:
        emit_segment(w, out, r, ray, q, TRACE_END_NONE, h->surf);
        v_set(r->o, q);
        return interact(w, ty, stack, sp, r, h, f, p0);
    }
}

/* The rest of a ray's tree from *r (live: *r itself goes on; else the stack). */
static void trace_rest(tr_worker *w, tr_out *out, tr_tally *ty, tr_wray *stack, int sp,
                       tr_wray *rp, int live, uint64_t ray, double p0)
{
    const trace_scene *sc = w->sc;
    const trace_options *o = w->o;
    tr_wray r = *rp;
    for (;;) {
        if (!live) {
            if (sp == 0) break;
            r = stack[--sp];
        }
        double p = r.pol.jss + r.pol.jpp, q[3];
        tr_hitrec h;
        if (r.depth > ty->max_depth) ty->max_depth = r.depth;
        if (r.depth >= o->max_depth) { ty->cutoff += p; ty->cut_depth++; live = 0; continue; }
        if (!find_hit(sc, o, r.o, r.d, r.last_surf, r.last_prim, r.hist, &h)) {
            for (int i = 0; i < 3; i++) q[i] = r.o[i] + o->escape_length * r.d[i];
            ty->segments++;
            ty->escaped += p;
            emit_segment(w, out, &r, ray, q, TRACE_END_ESCAPE, -1);
            live = 0;
            continue;
        }
        live = on_hit(w, out, ty, stack, &sp, &r, &h, ray, p0);
    }
}

static void trace_one(tr_worker *w, const tr_ray0 *r0, uint64_t ray, tr_tally *ty)
{
    tr_wray r;
    double p0;
    ray_start(&r, r0, ty, &p0);
    trace_rest(w, &w->out, ty, w->stack, 0, &r, 1, ray, p0);
}

/* A traced ray's tally (ray i of the batch) into the batch's powers and counts. */
static void fold(tr_worker *w, uint64_t i, const tr_tally *t)
{
    trace_summary *s = w->counts;
    tr_power *pw = &w->power[i];
    pw->emitted = t->emitted;
    pw->detected = t->detected;
    pw->absorbed = t->absorbed;
    pw->escaped = t->escaped;
    pw->cutoff = t->cutoff;
    s->rays++;
    s->segments += t->segments;
    s->interactions += t->interactions;
    s->tir += t->tir;
    s->hits += t->hits;
    s->cut_depth += t->cut_depth;
    s->cut_power += t->cut_power;
    s->cut_reflection += t->cut_reflection;
    s->medium_mismatch += t->mismatch;
    s->failures += t->failures;
    if (t->max_depth > s->max_depth_seen) s->max_depth_seen = t->max_depth;
}

/* Source ray number g (the source index *k moves forward only). */
static void source_ray(const trace_scene *sc, int *k, uint64_t g, tr_ray0 *r)
{
    while (*k + 1 < sc->nsrc && sc->src[*k + 1].first <= g) (*k)++;
    while (sc->src[*k].first + (uint64_t)sc->src[*k].nrays <= g) (*k)++;
    tr_source_ray(&sc->src[*k], (long)(g - sc->src[*k].first), r);
}

/* Lane l of a packet from a starting ray (its books are empty), and a ray's doubles
 * back from lane l. */
static void pk_put(tr_pk *p, int l, const tr_wray *r, double p0)
{
    for (int i = 0; i < 3; i++) {
        p->o[i][l] = r->o[i];
        p->d[i][l] = r->d[i];
        p->e[i][l] = r->pol.e[i];
    }
    p->n[l] = r->n;
    p->len[l] = r->len;
    p->opl[l] = r->opl;
    p->jss[l] = r->pol.jss;
    p->jpp[l] = r->pol.jpp;
    p->jre[l] = r->pol.jre;
    p->jim[l] = r->pol.jim;
    p->p0[l] = p0;
    p->cut[l] = 0;
    p->depth[l] = p->maxd[l] = r->depth;
    p->nseg[l] = p->nint[l] = p->nmis[l] = p->ncutr[l] = 0;
}

static void pk_get(const tr_pk *p, int l, tr_wray *r)
{
    for (int i = 0; i < 3; i++) {
        r->o[i] = p->o[i][l];
        r->d[i] = p->d[i][l];
        r->pol.e[i] = p->e[i][l];
    }
    r->n = p->n[l];
    r->len = p->len[l];
    r->opl = p->opl[l];
    r->pol.jss = p->jss[l];
    r->pol.jpp = p->jpp[l];
    r->pol.jre = p->jre[l];
    r->pol.jim = p->jim[l];
    r->depth = (int)p->depth[l];
}

/* The ray of lane l as packet p holds it, having left surface `last`. */
static tr_wray *lane_ray(const tr_lane *L, const tr_pk *p, int l, int last, tr_wray *r)
{
    *r = L->r;
    pk_get(p, l, r);
    r->last_surf = last;
    r->last_prim = -1;
    return r;
}

/* The books lane l kept in packet p go back to its tally (they were empty when it
 * entered the packet, so the sums are exact). */
static void lane_tally(tr_lane *L, const tr_pk *p, int l)
{
    tr_tally *ty = L->ty;
    if (p->maxd[l] > ty->max_depth) ty->max_depth = (int)p->maxd[l];
    ty->segments += (uint32_t)p->nseg[l];
    ty->interactions += (uint32_t)p->nint[l];
    ty->mismatch += (uint32_t)p->nmis[l];
    ty->cut_reflection += (uint32_t)p->ncutr[l];
    ty->cutoff += p->cut[l];
}

/* Lane l leaves the packet as p holds it (having left surface `last`) to go on alone:
 * its ray and books go back to L. */
static void lane_leave(tr_lane *L, const tr_pk *p, int l, int last)
{
    lane_ray(L, p, l, last, &L->r);
    lane_tally(L, p, l);
}

/* Lane l is finished here (the one-ray code takes its reflected rays, if any). */
static void lane_end(tr_lane *L)
{
    L->live = 0;
    L->state = L->sp ? LANE_SLOW : LANE_DONE;
}

/* What on_hit and interact record for lane l's step from in (having left `last`) to
 * out, and the books of a lane that stops here.  Returns 1 if it goes on. */
static int lane_books(tr_worker *w, tr_lane *L, int l, const tr_pk *in, const tr_pk *out,
                      const tr_pk_aux *x, const int *id, int last, unsigned calm)
{
    tr_tally *ty = L->ty;
    tr_wray s;
    int surf = id[x->cand[l] & 3], st = (int)x->status[l];
    double q[3] = {out->o[0][l], out->o[1][l], out->o[2][l]}, p = x->p[l];
    if (st == TR_PK_SCALAR) {                 /* the one-ray code takes this step */
        lane_leave(L, in, l, last);
        L->state = LANE_SLOW;
        return 0;
    }
    if (st == TR_PK_ABSORB || st == TR_PK_DETECT) {    /* the ray ends: books only */
        lane_tally(L, out, l);
        ty->segments++;
        if (w->want_seg || w->want_hit) {
            lane_ray(L, st == TR_PK_ABSORB ? in : out, l, last, &s);
            v_set(s.o, (double[3]){in->o[0][l], in->o[1][l], in->o[2][l]});
        }
        if (st == TR_PK_ABSORB) {
            ty->absorbed += p;
            emit_segment(w, &L->out, &s, L->ray, q, TRACE_END_ABSORB, surf);
        } else {
            tr_hitrec h = {surf, -1, x->t[l], {x->nrm[0][l], x->nrm[1][l], x->nrm[2][l]}};
            ty->detected += p;
            ty->hits++;
            emit_segment(w, &L->out, &s, L->ray, q, TRACE_END_DETECT, surf);
            emit_hit(w, &L->out, &s, L->ray, &h, q);
        }
        lane_end(L);
        return 0;
    }
    if (w->want_seg)                           /* REFRACT */
        emit_segment(w, &L->out, lane_ray(L, in, l, last, &s), L->ray, q, TRACE_END_NONE,
                     surf);
    if (w->o->fresnel && w->o->reflections) {
        tr_wray *c = lane_ray(L, out, l, surf, &L->stack[L->sp]);
        if (c->depth <= 32) c->hist |= 1u << (c->depth - 1);
        for (int i = 0; i < 3; i++) c->d[i] = x->rd[i][l];
        c->n = x->n1[l];
        c->pol.jss = x->Rs[l] * x->jss[l];
        c->pol.jpp = x->Rp[l] * x->jpp[l];
        c->pol.jre = x->rsp[l] * x->jre[l];
        c->pol.jim = x->rsp[l] * x->jim[l];
        keep(w, ty, &L->sp, c, L->p0);
    }
    if (calm & (1u << l)) return 1;
    lane_leave(L, out, l, surf);              /* too weak to go on */
    strong(w, ty, out->jss[l] + out->jpp[l], L->p0);
    lane_end(L);
    return 0;
}

/* Rays i0 .. i0+TR_LANES-1 of the worker side by side while each stays on the lens
 * shortcut, step by step in a packet (tr_packet.c); a lane that leaves it (no
 * candidate hit, depth limit, a ray going back, TIR, reflections waiting) is finished
 * alone afterwards by trace_rest from where it left.  Every lane computes exactly what
 * trace_one would; its records wait in the lane's buffers and are passed on in ray
 * order. */
static void trace_lanes(tr_worker *w, uint64_t i0, int *k)
{
    const trace_scene *sc = w->sc;
    const trace_options *o = w->o;
    int cur = 0, last = -1, each = w->want_seg || o->reflections;
    unsigned run = (1u << TR_LANES) - 1;
    tr_ray0 r0[TR_LANES];
    tr_pk pk[2];
    tr_pk_aux x;
    tr_pk_opt po = {o->fresnel, o->reflections, o->max_depth, 1, o->cutoff, sc->entry_z};
    uint64_t g = w->first + i0;
    source_ray(sc, k, g, &r0[0]);             /* moves *k to the first ray's source */
    const tr_source *src = &sc->src[*k];
    if (g + TR_LANES <= src->first + (uint64_t)src->nrays)
        tr_source_rays(src, (long)(g - src->first), TR_LANES, r0);
    else
        for (int l = 1; l < TR_LANES; l++) source_ray(sc, k, g + (uint64_t)l, &r0[l]);
    for (int l = 0; l < TR_LANES; l++) {
        tr_lane *L = &w->lane[l];
        L->ray = g + (uint64_t)l;
        L->ty = &w->tally[l];
        ray_start(&L->r, &r0[l], L->ty, &L->p0);
        pk_put(&pk[0], l, &L->r, L->p0);
        L->sp = 0;
        L->live = 1;
        L->state = LANE_RUN;
    }
    while (run) {
        const tr_pk *in = &pk[cur];
        tr_pk *out = &pk[cur ^ 1];
        const tr_pk_set *set = last >= 0 ? &sc->surf[last]->pk : &sc->entry_pk;
        if (set->nc <= 0) break;
        po.entry = last < 0;
        unsigned calm = tr_pk_step(in, out, &x, set, run, &po);
        unsigned next = calm;
        for (int l = 0; l < TR_LANES; l++)
            if ((run & (1u << l)) && (each || !(calm & (1u << l))) &&
                !lane_books(w, &w->lane[l], l, in, out, &x, set->id, last, calm))
                next &= ~(1u << l);
        last = -1;
        for (int l = 0; l < TR_LANES; l++) {     /* all on from the same surface */
            if (!(next & (1u << l))) continue;
            int surf = set->id[x.cand[l] & 3];
            if (last < 0) last = surf;
            if (surf == last) continue;
            lane_leave(&w->lane[l], out, l, surf);
            w->lane[l].state = LANE_SLOW;
            next &= ~(1u << l);
        }
        run = next;
        cur ^= 1;
    }
    for (int l = 0; l < TR_LANES; l++) {
        tr_lane *L = &w->lane[l];
        if (run & (1u << l)) {                   /* stopped by a surface not for packets */
            lane_leave(L, &pk[cur], l, last);
            L->state = LANE_SLOW;
        }
        if (buf_move(&w->out.seg, &L->out.seg) || buf_move(&w->out.hit, &L->out.hit))
            w->nomem = 1;
        if (L->state == LANE_SLOW)
            trace_rest(w, &w->out, L->ty, L->stack, L->sp, &L->r, L->live, L->ray, L->p0);
        fold(w, i0 + (uint64_t)l, L->ty);
    }
}

/* tr_pk_step is compiled for AVX-512: without it rays go one by one (same bits). */
static int packets_usable(void)
{
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
           __builtin_cpu_supports("avx512dq");
}

/* Trace the worker's batch: rays first .. first+count-1, records to w->out in ray
 * order, the powers of each ray to w->power and the counts to w->counts. */
static void trace_batch(tr_worker *w)
{
    const trace_scene *sc = w->sc;
    const trace_options *o = w->o;
    int k = 0;
    uint64_t i = 0;
    if (o->sequential && !o->float_hits && sc->seq_nsurf == sc->nsurf && sc->nentry > 0 &&
        packets_usable())
        for (; i + TR_LANES <= w->count; i += TR_LANES) trace_lanes(w, i, &k);
    for (; i < w->count; i++) {
        tr_ray0 r;
        source_ray(sc, &k, w->first + i, &r);
        trace_one(w, &r, w->first + i, &w->tally[0]);
        fold(w, i, &w->tally[0]);
    }
}

static void options_default(trace_options *o)
{
    memset(o, 0, sizeof *o);
    o->max_depth = 16;
    o->cutoff = 1e-6;
    o->fresnel = 1;
    o->reflections = 1;
    o->threads = 0;
    o->escape_length = 1;
    o->batch = 0;
    o->float_hits = 0;
    o->sequential = 1;
}

/* A delivered batch (counts c, powers pw[0..n-1]) into the summary: the powers ray
 * by ray, in ray order. */
static void add_batch(trace_summary *s, const trace_summary *c, const tr_power *pw,
                      uint64_t n)
{
    s->rays += c->rays;
    s->segments += c->segments;
    s->interactions += c->interactions;
    s->tir += c->tir;
    s->hits += c->hits;
    s->cut_depth += c->cut_depth;
    s->cut_power += c->cut_power;
    s->cut_reflection += c->cut_reflection;
    s->medium_mismatch += c->medium_mismatch;
    s->failures += c->failures;
    if (c->max_depth_seen > s->max_depth_seen) s->max_depth_seen = c->max_depth_seen;
    double e = s->emitted, d = s->detected, a = s->absorbed, x = s->escaped, k = s->cutoff;
    for (uint64_t i = 0; i < n; i++) {
        e += pw[i].emitted;
        d += pw[i].detected;
        a += pw[i].absorbed;
        x += pw[i].escaped;
        k += pw[i].cutoff;
    }
    s->emitted = e; s->detected = d; s->absorbed = a; s->escaped = x; s->cutoff = k;
}

/* ---------------- the run: a pool of workers and a window of batches ----------------
 * The rays are cut into batches of fixed size; batch b always holds the same rays,
 * whatever the thread count.  Threads (the caller and nthr-1 workers, created once
 * per run) claim the next batch in order and trace it into a slot of a ring of nslot
 * slots: its records, in ray order, the powers of each ray and the batch's counts.
 * Batch b may be claimed only once batch b-nslot has been delivered, so at most nslot
 * batches are in memory.
 * The caller delivers completed batches in batch order -- the sinks see every record
 * in ray order, from the calling thread -- and adds their powers ray by ray, in ray
 * order: every sum is the same to the last bit for any thread count (and any batch
 * size).  The caller delivers whatever is ready before it traces a batch itself, so
 * with cheap sinks it spends nearly all its time tracing, and with costly ones the
 * workers keep tracing ahead while it delivers. */

typedef struct tr_slot {
    tr_power *power;             /* one per ray of the batch */
    trace_summary counts;        /* the batch's counts (no powers) */
    tr_out out;                  /* the batch's records (buffers reused) */
    uint64_t batch;              /* which batch the slot holds */
    int done, nomem;
} tr_slot;

typedef struct tr_pool {
    const trace_scene *sc;
    pthread_mutex_t mu;
    pthread_cond_t more;         /* workers wait here: a slot freed, or stop */
    pthread_cond_t ready;        /* the caller waits here: a batch done */
    uint64_t nbatch, next;       /* batches; the next one to claim */
    uint64_t delivered;          /* batches handed to the sinks */
    long batch;                  /* rays per batch */
    tr_slot *slot;
    int nslot;
    int stop;                    /* no more claims (cancel, error) */
} tr_pool;

typedef struct tr_thread {
    tr_pool *pool;
    tr_worker *w;
} tr_thread;

/* Under the lock: claim the next batch if the window has room; its slot, or NULL. */
static tr_slot *claim(tr_pool *p, uint64_t *b)
{
    if (p->stop || p->next >= p->nbatch || p->next >= p->delivered + (uint64_t)p->nslot)
        return NULL;
    *b = p->next++;
    tr_slot *s = &p->slot[*b % (uint64_t)p->nslot];
    s->batch = *b;
    s->done = 0;
    return s;
}

/* Outside the lock: trace batch b into its slot (the slot is this thread's alone). */
static void fill(tr_pool *p, tr_worker *w, tr_slot *s, uint64_t b)
{
    uint64_t b0 = b * (uint64_t)p->batch, left = p->sc->nrays - b0;
    w->first = b0;
    w->count = left < (uint64_t)p->batch ? left : (uint64_t)p->batch;
    w->power = s->power;
    memset(&s->counts, 0, sizeof s->counts);
    w->counts = &s->counts;
    w->out = s->out;                       /* the slot's buffers, emptied */
    w->out.seg.n = w->out.hit.n = 0;
    w->nomem = 0;
    trace_batch(w);
    s->out = w->out;
    s->nomem = w->nomem;
}

static void *worker_main(void *arg)
{
    tr_thread *t = arg;
    tr_pool *p = t->pool;
    pthread_mutex_lock(&p->mu);
    for (;;) {
        uint64_t b;
        tr_slot *s = claim(p, &b);
        if (!s) {
            if (p->stop || p->next >= p->nbatch) break;
            pthread_cond_wait(&p->more, &p->mu);      /* the window is full */
            continue;
        }
        pthread_mutex_unlock(&p->mu);
        fill(p, t->w, s, b);
        pthread_mutex_lock(&p->mu);
        s->done = 1;
        if (b == p->delivered) pthread_cond_signal(&p->ready);
    }
    pthread_mutex_unlock(&p->mu);
    return NULL;
}

/* Hand a batch's records to the sinks (segments, then hits: each in ray order). */
static int deliver(const tr_slot *s, const trace_sink *k)
{
    for (size_t i = 0; k->segment && i < s->out.seg.n; i++)
        if (k->segment(k->ctx, (const trace_segment *)s->out.seg.p + i))
            return TRACE_ECANCEL;
    for (size_t i = 0; k->hit && i < s->out.hit.n; i++)
        if (k->hit(k->ctx, (const trace_hit *)s->out.hit.p + i)) return TRACE_ECANCEL;
    return TRACE_OK;
}

/* The caller's loop: deliver the next batch when it is done, else trace one, else
 * wait.  Returns TRACE_OK or the first error; the tallies go into *sum. */
static int drive(trace_scene *sc, tr_pool *p, tr_worker *w, const trace_sink *sink,
                 trace_summary *sum)
{
    int rc = TRACE_OK;
    pthread_mutex_lock(&p->mu);
    while (p->delivered < p->nbatch) {
        tr_slot *s = &p->slot[p->delivered % (uint64_t)p->nslot];
        uint64_t b;
        if (p->delivered < p->next && s->batch == p->delivered && s->done) {
            pthread_mutex_unlock(&p->mu);
            uint64_t b0 = p->delivered * (uint64_t)p->batch, left = sc->nrays - b0;
            uint64_t nb = left < (uint64_t)p->batch ? left : (uint64_t)p->batch;
            if (s->nomem) rc = fail(sc, TRACE_ENOMEM, "out of memory for trace output");
            else if ((rc = deliver(s, sink)) != TRACE_OK)
                fail(sc, rc, "the trace was cancelled");
            if (rc == TRACE_OK) add_batch(sum, &s->counts, s->power, nb);
            if (rc == TRACE_OK && sink->progress &&
                sink->progress(sink->ctx, b0 + nb, sc->nrays))
                rc = fail(sc, TRACE_ECANCEL, "the trace was cancelled");
            pthread_mutex_lock(&p->mu);
            if (rc != TRACE_OK) break;
            p->delivered++;
            pthread_cond_broadcast(&p->more);          /* a slot is free */
        } else if ((s = claim(p, &b)) != NULL) {
            pthread_mutex_unlock(&p->mu);
            fill(p, w, s, b);
            pthread_mutex_lock(&p->mu);
            s->done = 1;
        } else {
            pthread_cond_wait(&p->ready, &p->mu);
        }
    }
    p->stop = 1;
    pthread_cond_broadcast(&p->more);
    pthread_mutex_unlock(&p->mu);
    return rc;
}

static int check_options(trace_scene *sc, const trace_options *o)
{
    if (o->max_depth < 1 || o->max_depth > 10000)
        return fail(sc, TRACE_EINVAL, "depth limit must be 1..10000");
    if (!(o->cutoff >= 0 && o->cutoff < 1))
        return fail(sc, TRACE_EINVAL, "intensity cutoff must be in [0, 1)");
    if (o->threads < 0 || o->threads > 1024)
        return fail(sc, TRACE_EINVAL, "thread count must be 0..1024");
    if (!(o->escape_length >= 0 && isfinite(o->escape_length)))
        return fail(sc, TRACE_EINVAL, "escape length must be a non-negative number");
    if (o->batch < 0) return fail(sc, TRACE_EINVAL, "batch must be >= 0");
    return TRACE_OK;
}

/* Rays per batch: the option, else 8192 with sinks (records wait in memory) and
 * 65536 without; with several threads smaller, so that there are enough batches for
 * the last ones to end together and the window (nslot batches) stays within about a
 * million rays. */
static long batch_size(const trace_options *o, int sinks, int nthr, int nslot,
                       uint64_t nrays)
{
    if (o->batch) return o->batch;
    long b = sinks ? 8192 : 65536;
    while (b > 1024 && nthr > 1 &&
           (nrays / (uint64_t)b < 8 * (uint64_t)nthr || (uint64_t)b * nslot > (1u << 20)))
        b /= 2;
    return b;
}

static void free_worker(tr_worker *w)
{
    if (!w) return;
    free(w->stack);
    for (int l = 0; l < TR_LANES; l++) {
        free(w->lane[l].out.seg.p);
        free(w->lane[l].out.hit.p);
    }
    free(w);
}

/* A worker with its stacks (one for itself, one per lane); NULL: out of memory.
 * Each is its own allocation, a cache line apart from the others. */
static tr_worker *new_worker(const trace_scene *sc, const trace_options *o, int want_seg,
                             int want_hit)
{
    size_t size = (sizeof(tr_worker) + 63) / 64 * 64;
    tr_worker *w = aligned_alloc(64, size);
    if (!w) return NULL;
    memset(w, 0, sizeof *w);
    w->sc = sc;
    w->o = o;
    w->want_seg = want_seg;
    w->want_hit = want_hit;
    size_t depth = (size_t)o->max_depth + 4;
    w->stack = malloc((TR_LANES + 1) * depth * sizeof(tr_wray));
    if (!w->stack) { free(w); return NULL; }
    for (int l = 0; l < TR_LANES; l++) {
        w->lane[l].stack = w->stack + (size_t)(l + 1) * depth;
        w->lane[l].out.seg.size = sizeof(trace_segment);
        w->lane[l].out.hit.size = sizeof(trace_hit);
    }
    return w;
}

static int run(trace_scene *sc, const trace_options *oin, const trace_sink *sink,
               trace_summary *sum)
{
    trace_options o;
    trace_summary s;
    trace_sink none = {0};
    tr_pool p;
    int rc;
    if (!sc) return TRACE_EINVAL;
    if (oin) o = *oin; else options_default(&o);
    if (!sink) sink = &none;
    memset(&s, 0, sizeof s);
    if (sum) memset(sum, 0, sizeof *sum);
    if ((rc = check_options(sc, &o))) return rc;
    if ((rc = build(sc, &s.build_ms))) return rc;
    int nthr = o.threads ? o.threads : (int)sysconf(_SC_NPROCESSORS_ONLN);
    if (nthr < 1) nthr = 1;
    int want_seg = sink->segment != NULL, want_hit = sink->hit != NULL;
    memset(&p, 0, sizeof p);
    p.sc = sc;
    p.nslot = nthr == 1 ? 1 : 2 * nthr + 2;   /* one thread: trace, deliver, again */
    p.batch = batch_size(&o, want_seg || want_hit, nthr, p.nslot, sc->nrays);
    p.nbatch = (sc->nrays + (uint64_t)p.batch - 1) / (uint64_t)p.batch;
    if (p.nbatch < (uint64_t)p.nslot) p.nslot = p.nbatch ? (int)p.nbatch : 1;
    if (p.nbatch < (uint64_t)nthr) nthr = p.nbatch ? (int)p.nbatch : 1;
    tr_worker **w = calloc((size_t)nthr, sizeof *w);
    tr_thread *th = calloc((size_t)nthr, sizeof *th);
    pthread_t *tid = calloc((size_t)nthr, sizeof *tid);
    p.slot = calloc((size_t)p.nslot, sizeof *p.slot);
    rc = (w && th && tid && p.slot) ? TRACE_OK : TRACE_ENOMEM;
    size_t room = sc->nrays < (uint64_t)p.batch ? (size_t)sc->nrays + 1 : (size_t)p.batch;
    for (int i = 0; rc == TRACE_OK && i < p.nslot; i++) {
        p.slot[i].power = malloc(room * sizeof(tr_power));
        p.slot[i].out.seg.size = sizeof(trace_segment);
        p.slot[i].out.hit.size = sizeof(trace_hit);
        if (!p.slot[i].power) rc = TRACE_ENOMEM;
    }
    for (int i = 0; rc == TRACE_OK && i < nthr; i++)
        if (!(w[i] = new_worker(sc, &o, want_seg, want_hit))) rc = TRACE_ENOMEM;
    if (rc != TRACE_OK) fail(sc, rc, "out of memory");
    int mu = 0, more = 0, ready = 0, nstarted = 0;
    if (rc == TRACE_OK) {
        mu = pthread_mutex_init(&p.mu, NULL) == 0;
        more = pthread_cond_init(&p.more, NULL) == 0;
        ready = pthread_cond_init(&p.ready, NULL) == 0;
        if (!mu || !more || !ready) rc = fail(sc, TRACE_ENOMEM, "cannot make a lock");
    }
    double t0 = now_ms();
    if (rc == TRACE_OK) {
        /* a worker that cannot be started leaves its share to the others */
        for (int i = 1; i < nthr; i++) {
            th[nstarted] = (tr_thread){&p, w[i]};
            if (pthread_create(&tid[nstarted], NULL, worker_main, &th[nstarted]) == 0)
                nstarted++;
        }
        rc = drive(sc, &p, w[0], sink, &s);
        for (int i = 0; i < nstarted; i++) pthread_join(tid[i], NULL);
    }
    s.trace_ms = now_ms() - t0;
    if (mu) pthread_mutex_destroy(&p.mu);
    if (more) pthread_cond_destroy(&p.more);
    if (ready) pthread_cond_destroy(&p.ready);
    for (int i = 0; w && i < nthr; i++) free_worker(w[i]);
    for (int i = 0; p.slot && i < p.nslot; i++) {
        free(p.slot[i].power);
        free(p.slot[i].out.seg.p);
        free(p.slot[i].out.hit.p);
    }
    free(p.slot);
    free(w);
    free(th);
    free(tid);
    if (sum) *sum = s;
    return rc;
}

/* ---------------- the table ---------------- */

static const char *version(void)
{
    return "lensmat trace engine (ABI " "1" "), Embree " RTC_VERSION_STRING;
}

static int refract(const double d[3], const double nrm[3], double n1, double n2,
                   double out[3])
{
    return tr_refract(d, nrm, n1, n2, out);
}

static void fresnel(double n1, double n2, double cos_i, trace_fresnel_coef *out)
{
    tr_fresnel(n1, n2, cos_i, out);
}

static const trace_api api = {
    TRACE_ABI,
    version,
    scene_new,
    scene_free,
    scene_error,
    add_surface,
    add_mesh,
    add_source,
    options_default,
    build,
    run,
    refract,
    fresnel,
    tr_add_lens,
    tr_lens_fan,
};

const trace_api *trace_get_api(int abi)
{
    return abi == TRACE_ABI ? &api : NULL;
}
