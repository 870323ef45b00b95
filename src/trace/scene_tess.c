/* scene_tess.c -- the error-against-run-time table: one collimated bundle traced
 * through a spherical singlet modelled analytically, then as meshes of increasing
 * tessellation without refinement, with analytic normals, and with full analytic
 * re-intersection; each row gives the triangles, build and trace times, rays per
 * second, and the max and RMS distance of every ray's detector hit from the
 * analytic trace's.  This is the user's guide to choosing a tessellation. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "scene.h"

typedef struct hits {
    double *pos;        /* 3 per ray */
    unsigned char *got;
    uint64_t n;
    int (*stop)(void *ctx);     /* the caller's stop request, polled per batch */
    void *stop_ctx;
} hits;

static int on_progress(void *ctx, uint64_t done, uint64_t total)
{
    hits *k = ctx;
    (void)done, (void)total;
    return k->stop && k->stop(k->stop_ctx);
}

static int on_hit(void *ctx, const trace_hit *h)
{
    hits *k = ctx;
    if (h->ray >= k->n || k->got[h->ray]) return 0;   /* first hit of each ray */
    memcpy(k->pos + 3 * h->ray, h->pos, sizeof h->pos);
    k->got[h->ray] = 1;
    return 0;
}

/* The lens's two caps as scene surfaces (for the shared tessellation). */
static void caps(const sc_tess_spec *sp, sc_surface c[2])
{
    memset(c, 0, 2 * sizeof *c);
    for (int i = 0; i < 2; i++) {
        c[i].shape = SC_CAP;
        c[i].kind = SC_REFRACT;
        c[i].axis[2] = 1;
        c[i].aperture = sp->aperture;
        c[i].n1 = i ? sp->n : 1;
        c[i].n2 = i ? 1 : sp->n;
        c[i].radius = i ? sp->r2 : sp->r1;
        c[i].at[2] = i ? sp->thickness : 0;
    }
}

static void analytic(const sc_surface *c, trace_surface *t)
{
    memset(t, 0, sizeof *t);
    t->shape = TRACE_AXIAL;
    memcpy(t->at, c->at, sizeof t->at);
    memcpy(t->axis, c->axis, sizeof t->axis);
    t->radius = c->radius;
    t->aperture = TRACE_AP_DISC;
    t->r_outer = c->aperture;
}

/* Build and trace one model; fills the row's counts and times and the hits. */
static int one_model(const trace_api *tr, const sc_tess_spec *sp, int model, int level,
                     hits *k, sc_tess_row *row, char *err)
{
    static const int refine[] = {[SC_MODEL_MESH] = TRACE_REFINE_NONE,
                                 [SC_MODEL_MESH_NORMAL] = TRACE_REFINE_NORMAL,
                                 [SC_MODEL_MESH_FULL] = TRACE_REFINE_FULL};
    trace_scene *ts = tr->scene_new();
    sc_surface c[2];
    trace_surface an, det;
    trace_material m = {TRACE_REFRACT, 1, 1}, dm = {TRACE_DETECT, 1, 1};
    trace_source src;
    trace_options opt;
    trace_sink sink = {k, NULL, on_hit, on_progress};
    trace_summary sum;
    int rc = -1;

    if (!ts) return snprintf(err, SC_ERRMAX, "out of memory"), -1;
    memset(row, 0, sizeof *row);
    row->model = model;
    row->level = level;
    caps(sp, c);
    for (int i = 0; i < 2; i++) {
        m.n_front = c[i].n1;
        m.n_back = c[i].n2;
        analytic(&c[i], &an);
        if (model == SC_MODEL_ANALYTIC) {
            if (tr->add_surface(ts, &an, &m) < 0) goto engine;
        } else {
            trace_mesh mesh = {0};
            double *tri;
            long ntri;
            if (sc_tessellate(&c[i], level, &tri, &ntri, err)) goto out;
            mesh.vertex = tri;
            mesh.nvertex = 3 * ntri;
            mesh.ntri = ntri;
            mesh.underlying = &an;
            mesh.refine = refine[model];
            row->triangles += ntri;
            rc = tr->add_mesh(ts, &mesh, &m);
            free(tri);
            if (rc < 0) goto engine;
            rc = -1;
        }
    }
    memset(&det, 0, sizeof det);
    det.shape = TRACE_PLANE;
    det.at[2] = sp->z_detector;
    det.axis[2] = 1;
    det.aperture = TRACE_AP_DISC;
    det.r_outer = 100 * (sp->aperture + fabs(sp->z_detector));   /* catches every ray */
    if (tr->add_surface(ts, &det, &dm) < 0) goto engine;
    memset(&src, 0, sizeof src);
    src.type = TRACE_SRC_GRID;
    src.at[2] = -1;
    src.dir[2] = 1;
    src.radius = sp->beam_radius;
    src.count = sp->grid;
    if (tr->add_source(ts, &src, NULL) < 0) goto engine;
    if (tr->build(ts, &row->build_ms) < 0) goto engine;
    tr->options_default(&opt);
    opt.fresnel = 0;            /* one path per ray: compare like with like */
    opt.reflections = 0;
    opt.threads = sp->threads;
    opt.batch = 4096;           /* a stop is seen within a few ms even on fine meshes */
    memset(k->got, 0, k->n);
    rc = tr->run(ts, &opt, &sink, &sum);
    if (rc == TRACE_ECANCEL) {
        snprintf(err, SC_ERRMAX, "tessellation table: stopped");
        rc = -1;
        goto out;
    }
    if (rc < 0) {
        rc = -1;
        goto engine;
    }
    row->trace_ms = sum.trace_ms;
    row->rays = (long)sum.rays;
    row->rays_per_s = sum.trace_ms > 0 ? (double)sum.rays / (sum.trace_ms / 1e3) : 0;
    rc = 0;
    goto out;
engine:
    snprintf(err, SC_ERRMAX, "tessellation table (%s, level %d): %s",
             model == SC_MODEL_ANALYTIC ? "analytic" : "mesh", level, tr->error(ts));
out:
    tr->scene_free(ts);
    return rc;
}

