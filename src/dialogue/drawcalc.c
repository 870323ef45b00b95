/* drawcalc.c -- the content of the lens pictures (see drawcalc.h): cardinal points
 * and images from the paraxial engine; meridional fans, hexapolar bundles and
 * their hits at the paraxial image plane traced for real by the trace engine
 * (geometry only: no Fresnel split, no reflections, mounts absorbing outside each
 * semi-diameter); then one call into the imaging engine. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "drawcalc.h"
#include "../paraxial/paraxial.h"
#include "../trace/scene.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define FAN_RAYS 9          /* rays of a layout fan per object point */
#define SPOT_RINGS 16       /* hexapolar rings of a spot bundle: 817 rays per field */
#define PLOT_RAYS 61        /* rays of a ray-fan plot per field */

static void set_err(char *err, size_t cap, const char *fmt, const char *arg)
{
    if (err && cap) snprintf(err, cap, fmt, arg);
}

void dw_first_order(const dw_scene *s, dw_first *out)
{
    const trace_lens *l = s->lens;
    px_system sys;
    px_first f;
    px_conj c;
    out->z_f1 = out->z_f2 = out->z_h1 = out->z_h2 = out->z_n1 = out->z_n2 = NAN;
    out->z_img = out->y_img = NAN;
    out->afocal = 0;
    out->image_virtual = 0;
    px_system_init(&sys, l->n_object);
    for (int i = 0; i < l->nsurf; i++) {
        px_system_translate(&sys, l->surf[i].z);
        px_system_refract(&sys, l->surf[i].radius, l->surf[i].n_right);
    }
    if (px_first_order(&sys, &f) != PX_OK || f.afocal) {
        out->afocal = 1;
    } else {
        out->z_f1 = f.z_f1.v; out->z_f2 = f.z_f2.v;
        out->z_h1 = f.z_h1.v; out->z_h2 = f.z_h2.v;
        out->z_n1 = f.z_n1.v; out->z_n2 = f.z_n2.v;
        if (isinf(s->z_obj)) {   /* the object above the axis: rays come down at s->field */
            out->z_img = f.z_f2.v;
            out->y_img = -f.f_back.v * tan(s->field);
        } else if (px_conjugate(&sys, s->z_obj, &c) == PX_OK && !c.at_infinity) {
            out->z_img = c.z_img.v;
            out->y_img = c.lateral.v * s->field;
        }
        out->image_virtual = isfinite(out->z_img) && out->z_img <= sys.z_last;
    }
    px_system_free(&sys);
}

/* The size of the lens (its length or its diameter), for margins. */
static double lens_size(const trace_lens *l)
{
    double d = 0;
    for (int i = 0; i < l->nsurf; i++) d = fmax(d, 2 * l->surf[i].semi_diameter);
    return fmax(d, l->surf[l->nsurf - 1].z - l->surf[0].z);
}

/* A ray from the object point (field f: index into the scene's object points: 0 on
 * the axis, 1 at s->field) through (x, y) in the first vertex plane. */
static void aim(const dw_scene *s, int f, double x, double y, double z_start, trace_ray *r)
{
    double z1 = s->lens->surf[0].z, fld = f ? s->field : 0;
    memset(r, 0, sizeof *r);
    r->power = 1;
    if (isinf(s->z_obj)) {        /* parallel rays coming down at angle fld */
        r->d[1] = -sin(fld); r->d[2] = cos(fld);
        r->o[0] = x; r->o[1] = y + tan(fld) * (z1 - z_start); r->o[2] = z_start;
    } else {
        r->o[1] = fld; r->o[2] = s->z_obj;
        double dx = x, dy = y - fld, dz = z1 - s->z_obj, n = sqrt(dx * dx + dy * dy + dz * dz);
        r->d[0] = dx / n; r->d[1] = dy / n; r->d[2] = dz / n;
    }
}

/* Collected from the trace sinks. */
typedef struct collect {
    long nray;
    double *zy;        /* per ray: up to MAXPT points (z, y) */
    int *npt;
    int *end;          /* per ray: how its last segment ended (enum trace_end) */
    trace_hit *hit;    /* per ray: its hit (ray < 0: none) */
    int *has_hit;
} collect;
#define MAXPT 40

