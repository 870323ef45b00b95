/* tr_lens.c -- sequential lenses for the trace engine: a prescription as the classic
 * dialogue enters it (radius, vertex z, index to the right) becomes analytic axial
 * surfaces (with absorbing mounts and a detector if asked), and a meridional fan is
 * traced for real against the paraxial image the caller supplies.  Uses only the
 * engine's public table (the paraxial engine is the caller's business). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "tr_int.h"

static double lens_scale(const trace_lens *l)
{
    double L = fabs(l->surf[l->nsurf - 1].z - l->surf[0].z);
    for (int i = 0; i < l->nsurf; i++) {
        double r = l->surf[i].radius;
        if (isfinite(r)) L = fmax(L, fabs(r));
        L = fmax(L, l->surf[i].semi_diameter);
    }
    return fmax(L, 1.0);
}

static int check_lens(const trace_lens *l, char *err, size_t cap)
{
    if (!l || l->nsurf < 1 || !l->surf) {
        tr_set_err(err, cap, "a lens needs at least one surface");
        return -1;
    }
    if (!(l->n_object > 0 && isfinite(l->n_object))) {
        tr_set_err(err, cap, "index left of the first surface must be positive");
        return -1;
    }
    for (int i = 0; i < l->nsurf; i++) {
        const trace_lens_surface *s = &l->surf[i];
        if (!isfinite(s->z) || isnan(s->radius) || !(s->n_right > 0 && isfinite(s->n_right))
            || !(s->semi_diameter >= 0 && isfinite(s->semi_diameter))) {
            tr_set_err(err, cap, "surface %d: bad radius, position, index or "
                       "semi-diameter", i + 1);
            return -1;
        }
        if (i && s->z < l->surf[i - 1].z) {
            tr_set_err(err, cap, "surface %d lies left of surface %d", i + 1, i);
            return -1;
        }
        if (isfinite(s->radius) && s->radius != 0 && s->semi_diameter > fabs(s->radius)) {
            tr_set_err(err, cap, "surface %d: semi-diameter %g exceeds |radius| %g",
                       i + 1, s->semi_diameter, fabs(s->radius));
            return -1;
        }
        double h, rim, edge;
        if (i && trace_lens_cross(&l->surf[i - 1], s, &h, &rim, &edge)) {
            tr_set_err(err, cap, "surfaces %d and %d cross at height %.6g: their edge "
                       "thickness at the semi-diameter %.6g is %.6g (surface %d lies left "
                       "of surface %d there)", i, i + 1, h, rim, edge, i + 1, i);
            return -1;
        }
    }
    return 0;
}

static double sphere_sag(double r, double s)
{
    if (!isfinite(r) || r == 0) return 0;
    double c = 1 / r;
    return c * s * s / (1 + sqrt(fmax(0.0, 1 - c * c * s * s)));
}

/* z range of surface i with its mount */
static void zrange(const trace_scene *sc, int lens, int mount, double *lo, double *hi)
{
    const tr_shape *a = tr_scene_shape(sc, lens);
    *lo = a->lo[2];
    *hi = a->hi[2];
    if (mount >= 0) {
        const tr_shape *b = tr_scene_shape(sc, mount);
        *lo = fmin(*lo, b->lo[2]);
        *hi = fmax(*hi, b->hi[2]);
    }
}

/* When every surface (with its mount) lies in its own z slab, in order, a ray leaving
 * surface i forward can only meet surface i or its mount, or surface i+1 or its mount
 * (or the detector after the last): tell the engine so. */
static void set_hints(trace_scene *sc, int n, const int *lid, const int *mid, int det)
{
    double lo, hi, plo, phi;
    zrange(sc, lid[0], mid[0], &plo, &phi);
    double first_lo = plo;
    for (int i = 1; i < n; i++) {
        zrange(sc, lid[i], mid[i], &lo, &hi);
        if (!(lo > phi)) return;
        phi = hi;
    }
    if (det >= 0 && !(tr_scene_shape(sc, det)->lo[2] > phi)) return;
    int e[2] = {lid[0], mid[0]};
    tr_scene_set_entry(sc, e, 2, first_lo);
    for (int i = 0; i < n; i++) {
        int c[4] = {lid[i], mid[i], i + 1 < n ? lid[i + 1] : det, i + 1 < n ? mid[i + 1] : -1};
        if (i + 1 == n && det < 0) continue;
        tr_scene_set_seq(sc, lid[i], c, 4);
    }
}

