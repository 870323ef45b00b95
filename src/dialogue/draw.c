/* draw.c -- the pictures dialogue (lensmat --draw): read a lens from a classic record,
 * its answers or a prescription file, give its surfaces semi-diameters, choose an
 * object point, then draw as many pictures as asked -- the layout with real rays and
 * the cardinal points, a spot diagram at the paraxial image, a ray-fan plot -- each
 * written as NAME.png and NAME.svg.  Also the --trace dialogue's pictures of the lens
 * it just traced (draw.h).  Texts: prompts/draw.txt.  The imaging (OpenCV) and trace
 * (Embree) modules are loaded when the first picture is drawn, so the questions
 * before cost nothing. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#include "ask.h"
#include "../lens/lens.h"
#include "dialogues.h"
#include "draw.h"
#include "drawcalc.h"
#include "engine.h"
#include "prompts_draw.h"
#include "../trace/scene.h"

#define P(k) draw_prompts[DRAW_##k]
#define MAXSURF 200
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define WORD 4096
#define TABLE_GRID 201   /* the table's bundle: 201 x 201 cells (31 700 rays) */

typedef struct dsess {
    lm_io *io;
    const imaging_api *im;
    const trace_api *tr;
    const scene_api *sa;             /* the trace front end (the table), on first use */
    trace_lens_surface surf[MAXSURF];
    trace_lens lens;
    dw_scene sc;
    char unit[8];
    int have_lens_file;
    unsigned long long lens_dev, lens_ino;
    lm_lens_file lf;                 /* while the lens file question is asked */
    char name[WORD];                 /* the lens file, for titles */
} dsess;

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

/* The engines, loaded on the first picture.  0, or -1 (said on stderr). */
static int need_engines(dsess *d, double *load_ms, double *trace_ms)
{
    double t0 = now_ms();
    *load_ms = *trace_ms = 0;
    if (!d->im) {
        imaging_get_api_fn get = (imaging_get_api_fn)lm_engine_symbol("imaging",
                                                                      IMAGING_API_SYMBOL);
        d->im = get ? get(IMAGING_ABI) : NULL;
        if (!d->im || !d->im->draw) { d->im = NULL; fputs(P(NO_IMAGING), stderr); return -1; }
        *load_ms = now_ms() - t0;
    }
    if (!d->tr) {
        t0 = now_ms();
        trace_get_api_fn get = (trace_get_api_fn)lm_engine_symbol("trace", TRACE_API_SYMBOL);
        d->tr = get ? get(TRACE_ABI) : NULL;
        if (!d->tr) { fputs(P(NO_TRACE), stderr); return -1; }
        *trace_ms = now_ms() - t0;
    }
    return 0;
}

/* ---- the lens ---------------------------------------------------------------------- */

static int check_lens_file(void *ctx, const char *word, char *msg, size_t cap)
{
    dsess *d = ctx;
    struct stat st;
    lm_lens_file_free(&d->lf);
    if (lm_check_input(d->io, word, "the lens file", msg, cap)) return -1;
    if (lm_read_lens(word, &d->lf, msg, cap)) return -1;
    if (d->lf.nsurf > MAXSURF) {
        snprintf(msg, cap, P(TOO_MANY), word, d->lf.nsurf, MAXSURF);
        lm_lens_file_free(&d->lf);
        return -1;
    }
    if (stat(word, &st) == 0) {
        d->have_lens_file = 1;
        d->lens_dev = st.st_dev;
        d->lens_ino = st.st_ino;
    }
    return 0;
}

/* "8" or "8,8,5.5,...": into out[] (nsurf values); 0 or -1 with why in msg. */
static int parse_semis(dsess *d, const char *word, double *out, char *msg, size_t cap)
{
    int n = d->lf.nsurf, k = 0;
    const char *p = word;
    char tok[64];
    while (*p) {
        size_t len = strcspn(p, ",");
        double v;
        if (k == n || len == 0 || len >= sizeof tok) goto bad;
        memcpy(tok, p, len);
        tok[len] = '\0';
        if (lm_parse_number(tok, &v) != LM_NUM_OK || !(v > 0) || !isfinite(v)) goto bad;
        out[k++] = v;
        p += len;
        if (*p == ',') { p++; if (!*p) goto bad; }
    }
    if (k == 1) for (int i = 1; i < n; i++) out[i] = out[0];
    else if (k != n) goto bad;
    {   /* a zone the sphere has not, neighbours that cross: the lens model's check */
        ln_surface sf[MAXSURF];
        double z[MAXSURF];
        char why[LN_ERR_MAX];
        int bad;
        memset(sf, 0, sizeof sf);
        for (int i = 0; i < n; i++) {
            ln_set_radius(&sf[i], d->lf.surf[i].radius);
            sf[i].semi = out[i];
            z[i] = d->lf.surf[i].z;
        }
        if (ln_shape_check(sf, z, n, &bad, why, sizeof why) != LN_OK) {
            snprintf(msg, cap, "'%s': %s", word, why);
            return -1;
        }
    }
    return 0;
bad:
    snprintf(msg, cap, P(SEMI_BAD), word, n);
    return -1;
}

