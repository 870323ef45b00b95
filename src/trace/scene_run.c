/* scene_run.c -- the trace front end inside the module: turns a scene (scene.h)
 * into the engine's surfaces, meshes and sources (trace.h), runs it, and writes
 * what the scene asked for: ray segments in the seed's p.l form (two "x y z" lines
 * per segment), detector hits as CSV, a summary; a progress line on stderr for long
 * traces on a terminal.  A scene whose sources name wavelengths is traced once per
 * wavelength, each run with the indices and absorption of its glasses at that
 * wavelength from the catalogue (src/paraxial/glass.c), so every run's indices are
 * uniform (the engine's fast paths stay as they are).  Also the error-against-run-time
 * table.  Exports the table lm_scene_api() that the dialogue loads. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "common/lm_out.h"
#include "paraxial/paraxial.h"
#include "scene.h"
#include "scene_out.h"
#include "scene_pol.h"

#define DEG 0.017453292519943295

static const trace_api *engine(void) { return trace_get_api(TRACE_ABI); }

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

/* ---- scene -> engine ------------------------------------------------------------ */

/* ---- media at a wavelength ------------------------------------------------------ */

/* The wavelengths a scene traces: those its sources name, in the order first named
 * (a source naming none is at the d line); one entry 0 when none names any (the scene
 * traces as it always did: glasses at d, no wavelength column). */
static int scene_wavelengths(const sc_scene *sc, double *wl)
{
    int n = 0;
    if (!sc->named_wl) { wl[0] = 0; return 1; }
    for (int i = 0; i < sc->nsource; i++) {
        const sc_source *s = &sc->source[i];
        for (int j = 0; j < (s->nlambda ? s->nlambda : 1); j++) {
            double l = s->nlambda ? s->lambda[j] : PX_LAMBDA_D;
            int k = 0;
            while (k < n && wl[k] != l) k++;
            if (k == n && n < SC_MAXWLS + 1) wl[n++] = l;
        }
    }
    return n;
}

/* Does source s emit at wavelength l (a run of scene_wavelengths)? */
static int source_at(const sc_scene *sc, const sc_source *s, double l)
{
    if (!sc->named_wl) return 1;
    if (!s->nlambda) return l == PX_LAMBDA_D;
    for (int j = 0; j < s->nlambda; j++)
        if (s->lambda[j] == l) return 1;
    return 0;
}

/* Append "SRC:LINE: what" to the notes (SC_ERRMAX bytes, one a line) unless `what`
 * is there already (a glass on both faces of a lens is noted once per wavelength). */
static void add_note(char *note, const char *src, long line, const char *what)
{
    size_t len;
    if (!note || strstr(note, what)) return;
    len = strlen(note);
    snprintf(note + len, SC_ERRMAX - len, "%s%s:%ld: %s", len ? "\n" : "", src, line, what);
}

/* The index and absorption coefficient (1/mm: scene lengths are millimetres) of a
 * medium at l um (0: none named, the d line): a plain number n as it is, transparent;
 * a glass from the catalogue, absorbing where it has transmittance data.  A glass
 * whose index holds at l but whose transmittance table does not reach l is not
 * refused: its absorption is held at the value of the table's nearest end, and `note`
 * (if not NULL) says so -- an estimate, not data (outside its tabulated span a glass
 * usually absorbs more: toward its UV edge, and its IR bands).  0, or -1 with
 * "SRC:LINE: why" in err. */
