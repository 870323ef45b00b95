/* trace.c -- the ray-tracing dialogue (lensmat --trace): trace a scene file and
 * report what it did; enter a lens surface by surface (as the classic dialogue), or
 * read it from a classic record or prescription file (prescription.c), and trace a
 * fan from an object point for real, against the paraxial image; or the
 * error-against-run-time table of tessellated lenses.  Texts: prompts/trace.txt.
 * The trace module (Embree) is loaded on the first trace only, through
 * lm_engine_symbol: the paraxial part of a session never loads it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "ask.h"
#include "dialogues.h"
#include "draw.h"
#include "engine.h"
#include "../paraxial/paraxial.h"
#include "../trace/scene.h"
#include "prompts_trace.h"

#define P(k) trace_prompts[TRACE_##k]
#define MAXSURF 200
#define FAN 10          /* rays of a fan: heights (i/FAN) h_max, plus one near the axis */
#define NEAR_AXIS 1e-6  /* the near-axis ray's height, relative to h_max */
#define WORD 4096

typedef struct tdlg {
    lm_io *io;
    const scene_api *api;      /* NULL until the first trace */
    sc_scene scene;            /* the scene accepted by the last file question */
    int have_scene;
} tdlg;

typedef unsigned long long ull;

/* The module, loaded on first use.  0, or -1 (why printed by lm_engine_symbol). */
static int need_engine(tdlg *t)
{
    scene_api_fn get;
    if (t->api) return 0;
    get = (scene_api_fn)lm_engine_symbol("trace", SC_API_SYMBOL);
    if (get) t->api = get(SC_API_ABI);
    if (!t->api) {
        if (get) fprintf(stderr, "lensmat: the trace module's interface does not match\n");
        return -1;
    }
    return 0;
}

static int ask_num(tdlg *t, const char *q, const char *what, unsigned flags, double min,
                   double *v)
{
    lm_numspec spec = {what, flags, min};
    return lm_ask_number(t->io, q, q, &spec, v);
}

/* ---- scene files ------------------------------------------------------------------ */

/* The file question's check: the scene must load (its messages name file and line). */
static int check_scene(void *ctx, const char *word, char *msg, size_t cap)
{
    tdlg *t = ctx;
    char err[SC_ERRMAX];
    if (t->have_scene) t->api->free(&t->scene);
    t->have_scene = 0;
    if (lm_check_input(t->io, word, "the scene file", msg, cap)) return -1;
    if (t->api->load(word, &t->scene, err)) {
        snprintf(msg, cap, "%s", err);
        return -1;
    }
    t->have_scene = 1;
    /* the meshes and media files it read are the session's inputs too */
    for (int k = 0; k < t->scene.nsurf; k++) {
        const char *f[2] = {t->scene.surf[k].mesh_file, t->scene.surf[k].media_file};
        for (int m = 0; m < 2; m++) {
            char path[2 * WORD + 2];
            if (!f[m]) continue;
            if (f[m][0] == '/' || !t->scene.dir || !t->scene.dir[0])
                snprintf(path, sizeof path, "%s", f[m]);
            else snprintf(path, sizeof path, "%s/%s", t->scene.dir, f[m]);
            lm_files_note(m ? "the media file" : "the mesh file", path, NULL);
        }
    }
    /* its outputs (and the .part files written first) must not be the answers or
     * the record (the scene's own inputs the loader checked) */
    const char *out[4] = {t->scene.out_segments, t->scene.out_hits, t->scene.out_summary,
                          t->scene.out_polar};
    for (int i = 0; i < 4; i++) {
        char part[WORD + 8], why[512];
        if (!out[i]) continue;
        snprintf(part, sizeof part, "%s.part", out[i]);
        if (lm_check_output(t->io, out[i], why, sizeof why) ||
            lm_check_output(t->io, part, why, sizeof why)) {
            snprintf(msg, cap, "%s: output %s: %s", word, out[i], why);
            t->api->free(&t->scene);
            t->have_scene = 0;
            return -1;
        }
    }
    return 0;
}