static int on_segment(void *ctx, const trace_segment *sg)
{
    collect *c = ctx;
    long r = (long)sg->ray;
    if (r < 0 || r >= c->nray || sg->depth >= MAXPT - 1) return 0;
    double *p = c->zy + (size_t)r * 2 * MAXPT;
    c->end[r] = sg->end;
    if (c->npt[r] == 0) { p[0] = sg->p0[2]; p[1] = sg->p0[1]; c->npt[r] = 1; }
    if (c->npt[r] < MAXPT) {
        p[2 * c->npt[r]] = sg->p1[2]; p[2 * c->npt[r] + 1] = sg->p1[1];
        c->npt[r]++;
    }
    return 0;
}

static int on_hit(void *ctx, const trace_hit *h)
{
    collect *c = ctx;
    long r = (long)h->ray;
    if (r >= 0 && r < c->nray) { c->hit[r] = *h; c->has_hit[r] = 1; }
    return 0;
}

/* Trace rays through the lens with a detector at z_det (NaN: none; escaping rays
 * drawn escape long).  0, or -1 with err set; c filled (free with collect_free). */
static int run(const trace_api *tr, const trace_lens *lens, double z_det, double escape,
               const trace_ray *rays, long n, int segments, collect *c, char *err, size_t cap)
{
    trace_lens l = *lens;
    trace_source src;
    trace_options o;
    trace_sink sink = {c, segments ? on_segment : NULL, on_hit, NULL};
    trace_scene *sc;
    int rc = -1;

    memset(c, 0, sizeof *c);
    c->nray = n;
    c->npt = calloc((size_t)n, sizeof *c->npt);
    c->hit = calloc((size_t)n, sizeof *c->hit);
    c->has_hit = calloc((size_t)n, sizeof *c->has_hit);
    c->end = calloc((size_t)n, sizeof *c->end);
    if (segments) c->zy = calloc((size_t)n * 2 * MAXPT, sizeof *c->zy);
    if (!c->npt || !c->hit || !c->has_hit || !c->end || (segments && !c->zy)) {
        set_err(err, cap, "%s", "out of memory");
        return -1;
    }
    if (!(sc = tr->scene_new())) { set_err(err, cap, "%s", "out of memory"); return -1; }
    l.mounts = 1;
    l.z_detector = z_det;
    memset(&src, 0, sizeof src);
    src.type = TRACE_SRC_RAYS;
    src.count = n;
    src.ray = rays;
    src.n_medium = lens->n_object;
    tr->options_default(&o);
    o.fresnel = 0;
    o.reflections = 0;
    o.threads = 1;
    o.escape_length = escape;
    if (tr->add_lens(sc, &l) < 0 || tr->add_source(sc, &src, NULL) != TRACE_OK ||
        tr->run(sc, &o, &sink, NULL) != TRACE_OK)
        set_err(err, cap, "the trace failed: %s", tr->error(sc));
    else
        rc = 0;
    tr->scene_free(sc);
    return rc;
}

static void collect_free(collect *c)
{
    free(c->zy); free(c->npt); free(c->hit); free(c->has_hit); free(c->end);
    memset(c, 0, sizeof *c);
}

static int nfields(const dw_scene *s) { return s->field != 0 ? 2 : 1; }

static int need_image(const dw_first *f, char *err, size_t cap)
{
    if (f->afocal) { set_err(err, cap, "%s", "the system is afocal: it has no image plane"); return -1; }
    if (!isfinite(f->z_img)) { set_err(err, cap, "%s", "the image is at infinity"); return -1; }
    if (f->image_virtual) { set_err(err, cap, "%s", "the image is virtual: there is no real image plane to put a detector in"); return -1; }
    return 0;
}