static int medium_at(const char *glass, double n, double l, const char *src, long line,
                     double *nout, double *aout, char *err, char *note)
{
    double um = l > 0 ? l : PX_LAMBDA_D, lo, hi;
    const px_glass_rec *g;
    int rc;
    *nout = n;
    *aout = 0;
    if (!glass[0]) return 0;
    if ((rc = px_glass_index(glass, um, nout)) != PX_OK) {
        if (rc == PX_GLASS_RANGE && (g = px_glass_find(glass)))
            snprintf(err, SC_ERRMAX, "%s:%ld: %s has no index at %.10g nm: its formula "
                     "holds from %.10g to %.10g nm%s", src, line, glass, um * 1e3,
                     g->lmin * 1e3, g->lmax * 1e3, l > 0 ? "" : " (name the sources' "
                     "wavelengths: lambda)");
        else
            snprintf(err, SC_ERRMAX, "%s:%ld: %s has no index at %.10g nm", src, line,
                     glass, um * 1e3);
        return -1;
    }
    rc = px_glass_absorption(glass, um, aout);
    if (rc == PX_NO_TAU) { *aout = 0; return 0; }
    if (rc == PX_OK) return 0;
    if (rc == PX_GLASS_RANGE && px_glass_absorption_range(glass, &lo, &hi) == PX_OK &&
        px_glass_absorption(glass, um < lo ? lo : hi, aout) == PX_OK) {
        char what[SC_ERRMAX / 2];
        snprintf(what, sizeof what, "%s's internal transmittance is known from %.10g to "
                 "%.10g nm, not at %.10g nm: traced with its absorption at %.10g nm, "
                 "%.3g /mm (an estimate; outside its data a glass usually absorbs more)",
                 glass, lo * 1e3, hi * 1e3, um * 1e3, (um < lo ? lo : hi) * 1e3, *aout);
        if (note) add_note(note, src, line, what);
        return 0;
    }
    *aout = 0;
    if (rc == PX_GLASS_RANGE)
        snprintf(err, SC_ERRMAX, "%s:%ld: %s: no transmittance at %.10g nm", src, line,
                 glass, um * 1e3);
    return -1;
}

/* The media of every refracting surface and every source at every wavelength, before
 * anything is traced or written: 0 or -1 (err). */
static int check_media(const sc_scene *sc, const double *wl, int nwl, char *err,
                       char *note)
{
    double n, a;
    for (int k = 0; k < nwl; k++) {
        for (int i = 0; i < sc->nsurf; i++) {
            const sc_surface *s = &sc->surf[i];
            if (s->kind != SC_REFRACT) continue;
            if (medium_at(s->glass[0], s->n1, wl[k], s->src, s->line, &n, &a, err, note) ||
                medium_at(s->glass[1], s->n2, wl[k], s->src, s->line, &n, &a, err, note))
                return -1;
        }
        for (int i = 0; i < sc->nsource; i++) {
            const sc_source *s = &sc->source[i];
            if (source_at(sc, s, wl[k]) &&
                medium_at(s->glass, s->medium, wl[k], s->src, s->line, &n, &a, err, note))
                return -1;
        }
    }
    return 0;
}

static void to_material(const sc_surface *s, double n1, double n2, trace_material *m)
{
    static const int kinds[] = {[SC_REFRACT] = TRACE_REFRACT, [SC_MIRROR] = TRACE_MIRROR,
                                [SC_ABSORB] = TRACE_ABSORB, [SC_DETECT] = TRACE_DETECT,
                                [SC_MEDIA] = TRACE_REFRACT};
    m->kind = kinds[s->kind];
    m->n_front = s->kind == SC_REFRACT ? n1 : 1;
    m->n_back = s->kind == SC_REFRACT ? n2 : 1;
}

/* The analytic surface of s (not meshes). */
static void to_surface(const sc_surface *s, trace_surface *t)
{
    memset(t, 0, sizeof *t);
    memcpy(t->at, s->at, sizeof t->at);
    memcpy(t->axis, s->axis, sizeof t->axis);
    switch (s->shape) {
    case SC_PLANE:
        t->shape = TRACE_PLANE;
        memcpy(t->up, s->up, sizeof t->up);
        if (s->aperture > 0) {
            t->aperture = TRACE_AP_DISC;
            t->r_outer = s->aperture;
            t->r_inner = s->hole;
        } else {
            t->aperture = TRACE_AP_RECT;
            t->width = s->rect[0];
            t->height = s->rect[1];
        }
        break;
    case SC_SPHERE:
        t->shape = TRACE_SPHERE;
        t->radius = s->radius;
        break;
    default:
        t->shape = TRACE_AXIAL;
        t->radius = s->radius;
        t->conic = s->conic;
        t->nasph = s->ncoef < TRACE_MAXASPH ? s->ncoef : TRACE_MAXASPH;
        memcpy(t->asph, s->coef, (size_t)t->nasph * sizeof *t->asph);
        t->aperture = TRACE_AP_DISC;
        t->r_outer = s->aperture;
    }
}