static void report_output(tdlg *t, const char *name, const char *what)
{
    char shown[4 * WORD + 4];           /* a scene's name for a file, escaped */
    if (!name) return;
    lm_escape(name, shown, sizeof shown);
    lm_say(t->io, LM_BOTH, P(WRITTEN), shown, what);
}

static void report_outputs(tdlg *t)
{
    const sc_scene *sc = &t->scene;
    const int *f = sc->out_format;   /* what each file holds, in its format */
    report_output(t, sc->out_segments, f[0] == SC_OUT_NPY ? P(WRITTEN_SEGMENTS_NPY) :
                  f[0] == SC_OUT_H5 ? P(WRITTEN_SEGMENTS_H5) : P(WRITTEN_SEGMENTS));
    report_output(t, sc->out_hits, f[1] == SC_OUT_NPY ? P(WRITTEN_HITS_NPY) :
                  f[1] == SC_OUT_H5 ? P(WRITTEN_HITS_H5) : P(WRITTEN_HITS));
    report_output(t, sc->out_summary, f[2] == SC_OUT_H5 ? P(WRITTEN_SUMMARY_H5) :
                  P(WRITTEN_SUMMARY));
    report_output(t, sc->out_polar, sc->out_polar_format == SC_OUT_NPY ?
                  P(WRITTEN_POLAR_NPY) : P(WRITTEN_POLAR));
}

static void report_summary(tdlg *t, const trace_summary *s)
{
    lm_io *io = t->io;
    double bal = s->emitted - (s->detected + s->absorbed + s->escaped + s->cutoff);
    lm_say(io, LM_BOTH, P(RAYS), (ull)s->rays, (ull)s->segments, (ull)s->interactions,
           (ull)s->tir);
    lm_say(io, LM_BOTH, P(HITS), (ull)s->hits);
    lm_say(io, LM_BOTH, P(POWER), s->emitted, s->detected, s->absorbed, s->escaped, s->cutoff);
    lm_say(io, LM_BOTH, P(BALANCE), lm_clean(io, bal));
    lm_say(io, LM_BOTH, P(CUTS), (ull)s->cut_depth, (ull)s->cut_power,
           (ull)s->cut_reflection);
    if (s->failures) lm_say(io, LM_BOTH, P(WARN_FAILURES), (ull)s->failures);
    if (s->medium_mismatch) {
        lm_say(io, LM_BOTH, P(WARN_MISMATCH), (ull)s->medium_mismatch);
        if (t->scene.nmismatch)
            lm_say(io, LM_BOTH, P(MISMATCH_WHERE), t->scene.nmismatch,
                   t->scene.mismatch_where);
        else lm_say(io, LM_BOTH, "%s", P(MISMATCH_UNLOCATED));
        lm_say(io, LM_BOTH, "%s", P(MISMATCH_ERROR));
    }
    if (fabs(bal) > 1e-9 * (s->emitted > 1 ? s->emitted : 1))
        lm_say(io, LM_BOTH, P(WARN_BALANCE), bal);
    lm_say(io, LM_OUT, P(TIMING_OUT), s->build_ms, s->trace_ms,
           s->trace_ms > 0 ? (double)s->rays / (s->trace_ms / 1e3) : 0.0);
    if (s->lens_surfaces)
        lm_say(io, LM_OUT, P(LENS_PATH_OUT), s->lens_surfaces, s->lens_kernel);
}

/* The stop callback long traces poll: a signal arrived (ask.h). */
static int stop_requested(void *ctx)
{
    (void)ctx;
    return lm_stop_requested() != 0;
}