int dw_layout(const trace_api *tr, const imaging_api *im, const dw_scene *s,
              const char *title, const im_out *out, im_layout_info *info,
              char *err, size_t cap)
{
    const trace_lens *l = s->lens;
    dw_first f;
    double size = lens_size(l), z_start = l->surf[0].z - 0.25 * size;
    int nf = nfields(s);
    long n = (long)nf * FAN_RAYS, nir = 0;
    trace_ray *rays = calloc((size_t)n, sizeof *rays);
    im_surface *surf = calloc((size_t)l->nsurf, sizeof *surf);
    im_ray *ir = calloc((size_t)(2 * n), sizeof *ir);
    double *back = calloc((size_t)(4 * n), sizeof *back);   /* virtual continuations */
    collect c = {0};
    int rc = -1;

    if (!rays || !surf || !ir || !back) { set_err(err, cap, "%s", "out of memory"); goto out; }
    dw_first_order(s, &f);
    for (int k = 0; k < nf; k++)
        for (int i = 0; i < FAN_RAYS; i++)
            aim(s, k, 0, s->frac * l->surf[0].semi_diameter * (-1 + 2.0 * i / (FAN_RAYS - 1)),
                z_start, &rays[k * FAN_RAYS + i]);
    /* rays end at a real image; otherwise they leave the lens for half its size
     * beyond the image, or beyond the lens */
    double z_last = l->surf[l->nsurf - 1].z, esc = size;
    if (isfinite(f.z_img) && !f.image_virtual) esc = 0;
    else if (isfinite(f.z_img)) esc = fmax(size, fabs(z_last - f.z_img));
    if (run(tr, l, esc == 0 ? f.z_img : NAN, esc > 0 ? esc : 1, rays, n, 1, &c, err, cap))
        goto out;
    for (long i = 0; i < n; i++) {
        ir[nir].zy = c.zy + (size_t)i * 2 * MAXPT;
        ir[nir].n = c.npt[i];
        ir[nir++].group = (int)(i / FAN_RAYS);
    }
    /* a virtual image: each ray that leaves the lens, continued back to the image
     * plane, dashed (as the document's Figure 5) */
    for (long i = 0; i < n && f.image_virtual; i++) {
        const double *p = c.zy + (size_t)i * 2 * MAXPT;
        int k = c.npt[i];
        if (k != l->nsurf + 2 || c.end[i] != TRACE_END_ESCAPE) continue;   /* through every surface */
        double z0 = p[2 * (k - 2)], y0 = p[2 * (k - 2) + 1];
        double dz = p[2 * (k - 1)] - z0, dy = p[2 * (k - 1) + 1] - y0;
        if (!(dz > 0)) continue;
        double *b = back + 4 * i, yb = y0 + dy * (f.z_img - z0) / dz;
        /* only the rays that come back near their image point (the aberrated
         * margin would hide the picture) */
        double y_want = i < FAN_RAYS ? 0 : f.y_img;
        if (!(fabs(yb - y_want) <= 0.1 * size)) continue;
        b[0] = z0; b[1] = y0; b[2] = f.z_img; b[3] = yb;
        ir[nir].zy = b;
        ir[nir].n = 2;
        ir[nir].group = (int)(i / FAN_RAYS);
        ir[nir++].dashed = 1;
    }
    for (int i = 0; i < l->nsurf; i++) {
        surf[i].z = l->surf[i].z;
        surf[i].radius = l->surf[i].radius;
        surf[i].semi = l->surf[i].semi_diameter;
        surf[i].n_right = l->surf[i].n_right;
    }
    im_layout L = {title, s->unit, l->n_object, l->nsurf, surf, (int)nir, ir,
                   f.z_f1, f.z_f2, f.z_h1, f.z_h2, f.z_n1, f.z_n2,
                   isinf(s->z_obj) ? NAN : s->z_obj, s->field,
                   f.z_img, f.y_img, f.image_virtual};
    if (!isinf(s->z_obj) && s->field == 0 && isfinite(f.z_img)) {
        /* an on-axis point: the object drawn as an arrow of half the first
         * semi-diameter, with its paraxial image */
        dw_scene t = *s;
        dw_first g;
        t.field = L.y_obj = 0.5 * l->surf[0].semi_diameter;
        dw_first_order(&t, &g);
        L.y_img = g.y_img;
    }
    if (isinf(s->z_obj) && s->field == 0) L.z_img = NAN;   /* a point image: F2 says it */
    rc = im->draw->layout(&L, out, info, err, cap) ? -1 : 0;
out:
    collect_free(&c);
    free(rays); free(surf); free(ir); free(back);
    return rc;
}

