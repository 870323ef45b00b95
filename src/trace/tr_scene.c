/* tr_scene.c -- the trace engine's scene on Embree 3.  Owns: surfaces (analytic ones
 * as Embree user geometry, meshes as robust triangle geometry with double copies of
 * their vertices), sources, the Embree device (created on the first build, never
 * before), the lens hints, and the one question the trace loop asks of the scene:
 * which surface does this ray meet next (in double). */
#include <float.h>
#include <math.h>
#include <stdio.h>
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
} tr_ctx;

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

trace_scene *tr_scene_new(void)
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
    free(sc->far);
    sc->far = NULL;
    sc->nfar = sc->nembree = 0;
}

void tr_scene_free(trace_scene *sc)
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

const char *tr_scene_error(const trace_scene *sc)
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

int tr_add_surface(trace_scene *sc, const trace_surface *s, const trace_material *m)
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

/* ---- closed meshes: a ray going into one must meet it again ---- */

static uint64_t mix64(uint64_t x)
{
    x ^= x >> 33; x *= 0xff51afd7ed558ccdULL; x ^= x >> 33; x *= 0xc4ceb9fe1a85ec53ULL;
    return x ^ (x >> 33);
}

/* Is the mesh closed (vertices welded where their coordinates are equal, every edge
 * used once in each direction)?  1: its normals point outward (positive volume), -1:
 * inward, 0: not closed, or out of memory. */
static int mesh_closed(const tr_surf *f)
{
    size_t nv = (size_t)f->nv, cap = 16, ne = (size_t)f->ntri * 3, ecap = 16;
    while (cap < 2 * nv) cap *= 2;
    while (ecap < 2 * ne) ecap *= 2;
    long *slot = malloc(cap * sizeof *slot);
    uint32_t *weld = malloc(nv * sizeof *weld);
    uint64_t *edge = malloc(ecap * sizeof *edge);
    int closed = 0;
    if (!slot || !weld || !edge) goto out;
    for (size_t i = 0; i < cap; i++) slot[i] = -1;
    for (size_t i = 0; i < nv; i++) {
        uint64_t b[3], h = 0;
        memcpy(b, f->vtx + 3 * i, sizeof b);
        for (int j = 0; j < 3; j++)      /* -0 and 0 are one coordinate */
            h = mix64(h ^ (b[j] == 0x8000000000000000ULL ? 0 : b[j]));
        size_t k = h & (cap - 1);
        for (;; k = (k + 1) & (cap - 1)) {
            if (slot[k] < 0) { slot[k] = (long)i; weld[i] = (uint32_t)i; break; }
            const double *a = f->vtx + 3 * slot[k], *c = f->vtx + 3 * i;
            if (a[0] == c[0] && a[1] == c[1] && a[2] == c[2]) {
                weld[i] = (uint32_t)slot[k];
                break;
            }
        }
    }
    memset(edge, 0xff, ecap * sizeof *edge);          /* empty: all ones */
    double vol = 0;
    for (long t = 0; t < f->ntri; t++) {
        uint32_t w[3];
        for (int j = 0; j < 3; j++) w[j] = weld[f->idx[3 * t + j]];
        const double *a = f->vtx + 3 * w[0], *b = f->vtx + 3 * w[1], *c = f->vtx + 3 * w[2];
        double bc[3];
        v_cross(b, c, bc);
        vol += v_dot(a, bc);
        for (int j = 0; j < 3; j++) {
            uint64_t key = (uint64_t)w[j] << 32 | w[(j + 1) % 3];
            size_t k = mix64(key) & (ecap - 1);
            for (;; k = (k + 1) & (ecap - 1)) {
                if (edge[k] == key) goto out;          /* an edge used twice one way */
                if (edge[k] == UINT64_MAX) { edge[k] = key; break; }
            }
        }
    }
    for (size_t k = 0; k < ecap; k++) {                /* each edge once the other way */
        if (edge[k] == UINT64_MAX) continue;
        uint64_t rev = (edge[k] << 32) | (edge[k] >> 32);
        size_t j = mix64(rev) & (ecap - 1);
        for (;; j = (j + 1) & (ecap - 1)) {
            if (edge[j] == rev) break;
            if (edge[j] == UINT64_MAX) goto out;
        }
    }
    closed = vol > 0 ? 1 : vol < 0 ? -1 : 0;
out:
    free(slot);
    free(weld);
    free(edge);
    return closed;
}