/* "FILE:LINE: engine message" into err. */
static int engine_fail(const trace_api *tr, trace_scene *ts, const char *src, long line,
                       char *err)
{
    snprintf(err, SC_ERRMAX, "%s:%ld: %s", src, line, tr->error(ts));
    return -1;
}

/* Absorption of a surface just added (id) when either medium absorbs. */
static int set_alpha(const trace_api *tr, trace_scene *ts, int id, double a1, double a2,
                     const sc_surface *s, char *err)
{
    if (id < 0) return engine_fail(tr, ts, s->src, s->line, err);
    if ((a1 > 0 || a2 > 0) && tr->set_absorption(ts, id, a1, a2) < 0)
        return engine_fail(tr, ts, s->src, s->line, err);
    return 0;
}

/* Surface s with its media at wavelength l (0: none named). */
static int add_surface(const trace_api *tr, trace_scene *ts, const sc_surface *s,
                       double l, char *err)
{
    trace_material m;
    trace_surface an;
    trace_mesh mesh;
    double n1 = s->n1, n2 = s->n2, a1 = 0, a2 = 0;
    if (s->kind == SC_REFRACT &&
        (medium_at(s->glass[0], s->n1, l, s->src, s->line, &n1, &a1, err, NULL) ||
         medium_at(s->glass[1], s->n2, l, s->src, s->line, &n2, &a2, err, NULL)))
        return -1;
    to_material(s, n1, n2, &m);
    if (s->shape != SC_MESH && !s->tessellate) {
        to_surface(s, &an);
        return set_alpha(tr, ts, tr->add_surface(ts, &an, &m), a1, a2, s, err);
    }
    memset(&mesh, 0, sizeof mesh);
    mesh.vertex = s->idx ? s->vtx : s->tri;   /* an OBJ: its shared vertices */
    mesh.nvertex = s->idx ? s->nvtx : 3 * s->ntri;
    mesh.index = s->idx;
    mesh.shared = s->idx != NULL;   /* the scene's arrays outlive the engine's scene */
    mesh.ntri = s->ntri;
    mesh.media = s->media;
    if (s->shape != SC_MESH) {
        to_surface(s, &an);
        mesh.underlying = &an;
        mesh.refine = s->refine ? TRACE_REFINE_FULL : TRACE_REFINE_NONE;
    } else if (s->sphere[3] > 0) {
        memset(&an, 0, sizeof an);
        an.shape = TRACE_SPHERE;
        memcpy(an.at, s->sphere, sizeof an.at);
        an.radius = s->sphere[3];
        mesh.underlying = &an;
        mesh.refine = TRACE_REFINE_FULL;
    }
    return set_alpha(tr, ts, tr->add_mesh(ts, &mesh, &m), a1, a2, s, err);
}