/* Returns LM_GO, LM_QUIT or LM_FAIL (a trace that fails is an error in a replay). */
static int do_scene(tdlg *t)
{
    char name[WORD], err[SC_ERRMAX];
    sc_result res;
    const sc_scene *sc = &t->scene;
    int rc;

    if (need_engine(t)) return LM_FAIL;
    if ((rc = lm_ask_file(t->io, P(SCENE_FILE), P(SCENE_FILE), P(SCENE_FILE_WHAT),
                          check_scene, t, name, sizeof name)))
        return rc;
    lm_say(t->io, LM_BOTH, P(SCENE_LOADED), sc->name, sc->nsurf, sc->nsource, sc->depth,
           sc->cutoff);
    t->scene.stop = stop_requested;
    t->scene.stop_ctx = NULL;
    rc = t->api->run(sc, &res, err);
    if (rc) {
        lm_say(t->io, LM_REC, P(TRACE_FAILED_OUT), err);
        fprintf(stderr, "lensmat: %s\n", err);
        if (res.stopped) return LM_FAIL;     /* main exits with 128 + the signal */
        if (!t->io->interactive) return LM_FAIL;
        return LM_GO;
    }
    for (const char *p = res.note; *p; ) {   /* glasses traced outside their data */
        int len = (int)strcspn(p, "\n");
        lm_say(t->io, LM_BOTH, P(WARN_ABSORPTION), len, p);
        p += len + (p[len] == '\n');
    }
    report_summary(t, &res.sum);
    report_outputs(t);
    return LM_GO;
}

/* ---- a lens: entered surface by surface, or read from a file ----------------------- */

typedef struct lens {
    px_system sys;
    trace_lens_surface surf[MAXSURF];
    trace_lens tl;
} lens;

/* Append surface s to the lens and its paraxial system, and echo it. */
static void add_surface(tdlg *t, lens *l, const trace_lens_surface *s)
{
    l->surf[l->tl.nsurf++] = *s;
    if (isinf(s->radius))
        lm_say(t->io, LM_BOTH, P(SURFACE_ECHO_PLANE), l->tl.nsurf, s->z, s->n_right,
               s->semi_diameter);
    else
        lm_say(t->io, LM_BOTH, P(SURFACE_ECHO), l->tl.nsurf, s->radius, s->z, s->n_right,
               s->semi_diameter);
    px_system_translate(&l->sys, s->z);
    px_system_refract(&l->sys, s->radius, s->n_right);
}

/* A number answer whose check needs the other answers, asked as a word so that a bad
 * one is refused before it is echoed.  0 with *v, or -1 with why in msg. */
static int word_number(const char *word, double *v, char *msg, size_t cap)
{
    enum lm_num_status st = lm_parse_number(word, v);
    if (st == LM_NUM_OK) return 0;
    snprintf(msg, cap, "'%s': %s", word, lm_num_status_text(st));
    return -1;
}

/* The surface being entered, for the checks of its location and semi-diameter. */
typedef struct entering {
    const lens *l;
    trace_lens_surface s;       /* the answers so far */
} entering;

/* The location: not left of the previous surface, and not touching it on the axis
 * with its sag left of the previous one's (no semi-diameter could help then). */
static int check_location(void *ctx, const char *word, char *msg, size_t cap)
{
    entering *e = ctx;
    int n = e->l->tl.nsurf;
    double v, h, rim, edge;
    if (word_number(word, &v, msg, cap)) return -1;
    if (!n) return 0;
    const trace_lens_surface *a = &e->l->surf[n - 1];
    if (v < a->z) {
        snprintf(msg, cap, P(LOCATION_LEFT), word, a->z);
        return -1;
    }
    trace_lens_surface b = {e->s.radius, v, 1, a->semi_diameter};
    if (trace_lens_cross(a, &b, &h, &rim, &edge) && h == 0) {
        snprintf(msg, cap, P(LOCATION_TOUCH), word, n + 1, n, edge, rim);
        return -1;
    }
    return 0;
}

/* The semi-diameter: > 0, at most |radius| (a sphere ends there), and the surface must
 * not cross the previous one within the two semi-diameters. */