int tr_add_lens(trace_scene *sc, const trace_lens *l)
{
    const trace_api *tr = trace_get_api(TRACE_ABI);
    char err[256];
    int first = -1, id;
    if (!sc) return TRACE_EINVAL;
    if (check_lens(l, err, sizeof err)) return tr_scene_fail(sc, TRACE_EINVAL, err);
    double L = lens_scale(l);
    int alone = tr_scene_nsurf(sc) == 0, det = -1;
    int *lid = malloc((size_t)l->nsurf * 2 * sizeof(int)), *mid;
    if (!lid) return tr_scene_fail(sc, TRACE_ENOMEM, "out of memory");
    mid = lid + l->nsurf;
    for (int i = 0; i < l->nsurf; i++) {
        const trace_lens_surface *ls = &l->surf[i];
        trace_surface s;
        trace_material m = {TRACE_REFRACT, i ? l->surf[i - 1].n_right : l->n_object,
                            ls->n_right};
        memset(&s, 0, sizeof s);
        s.shape = TRACE_AXIAL;
        s.at[2] = ls->z;
        s.axis[2] = 1;
        s.radius = isfinite(ls->radius) ? ls->radius : 0;
        s.aperture = TRACE_AP_DISC;
        s.r_outer = ls->semi_diameter > 0 ? ls->semi_diameter : s.radius == 0 ? 10 * L : 0;
        if ((id = tr->add_surface(sc, &s, &m)) < 0) { free(lid); return id; }
        if (first < 0) first = id;
        lid[i] = id;
        mid[i] = -1;
        if (l->mounts && ls->semi_diameter > 0) {
            trace_surface a;
            trace_material ma = {TRACE_ABSORB, m.n_front, m.n_back};
            memset(&a, 0, sizeof a);
            a.shape = TRACE_PLANE;
            a.at[2] = ls->z + sphere_sag(s.radius, ls->semi_diameter);
            a.axis[2] = 1;
            a.aperture = TRACE_AP_DISC;
            a.r_inner = ls->semi_diameter;
            a.r_outer = fmax(4 * ls->semi_diameter, 10 * L);
            if ((id = tr->add_surface(sc, &a, &ma)) < 0) { free(lid); return id; }
            mid[i] = id;
        }
    }
    if (isfinite(l->z_detector)) {
        trace_surface d;
        double n = l->surf[l->nsurf - 1].n_right;
        trace_material md = {TRACE_DETECT, n, n};
        memset(&d, 0, sizeof d);
        d.shape = TRACE_PLANE;
        d.at[2] = l->z_detector;
        d.axis[2] = 1;
        d.aperture = TRACE_AP_DISC;
        d.r_outer = 100 * L + fabs(l->z_detector - l->surf[0].z);
        if ((id = tr->add_surface(sc, &d, &md)) < 0) { free(lid); return id; }
        det = id;
    }
    if (alone) set_hints(sc, l->nsurf, lid, mid, det);
    free(lid);
    return first;
}

typedef struct fan_ctx {
    trace_fan_ray *out;
    int *seen;
    double *y1;         /* per ray: height where it meets surface 1 (NaN: it does not) */
    int n, first;       /* rays; surface 1's id */
} fan_ctx;

static int fan_seg(void *ctx, const trace_segment *g)
{
    fan_ctx *f = ctx;
    if (g->ray < (uint64_t)f->n && g->depth == 0)
        f->y1[g->ray] = g->surface == f->first ? g->p1[1] : NAN;
    return 0;
}

static int fan_hit(void *ctx, const trace_hit *h)
{
    fan_ctx *f = ctx;
    if (h->ray >= (uint64_t)f->n) return 0;
    trace_fan_ray *o = &f->out[h->ray];
    f->seen[h->ray] = 1;
    o->status = h->history ? 2 : 0;
    o->y_image = h->pos[1];
    o->opl = h->opl;
    if (h->dir[1] == 0) {
        o->status = o->status ? o->status : 3;
        o->z_cross = NAN;
    } else {
        o->z_cross = h->pos[2] - h->pos[1] * h->dir[2] / h->dir[1];
    }
    return 0;
}

/* Where the rays of a fan start and where they go: ray i is aimed at the point of
 * surface 1 at height aim[i].  The object medium is homogeneous, so the straight line
 * from the object to that point meets surface 1 there (the engine's hit is that point
 * to rounding): the launch slope comes in closed form, no iteration.  A collimated
 * ray runs parallel to the axis at height aim[i] and starts just left of surface 1
 * and its mount (z_start), not far away: hits are solved about the ray's origin, so a
 * far start costs precision (issue 9). */
static void fan_rays(const trace_lens *l, double z_obj, double y_obj, double z_start,
                     int n, const double *aim, trace_ray *rays)
{
    const trace_lens_surface *s1 = &l->surf[0];
    for (int i = 0; i < n; i++) {
        memset(&rays[i], 0, sizeof rays[i]);
        if (isinf(z_obj)) {
            rays[i].o[1] = aim[i];
            rays[i].o[2] = z_start;
            rays[i].d[2] = 1;
        } else {
            rays[i].o[1] = y_obj;
            rays[i].o[2] = z_obj;
            rays[i].d[1] = aim[i] - y_obj;
            rays[i].d[2] = s1->z + sphere_sag(s1->radius, fabs(aim[i])) - z_obj;
        }
        rays[i].power = 1;
    }
}