/* Hexapolar bundle of each field, hits in the paraxial image plane of the axis. */
int dw_spot(const trace_api *tr, const imaging_api *im, const dw_scene *s,
            const char *title, const im_out *out, im_sd_info *info, double *airy,
            char *err, size_t cap)
{
    const trace_lens *l = s->lens;
    dw_first f;
    int nf = nfields(s);
    long per = 1 + 3L * SPOT_RINGS * (SPOT_RINGS + 1), n = nf * per, k = 0, m = 0;
    trace_ray *rays = calloc((size_t)n, sizeof *rays);
    im_sd_point *pt = calloc((size_t)n, sizeof *pt);
    collect c = {0};
    double h = s->frac * l->surf[0].semi_diameter, best = -1, sinu = 0;
    char names[2][64];
    const char *nm[2] = {names[0], names[1]};
    int rc = -1;

    *airy = 0;
    if (!rays || !pt) { set_err(err, cap, "%s", "out of memory"); goto out; }
    dw_first_order(s, &f);
    if (need_image(&f, err, cap)) goto out;
    for (int g = 0; g < nf; g++) {
        aim(s, g, 0, 0, l->surf[0].z - 1, &rays[k++]);
        for (int r = 1; r <= SPOT_RINGS; r++)
            for (int j = 0; j < 6 * r; j++) {
                double a = 2 * M_PI * j / (6 * r), rho = h * r / SPOT_RINGS;
                aim(s, g, rho * sin(a), rho * cos(a), l->surf[0].z - 1, &rays[k++]);
            }
    }
    if (run(tr, l, f.z_img, 1, rays, n, 0, &c, err, cap)) goto out;
    for (long i = 0; i < n; i++) {
        if (!c.has_hit[i]) continue;
        pt[m].x = c.hit[i].pos[0]; pt[m].y = c.hit[i].pos[1]; pt[m].group = (int)(i / per);
        m++;
        /* the on-axis bundle's outermost ring reaching the image gives the
         * image-side aperture */
        if (i < per) {
            int ring = 0;
            while (ring < SPOT_RINGS && i >= 1 + 3L * ring * (ring + 1)) ring++;
            if (ring > best) {
                double *d = c.hit[i].dir;
                best = ring;
                sinu = sqrt(d[0] * d[0] + d[1] * d[1]) / sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            }
        }
    }
    if (!m) { set_err(err, cap, "%s", "no ray reaches the image plane (all vignetted)"); goto out; }
    if (s->wavelength > 0 && sinu > 0)
        *airy = 0.61 * s->wavelength / (l->surf[l->nsurf - 1].n_right * sinu);
    snprintf(names[0], sizeof names[0], "on the axis");
    if (isinf(s->z_obj)) snprintf(names[1], sizeof names[1], "field %.4g deg", s->field * 180 / M_PI);
    else snprintf(names[1], sizeof names[1], "object height %.4g", s->field);
    im_spotdiag S = {title, s->unit, (int)m, pt, nf, nm, 1, *airy};
    rc = im->draw->spot(&S, out, info, err, cap) ? -1 : 0;
out:
    collect_free(&c);
    free(rays); free(pt);
    return rc;
}

/* Transverse aberration against relative height at the first surface, per field,
 * about the ray through the first vertex. */
int dw_fan(const trace_api *tr, const imaging_api *im, const dw_scene *s,
           const char *title, const im_out *out, im_plot_info *info,
           char *err, size_t cap)
{
    const trace_lens *l = s->lens;
    dw_first f;
    int nf = nfields(s);
    long n = (long)nf * PLOT_RAYS;
    trace_ray *rays = calloc((size_t)n, sizeof *rays);
    double *x = calloc((size_t)n, sizeof *x), *y = calloc((size_t)n, sizeof *y);
    collect c = {0};
    char names[2][64], ylab[96];
    im_series ser[2];
    int rc = -1;

    if (!rays || !x || !y) { set_err(err, cap, "%s", "out of memory"); goto out; }
    dw_first_order(s, &f);
    if (need_image(&f, err, cap)) goto out;
    for (int g = 0; g < nf; g++)
        for (int i = 0; i < PLOT_RAYS; i++) {
            double p = -1 + 2.0 * i / (PLOT_RAYS - 1);
            x[g * PLOT_RAYS + i] = p;
            aim(s, g, 0, p * s->frac * l->surf[0].semi_diameter, l->surf[0].z - 1,
                &rays[g * PLOT_RAYS + i]);
        }
    if (run(tr, l, f.z_img, 1, rays, n, 0, &c, err, cap)) goto out;
    for (int g = 0; g < nf; g++) {
        long ref = g * PLOT_RAYS + PLOT_RAYS / 2;
        for (int i = 0; i < PLOT_RAYS; i++) {
            long r = g * PLOT_RAYS + i;
            y[r] = c.has_hit[r] && c.has_hit[ref] ? c.hit[r].pos[1] - c.hit[ref].pos[1] : NAN;
        }
        ser[g].name = names[g];
        ser[g].n = PLOT_RAYS;
        ser[g].x = x + g * PLOT_RAYS;
        ser[g].y = y + g * PLOT_RAYS;
        ser[g].style = IM_LINES | IM_MARKERS;
    }
    snprintf(names[0], sizeof names[0], "on the axis");
    if (isinf(s->z_obj)) snprintf(names[1], sizeof names[1], "field %.4g deg", s->field * 180 / M_PI);
    else snprintf(names[1], sizeof names[1], "object height %.4g", s->field);
    snprintf(ylab, sizeof ylab, "transverse aberration at the image plane (%s)",
             s->unit ? s->unit : "units");
    im_plot P = {title, "relative ray height at surface 1", ylab, 0, 0, 1, nf, ser,
                 "about the ray through the first vertex; gaps: vignetted rays"};
    rc = im->draw->plot(&P, out, info, err, cap) ? -1 : 0;
out:
    collect_free(&c);
    free(rays); free(x); free(y);
    return rc;
}