static int check_semis(void *ctx, const char *word, char *msg, size_t cap)
{
    double v[MAXSURF];
    return parse_semis(ctx, word, v, msg, cap);
}

static void echo_lens(dsess *d)
{
    lm_say(d->io, LM_BOTH, P(LENS_ECHO), d->lens.nsurf, d->lens.n_object);
    for (int i = 0; i < d->lens.nsurf; i++) {
        const trace_lens_surface *s = &d->surf[i];
        if (isinf(s->radius))
            lm_say(d->io, LM_BOTH, P(SURFACE_ECHO_PLANE), i + 1, s->z, s->n_right, s->semi_diameter);
        else
            lm_say(d->io, LM_BOTH, P(SURFACE_ECHO), i + 1, s->radius, s->z, s->n_right,
                   s->semi_diameter);
    }
}

static int read_lens(dsess *d)
{
    char word[WORD], q[512], msg[256];
    char *name = d->name;
    double semi[MAXSURF];
    int rc;
    if ((rc = lm_ask_file(d->io, P(LENS_FILE), P(LENS_FILE), P(LENS_FILE_WHAT),
                          check_lens_file, d, name, sizeof d->name)))
        return rc;
    snprintf(q, sizeof q, P(SEMI), d->lf.nsurf);
    if ((rc = lm_ask_word(d->io, q, q, P(SEMI_WHAT), check_semis, d, word, sizeof word)))
        return rc;
    parse_semis(d, word, semi, msg, sizeof msg);
    d->lens.n_object = d->lf.n_object;
    d->lens.nsurf = d->lf.nsurf;
    d->lens.surf = d->surf;
    d->sc.lens = &d->lens;
    for (int i = 0; i < d->lf.nsurf; i++) {
        d->surf[i].radius = d->lf.surf[i].radius;
        d->surf[i].z = d->lf.surf[i].z;
        d->surf[i].n_right = d->lf.surf[i].n_right;
        d->surf[i].semi_diameter = semi[i];
    }
    echo_lens(d);
    if (d->lf.nobj) {   /* the file's own object planes, ready for the object question */
        lm_say(d->io, LM_BOTH, "%s", P(FILE_OBJECTS));
        for (int i = 0; i < d->lf.nobj; i++)
            lm_say(d->io, LM_BOTH, P(FILE_OBJECT), lm_clean(d->io, d->surf[0].z - d->lf.obj[i]));
        lm_say(d->io, LM_BOTH, "\n");
    }
    return LM_GO;
}

/* ---- the object ------------------------------------------------------------------------ */

static int check_fill(void *ctx, const char *word, char *msg, size_t cap)
{
    double v;
    (void)ctx;
    if (lm_parse_number(word, &v) != LM_NUM_OK || !(v > 0 && v <= 1)) {
        snprintf(msg, cap, P(FILL_BAD), word);
        return -1;
    }
    return 0;
}

static int check_angle(void *ctx, const char *word, char *msg, size_t cap)
{
    double v;
    (void)ctx;
    if (lm_parse_number(word, &v) != LM_NUM_OK || !(fabs(v) < 80)) {
        snprintf(msg, cap, P(ANGLE_BAD), word);
        return -1;
    }
    return 0;
}

static int ask_unit(dsess *d)
{
    static const char *const units[] = {"mm", "cm", "m", "in", "none", NULL};
    int u, rc;
    if ((rc = lm_ask_choice(d->io, P(UNIT), P(UNIT), P(UNIT_WHAT), units, &u))) return rc;
    snprintf(d->unit, sizeof d->unit, "%s", units[u]);
    d->sc.unit = u == 4 ? NULL : d->unit;
    return LM_GO;
}