static int check_surface_semi(void *ctx, const char *word, char *msg, size_t cap)
{
    entering *e = ctx;
    int n = e->l->tl.nsurf;
    double v, h, rim, edge;
    if (word_number(word, &v, msg, cap)) return -1;
    if (!(v > 0)) {
        snprintf(msg, cap, P(SEMI_ALL_BAD), word);
        return -1;
    }
    if (isfinite(e->s.radius) && v > fabs(e->s.radius)) {
        snprintf(msg, cap, P(SEMI_BIG), word, fabs(e->s.radius));
        return -1;
    }
    trace_lens_surface b = e->s;
    b.semi_diameter = v;
    if (n && trace_lens_cross(&e->l->surf[n - 1], &b, &h, &rim, &edge)) {
        snprintf(msg, cap, P(SEMI_CROSS), word, n, n + 1, h, edge, rim, h);
        return -1;
    }
    return 0;
}

static int enter_surface(tdlg *t, lens *l)
{
    entering e = {l, {0, 0, 0, 0}};
    char word[64];
    int rc;
    if ((rc = ask_num(t, P(RADIUS), P(RADIUS_WHAT), LM_ALLOW_PLANE, 0, &e.s.radius)) ||
        (rc = lm_ask_word(t->io, P(LOCATION), P(LOCATION), P(LOCATION_WHAT),
                          check_location, &e, word, sizeof word)))
        return rc;
    lm_parse_number(word, &e.s.z);
    if ((rc = ask_num(t, P(INDEX_RIGHT), P(INDEX_RIGHT_WHAT), LM_POSITIVE | LM_INDEX, 0, &e.s.n_right)) ||
        (rc = lm_ask_word(t->io, P(SEMI), P(SEMI), P(SEMI_WHAT), check_surface_semi, &e,
                          word, sizeof word)))
        return rc;
    lm_parse_number(word, &e.s.semi_diameter);
    add_surface(t, l, &e.s);
    return LM_GO;
}

/* A fraction in (0, 1], asked as a word so that a bad answer is refused before it is
 * echoed. */
static int check_fraction(void *ctx, const char *word, char *msg, size_t cap)
{
    double v;
    (void)ctx;
    if (lm_parse_number(word, &v) != LM_NUM_OK || !(v > 0 && v <= 1)) {
        snprintf(msg, cap, "'%s': give a number greater than 0 and at most 1", word);
        return -1;
    }
    return 0;
}

/* Paraxial image of the object (z_obj = -inf: at infinity).  0, or -1 at infinity. */
static int paraxial_image(const lens *l, double z_obj, double *z_img)
{
    px_image im;
    px_cardinal k;
    if (isinf(z_obj)) {
        px_cardinal_points(&l->sys, 0, &k);
        *z_img = k.focal2;
        return 0;
    }
    if (px_image_plane(&l->sys, z_obj, &im) == PX_AT_INFINITY) return -1;
    *z_img = im.z_img;
    return 0;
}

static void report_fan(tdlg *t, const double *h, const trace_fan_ray *r, int n, double z_img,
                       const lens *l)
{
    lm_io *io = t->io;
    lm_say(io, LM_BOTH, P(FAN_HEAD));
    for (int i = 0; i < n; i++) {
        const char *why = r[i].status == 1 ? P(FAN_VIGNETTED) : r[i].status == 2 ? P(FAN_TIR)
                        : P(FAN_PARALLEL);
        if (r[i].status) lm_say(io, LM_BOTH, P(FAN_MISS), h[i], why);
        else lm_say(io, LM_BOTH, P(FAN_ROW), r[i].h, r[i].z_cross, lm_clean(io, r[i].lsa),
                    lm_clean(io, r[i].y_image));
    }
    if (!r[0].status) {
        double scale = fabs(z_img - l->sys.z_last);
        lm_say(io, LM_BOTH, P(FAN_AGREE), r[0].h, fabs(r[0].lsa) / (scale > 0 ? scale : 1));
    }
}

