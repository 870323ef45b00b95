/* scene_run.c -- the trace front end inside the module: turns a scene (scene.h)
 * into the engine's surfaces, meshes and sources (trace.h), runs it, and writes
 * what the scene asked for: ray segments in the seed's p.l form (two "x y z" lines
 * per segment), detector hits as CSV, a summary; a progress line on stderr for long
 * traces on a terminal.  Also the error-against-run-time table.  Exports the table
 * lm_scene_api() that the dialogue loads. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "scene.h"

#define DEG 0.017453292519943295

static const trace_api *engine(void) { return trace_get_api(TRACE_ABI); }

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec / 1e6;
}

/* ---- scene -> engine ------------------------------------------------------------ */

static void to_material(const sc_surface *s, trace_material *m)
{
    static const int kinds[] = {[SC_REFRACT] = TRACE_REFRACT, [SC_MIRROR] = TRACE_MIRROR,
                                [SC_ABSORB] = TRACE_ABSORB, [SC_DETECT] = TRACE_DETECT,
                                [SC_MEDIA] = TRACE_REFRACT};
    m->kind = kinds[s->kind];
    m->n_front = s->kind == SC_REFRACT ? s->n1 : 1;
    m->n_back = s->kind == SC_REFRACT ? s->n2 : 1;
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

static int add_surface(const trace_api *tr, trace_scene *ts, const sc_surface *s,
                       char *err)
{
    trace_material m;
    trace_surface an;
    trace_mesh mesh;
    to_material(s, &m);
    if (s->shape != SC_MESH && !s->tessellate) {
        to_surface(s, &an);
        return tr->add_surface(ts, &an, &m) < 0 ? engine_fail(tr, ts, s->src, s->line, err) : 0;
    }
    memset(&mesh, 0, sizeof mesh);
    mesh.vertex = s->tri;
    mesh.nvertex = 3 * s->ntri;
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
    return tr->add_mesh(ts, &mesh, &m) < 0 ? engine_fail(tr, ts, s->src, s->line, err) : 0;
}

static int add_source(const trace_api *tr, trace_scene *ts, const sc_source *s, char *err)
{
    trace_source t;
    trace_ray *rays = NULL;
    int rc;
    memset(&t, 0, sizeof t);
    memcpy(t.at, s->from, sizeof t.at);
    memcpy(t.dir, s->dir, sizeof t.dir);
    t.power = s->power;
    t.n_medium = s->medium;
    if (s->polarised) {
        t.pol = TRACE_LINEAR;
        memcpy(t.pol_dir, s->pol, sizeof t.pol_dir);
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
    char *seg_part, *hit_part;
    int tty;
    double t0, last;
    int shown;
    char *err;
    int (*stop)(void *ctx);     /* the caller's stop callback, or NULL */
    void *stop_ctx;
    unsigned records;           /* records written since the last poll */
    int stopped;
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
    return fprintf(o->seg, "%.10g %.10g %.10g\n%.10g %.10g %.10g\n", s->p0[0], s->p0[1],
                   s->p0[2], s->p1[0], s->p1[1], s->p1[2]) < 0;
}

static const char hit_header[] =
    "ray,depth,surface,triangle,x,y,z,dx,dy,dz,power_s,power_p,power,length,opl\n";

static int w_hit(void *ctx, const trace_hit *h)
{
    out *o = ctx;
    if (poll_records(o)) return 1;
    return fprintf(o->hit, "%llu,%d,%d,%ld,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,"
                   "%.17g,%.17g,%.17g,%.17g\n", (unsigned long long)h->ray, h->depth,
                   h->surface, h->prim, h->pos[0], h->pos[1], h->pos[2], h->dir[0],
                   h->dir[1], h->dir[2], h->power_s, h->power_p, h->power_s + h->power_p,
                   h->length, h->opl) < 0;
}

/* A progress line on stderr, only on a terminal and once the trace has run 1 s. */
static int w_progress(void *ctx, uint64_t done, uint64_t total)
{
    out *o = ctx;
    double t = now_ms();
    if (stop_now(o)) return 1;
    if (!o->tty || t - o->t0 < 1000 || (t - o->last < 200 && done < total)) return 0;
    o->last = t;
    o->shown = 1;
    fprintf(stderr, "\rlensmat: traced %llu of %llu rays (%.0f%%)", (unsigned long long)done,
            (unsigned long long)total, total ? 100.0 * (double)done / (double)total : 100.0);
    return 0;
}

static char *part_name(const char *name)
{
    char *p = malloc(strlen(name) + 6);
    if (p) sprintf(p, "%s.part", name);
    return p;
}

static FILE *open_part(const char *name, char **part, char *err)
{
    FILE *f;
    if (!(*part = part_name(name))) {
        snprintf(err, SC_ERRMAX, "out of memory");
        return NULL;
    }
    if (!(f = fopen(*part, "w")))
        snprintf(err, SC_ERRMAX, "%s: cannot write: %s", *part, strerror(errno));
    return f;
}

/* Close f and rename part to name when ok (else leave the .part); 0 or -1, with a
 * message in err unless one is there already. */
static int finish(FILE *f, const char *part, const char *name, int ok, char *err)
{
    int bad = ferror(f) | fclose(f);
    if (bad && !err[0]) snprintf(err, SC_ERRMAX, "%s: write error", part);
    if (!ok || bad) return -1;
    if (rename(part, name) && !err[0]) {
        snprintf(err, SC_ERRMAX, "%s: cannot rename to %s: %s", part, name, strerror(errno));
        return -1;
    }
    return 0;
}

static int write_summary(const sc_scene *sc, const trace_summary *s, char *err)
{
    char *part;
    FILE *f = open_part(sc->out_summary, &part, err);
    int rc;
    if (!f) { free(part); return -1; }
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
    rc = finish(f, part, sc->out_summary, 1, err);
    free(part);
    return rc;
}

static int build_scene(const trace_api *tr, const sc_scene *sc, trace_scene **out_ts,
                       char *err)
{
    trace_scene *ts = tr->scene_new();
    if (!ts) return snprintf(err, SC_ERRMAX, "out of memory"), -1;
    for (int i = 0; i < sc->nsurf; i++)
        if (add_surface(tr, ts, &sc->surf[i], err)) goto bad;
    for (int i = 0; i < sc->nsource; i++)
        if (add_source(tr, ts, &sc->source[i], err)) goto bad;
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
    trace_scene *ts;
    trace_options opt;
    trace_sink sink = {0};
    out o = {0};
    int rc;

    err[0] = '\0';
    memset(res, 0, sizeof *res);
    if (!tr) return snprintf(err, SC_ERRMAX, "the trace engine's ABI does not match"), -1;
    if (build_scene(tr, sc, &ts, err)) return -1;
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
    sink.ctx = &o;
    sink.progress = w_progress;
    if (sc->out_segments) {
        if (!(o.seg = open_part(sc->out_segments, &o.seg_part, err))) goto out;
        sink.segment = w_segment;
    }
    if (sc->out_hits) {
        if (!(o.hit = open_part(sc->out_hits, &o.hit_part, err))) goto out;
        fputs(hit_header, o.hit);
        sink.hit = w_hit;
    }
    rc = stop_now(&o) ? TRACE_ECANCEL : tr->run(ts, &opt, &sink, &res->sum);
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
    if (o.seg) finish(o.seg, o.seg_part, sc->out_segments, !err[0], err);
    if (o.hit) finish(o.hit, o.hit_part, sc->out_hits, !err[0], err);
    free(o.seg_part);
    free(o.hit_part);
    tr->scene_free(ts);
    if (!err[0] && sc->out_summary) write_summary(sc, &res->sum, err);
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