/* Source s at wavelength l (0: none named). */
static int add_source(const trace_api *tr, trace_scene *ts, const sc_scene *sc,
                      const sc_source *s, double l, char *err)
{
    trace_source t;
    trace_ray *rays = NULL;
    int rc;
    memset(&t, 0, sizeof t);
    memcpy(t.at, s->from, sizeof t.at);
    memcpy(t.dir, s->dir, sizeof t.dir);
    t.power = s->power;
    if (medium_at(s->glass, s->medium, l, s->src, s->line, &t.n_medium, &t.alpha_medium, err,
                  NULL))
        return -1;
    t.lambda = l;
    if (s->polarised == 1) {
        t.pol = TRACE_LINEAR;
        memcpy(t.pol_dir, s->pol, sizeof t.pol_dir);
    } else if (s->polarised == 2) {   /* in the Stokes frame: its reference (0: +x) */
        t.pol = TRACE_ELLIPTIC;
        memcpy(t.pol_dir, sc->polar_ref, sizeof t.pol_dir);
        memcpy(t.jones, s->jones, sizeof t.jones);
    } else if (s->polarised == 3) {
        t.pol = TRACE_PARTIAL;
        memcpy(t.pol_dir, sc->polar_ref, sizeof t.pol_dir);
        memcpy(t.stokes, s->stokes, sizeof t.stokes);
    }
    t.half_angle = s->angle * DEG;
    t.count = s->count;
    t.rings = s->rings;
    switch (s->type) {
    case SC_RAY:
        t.type = TRACE_SRC_RAYS;
        t.count = 1;
        if (!(rays = calloc(1, sizeof *rays))) goto oom;
        memcpy(rays[0].o, s->from, sizeof rays[0].o);
        memcpy(rays[0].d, s->dir, sizeof rays[0].d);
        break;
    case SC_FAN:
        if (s->has_to) {
            t.type = TRACE_SRC_AIMED;
            memcpy(t.to0, s->to[0], sizeof t.to0);
            memcpy(t.to1, s->to[1], sizeof t.to1);
        } else {
            t.type = TRACE_SRC_FAN;
            memcpy(t.up, s->up, sizeof t.up);
        }
        break;
    case SC_POINT: {
        long n = sc_point_count(s);
        sc_ray *r = malloc((size_t)n * sizeof *r);
        if (!r || !(rays = calloc((size_t)n, sizeof *rays))) { free(r); goto oom; }
        sc_point_rays(s, r);
        for (long i = 0; i < n; i++) {
            memcpy(rays[i].o, r[i].o, sizeof rays[i].o);
            memcpy(rays[i].d, r[i].d, sizeof rays[i].d);
        }
        free(r);
        t.type = TRACE_SRC_RAYS;
        t.count = n;
        break;
    }
    case SC_CONE: t.type = TRACE_SRC_CONE; break;
    case SC_COLLIMATED:
        t.type = TRACE_SRC_GRID;
        t.radius = s->radius;
        break;
    case SC_GAUSSIAN:
        t.type = TRACE_SRC_GAUSSIAN;
        t.waist = s->waist;
        t.wavelength = s->wavelength;
        t.trunc = s->trunc;
        break;
    }
    t.ray = rays;
    rc = tr->add_source(ts, &t, NULL);
    free(rays);
    return rc < 0 ? engine_fail(tr, ts, s->src, s->line, err) : 0;
oom:
    free(rays);
    snprintf(err, SC_ERRMAX, "%s:%ld: out of memory", s->src, s->line);
    return -1;
}

/* ---- outputs -------------------------------------------------------------------- */

typedef struct out {
    FILE *seg, *hit;
    lm_out seg_out, hit_out;    /* where seg and hit go (src/common/lm_out.h) */
    so_table *seg_t, *hit_t;    /* their formats (scene_out.c); an HDF5 table that
                                   shares the segments' file has no FILE of its own */
    int tty;
    double t0, last;
    int shown;
    char *err;
    int (*stop)(void *ctx);     /* the caller's stop callback, or NULL */
    void *stop_ctx;
    unsigned records;           /* records written since the last poll */
    int stopped;
    int wl;                     /* write the wavelength column (the scene names some) */
    uint64_t ray0;              /* rays of the wavelengths traced before this run */
    double *stokes;             /* polarization on: the hit's S0..S3 (scene_polout.c
                                   keeps each record's), else NULL */
} out;

/* Poll the stop callback; 1 (and o->stopped) if the trace must stop. */
static int stop_now(out *o)
{
    if (!o->stopped && o->stop && o->stop(o->stop_ctx)) o->stopped = 1;
    return o->stopped;
}

/* Writing a batch's records can take a while too (a few M segments): poll every 4096. */
static int poll_records(out *o)
{
    if (++o->records < 4096) return 0;
    o->records = 0;
    return stop_now(o);
}

static int w_segment(void *ctx, const trace_segment *s)
{
    out *o = ctx;
    if (poll_records(o)) return 1;
    return so_segment(o->seg_t, o->seg, s);
}

static int w_hit(void *ctx, const trace_hit *h)
{
    out *o = ctx;
    if (poll_records(o)) return 1;
    int rc = so_hit(o->hit_t, o->hit, h, h->ray + o->ray0, o->stokes);
    if (o->stokes)   /* a hit without its record would say so, not repeat the last */
        for (int i = 0; i < 4; i++) o->stokes[i] = NAN;
    return rc;
}