static int trace_object(tdlg *t, lens *l)
{
    lm_io *io = t->io;
    double d, z_obj, z_img, frac, h[FAN + 1];
    trace_fan_ray out[FAN + 1];
    char word[64], err[SC_ERRMAX];
    int rc;

    if ((rc = ask_num(t, P(OBJECT), P(OBJECT_WHAT), LM_POSITIVE | LM_ALLOW_INF, 0, &d)) ||
        (rc = lm_ask_word(io, P(HEIGHT), P(HEIGHT), P(HEIGHT_WHAT), check_fraction, NULL,
                          word, sizeof word)))
        return rc;
    lm_parse_number(word, &frac);
    z_obj = isinf(d) ? -INFINITY : l->sys.z_first - d;
    if (isinf(z_obj)) lm_say(io, LM_BOTH, P(OBJECT_ECHO_INF));
    else lm_say(io, LM_BOTH, P(OBJECT_ECHO), z_obj);
    if (paraxial_image(l, z_obj, &z_img)) {
        lm_say(io, LM_BOTH, P(PARAXIAL_INFINITY));
        return LM_GO;
    }
    lm_say(io, LM_BOTH, P(PARAXIAL), lm_clean(io, z_img));
    if (z_img <= l->sys.z_last) {   /* the fan is traced forward to a detector there */
        lm_say(io, LM_BOTH, P(PARAXIAL_VIRTUAL));
        return LM_GO;
    }
    h[0] = NEAR_AXIS * frac * l->surf[0].semi_diameter;
    for (int i = 1; i <= FAN; i++) h[i] = frac * l->surf[0].semi_diameter * i / FAN;
    if (need_engine(t)) return LM_FAIL;
    l->tl.surf = l->surf;
    l->tl.mounts = 1;
    l->tl.z_detector = NAN;
    if (t->api->engine->lens_fan(&l->tl, z_obj, 0, z_img, FAN + 1, h, out, err,
                                 sizeof err)) {
        lm_say(io, LM_BOTH, P(LENS_FAILED), err);
        return io->interactive ? LM_GO : LM_FAIL;
    }
    report_fan(t, h, out, FAN + 1, z_img, l);
    lm_draw_remember(&l->tl, z_obj, frac);   /* for the "draw" choice */
    return LM_GO;
}

/* The object points of a lens whose surfaces are in: fan, LSA, as many as asked. */
static int trace_objects(tdlg *t, lens *l)
{
    int rc, more;
    if (px_is_afocal(&l->sys)) {
        lm_say(t->io, LM_BOTH, P(AFOCAL));
        return LM_GO;
    }
    do {
        if ((rc = trace_object(t, l))) return rc;
        if ((rc = lm_ask_yn(t->io, P(ANOTHER_OBJECT), P(ANOTHER_OBJECT),
                            P(ANOTHER_OBJECT_WHAT), &more)))
            return rc;
    } while (more);
    return LM_GO;
}

static int do_lens(tdlg *t)
{
    lm_io *io = t->io;
    lens *l = calloc(1, sizeof *l);
    int rc, more;

    if (!l) return LM_FAIL;
    if ((rc = ask_num(t, P(INDEX_LEFT), P(INDEX_LEFT_WHAT), LM_POSITIVE | LM_INDEX, 0, &l->tl.n_object)))
        goto out;
    px_system_init(&l->sys, l->tl.n_object);
    do {
        if ((rc = enter_surface(t, l))) goto out;
        if (l->tl.nsurf == MAXSURF) break;
        if ((rc = lm_ask_yn(io, P(ANOTHER_SURFACE), P(ANOTHER_SURFACE),
                            P(ANOTHER_SURFACE_WHAT), &more)))
            goto out;
    } while (more);
    rc = trace_objects(t, l);
out:
    px_system_free(&l->sys);   /* zeroed by calloc if never initialised */
    free(l);
    return rc;
}

/* The largest semi-diameter lf's surfaces can share: *max (inf: planes only) is the
 * smallest |radius| (a sphere ends there), or lower where two consecutive surfaces
 * would cross (*cross: the first of them, 1-based; 0 if none).  -1 if two surfaces
 * cross on the axis, where no semi-diameter helps (*cross says which). */