int tr_add_mesh(trace_scene *sc, const trace_mesh *mesh, const trace_material *m)
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
        if (fabs(x) > TR_EMBREE_MAX) {     /* Embree holds meshes in single precision */
            snprintf(msg, sizeof msg, "vertex %ld: coordinate %g is beyond the range of "
                     "meshes (|x| <= %g)", i / 3 + 1, x, TR_EMBREE_MAX);
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
    f->closed = mesh_closed(f);
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

int tr_add_source(trace_scene *sc, const trace_source *s, uint64_t *first)
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
    const double *c = f->eoff;
    struct RTCBounds *b = a->bounds_o;
    b->lower_x = nextafterf((float)(f->shape.lo[0] - c[0] - f->pad), -INFINITY);
    b->lower_y = nextafterf((float)(f->shape.lo[1] - c[1] - f->pad), -INFINITY);
    b->lower_z = nextafterf((float)(f->shape.lo[2] - c[2] - f->pad), -INFINITY);
    b->upper_x = nextafterf((float)(f->shape.hi[0] - c[0] + f->pad), INFINITY);
    b->upper_y = nextafterf((float)(f->shape.hi[1] - c[1] + f->pad), INFINITY);
    b->upper_z = nextafterf((float)(f->shape.hi[2] - c[2] + f->pad), INFINITY);
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

static void user_intersect(const struct RTCIntersectFunctionNArguments *a)
{
    if (a->N != 1 || !a->valid[0]) return;
    tr_ctx *x = (tr_ctx *)a->context;
    const tr_surf *f = a->geometryUserPtr;
    struct RTCRayHit *rh = (struct RTCRayHit *)a->rayhit;
    double t, n[3], p[3];
    int leaving = leaves(x->sc, x->last_surf, f), ok;
    if (x->float_hits) ok = tr_shape_hit_float(&f->shape, x->o, x->d, leaving, &t, n);
    else if ((ok = tr_shape_hit_t(&f->shape, x->o, x->d, leaving, &t, p)))
        tr_shape_hit_normal(&f->shape, p, n);
    if (!ok || !(t < x->best_t)) return;
    float tf = (float)(t - x->ta);
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
    x->best_far = ok == 2 && !x->float_hits;
    if (x->best_far) tr_shape_world(&f->shape, p, x->best_q);
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
    for (long i = 0; i < 3 * f->nv; i++) v[i] = (float)(f->vtx[i] - sc->eoff[i % 3]);
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

/* The same surface at the same place (every figure equal; a plane also with its
 * normal reversed)? */
static int same_place(const tr_shape *a, const tr_shape *b)
{
    if (a->shape != b->shape || a->aperture != b->aperture || a->nasph != b->nasph)
        return 0;
    for (int i = 0; i < 3; i++) if (a->at[i] != b->at[i]) return 0;
    int flip = a->shape == TRACE_PLANE && a->w[0] == -b->w[0] && a->w[1] == -b->w[1] &&
               a->w[2] == -b->w[2];
    if (!flip && a->shape != TRACE_SPHERE)
        for (int i = 0; i < 3; i++) if (a->w[i] != b->w[i]) return 0;
    if (a->radius != b->radius || a->c != b->c || a->k != b->k ||
        a->r_outer2 != b->r_outer2 || a->r_inner2 != b->r_inner2 || a->hw != b->hw ||
        a->hh != b->hh)
        return 0;
    for (int i = 0; i < a->nasph; i++) if (a->asph[i] != b->asph[i]) return 0;
    if (a->aperture == TRACE_AP_RECT)       /* the same rectangle, or turned by pi */
        for (int i = 0; i < 3; i++)
            if (fabs(a->u[i]) != fabs(b->u[i]) || fabs(a->v[i]) != fabs(b->v[i])) return 0;
    return 1;
}

/* Groups of coincident analytic surfaces, their members in the order they were added:
 * a ray that meets one meets the others at the same point, one after the other (see
 * tr_find_hit).  The lens shortcut does not know them: a scene with any is traced
 * through Embree alone. */
static void group_coincident(trace_scene *sc)
{
    sc->ngroup = 0;
    for (int i = 0; i < sc->nsurf; i++) {
        tr_surf *f = sc->surf[i];
        f->group = f->gprev = f->gnext = -1;
        if (f->is_mesh) continue;
        for (int j = i - 1; j >= 0; j--) {
            tr_surf *g = sc->surf[j];
            if (g->is_mesh || !same_place(&f->shape, &g->shape)) continue;
            if (g->group < 0) { g->group = j; sc->ngroup++; }
            while (g->gnext >= 0) g = sc->surf[g->gnext];   /* the group's last member */
            f->group = g->group;
            f->gprev = g->id;
            g->gnext = f->id;
            sc->ngroup++;
            break;
        }
    }
    if (sc->ngroup) sc->seq_nsurf = -1;
}

/* Within the range Embree's single precision serves (meshes always are: add_mesh
 * refuses vertices beyond it)? */
static int in_range(const tr_surf *f)
{
    if (f->is_mesh) return 1;
    for (int i = 0; i < 3; i++)
        if (!(fabs(f->shape.lo[i]) <= TR_EMBREE_MAX && fabs(f->shape.hi[i]) <= TR_EMBREE_MAX))
            return 0;
    return 1;
}

/* The box of what Embree holds, and how far its float ray may stray from the double
 * one inside it: Embree's coordinates are the world's less the box's centre (eoff),
 * the origin rounds to half an ulp of the largest of those coordinates M, the
 * direction to half an ulp of each component, over at most the box's diagonal D.
 * Every analytic surface's box grows by eight times that (a ray that meets the surface
 * in double is always offered to it); the box itself by as much again. */
static void embree_box(trace_scene *sc)
{
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int i = 0; i < sc->nsurf; i++) {
        const tr_surf *f = sc->surf[i];
        if (!in_range(f)) continue;
        for (int j = 0; j < 3; j++) {
            if (f->is_mesh) {
                for (long v = 0; v < f->nv; v++) {
                    lo[j] = fmin(lo[j], f->vtx[3 * v + j]);
                    hi[j] = fmax(hi[j], f->vtx[3 * v + j]);
                }
            } else {
                lo[j] = fmin(lo[j], f->shape.lo[j]);
                hi[j] = fmax(hi[j], f->shape.hi[j]);
            }
        }
    }
    double m = 0, d[3];
    for (int j = 0; j < 3; j++) {
        if (!(lo[j] <= hi[j])) { lo[j] = hi[j] = 0; }
        sc->eoff[j] = lo[j] / 2 + hi[j] / 2;
        m = fmax(m, fmax(fabs(lo[j] - sc->eoff[j]), fabs(hi[j] - sc->eoff[j])));
        d[j] = hi[j] - lo[j];
    }
    sc->epad = 8 * FLT_EPSILON * (m + v_norm(d)) + 1e-300;
    for (int j = 0; j < 3; j++) {
        sc->elo[j] = lo[j] - 2 * sc->epad;
        sc->ehi[j] = hi[j] + 2 * sc->epad;
    }
}

int tr_build(trace_scene *sc, double *ms)
{
    if (!sc) return TRACE_EINVAL;
    if (sc->built) { if (ms) *ms = sc->build_ms; return TRACE_OK; }
    double t0 = tr_now_ms();
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
    if (sc->nsurf && !(sc->far = malloc((size_t)sc->nsurf * sizeof *sc->far))) {
        drop_embree(sc);
        return fail(sc, TRACE_ENOMEM, "out of memory");
    }
    embree_box(sc);
    group_coincident(sc);
    for (int i = 0; i < sc->nsurf; i++) {
        tr_surf *f = sc->surf[i];
        if (!f->is_mesh && !in_range(f)) { sc->far[sc->nfar++] = i; continue; }
        f->pad = sc->epad;
        f->eoff = sc->eoff;
        sc->nembree++;
        int rc = f->is_mesh ? attach_mesh(sc, f) : attach_user(sc, f);
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
    sc->build_ms = tr_now_ms() - t0;
    if (ms) *ms = sc->build_ms;
    return TRACE_OK;
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
        int best = x->best_surf;
        rtcIntersect1(sc->scn, &x->ec, &r2);
        x->best_surf = best;                /* analytic hits are the true ray's already */
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
    rtcIntersect1(sc->scn, &x.ec, &rh);
    if (!float_hits && last_surf >= 0 && last_prim >= 0 &&
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
    if (!float_hits && rh.hit.geomID != RTC_INVALID_GEOMETRY_ID &&
        rh.hit.geomID != (unsigned)last_surf) {
        const tr_surf *m = sc->surf[rh.hit.geomID];
        double n[3];
        if (m->is_mesh && m->closed) {
            tri_normal(m, rh.hit.primID, n);
            if (v_dot(n, d) * m->closed > 0) closed_retry(sc, &x, &rh, m, o, d, ta);
        }
    }
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return 0;
    const tr_surf *f = sc->surf[rh.hit.geomID];
    if (!f->is_mesh) {
        h->surf = f->id;
        h->prim = -1;
        h->t = x.best_t;
        v_set(h->n, x.best_n);
        h->far = x.best_far;
        v_set(h->q, x.best_q);
        return 1;
    }
    long prim = rh.hit.primID;
    double t = float_hits ? ta + rh.ray.tfar : tri_plane_t(f, prim, o, d), n[3];
    if (!(t > 0 && isfinite(t))) t = ta + rh.ray.tfar;
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
        h->far = x.best_far;
        v_set(h->q, x.best_q);
        return 1;
    }
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
    if (sc->nembree && slab(sc->elo, sc->ehi, o, d, &ta))
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
