/* tr_scene.c -- the trace engine's scene on Embree 3.  Owns: surfaces (analytic ones
 * as Embree user geometry, meshes as robust triangle geometry with double copies of
 * their vertices, closed meshes recognised), sources, the Embree device (created on
 * the first build, never before) in a frame centred on what it holds, the surfaces
 * kept out of its range, groups of coincident surfaces, and the lens hints.  Which
 * surface a ray meets next is tr_hit.c's. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include "tr_eng.h"

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
            tr_pk_set_add(&sc->entry_pk, cand[i], &f->shape, &f->mat, 0, NULL);
        }
    sc->entry_z = z;
    sc->entry_zmin = -INFINITY;
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
            tr_pk_set_add(&f->pk, cand[i], &c->shape, &c->mat, cand[i] == id,
                          &f->shape);
        }
    sc->seq_nsurf = sc->nsurf;
}

/* ---------------- scene ---------------- */

trace_scene *tr_scene_new(void)
{
    trace_scene *sc = calloc(1, sizeof(trace_scene));
    if (sc) sc->entry_zmin = -INFINITY;
    return sc;
}

static void source_box(const tr_source *ts, double lo[3], double hi[3]);
static int box_inside(const double lo[3], const double hi[3], const double *blo,
                      const double *bhi);
static int in_range(const tr_surf *f);

static void drop_embree(trace_scene *sc)
{
    if (sc->scn) rtcReleaseScene(sc->scn);
    if (sc->dev) rtcReleaseDevice(sc->dev);
    sc->scn = NULL;
    sc->dev = NULL;
    sc->built = 0;
    free(sc->far);
    sc->far = NULL;
    sc->nfar = sc->nembree = sc->ninline = 0;
    free(sc->ch_surf);
    sc->ch_surf = NULL;
    sc->nch = 0;
}