static int lens_file_limit(const lm_lens_file *lf, double *max, int *cross)
{
    double h, rim, edge;
    *max = INFINITY;
    *cross = 0;
    for (int i = 0; i < lf->nsurf; i++)
        if (isfinite(lf->surf[i].radius)) *max = fmin(*max, fabs(lf->surf[i].radius));
    if (isinf(*max)) return 0;
    for (int i = 1; i < lf->nsurf; i++) {
        trace_lens_surface a = {lf->surf[i - 1].radius, lf->surf[i - 1].z, 1, *max};
        trace_lens_surface b = {lf->surf[i].radius, lf->surf[i].z, 1, *max};
        if (!trace_lens_cross(&a, &b, &h, &rim, &edge)) continue;
        *cross = i;
        if (h == 0) return -1;
        *max = h;
    }
    return 0;
}

/* The record question's check: the file must read as a lens (a classic record, its
 * answers, or a prescription; messages with file and line) of at most MAXSURF
 * surfaces, none touching the next on the axis and crossing it. */
static int check_lens_file(void *ctx, const char *word, char *msg, size_t cap)
{
    lm_lens_file *lf = ctx;
    double max;
    int cross;
    lm_lens_file_free(lf);
    if (lm_check_input(NULL, word, "the lens file", msg, cap)) return -1;
    if (lm_read_lens(word, lf, msg, cap)) return -1;
    if (lf->nsurf > MAXSURF) {
        snprintf(msg, cap, P(RECORD_TOO_MANY), word, lf->nsurf, MAXSURF);
        lm_lens_file_free(lf);
        return -1;
    }
    if (lens_file_limit(lf, &max, &cross)) {
        snprintf(msg, cap, P(RECORD_TOUCH), word, cross, cross + 1, lf->surf[cross].z);
        lm_lens_file_free(lf);
        return -1;
    }
    return 0;
}

typedef struct semi_limit {
    double max;
    int cross;          /* the limit is where surfaces cross, cross + 1 cross (0: none) */
} semi_limit;

/* The semi-diameter's check: > 0 and at most the limit. */
static int check_semi(void *ctx, const char *word, char *msg, size_t cap)
{
    const semi_limit *lim = ctx;
    double v;
    if (lm_parse_number(word, &v) != LM_NUM_OK || !(v > 0)) {
        snprintf(msg, cap, P(SEMI_ALL_BAD), word);
        return -1;
    }
    if (v > lim->max) {
        if (lim->cross) snprintf(msg, cap, P(SEMI_ALL_CROSSES), word, lim->cross,
                                 lim->cross + 1, lim->max);
        else snprintf(msg, cap, P(SEMI_ALL_BIG), word, lim->max);
        return -1;
    }
    return 0;
}

/* One semi-diameter for every surface of lf: *semi.  The largest allowed (the smallest
 * |radius|, or where two surfaces would cross) is said in the question. */
static int ask_semi_all(tdlg *t, const lm_lens_file *lf, double *semi)
{
    semi_limit lim;
    char q[512], word[64];
    int rc;
    lens_file_limit(lf, &lim.max, &lim.cross);
    if (isinf(lim.max)) snprintf(q, sizeof q, "%s", P(SEMI_ALL_PLANE));
    else if (lim.cross) snprintf(q, sizeof q, P(SEMI_ALL_CROSS), lim.max, lim.cross,
                                 lim.cross + 1);
    else snprintf(q, sizeof q, P(SEMI_ALL), lim.max);
    if ((rc = lm_ask_word(t->io, q, q, P(SEMI_ALL_WHAT), check_semi, &lim, word,
                          sizeof word)))
        return rc;
    lm_parse_number(word, semi);
    return LM_GO;
}