/* The batch sink's side (trace_batch_sink): the same rows and the same polls as the
 * callbacks above, record for record.  How many of n records go before the next poll
 * (counted as poll_records counts: a poll before every 4096th); 0: stop. */
static size_t poll_run(out *o, size_t n)
{
    if (o->records == 4095) {
        o->records = 0;
        return stop_now(o) ? 0 : 1;
    }
    size_t k = 4095 - o->records;
    if (k > n) k = n;
    o->records += (unsigned)k;
    return k;
}

static int w_segments(void *ctx, const trace_segment *s, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (w_segment(ctx, s + i)) return 1;
    return 0;
}

static int w_hits(void *ctx, const trace_hit *h, size_t n)
{
    out *o = ctx;
    if (!o->hit_t) return 0;   /* no hits output: taken for polarization's records */
    if (o->stokes) {           /* one at a time: each after its polarization record */
        for (size_t i = 0; i < n; i++)
            if (w_hit(ctx, h + i)) return 1;
        return 0;
    }
    while (n) {
        size_t k = poll_run(o, n);
        if (!k || so_hits(o->hit_t, o->hit, h, k, o->ray0)) return 1;
        h += k;
        n -= k;
    }
    return 0;
}

/* A progress line on stderr, only on a terminal and once the trace has run 1 s. */
static int w_progress(void *ctx, uint64_t done, uint64_t total)
{
    out *o = ctx;
    double t = now_ms();
    if (stop_now(o)) return 1;
    done += o->ray0;
    total += o->ray0;
    if (!o->tty || t - o->t0 < 1000 || (t - o->last < 200 && done < total)) return 0;
    o->last = t;
    o->shown = 1;
    fprintf(stderr, "\rlensmat: traced %llu of %llu rays (%.0f%%)", (unsigned long long)done,
            (unsigned long long)total, total ? 100.0 * (double)done / (double)total : 100.0);
    return 0;
}

/* An output through the shared writer: a unique temporary beside a regular file, in
 * place for a device or FIFO, "-" for standard output (src/common/lm_out.h). */
static FILE *open_part(const char *name, lm_out *o, char *err)
{
    if (lm_out_open(o, name, 0, err, SC_ERRMAX)) return NULL;
    return o->f;
}

/* Commit o when ok, else keep what was written as NAME.part (never under its name);
 * 0 or -1, with a message in err unless one is there already. */
static int finish(lm_out *o, int ok, char *err)
{
    char why[SC_ERRMAX];
    if (!ok) { lm_out_abort(o, 1); return -1; }
    if (lm_out_commit(o, why, sizeof why)) {
        if (!err[0]) snprintf(err, SC_ERRMAX, "%s", why);
        return -1;
    }
    return 0;
}

/* Does output i (0 segments, 1 hits, 2 summary) go into the HDF5 file of an earlier
 * output (same name, both HDF5)?  Then that one writes its table. */
static int h5_with(const sc_scene *sc, int i, int j)
{
    const char *n[3] = {sc->out_segments, sc->out_hits, sc->out_summary};
    return j < i && n[i] && n[j] && sc->out_format[i] == SC_OUT_H5 &&
           sc->out_format[j] == SC_OUT_H5 && strcmp(n[i], n[j]) == 0;
}
static int h5_shared(const sc_scene *sc, int i) { return h5_with(sc, i, 0) || h5_with(sc, i, 1); }

/* A table of the format the scene gave output `name` (f: its file, NULL for an HDF5
 * table written with another's; a CSV is formatted on the trace's thread count);
 * NULL with a message. */
static so_table *table(const sc_scene *sc, FILE *f, int fmt, int hits, int wl,
                       const char *name, char *err)
{
    char why[SC_ERRMAX / 2];
    so_table *t = so_open(f, (sc_out_format)fmt, hits, wl, hits && sc->polar, sc->threads,
                          why, sizeof why);
    if (!t) snprintf(err, SC_ERRMAX, "%s: %s", name, why);
    return t;
}