void tr_scene_free(trace_scene *sc)
{
    if (!sc) return;
    drop_embree(sc);
    for (int i = 0; i < sc->nsurf; i++) {
        if (!sc->surf[i]->shared) {
            free(sc->surf[i]->vtx);
            free(sc->surf[i]->idx);
        }
        free(sc->surf[i]->media);
        free(sc->surf[i]->weld);
        free(sc->surf[i]->vt_start);
        free(sc->surf[i]->vt_tri);
        free(sc->surf[i]->perm);
        free(sc->surf[i]);
    }
    free(sc->surf);
    for (int i = 0; i < sc->nsrc; i++) tr_source_free(&sc->src[i]);
    free(sc->src);
    tr_polar_free(sc->polar);
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

int tr_set_absorption(trace_scene *sc, int id, double af, double ab)
{
    if (!sc) return TRACE_EINVAL;
    if (id < 0 || id >= sc->nsurf) return fail(sc, TRACE_EINVAL, "no such surface");
    if (!(af >= 0 && isfinite(af) && ab >= 0 && isfinite(ab)))
        return fail(sc, TRACE_EINVAL, "absorption coefficients must be numbers >= 0");
    sc->surf[id]->alpha_front = af;
    sc->surf[id]->alpha_back = ab;
    if (af > 0 || ab > 0) sc->absorbing = 1;
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
 * inward, 0: not closed.  The welding is left in weld[nv] (for the adjacency);
 * -2: out of memory. */
static int mesh_closed(const tr_surf *f, uint32_t *weld)
{
    size_t nv = (size_t)f->nv, cap = 16, ne = (size_t)f->ntri * 3, ecap = 16;
    while (cap < 2 * nv) cap *= 2;
    while (ecap < 2 * ne) ecap *= 2;
    long *slot = malloc(cap * sizeof *slot);
    uint64_t *edge = malloc(ecap * sizeof *edge);
    int closed = 0;
    if (!slot || !edge) { closed = -2; goto out; }
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
    free(slot);
    slot = NULL;
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
    f->shared = mesh->shared && mesh->index;   /* the caller's arrays, in place */
    f->vtx = f->shared ? (double *)mesh->vertex : malloc((size_t)nv * 3 * sizeof(double));
    f->idx = f->shared ? (uint32_t *)mesh->index
                       : malloc((size_t)f->ntri * 3 * sizeof(uint32_t));
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
        if (!f->shared) f->vtx[i] = x;
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
        if (!f->shared) f->idx[i] = k;
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
    uint32_t *weld = malloc((size_t)nv * sizeof *weld);
    f->closed = weld ? mesh_closed(f, weld) : -2;
    f->weld = weld;                 /* the adjacency follows Embree's build (tr_build) */
    if (f->closed == -2) {
        rc = fail(sc, TRACE_ENOMEM, "out of memory for the mesh");
        goto bad;
    }
    sc->nclosed += f->closed != 0;
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
    if (!f->shared) {
        free(f->vtx);
        free(f->idx);
    }
    free(f->media);
    free(f->weld);
    free(f->vt_start);
    free(f->vt_tri);
    free(f->perm);
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
    if (ts->s.alpha_medium > 0) sc->absorbing = 1;
    if (sc->built) {   /* rays from outside the start box the meshes' margins assumed */
        double lo[3], hi[3];
        source_box(ts, lo, hi);
        if (!sc->sglobal && !box_inside(lo, hi, sc->slo, sc->shi)) drop_embree(sc);
    }
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

static int attach_user(trace_scene *sc, tr_surf *f)
{
    RTCGeometry g = rtcNewGeometry(sc->dev, RTC_GEOMETRY_TYPE_USER);
    if (!g) return -1;
    rtcSetGeometryUserPrimitiveCount(g, 1);
    rtcSetGeometryUserData(g, f);
    rtcSetGeometryBoundsFunction(g, user_bounds, NULL);
    rtcSetGeometryIntersectFunction(g, tr_user_intersect);
    rtcSetGeometryOccludedFunction(g, tr_user_occluded);
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

/* The box of the points source s's rays start from (conservative). */
static void source_box(const tr_source *ts, double lo[3], double hi[3])
{
    const trace_source *s = &ts->s;
    double r = s->type == TRACE_SRC_GRID ? s->radius :
               s->type == TRACE_SRC_GAUSSIAN ? ts->s.trunc * s->waist : 0;
    for (int j = 0; j < 3; j++) { lo[j] = s->at[j] - r; hi[j] = s->at[j] + r; }
    if (s->type == TRACE_SRC_RAYS)
        for (long i = 0; i < ts->nrays; i++)
            for (int j = 0; j < 3; j++) {
                lo[j] = fmin(lo[j], ts->rays[i].o[j]);
                hi[j] = fmax(hi[j], ts->rays[i].o[j]);
            }
}

static int box_inside(const double lo[3], const double hi[3], const double *blo,
                      const double *bhi)
{
    for (int j = 0; j < 3; j++)
        if (!(lo[j] >= blo[j] && hi[j] <= bhi[j])) return 0;
    return 1;
}

/* Where rays may start (sc->slo/shi): every source's origins and every surface that
 * passes rays on; a ray ends on a detector or an absorber and never starts there.
 * Anything of that outside the box that hands Embree its own origins (a far surface,
 * a far source) makes it the whole of that box (sglobal). */
static void start_box(trace_scene *sc)
{
    sc->sglobal = 0;
    for (int j = 0; j < 3; j++) { sc->slo[j] = INFINITY; sc->shi[j] = -INFINITY; }
    for (int i = 0; i < sc->nsurf; i++) {
        const tr_surf *f = sc->surf[i];
        if (f->mat.kind == TRACE_DETECT || f->mat.kind == TRACE_ABSORB) continue;
        if (!in_range(f)) { sc->sglobal = 1; continue; }
        for (int j = 0; j < 3; j++) {
            if (f->is_mesh) {
                for (long v = 0; v < f->nv; v++) {
                    sc->slo[j] = fmin(sc->slo[j], f->vtx[3 * v + j]);
                    sc->shi[j] = fmax(sc->shi[j], f->vtx[3 * v + j]);
                }
            } else {
                sc->slo[j] = fmin(sc->slo[j], f->shape.lo[j]);
                sc->shi[j] = fmax(sc->shi[j], f->shape.hi[j]);
            }
        }
    }
    for (int i = 0; i < sc->nsrc; i++) {
        double lo[3], hi[3];
        source_box(&sc->src[i], lo, hi);
        if (!box_inside(lo, hi, sc->nlo, sc->nhi)) sc->sglobal = 1;
        for (int j = 0; j < 3; j++) {
            sc->slo[j] = fmin(sc->slo[j], lo[j]);
            sc->shi[j] = fmax(sc->shi[j], hi[j]);
        }
    }
}

/* A mesh's margin: how far a float ray may stray from the double one where it meets
 * that mesh.  As epad (embree_box), with the distance a ray travels to it bounded by
 * the diagonal of the mesh's box and where rays start (never more than epad's), and
 * the coordinates that round (a ray's float origin, the mesh's float vertices, in
 * Embree's frame) bounded by that same box's largest, not by all Embree holds: a
 * detector plane far from a small mesh no longer widens the mesh's margin, so fewer
 * hits need the double-precision test of the triangles around them (tr_wt_ring). */
static double mesh_pad(const trace_scene *sc, const tr_surf *f)
{
    double lo[3], hi[3], d[3], m = 0;
    if (sc->sglobal) return sc->epad;
    for (int j = 0; j < 3; j++) { lo[j] = sc->slo[j]; hi[j] = sc->shi[j]; }
    for (long v = 0; v < f->nv; v++)
        for (int j = 0; j < 3; j++) {
            lo[j] = fmin(lo[j], f->vtx[3 * v + j]);
            hi[j] = fmax(hi[j], f->vtx[3 * v + j]);
        }
    for (int j = 0; j < 3; j++) {
        d[j] = hi[j] - lo[j];
        m = fmax(m, fmax(fabs(lo[j] - sc->eoff[j]), fabs(hi[j] - sc->eoff[j])));
    }
    /* a ray starts in that box (not sglobal: in the box where Embree's ray starts at
     * its own origin, tr_hit.c) and goes at most its diagonal to the mesh: one
     * diagonal, not epad's three */
    double p = 8 * FLT_EPSILON * (fmin(m, sc->emag) + v_norm(d)) + 1e-300;
    return p < sc->epad ? p : sc->epad;
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
 * direction to half an ulp of each component, over at most three times the box's
 * diagonal D (a ray starting within D of the box starts there, see tr_hit.c).
 * Every analytic surface's box grows by eight times that (a ray that meets the surface
 * in double is always offered to it); the box itself by as much again.  centre: the
 * frame's origin, if not the box's centre (mesh_frame). */
static void embree_box(trace_scene *sc, const double *centre)
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
        sc->eoff[j] = centre ? centre[j] : lo[j] / 2 + hi[j] / 2;
        m = fmax(m, fmax(fabs(lo[j] - sc->eoff[j]), fabs(hi[j] - sc->eoff[j])));
        d[j] = hi[j] - lo[j];
    }
    double diag = v_norm(d);
    sc->epad = 8 * FLT_EPSILON * (m + 3 * diag) + 1e-300;
    sc->emag = m;
    for (int j = 0; j < 3; j++) {
        sc->elo[j] = lo[j] - 2 * sc->epad;
        sc->ehi[j] = hi[j] + 2 * sc->epad;
        sc->nlo[j] = sc->elo[j] - diag;
        sc->nhi[j] = sc->ehi[j] + diag;
    }
}

/* Embree's frame centred on the meshes and where rays start, when those are all
 * the rays' starts (not sglobal): what rounds to float where rays meet a mesh (the
 * ray's origin, the mesh's vertices) is then as small as the meshes' own
 * neighbourhood allows, not half of all Embree holds (a detector plane far away),
 * and so is each mesh's margin (mesh_pad); the analytic surfaces' boxes take the
 * larger epad that follows (their hits are solved in double either way). */
static void mesh_frame(trace_scene *sc)
{
    double lo[3], hi[3], c[3];
    int any = 0;
    if (sc->sglobal) return;
    for (int j = 0; j < 3; j++) { lo[j] = sc->slo[j]; hi[j] = sc->shi[j]; }
    for (int i = 0; i < sc->nsurf; i++) {
        const tr_surf *f = sc->surf[i];
        if (!f->is_mesh) continue;
        any = 1;
        for (long v = 0; v < f->nv; v++)
            for (int j = 0; j < 3; j++) {
                lo[j] = fmin(lo[j], f->vtx[3 * v + j]);
                hi[j] = fmax(hi[j], f->vtx[3 * v + j]);
            }
    }
    if (!any) return;
    for (int j = 0; j < 3; j++) c[j] = lo[j] / 2 + hi[j] / 2;
    embree_box(sc, c);       /* the boxes only grow: start_box's answer stands */
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
    embree_box(sc, NULL);
    start_box(sc);
    mesh_frame(sc);
    /* LENSMAT_TRACE_EXACT=1: every mesh hit decided by the double-precision test of
     * the triangles around it, no float margin trusted -- to check the margins change
     * no bit (tests/t_64_mesh.sh) */
    const char *ex = getenv("LENSMAT_TRACE_EXACT");
    sc->wt_all = ex && *ex && strcmp(ex, "0") != 0;
    /* LENSMAT_TRACE_CHUNK=N: meshes of more than N triangles in chunks of N (0: one
     * BVH each), to test the chunks on small meshes (tests/t_64_mesh.sh) */
    const char *ch = getenv("LENSMAT_TRACE_CHUNK");
    sc->chunk = ch && *ch ? atol(ch) : TR_CHUNK_TRI;
    sc->ch_base = sc->nsurf;
    group_coincident(sc);
    if (sc->seq_nsurf != sc->nsurf && !sc->ngroup) tr_seq_detect(sc);
    /* a mesh scene's few analytic surfaces go before Embree (TR_INLINE_MAX) */
    int nmesh = 0, nan = 0;
    for (int i = 0; i < sc->nsurf; i++) {
        if (sc->surf[i]->is_mesh) nmesh++;
        else if (in_range(sc->surf[i])) nan++;
    }
    int inl = nmesh > 0 && nan <= TR_INLINE_MAX && !sc->ngroup;
    sc->ninline = 0;
    for (int i = 0; i < sc->nsurf; i++) {
        tr_surf *f = sc->surf[i];
        if (!f->is_mesh && !in_range(f)) { sc->far[sc->nfar++] = i; continue; }
        f->pad = f->is_mesh ? mesh_pad(sc, f) : sc->epad;
        f->eoff = sc->eoff;
        if (!f->is_mesh && inl) { sc->inl[sc->ninline++] = i; continue; }
        sc->nembree++;
        int rc = f->is_mesh ? tr_mesh_attach(sc, f) : attach_user(sc, f);
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
    /* the meshes' adjacency for the double-precision edge test, after Embree's build
     * and its temporaries (the peak): 14 bytes a triangle less at the peak */
    for (int i = 0; i < sc->nsurf; i++)
        if (sc->surf[i]->is_mesh && !sc->surf[i]->vt_tri && tr_wt_adjacency(sc->surf[i])) {
            drop_embree(sc);
            return fail(sc, TRACE_ENOMEM, "out of memory for the mesh");
        }
    sc->built = 1;
    sc->build_ms = tr_now_ms() - t0;
    if (ms) *ms = sc->build_ms;
    return TRACE_OK;
}