/* One trace of the fan through lens l (with its detector).  TRACE_OK or an error. */
static int fan_once(const trace_api *tr, const trace_lens *l, const trace_ray *rays, int n,
                    fan_ctx *fc, char *err, size_t cap)
{
    trace_scene *sc = tr->scene_new();
    trace_source src;
    trace_options o;
    int rc;
    if (!sc) {
        tr_set_err(err, cap, "out of memory");
        return TRACE_ENOMEM;
    }
    if ((rc = tr->add_lens(sc, l)) < 0) goto fail;
    fc->first = rc;
    memset(&src, 0, sizeof src);
    src.type = TRACE_SRC_RAYS;
    src.count = n;
    src.ray = rays;
    src.n_medium = l->n_object;
    if ((rc = tr->add_source(sc, &src, NULL)) < 0) goto fail;
    tr->options_default(&o);
    o.fresnel = 0;
    o.reflections = 0;
    o.cutoff = 0;
    o.threads = 1;
    o.max_depth = 2 * l->nsurf + 4;
    for (int i = 0; i < n; i++) {
        fc->seen[i] = 0;
        fc->y1[i] = NAN;
    }
    trace_sink sink = {fc, fan_seg, fan_hit, NULL};
    if ((rc = tr->run(sc, &o, &sink, NULL)) < 0) goto fail;
    tr->scene_free(sc);
    return TRACE_OK;
fail:
    tr_set_err(err, cap, "%s", tr->error(sc));
    tr->scene_free(sc);
    return rc;
}

int tr_lens_fan(const trace_lens *lens, double z_obj, double y_obj, double z_par,
                int nrays, const double *h, trace_fan_ray *out, char *err, size_t cap)
{
    const trace_api *tr = trace_get_api(TRACE_ABI);
    trace_ray *rays = NULL;
    double *aim = NULL, *y1 = NULL;
    int *seen = NULL, rc;
    if (check_lens(lens, err, cap)) return TRACE_EINVAL;
    if (nrays < 1 || !h || !out || !isfinite(z_par) || isnan(z_obj) || !isfinite(y_obj)) {
        tr_set_err(err, cap, "a fan needs rays, heights, outputs and a paraxial image z");
        return TRACE_EINVAL;
    }
    const trace_lens_surface *s1 = &lens->surf[0];
    double z1 = s1->z;
    if (isfinite(z_obj) && z_obj >= z1) {
        tr_set_err(err, cap, "the object must lie left of the first surface");
        return TRACE_EINVAL;
    }
    for (int i = 0; i < nrays; i++)
        if (!isfinite(h[i])) {
            tr_set_err(err, cap, "ray %d: height is not a number", i + 1);
            return TRACE_EINVAL;
        }
    trace_lens l = *lens;
    l.z_detector = z_par;
    /* surface 1 and its mount reach left to z1 + its sag at the rim (< z1 if concave) */
    double r1 = isfinite(s1->radius) ? fabs(s1->radius) : 0;
    double rim = s1->semi_diameter > 0 ? s1->semi_diameter : r1;
    double z_start = z1 + fmin(0.0, sphere_sag(s1->radius, rim)) - 0.01 * fmax(rim, 1e-3);
    rays = calloc((size_t)nrays, sizeof *rays);
    seen = calloc((size_t)nrays, sizeof *seen);
    aim = calloc((size_t)nrays, sizeof *aim);
    y1 = calloc((size_t)nrays, sizeof *y1);
    if (!rays || !seen || !aim || !y1) {
        tr_set_err(err, cap, "out of memory");
        rc = TRACE_ENOMEM;
        goto done;
    }
    fan_ctx fc = {out, seen, y1, nrays, -1};
    memcpy(aim, h, (size_t)nrays * sizeof *aim);
    /* A ray aimed at the very rim may land a rounding error outside it, or leave it
     * onto its mount (which begins there): aim such rays a few units in the last place
     * further in, until they get through (at most 8 times; what still does not is
     * vignetted). */
    for (int round = 0;; round++) {
        for (int i = 0; i < nrays; i++) {
            memset(&out[i], 0, sizeof out[i]);
            out[i].h = h[i];
            out[i].status = 1;
            out[i].z_cross = out[i].lsa = out[i].y_image = out[i].opl = NAN;
        }
        fan_rays(&l, z_obj, y_obj, z_start, nrays, aim, rays);
        if ((rc = fan_once(tr, &l, rays, nrays, &fc, err, cap)) < 0) goto done;
        int again = 0;
        for (int i = 0; i < nrays && round < 8; i++)
            if (!seen[i] && rim > 0 && fabs(h[i]) >= rim * (1 - 1e-9) &&
                fabs(h[i]) <= rim) {
                aim[i] = h[i] * (1 - ldexp(1.0, 2 * round - 52));
                again = 1;
            }
        if (!again) break;
    }
    for (int i = 0; i < nrays; i++) {
        if (isnan(y1[i])) {             /* it missed surface 1: vignetted */
            out[i].status = 1;
            out[i].z_cross = out[i].lsa = out[i].y_image = out[i].opl = NAN;
            continue;
        }
        out[i].h = y1[i];
        if (!seen[i]) continue;
        out[i].lsa = out[i].z_cross - z_par;
        if (isinf(z_obj)) out[i].opl -= lens->n_object * (z1 - z_start);
    }
    rc = TRACE_OK;
done:
    free(rays);
    free(seen);
    free(aim);
    free(y1);
    return rc;
}