int dw_table(const scene_api *sa, const imaging_api *im, const dw_scene *s, long grid,
             const char *title, const im_out *out, sc_tess_row *rows, char *err, size_t cap)
{
    static const int levels[DW_TESS_LEVELS] = {4, 8, 16, 32, 64, 128};
    static const char *const names[3] = {"mesh: flat triangles", "mesh + analytic normals",
                                         "mesh + re-intersection"};
    const trace_lens *l = s->lens;
    sc_tess_spec sp;
    px_system sys;
    px_cardinal k;
    double x[3][DW_TESS_LEVELS], y[3][DW_TESS_LEVELS];
    im_series ser[3];
    char note[160];

    if (l->nsurf < 2 || fabs(l->surf[0].n_right - l->n_object) < 1e-12) {
        set_err(err, cap, "%s", "the lens has no first element (glass between surfaces 1 and 2)");
        return -1;
    }
    memset(&sp, 0, sizeof sp);
    sp.r1 = isfinite(l->surf[0].radius) ? l->surf[0].radius : 0;
    sp.r2 = isfinite(l->surf[1].radius) ? l->surf[1].radius : 0;
    sp.thickness = l->surf[1].z - l->surf[0].z;
    sp.n = l->surf[0].n_right;
    sp.aperture = fmin(l->surf[0].semi_diameter, l->surf[1].semi_diameter);
    if (!(sp.thickness > 0)) { set_err(err, cap, "%s", "the first element has no thickness"); return -1; }
    /* the element alone in air, its paraxial focus the detector (as --trace's table) */
    px_system_init(&sys, 1);
    px_system_translate(&sys, 0);
    px_system_refract(&sys, l->surf[0].radius, sp.n);
    px_system_translate(&sys, sp.thickness);
    px_system_refract(&sys, l->surf[1].radius, 1);
    if (px_is_afocal(&sys)) {
        px_system_free(&sys);
        set_err(err, cap, "%s", "the first element is afocal");
        return -1;
    }
    px_cardinal_points(&sys, 0, &k);
    px_system_free(&sys);
    if (!(k.focal2 > sp.thickness)) {
        set_err(err, cap, "%s", "the first element does not focus a parallel beam behind itself");
        return -1;
    }
    sp.z_detector = k.focal2;
    sp.beam_radius = 0.9 * sp.aperture;
    sp.grid = grid;
    sp.levels = levels;
    sp.nlevels = DW_TESS_LEVELS;
    if (sa->tess_table(&sp, rows, err)) return -1;
    for (int m = 0; m < 3; m++) {
        for (int i = 0; i < DW_TESS_LEVELS; i++) {
            const sc_tess_row *r = &rows[1 + i * 3 + m];
            x[m][i] = r->trace_ms;
            y[m][i] = r->err_rms;
        }
        ser[m].name = names[m];
        ser[m].n = DW_TESS_LEVELS;
        ser[m].x = x[m];
        ser[m].y = y[m];
        ser[m].style = IM_LINES | IM_MARKERS;
    }
    snprintf(note, sizeof note, "levels 4, 8, ..., 128 per model; the analytic "
             "surfaces (the reference) trace in %.3g ms", rows[0].trace_ms);
    char ylab[96];
    snprintf(ylab, sizeof ylab, "RMS error at the detector (%s)", s->unit ? s->unit : "units");
    im_plot P = {title, "trace time (ms)", ylab, 1, 1, 0, 3, ser, note};
    return im->draw->plot(&P, out, NULL, err, cap) ? -1 : 0;
}
