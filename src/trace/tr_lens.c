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
    int n;
} fan_ctx;

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

int tr_lens_fan(const trace_lens *lens, double z_obj, double y_obj, double z_par,
                int nrays, const double *h, trace_fan_ray *out, char *err, size_t cap)
{
    const trace_api *tr = trace_get_api(TRACE_ABI);
    trace_scene *sc = NULL;
    trace_ray *rays = NULL;
    int *seen = NULL, rc;
    if (check_lens(lens, err, cap)) return TRACE_EINVAL;
    if (nrays < 1 || !h || !out || !isfinite(z_par) || isnan(z_obj) || !isfinite(y_obj)) {
        tr_set_err(err, cap, "a fan needs rays, heights, outputs and a paraxial image z");
        return TRACE_EINVAL;
    }
    double z1 = lens->surf[0].z, L = lens_scale(lens);
    if (isfinite(z_obj) && z_obj >= z1) {
        tr_set_err(err, cap, "the object must lie left of the first surface");
        return TRACE_EINVAL;
    }
    trace_lens l = *lens;
    l.z_detector = z_par;
    sc = tr->scene_new();
    rays = calloc((size_t)nrays, sizeof *rays);
    seen = calloc((size_t)nrays, sizeof *seen);
    if (!sc || !rays || !seen) {
        tr_set_err(err, cap, "out of memory");
        rc = TRACE_ENOMEM;
        goto done;
    }
    if ((rc = tr->add_lens(sc, &l)) < 0) goto scene_err;
    double z_start = z1 - 2 * L - 1;
    for (int i = 0; i < nrays; i++) {
        if (!isfinite(h[i])) {
            tr_set_err(err, cap, "ray %d: height is not a number", i + 1);
            rc = TRACE_EINVAL;
            goto done;
        }
        if (isinf(z_obj)) {
            rays[i].o[1] = h[i];
            rays[i].o[2] = z_start;
            rays[i].d[2] = 1;
        } else {
            rays[i].o[1] = y_obj;
            rays[i].o[2] = z_obj;
            rays[i].d[1] = h[i] - y_obj;
            rays[i].d[2] = z1 - z_obj;
        }
        rays[i].power = 1;
        memset(&out[i], 0, sizeof out[i]);
        out[i].h = h[i];
        out[i].status = 1;
        out[i].z_cross = out[i].lsa = out[i].y_image = out[i].opl = NAN;
    }
    trace_source src;
    memset(&src, 0, sizeof src);
    src.type = TRACE_SRC_RAYS;
    src.count = nrays;
    src.ray = rays;
    src.n_medium = lens->n_object;
    if ((rc = tr->add_source(sc, &src, NULL)) < 0) goto scene_err;
    trace_options o;
    tr->options_default(&o);
    o.fresnel = 0;
    o.reflections = 0;
    o.cutoff = 0;
    o.threads = 1;
    o.max_depth = 2 * l.nsurf + 4;
    fan_ctx fc = {out, seen, nrays};
    trace_sink sink = {&fc, NULL, fan_hit, NULL};
    if ((rc = tr->run(sc, &o, &sink, NULL)) < 0) goto scene_err;
    for (int i = 0; i < nrays; i++) {
        if (!seen[i]) continue;
        out[i].lsa = out[i].z_cross - z_par;
        if (isinf(z_obj)) out[i].opl -= lens->n_object * (z1 - z_start);
    }
    rc = TRACE_OK;
    goto done;
scene_err:
    tr_set_err(err, cap, "%s", tr->error(sc));
done:
    tr->scene_free(sc);
    free(rays);
    free(seen);
    return rc;
}