/* A lens read from a classic record, its answers or a prescription file. */
static int do_record(tdlg *t)
{
    lm_io *io = t->io;
    lm_lens_file lf = {0};
    lens *l = NULL;
    char name[WORD];
    double semi;
    int rc;

    if ((rc = lm_ask_file(io, P(RECORD_FILE), P(RECORD_FILE), P(RECORD_FILE_WHAT),
                          check_lens_file, &lf, name, sizeof name)) ||
        (rc = ask_semi_all(t, &lf, &semi)))
        goto out;
    if (!(l = calloc(1, sizeof *l))) { rc = LM_FAIL; goto out; }
    lm_say(io, LM_BOTH, P(RECORD_LENS), lf.nsurf, lf.n_object);
    l->tl.n_object = lf.n_object;
    px_system_init(&l->sys, lf.n_object);
    for (int i = 0; i < lf.nsurf; i++) {
        trace_lens_surface s = {lf.surf[i].radius, lf.surf[i].z, lf.surf[i].n_right, semi};
        add_surface(t, l, &s);
    }
    if (lf.nobj) {
        lm_say(io, LM_BOTH, "%s", P(RECORD_OBJECTS));
        for (int i = 0; i < lf.nobj; i++)
            lm_say(io, LM_BOTH, P(RECORD_OBJECT), lm_clean(io, l->sys.z_first - lf.obj[i]));
        lm_say(io, LM_BOTH, "\n");
    }
    rc = trace_objects(t, l);
out:
    if (l) px_system_free(&l->sys);
    free(l);
    lm_lens_file_free(&lf);
    return rc;
}

/* ---- the error-against-run-time table ------------------------------------------------ */

static int check_grid(void *ctx, const char *word, char *msg, size_t cap)
{
    double v;
    (void)ctx;
    if (lm_parse_number(word, &v) != LM_NUM_OK || v != floor(v) || v < 1 || v > 2000) {
        snprintf(msg, cap, "'%s': give a whole number from 1 to 2000", word);
        return -1;
    }
    return 0;
}

/* The table's semi-diameter: > 0, at most each |radius|, and the two surfaces must
 * not cross within it (sp holds r1, r2 and the thickness). */
static int check_table_semi(void *ctx, const char *word, char *msg, size_t cap)
{
    const sc_tess_spec *sp = ctx;
    double v, h, rim, edge, r = fmin(fabs(sp->r1), fabs(sp->r2));
    if (word_number(word, &v, msg, cap)) return -1;
    if (!(v > 0)) {
        snprintf(msg, cap, P(SEMI_ALL_BAD), word);
        return -1;
    }
    if (v > r) {
        snprintf(msg, cap, P(SEMI_ALL_BIG), word, r);
        return -1;
    }
    trace_lens_surface a = {sp->r1, 0, sp->n, v}, b = {sp->r2, sp->thickness, 1, v};
    if (trace_lens_cross(&a, &b, &h, &rim, &edge)) {
        snprintf(msg, cap, P(SEMI_CROSS), word, 1, 2, h, edge, rim, h);
        return -1;
    }
    return 0;
}

static void table_rows(tdlg *t, const sc_tess_row *rows, int n)
{
    lm_io *io = t->io;
    lm_say(io, LM_OUT, "%s", P(T_HEAD_OUT));
    lm_say(io, LM_REC, "%s", P(T_HEAD_REC));
    for (int i = 0; i < n; i++) {
        const sc_tess_row *r = &rows[i];
        char name[64];
        const char *fmt = r->model == SC_MODEL_ANALYTIC ? P(T_ANALYTIC)
                        : r->model == SC_MODEL_MESH ? P(T_MESH)
                        : r->model == SC_MODEL_MESH_NORMAL ? P(T_MESH_NORMAL) : P(T_MESH_FULL);
        snprintf(name, sizeof name, fmt, r->level);
        lm_say(io, LM_OUT, P(T_ROW_OUT), name, r->triangles, r->build_ms, r->trace_ms,
               r->rays_per_s, r->err_max, r->err_rms, r->lost);
        lm_say(io, LM_REC, P(T_ROW_REC), name, r->triangles, r->err_max, r->err_rms, r->lost);
    }
}