static void echo_first(dsess *d)
{
    lm_io *io = d->io;
    dw_first f;
    dw_first_order(&d->sc, &f);
    if (f.afocal) { lm_say(io, LM_BOTH, "%s", P(FIRST_AFOCAL)); return; }
    lm_say(io, LM_BOTH, P(FIRST_ECHO), f.z_f1, f.z_f2, f.z_h1, f.z_h2, f.z_n1, f.z_n2);
    if (isfinite(f.z_img))
        lm_say(io, LM_BOTH, P(IMAGE_ECHO), f.z_img, lm_clean(io, f.y_img),
               f.image_virtual ? P(IMAGE_VIRTUAL) : "");
    else lm_say(io, LM_BOTH, "%s", P(IMAGE_NONE));
}

static int ask_object(dsess *d)
{
    lm_numspec dist = {P(OBJECT_WHAT), LM_POSITIVE | LM_ALLOW_INF, 0};
    lm_numspec height = {P(HEIGHT_WHAT), 0, 0};
    double v, f;
    char word[64];
    int rc;
    if ((rc = lm_ask_number(d->io, P(OBJECT), P(OBJECT), &dist, &v))) return rc;
    d->sc.z_obj = isinf(v) ? -INFINITY : d->surf[0].z - v;
    if (isinf(v)) {
        if ((rc = lm_ask_word(d->io, P(ANGLE), P(ANGLE), P(ANGLE_WHAT), check_angle, NULL,
                              word, sizeof word)))
            return rc;
        lm_parse_number(word, &f);
        d->sc.field = f * M_PI / 180;
    } else {
        if ((rc = lm_ask_number(d->io, P(HEIGHT), P(HEIGHT), &height, &f))) return rc;
        d->sc.field = f;
    }
    if ((rc = lm_ask_word(d->io, P(FILL), P(FILL), P(FILL_WHAT), check_fill, NULL, word,
                          sizeof word)))
        return rc;
    lm_parse_number(word, &d->sc.frac);
    if (isinf(v)) lm_say(d->io, LM_BOTH, P(OBJECT_ECHO_INF), f);
    else lm_say(d->io, LM_BOTH, P(OBJECT_ECHO), d->sc.z_obj, f);
    echo_first(d);
    return LM_GO;
}

/* ---- pictures ---------------------------------------------------------------------------- */

typedef struct pic { dsess *d; char svg[WORD]; } pic;

/* The picture question's check: NAME.png, neither NAME.png nor NAME.svg an input of
 * this session, the folder writable. */
static int check_picture(void *ctx, const char *word, char *msg, size_t cap)
{
    pic *p = ctx;
    size_t n = strlen(word);
    struct stat st;
    char dir[WORD];
    const char *slash;
    if (n < 5 || strcasecmp(word + n - 4, ".png") || n >= sizeof p->svg) {
        snprintf(msg, cap, P(PICTURE_PNG), word);
        return -1;
    }
    snprintf(p->svg, sizeof p->svg, "%.*s.svg", (int)(n - 4), word);
    if (lm_check_output(p->d->io, word, msg, cap) || lm_check_output(p->d->io, p->svg, msg, cap))
        return -1;
    for (int k = 0; k < 2; k++) {
        const char *f = k ? p->svg : word;
        if (p->d->have_lens_file && stat(f, &st) == 0 && (unsigned long long)st.st_dev == p->d->lens_dev &&
            (unsigned long long)st.st_ino == p->d->lens_ino) {
            snprintf(msg, cap, P(PICTURE_INPUT), f);
            return -1;
        }
    }
    slash = strrchr(word, '/');
    if (slash) snprintf(dir, sizeof dir, "%.*s", slash == word ? 1 : (int)(slash - word), word);
    else snprintf(dir, sizeof dir, ".");
    if (access(dir, W_OK | X_OK) != 0) {
        snprintf(msg, cap, P(PICTURE_DIR), word, dir);
        return -1;
    }
    return 0;
}

static const char *unit_name(const dsess *d) { return d->sc.unit ? d->sc.unit : "unit"; }