/* The end of output i's table (0 segments, 1 hits) before its file is closed: .npy
 * gets its row count; an HDF5 file gets its tables (the later outputs that share it
 * too: the hits, the summary when the run went well).  After a failure (err holds a
 * message) the rows are still written out and the writer stopped: the .part stays. */
static void end_table(const sc_scene *sc, out *o, int i, const sc_result *res,
                      const double *wl, const trace_summary *per, int nwl, char *err)
{
    FILE *f = i ? o->hit : o->seg;
    const char *part = i ? sc->out_hits : sc->out_segments;
    char why[SC_ERRMAX / 2];
    int rc;
    if (!(i ? o->hit_t : o->seg_t)) return;   /* its table could not be set up */
    if (sc->out_format[i] != SC_OUT_H5) {   /* also after a failure: its writer stops */
        rc = so_finish(i ? o->hit_t : o->seg_t, f, why, sizeof why);
    } else {
        so_summary m = {sc->name, &res->sum, sc->named_wl ? nwl : 0, wl, per};
        if (err[0]) return;
        rc = so_h5_write(f, i == 1 || h5_with(sc, 1, i) ? o->hit_t : NULL,
                         i == 0 ? o->seg_t : NULL, h5_with(sc, 2, i) ? &m : NULL, why,
                         sizeof why);
    }
    if (rc && !err[0]) snprintf(err, SC_ERRMAX, "%s: %s", part, why);
}

/* One wavelength's run into the scene's summary (counts and powers add). */
static void add_summary(trace_summary *a, const trace_summary *b)
{
    a->rays += b->rays;
    a->segments += b->segments;
    a->interactions += b->interactions;
    a->tir += b->tir;
    a->hits += b->hits;
    a->cut_depth += b->cut_depth;
    a->cut_power += b->cut_power;
    a->cut_reflection += b->cut_reflection;
    a->medium_mismatch += b->medium_mismatch;
    a->failures += b->failures;
    if (b->max_depth_seen > a->max_depth_seen) a->max_depth_seen = b->max_depth_seen;
    a->emitted += b->emitted;
    a->detected += b->detected;
    a->absorbed += b->absorbed;
    a->escaped += b->escaped;
    a->cutoff += b->cutoff;
    a->build_ms += b->build_ms;
    a->trace_ms += b->trace_ms;
    if (b->lens_surfaces > a->lens_surfaces) {
        a->lens_surfaces = b->lens_surfaces;
        memcpy(a->lens_kernel, b->lens_kernel, sizeof a->lens_kernel);
    }
}

static int write_summary(const sc_scene *sc, const trace_summary *s, const double *wl,
                         const trace_summary *per, int nwl, char *err)
{
    lm_out o;
    FILE *f;
    int rc;
    if (h5_shared(sc, 2)) return 0;   /* written with the tables */
    if (!(f = open_part(sc->out_summary, &o, err))) return -1;
    if (sc->out_format[2] == SC_OUT_H5) {
        so_summary m = {sc->name, s, sc->named_wl ? nwl : 0, wl, per};
        char why[SC_ERRMAX / 2];
        rc = so_h5_write(f, NULL, NULL, &m, why, sizeof why);
        if (rc) snprintf(err, SC_ERRMAX, "%s: %s", sc->out_summary, why);
        return finish(&o, !rc, err);
    }
    fprintf(f, "scene %s\nrays %llu\nsegments %llu\ninteractions %llu\ntir %llu\n"
            "hits %llu\ncut_depth %llu\ncut_power %llu\ncut_reflection %llu\n"
            "failures %llu\nmedium_mismatch %llu\nemitted %.17g\ndetected %.17g\n"
            "absorbed %.17g\nescaped %.17g\ncutoff %.17g\nbalance_error %.3g\n",
            sc->name, (unsigned long long)s->rays, (unsigned long long)s->segments,
            (unsigned long long)s->interactions, (unsigned long long)s->tir,
            (unsigned long long)s->hits, (unsigned long long)s->cut_depth,
            (unsigned long long)s->cut_power, (unsigned long long)s->cut_reflection,
            (unsigned long long)s->failures, (unsigned long long)s->medium_mismatch,
            s->emitted, s->detected, s->absorbed, s->escaped, s->cutoff,
            s->emitted - (s->detected + s->absorbed + s->escaped + s->cutoff));
    for (int k = 0; sc->named_wl && k < nwl; k++)   /* one line per wavelength */
        fprintf(f, "wavelength_nm %.10g rays %llu hits %llu emitted %.17g detected %.17g "
                "absorbed %.17g escaped %.17g cutoff %.17g\n", wl[k] * 1e3,
                (unsigned long long)per[k].rays, (unsigned long long)per[k].hits,
                per[k].emitted, per[k].detected, per[k].absorbed, per[k].escaped,
                per[k].cutoff);
    return finish(&o, 1, err);
}