static int tess_table(tdlg *t)
{
    static const int levels[] = {4, 8, 16, 32, 64, 128};
    enum { NL = sizeof levels / sizeof levels[0] };
    lm_io *io = t->io;
    sc_tess_spec sp = {0};
    sc_tess_row rows[1 + 3 * NL];
    lens l;
    char word[64], err[SC_ERRMAX];
    double g;
    int rc;

    lm_say(io, LM_BOTH, "%s", P(TABLE_INTRO));
    if ((rc = ask_num(t, P(T_R1), P(T_R1_WHAT), LM_ALLOW_PLANE, 0, &sp.r1)) ||
        (rc = ask_num(t, P(T_R2), P(T_R2_WHAT), LM_ALLOW_PLANE, 0, &sp.r2)) ||
        (rc = ask_num(t, P(T_THICK), P(T_THICK_WHAT), LM_POSITIVE, 0, &sp.thickness)) ||
        (rc = ask_num(t, P(T_INDEX), P(T_INDEX_WHAT), LM_POSITIVE | LM_INDEX, 0, &sp.n)) ||
        (rc = lm_ask_word(io, P(T_SEMI), P(T_SEMI), P(T_SEMI_WHAT), check_table_semi, &sp,
                          word, sizeof word)))
        return rc;
    lm_parse_number(word, &sp.aperture);
    if ((rc = lm_ask_word(io, P(T_GRID), P(T_GRID), P(T_GRID_WHAT), check_grid, NULL, word,
                          sizeof word)))
        return rc;
    lm_parse_number(word, &g);
    sp.grid = (long)g;
    /* the paraxial focus, from the paraxial engine */
    px_system_init(&l.sys, 1);
    px_system_translate(&l.sys, 0);
    px_system_refract(&l.sys, sp.r1, sp.n);
    px_system_translate(&l.sys, sp.thickness);
    px_system_refract(&l.sys, sp.r2, 1);
    if (px_is_afocal(&l.sys)) {
        px_system_free(&l.sys);
        lm_say(io, LM_BOTH, "%s", P(T_NO_FOCUS));
        return LM_GO;
    }
    paraxial_image(&l, -INFINITY, &sp.z_detector);
    px_system_free(&l.sys);
    sp.beam_radius = 0.9 * sp.aperture;
    sp.levels = levels;
    sp.nlevels = NL;
    sp.r1 = isinf(sp.r1) ? 0 : sp.r1;
    sp.r2 = isinf(sp.r2) ? 0 : sp.r2;
    lm_say(io, LM_BOTH, P(T_LENS), sp.r1, sp.r2, sp.thickness, sp.n, sp.aperture,
           sp.z_detector, sp.beam_radius, sp.grid, sp.grid);
    if (need_engine(t)) return LM_FAIL;
    sp.stop = stop_requested;
    if (t->api->tess_table(&sp, rows, err)) {
        lm_say(io, LM_BOTH, P(T_FAILED), err);
        return io->interactive && !lm_stop_requested() ? LM_GO : LM_FAIL;
    }
    table_rows(t, rows, 1 + 3 * NL);
    return LM_GO;
}

/* ---- the dialogue ------------------------------------------------------------------- */

int lm_trace(lm_io *io)
{
    static const char *const modes[] = {"scene", "lens", "record", "table", "draw", NULL};
    tdlg t = {io, NULL, {0}, 0};
    int rc, mode, more;

    lm_say(io, LM_BOTH, "%s", P(INTRO));
    do {
        if ((rc = lm_ask_choice(io, P(MODE), P(MODE), P(MODE_WHAT), modes, &mode))) break;
        rc = mode == 0 ? do_scene(&t) : mode == 1 ? do_lens(&t)
           : mode == 2 ? do_record(&t) : mode == 3 ? tess_table(&t) : lm_draw_last(io);
        if (rc) break;
        rc = lm_ask_yn(io, P(ANOTHER), P(ANOTHER), P(ANOTHER_WHAT), &more);
    } while (!rc && more);
    if (t.have_scene) t.api->free(&t.scene);
    if (rc) return rc;
    lm_check_leftover(io);
    lm_say(io, LM_OUT, P(WRITTEN_OUT), io->rec_shown);
    return LM_GO;
}

const char *lm_trace_example(void) { return P(EXAMPLE); }