/* The wavelength in lens units from nanometres (0 without a unit). */
static double lens_wavelength(const dsess *d, double nm)
{
    static const char *const u[] = {"mm", "cm", "m", "in"};
    static const double per_nm[] = {1e-6, 1e-7, 1e-9, 1e-9 / 0.0254};
    for (int i = 0; i < 4; i++)
        if (d->sc.unit && !strcmp(d->sc.unit, u[i])) return nm * per_nm[i];
    return 0;
}

static void report_layout(dsess *d, const im_layout_info *li)
{
    lm_io *io = d->io;
    lm_say(io, LM_OUT, P(SCALE_OUT), li->px_per_unit, unit_name(d), li->y0, li->x0);
    for (int i = 0; i < li->nmark; i++)
        lm_say(io, LM_OUT, P(MARK_OUT), li->mark[i].name, li->mark[i].x, li->mark[i].label_x,
               li->mark[i].label_y);
    if (li->offpicture) lm_say(io, LM_BOTH, P(OFFPICTURE), li->offpicture);
}

static const char *const whats[] = {"layout", "spot", "fan", "table", "done", NULL};
enum { W_LAYOUT, W_SPOT, W_FAN, W_TABLE, W_DONE };

static void report_table(dsess *d, const sc_tess_row *rows)
{
    static const char *const model[] = {"analytic", "mesh", "mesh +normal", "mesh +refine"};
    for (int i = 0; i < 1 + 3 * DW_TESS_LEVELS; i++) {
        const sc_tess_row *r = &rows[i];
        lm_say(d->io, LM_BOTH, P(TABLE_ROW), model[r->model], r->level, r->triangles,
               r->err_rms, r->err_max, r->lost);
        lm_say(d->io, LM_OUT, P(TABLE_TIME_OUT), r->trace_ms);
        lm_say(d->io, LM_BOTH, "\n");
    }
}

static int stop_asked(void *ctx) { (void)ctx; return lm_stop_requested(); }

/* One picture: its questions, drawing, report. */
static int picture(dsess *d, int what)
{
    lm_io *io = d->io;
    lm_numspec wl = {P(WAVELENGTH_WHAT), LM_NONNEG, 0};
    pic p = {d, ""};
    char png[WORD], err[1024], title[256];
    double nm = 0, load_ms, trace_ms, t0, airy = 0;
    im_layout_info li;
    im_sd_info si;
    im_plot_info pi;
    sc_tess_row rows[1 + 3 * DW_TESS_LEVELS];
    int rc;

    if (what == W_SPOT && d->sc.unit &&
        (rc = lm_ask_number(io, P(WAVELENGTH), P(WAVELENGTH), &wl, &nm)))
        return rc;
    if ((rc = lm_ask_file(io, P(PICTURE), P(PICTURE), P(PICTURE_WHAT), check_picture, &p, png,
                          sizeof png)))
        return rc;
    if (need_engines(d, &load_ms, &trace_ms)) return LM_FAIL;
    if (what == W_TABLE && !d->sa) {
        scene_api_fn get = (scene_api_fn)lm_engine_symbol("trace", SC_API_SYMBOL);
        if (!get || !(d->sa = get(SC_API_ABI))) { fputs(P(NO_TRACE), stderr); return LM_FAIL; }
    }
    d->sc.lens = &d->lens;
    d->sc.wavelength = lens_wavelength(d, nm);
    im_out out = {png, p.svg, 0, 0, stop_asked, NULL};
    t0 = now_ms();
    if (what == W_LAYOUT) {
        const char *base = strrchr(d->name, '/');
        base = base ? base + 1 : d->name[0] ? d->name : "the lens traced";
        snprintf(title, sizeof title, "%.120s: %d surface%s, real rays, cardinal points", base,
                 d->lens.nsurf, d->lens.nsurf == 1 ? "" : "s");
        rc = dw_layout(d->tr, d->im, &d->sc, title, &out, &li, err, sizeof err);
    } else if (what == W_SPOT) {
        snprintf(title, sizeof title, "Spot diagram at the paraxial image plane");
        rc = dw_spot(d->tr, d->im, &d->sc, title, &out, &si, &airy, err, sizeof err);
    } else if (what == W_FAN) {
        snprintf(title, sizeof title, "Ray fan: transverse aberration");
        rc = dw_fan(d->tr, d->im, &d->sc, title, &out, &pi, err, sizeof err);
    } else {
        snprintf(title, sizeof title, "Tessellated first element: error against trace time");
        lm_say(io, LM_BOTH, P(TABLE_INTRO), TABLE_GRID, TABLE_GRID);
        rc = dw_table(d->sa, d->im, &d->sc, TABLE_GRID, title, &out, rows, err, sizeof err);
    }
    if (lm_stop_requested()) return LM_FAIL;   /* nothing written (im_out.stop) */
    if (rc) {
        lm_say(io, LM_BOTH, P(FAILED), err);
        return io->interactive ? LM_GO : LM_FAIL;
    }
    lm_say(io, LM_OUT, P(TIMING_OUT), now_ms() - t0, load_ms, trace_ms);
    char ep[4200], es[4200];           /* the names, control bytes escaped */
    lm_escape(png, ep, sizeof ep);
    lm_escape(p.svg, es, sizeof es);
    lm_say(io, LM_BOTH, P(WRITTEN), ep, es,
           what == W_LAYOUT ? P(WRITTEN_LAYOUT) : what == W_SPOT ? P(WRITTEN_SPOT)
           : what == W_FAN ? P(WRITTEN_FAN) : P(WRITTEN_TABLE));
    if (what == W_TABLE) report_table(d, rows);
    if (what == W_LAYOUT) report_layout(d, &li);
    if (what == W_SPOT) {
        int ng = d->sc.field != 0 ? 2 : 1;
        for (int g = 0; g < ng; g++)
            lm_say(io, LM_BOTH, P(SPOT_STATS), g ? "off the axis" : "on the axis", si.group[g].n,
                   lm_clean(io, si.group[g].cx), lm_clean(io, si.group[g].cy), si.group[g].rms,
                   si.group[g].rmax);
        if (airy > 0) lm_say(io, LM_BOTH, P(SPOT_AIRY), airy, nm);
    }
    if (what == W_FAN && pi.skipped) lm_say(io, LM_BOTH, P(FAN_SKIPPED), pi.skipped);
    return LM_GO;
}