/* Max and RMS distance of k's hits from the reference's, ray by ray. */
static void compare(const hits *ref, const hits *k, sc_tess_row *row)
{
    double sum2 = 0, mx = 0;
    long n = 0, lost = 0;
    for (uint64_t i = 0; i < k->n; i++) {
        double d2 = 0;
        if (ref->got[i] != k->got[i]) lost++;
        if (!ref->got[i] || !k->got[i]) continue;
        for (int j = 0; j < 3; j++) {
            double d = k->pos[3 * i + j] - ref->pos[3 * i + j];
            d2 += d * d;
        }
        sum2 += d2;
        if (d2 > mx) mx = d2;
        n++;
    }
    row->err_max = sqrt(mx);
    row->err_rms = n ? sqrt(sum2 / (double)n) : 0;
    row->rays = n;
    row->lost = lost;
}

static int alloc_hits(hits *k, uint64_t n)
{
    k->n = n;
    k->pos = malloc(n * 3 * sizeof *k->pos);
    k->got = calloc(n, 1);
    return k->pos && k->got ? 0 : -1;
}

int sc_tess_table(const sc_tess_spec *sp, sc_tess_row *rows, char *err)
{
    const trace_api *tr = trace_get_api(TRACE_ABI);
    hits ref = {0}, k = {0};
    uint64_t n = (uint64_t)sp->grid * (uint64_t)sp->grid;
    int r = 0, rc = -1;

    err[0] = '\0';
    if (!tr) return snprintf(err, SC_ERRMAX, "the trace engine's ABI does not match"), -1;
    if (sp->grid < 1 || sp->grid > 10000 || !(sp->beam_radius > 0) ||
        !(sp->beam_radius <= sp->aperture))
        return snprintf(err, SC_ERRMAX, "tessellation table: the beam must be a grid of 1 to "
                        "10000 and fit the aperture"), -1;
    ref.stop = k.stop = sp->stop;
    ref.stop_ctx = k.stop_ctx = sp->stop_ctx;
    if (alloc_hits(&ref, n) || alloc_hits(&k, n)) {
        snprintf(err, SC_ERRMAX, "out of memory");
        goto out;
    }
    if (one_model(tr, sp, SC_MODEL_ANALYTIC, 0, &ref, &rows[r], err)) goto out;
    compare(&ref, &ref, &rows[r++]);
    for (int l = 0; l < sp->nlevels; l++)
        for (int model = SC_MODEL_MESH; model <= SC_MODEL_MESH_FULL; model++) {
            if (one_model(tr, sp, model, sp->levels[l], &k, &rows[r], err)) goto out;
            compare(&ref, &k, &rows[r++]);
        }
    rc = 0;
out:
    free(ref.pos);
    free(ref.got);
    free(k.pos);
    free(k.got);
    return rc;
}