/* The engine's scene at wavelength l (0: none named): every surface with its media at
 * l, the sources that emit at l. */
static int build_scene(const trace_api *tr, const sc_scene *sc, double l,
                       trace_scene **out_ts, char *err)
{
    trace_scene *ts = tr->scene_new();
    if (!ts) return snprintf(err, SC_ERRMAX, "out of memory"), -1;
    for (int i = 0; i < sc->nsurf; i++)
        if (add_surface(tr, ts, &sc->surf[i], l, err)) goto bad;
    for (int i = 0; i < sc->nsource; i++)
        if (source_at(sc, &sc->source[i], l) && add_source(tr, ts, sc, &sc->source[i], l, err))
            goto bad;
    *out_ts = ts;
    return 0;
bad:
    tr->scene_free(ts);
    return -1;
}

/* Rays per batch: the stop callback is polled between batches (and while records are
 * written), so a batch must take a few ms at most even in a slow scene.  A ray costs
 * up to `depth` interactions of about 0.1-1 us; 2^15 interactions per batch keeps a
 * poll within ~30 ms while the batches stay large enough (64 rays or more) that
 * handing them out costs under 1 % (results do not depend on the batch size). */
static long stop_batch(int depth)
{
    long b = 32768 / (depth > 0 ? depth : 1);
    return b < 64 ? 64 : b > 4096 ? 4096 : b;
}

