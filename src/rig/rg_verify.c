/* rg_verify.c -- the independent check of a pose: the rig built as a scene of the
 * trace engine (its public table only, handed in by the caller) -- m1 and m2 as
 * mirror discs, the cornea as an axial surface whose Fresnel reflection is followed
 * (a biconic, which the tracer has no surface for: its tangent plane where the beam
 * meets it),
 * a detector disc at the detector point -- and one laser ray traced through it. */
#include <stdio.h>
#include <string.h>
#include "trace/trace.h"
#include "rig/rg_geom.h"
#include "rig/rg_vec.h"

#define DET_RADIUS 25.0     /* mm: a catching disc, wide enough for a quantised pose's
                               miss and for the spots of an eye decentred 0.5 mm or
                               tilted 5 deg (the many-eyes study's population) */

typedef struct vf_ctx {
    int ids[4];             /* m1, m2, cornea, detector */
    int nseg;
    trace_segment seg[3];   /* the laser -> m1 -> m2 -> cornea legs */
    trace_segment last;     /* cornea -> detector */
    int have_last;
    trace_hit hit;
    int have_hit;
} vf_ctx;

static int on_segment(void *ctx, const trace_segment *s)
{
    vf_ctx *c = ctx;
    if (s->ray != 0) return 0;
    if (s->depth < 3 && s->depth == c->nseg && s->surface == c->ids[s->depth])
        c->seg[c->nseg++] = *s;
    else if (s->depth == 3 && s->end == TRACE_END_DETECT && s->surface == c->ids[3]) {
        c->last = *s;
        c->have_last = 1;
    }
    return 0;
}

static int on_hit(void *ctx, const trace_hit *h)
{
    vf_ctx *c = ctx;
    if (h->surface == c->ids[3] && h->depth == 3 && (h->history & 7u) == 7u) {
        c->hit = *h;
        c->have_hit = 1;
    }
    return 0;
}

static void dir_of(const trace_segment *s, double d[3])
{
    v3sub(d, s->p1, s->p0);
    v3norm(d);
}

static double law_err(const trace_segment *a, const trace_segment *b, const double n[3])
{
    double di[3], dout[3], want[3];
    dir_of(a, di);
    dir_of(b, dout);
    v3reflect(want, di, n);
    return v3dist(want, dout);
}

int rg_verify_pose(const struct trace_api *tr, const rg_geometry *g, const rg_pose *p,
              const double target[3], rg_verify *v, char *err, size_t errcap)
{
    memset(v, 0, sizeof *v);
    v->err_target = v->err_detector = v->reflect_err = INFINITY;
    for (int i = 0; i < 3; i++) v->spot[i] = v->det[i] = NAN;
    if (!tr) {
        snprintf(err, errcap, "no trace engine to verify with");
        return RG_EINVAL;
    }
    trace_scene *sc = tr->scene_new();
    if (!sc) { snprintf(err, errcap, "out of memory"); return RG_ENOMEM; }
    vf_ctx c;
    memset(&c, 0, sizeof c);
    double n1[3], n2[3], c2[3], w[3];
    rg_gimbal_normal(&g->m1, p->j[RG_J_M1A], p->j[RG_J_M1B], n1);
    rg_gimbal_normal(&g->m2, p->j[RG_J_M2A], p->j[RG_J_M2B], n2);
    rg_m2_center(g, p->j[RG_J_U], p->j[RG_J_V], c2);
    trace_material mir = {TRACE_MIRROR, 1, 1}, cor = {TRACE_REFRACT, 1.0, 1.376},
                   det = {TRACE_DETECT, 1, 1};
    trace_surface s;
    int rc = RG_OK;

    memset(&s, 0, sizeof s);
    s.shape = TRACE_PLANE;
    s.aperture = TRACE_AP_DISC;
    v3axpy(s.at, g->m1.center, g->m1.offset, n1);
    v3copy(s.axis, n1);
    s.r_outer = g->m1.radius;
    c.ids[0] = tr->add_surface(sc, &s, &mir);
    v3axpy(s.at, c2, g->m2.offset, n2);
    v3copy(s.axis, n2);
    s.r_outer = g->m2.radius;
    c.ids[1] = tr->add_surface(sc, &s, &mir);

    memset(&s, 0, sizeof s);
    s.aperture = TRACE_AP_DISC;
    const rg_cornea *k = &g->cornea;
    double tn[3];
    if (k->model == RG_BICONIC) {
        /* the tracer has no biconic: the tangent plane where this pose's beam meets
         * the surface (the analytic forward model's spot; the target when the model
         * finds none) reflects that ray exactly as the surface does -- a quantised
         * pose lands microns off the target, and the plane there would tilt the
         * reflected ray by 2 x miss / R */
        double pe[3], rel[3], ne[3], at[3];
        rg_beam fb;
        if (rg_forward_path(g, p, &fb, 0) == 0) v3copy(at, fb.spot);
        else v3copy(at, target);
        v3sub(rel, at, k->trans);
        m3tmul(pe, k->rot, rel);
        rg_normal_eye(k, pe, ne);
        m3mul(tn, k->rot, ne);
        s.shape = TRACE_PLANE;
        v3copy(s.at, at);
        v3scale(s.axis, tn, -1);
        s.r_outer = 0.5;
    } else {
        s.shape = TRACE_AXIAL;
        v3copy(s.at, k->trans);
        v3set(s.axis, k->rot[2], k->rot[5], k->rot[8]);
        s.radius = k->R;
        s.conic = k->model == RG_SPHERE ? 0 : k->Q;
        if (k->model == RG_ASPHERE && k->nasph > 0) {
            s.nasph = k->nasph + 1;          /* the tracer's asph[0] is the s^2 term */
            for (int i = 0; i < k->nasph && i + 1 < TRACE_MAXASPH; i++)
                s.asph[i + 1] = k->asph[i];
        }
        s.r_outer = k->zone;
    }
    c.ids[2] = tr->add_surface(sc, &s, &cor);

    memset(&s, 0, sizeof s);
    s.shape = TRACE_PLANE;
    s.aperture = TRACE_AP_DISC;
    rg_detector_normal(g, w);
    v3copy(s.at, g->detector);
    v3copy(s.axis, w);
    s.r_outer = DET_RADIUS;
    c.ids[3] = tr->add_surface(sc, &s, &det);
    for (int i = 0; i < 4; i++)
        if (c.ids[i] < 0) {
            snprintf(err, errcap, "trace engine refused surface %d: %s", i, tr->error(sc));
            tr->scene_free(sc);
            return RG_EIO;
        }

    trace_ray ray;
    memset(&ray, 0, sizeof ray);
    v3copy(ray.o, g->laser_at);
    v3copy(ray.d, g->laser_dir);
    ray.power = 1;
    trace_source src;
    memset(&src, 0, sizeof src);
    src.type = TRACE_SRC_RAYS;
    src.count = 1;
    src.ray = &ray;
    trace_options o;
    tr->options_default(&o);
    o.threads = 1;
    o.max_depth = 8;
    o.cutoff = 1e-12;
    trace_sink sink = {&c, on_segment, on_hit, NULL};
    if (tr->add_source(sc, &src, NULL) < 0 || tr->run(sc, &o, &sink, NULL) < 0) {
        snprintf(err, errcap, "trace failed: %s", tr->error(sc));
        tr->scene_free(sc);
        return RG_EIO;
    }
    tr->scene_free(sc);

    if (c.nseg == 3) {
        v3copy(v->spot, c.seg[2].p1);
        v->err_target = v3dist(v->spot, target);
    }
    if (c.nseg == 3 && c.have_last && c.have_hit) {
        v->hit = 1;
        v3copy(v->det, c.hit.pos);
        v->err_detector = v3dist(v->det, g->detector);
        /* the reflection law at both mirrors and the cornea, with normals from the
         * mounts and the cornea model (not from the tracer) */
        if (k->model != RG_BICONIC) {
            double pe[3], rel[3], ne[3];
            v3sub(rel, v->spot, k->trans);
            m3tmul(pe, k->rot, rel);
            rg_normal_eye(k, pe, ne);
            m3mul(tn, k->rot, ne);
        }
        v->reflect_err = fmax(law_err(&c.seg[0], &c.seg[1], n1),
                              fmax(law_err(&c.seg[1], &c.seg[2], n2),
                                   law_err(&c.seg[2], &c.last, tn)));
    }
    if (errcap) err[0] = 0;
    return rc;
}