static int pictures(dsess *d)
{
    int rc, what;
    for (;;) {
        if ((rc = lm_ask_choice(d->io, P(WHAT), P(WHAT), P(WHAT_WHAT), whats, &what))) return rc;
        if (what == W_DONE) return LM_GO;
        if ((rc = picture(d, what))) return rc;
    }
}

int lm_draw(lm_io *io)
{
    dsess *d = calloc(1, sizeof *d);
    int rc;
    if (!d) return LM_FAIL;
    d->io = io;
    lm_say(io, LM_BOTH, "%s", P(INTRO));
    if (!(rc = read_lens(d)) && !(rc = ask_unit(d)) && !(rc = ask_object(d)))
        rc = pictures(d);
    lm_lens_file_free(&d->lf);
    free(d);
    if (rc) return rc;
    lm_check_leftover(io);
    lm_say(io, LM_OUT, P(WRITTEN_OUT), io->rec_shown);
    return LM_GO;
}

const char *lm_draw_example(void) { return P(EXAMPLE); }

/* ---- the --trace dialogue's pictures ---------------------------------------------------- */

static struct {
    int have;
    trace_lens_surface surf[MAXSURF];
    trace_lens lens;
    double z_obj, frac;
} last;

void lm_draw_remember(const trace_lens *l, double z_obj, double frac)
{
    if (l->nsurf < 1 || l->nsurf > MAXSURF) return;
    memcpy(last.surf, l->surf, (size_t)l->nsurf * sizeof *l->surf);
    last.lens = *l;
    last.lens.surf = last.surf;
    last.z_obj = z_obj;
    last.frac = frac;
    last.have = 1;
}

int lm_draw_last(lm_io *io)
{
    dsess *d;
    int rc;
    if (!last.have) { lm_say(io, LM_BOTH, "%s", P(LAST_NONE)); return LM_GO; }
    if (!(d = calloc(1, sizeof *d))) return LM_FAIL;
    d->io = io;
    memcpy(d->surf, last.surf, sizeof d->surf);
    d->lens = last.lens;
    d->lens.surf = d->surf;
    d->sc.lens = &d->lens;
    d->sc.z_obj = last.z_obj;
    d->sc.frac = last.frac;
    lm_say(io, LM_BOTH, P(LAST_ECHO), d->lens.nsurf);
    if (!(rc = ask_unit(d))) {
        echo_first(d);
        rc = pictures(d);
    }
    free(d);
    return rc;
}