static int run(const sc_scene *sc, sc_result *res, char *err)
{
    const trace_api *tr = engine();
    trace_scene *ts = NULL;
    trace_options opt;
    trace_batch_sink sink = {0};
    out o = {0};
    sp_out po = {0};                /* polarization: scene_polout.c */
    int rc = TRACE_OK, nwl;
    double wl[SC_MAXWLS + 1];
    trace_summary per[SC_MAXWLS + 1];

    err[0] = '\0';
    memset(res, 0, sizeof *res);
    memset(per, 0, sizeof per);
    if (!tr) return snprintf(err, SC_ERRMAX, "the trace engine's ABI does not match"), -1;
    nwl = scene_wavelengths(sc, wl);
    if (check_media(sc, wl, nwl, err, res->note) || build_scene(tr, sc, wl[0], &ts, err))
        return -1;
    tr->options_default(&opt);
    opt.max_depth = sc->depth;
    opt.cutoff = sc->cutoff;
    opt.fresnel = sc->fresnel;
    opt.reflections = sc->reflections;
    opt.threads = sc->threads;
    opt.escape_length = sc->escape;
    opt.batch = stop_batch(sc->depth);
    /* LENSMAT_TRACE_BVH=1: every segment by Embree, the lens path (tr_seqscan.c) off --
     * to check that it changes no bit of any output */
    const char *bvh = getenv("LENSMAT_TRACE_BVH");
    if (bvh && *bvh && strcmp(bvh, "0") != 0) opt.sequential = 0;
    o.err = err;
    o.stop = sc->stop;
    o.stop_ctx = sc->stop_ctx;
    o.tty = isatty(2);
    o.t0 = now_ms();
    o.wl = sc->named_wl;
    o.stokes = sc->polar ? po.stokes : NULL;
    sink.ctx = &o;
    sink.progress = w_progress;
    if (sc->out_segments) {
        if (!(o.seg = open_part(sc->out_segments, &o.seg_out, err)) ||
            !(o.seg_t = table(sc, o.seg, sc->out_format[0], 0, o.wl, sc->out_segments, err)))
            goto out;
        sink.segments = w_segments;
    }
    if (sc->out_hits) {
        if ((!h5_shared(sc, 1) && !(o.hit = open_part(sc->out_hits, &o.hit_out, err))) ||
            !(o.hit_t = table(sc, o.hit, sc->out_format[1], 1, o.wl, sc->out_hits, err)))
            goto out;
        sink.hits = w_hits;
    }
    if (sc->out_polar) {
        if (sp_open(sc, &po, err)) goto out;
        if (!sink.hits) sink.hits = w_hits;   /* the records come with hits (none kept) */
    }
    /* one run per wavelength, in the order the sources name them; rays are numbered on
     * from one run to the next */
    for (int k = 0; k < nwl && rc >= 0; k++) {
        if (!ts && build_scene(tr, sc, wl[k], &ts, err)) goto out;
        if (sc->polar && sp_engine(tr, ts, sc, wl[k], o.ray0, &po, err)) goto out;
        rc = stop_now(&o) ? TRACE_ECANCEL : tr->run_batches(ts, &opt, &sink, &per[k]);
        add_summary(&res->sum, &per[k]);
        o.ray0 += per[k].rays;
        if (rc >= 0) { tr->scene_free(ts); ts = NULL; }
    }
    if (o.shown) fputc('\n', stderr);
    res->progress_shown = o.shown;
    res->stopped = o.stopped;
    if (rc < 0) {
        snprintf(err, SC_ERRMAX, "%s: the trace stopped: %s%s", sc->name,
                 o.stopped ? "interrupted" : rc == TRACE_ECANCEL ?
                 "an output could not be written" : tr->error(ts),
                 sc->out_segments || sc->out_hits ? "; the outputs written so far are "
                 "left as .part files (incomplete)" : "");
    } else if (sc->mismatch_error && res->sum.medium_mismatch) {
        res->mismatch_failed = 1;
        snprintf(err, SC_ERRMAX, "%s: %llu rays met a surface whose index on their side "
                 "differs from the medium they travel in%s%s (the scene says `mismatch "
                 "error`)%s", sc->name, (unsigned long long)res->sum.medium_mismatch,
                 sc->nmismatch ? ": first " : "", sc->mismatch_where,
                 sc->out_segments || sc->out_hits ? "; the outputs are left as .part "
                 "files" : "");
    }
out:
    /* finish() leaves a message in err on any failure */
    if (o.seg) {
        end_table(sc, &o, 0, res, wl, per, nwl, err);
        finish(&o.seg_out, !err[0], err);
    }
    if (o.hit) {
        end_table(sc, &o, 1, res, wl, per, nwl, err);
        finish(&o.hit_out, !err[0], err);
    }
    sp_finish(&po, !err[0], err);
    so_free(o.seg_t);
    so_free(o.hit_t);
    if (ts) tr->scene_free(ts);
    if (!err[0] && sc->out_summary) write_summary(sc, &res->sum, wl, per, nwl, err);
    return err[0] ? -1 : 0;
}

/* The table refuses a singlet whose surfaces cross within the semi-diameter, as
 * add_lens does (the dialogue asks again before it gets here). */
static int tess_table(const sc_tess_spec *sp, sc_tess_row *rows, char *err)
{
    trace_lens_surface a = {sp->r1, 0, sp->n, sp->aperture};
    trace_lens_surface b = {sp->r2, sp->thickness, 1, sp->aperture};
    double h, rim, edge;
    if (trace_lens_cross(&a, &b, &h, &rim, &edge))
        return snprintf(err, SC_ERRMAX, "tessellation table: the surfaces cross at height "
                        "%.6g: their edge thickness at the semi-diameter %.6g is %.6g", h,
                        rim, edge), -1;
    return sc_tess_table(sp, rows, err);
}

static const scene_api api = {SC_API_ABI, sc_load, sc_free, run, tess_table, NULL};

__attribute__((visibility("default"))) const scene_api *lm_scene_api(int abi)
{
    static scene_api a;
    if (abi != SC_API_ABI || !engine()) return NULL;
    a = api;
    a.engine = engine();
    return &a;
}
