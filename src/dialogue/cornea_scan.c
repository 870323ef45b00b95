/* cornea_scan.c -- the --cornea-scan dialogue (issue 12): one cornea measurement.
 * The rig (the example geometry, or a rig file planned only or run on the simulated
 * chip) scans a synthetic eye the user describes (radius, Q, cylinder and axis,
 * decentration, tilt) with a pattern (spiral, rings, grid); each exposure's spot is
 * traced through the eye and made into a full detector frame whose centroid is the
 * measurement (or, quicker, the traced hit plus Gaussian noise); the cornea engine
 * fits the chosen model, the fit's model is checked against the tracer, and the report
 * is printed, recorded and (optionally) written under a name: Sim K (apex and 3 mm
 * zone), radii, Q, pose, singular values, what is not determined, the spots rejected
 * and why, as NAME.txt, NAME.csv and NAME.json, with the four maps when asked
 * (cornea_out.c).  The eye may carry a keratoconus-like cone.  The measurement itself
 * is the topography pipeline (src/topo, lensmat-topo.so); texts in
 * prompts/cornea_scan.txt.  The rig, cornea, trace and topo engines are loaded here;
 * the imaging engine only when frames or maps are used. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "calcio.h"
#include "cornea_out.h"
#include "dialogues.h"
#include "engine.h"
#include "../imaging/imaging.h"
#include "../topo/topo.h"
#include "../trace/trace.h"
#include "prompts_cornea_scan.h"

#define CS(k) cornea_scan_prompts[CORNEA_SCAN_##k]
#define DEG (3.14159265358979323846 / 180)
#define WORD 4096
#define CHECK_TOL_UM 1e-3       /* tracer against the fit's model: 1 nm */

/* One number in [lo, hi] (whole when integral), asked again on a terminal. */
static int ranged(calc *c, const char *q, const char *what, const char *range, double lo,
                  double hi, int integral, double *v)
{
    for (;;) {
        lm_mark m;
        int rc;
        calc_mark(c, &m);
        if ((rc = calc_num(c, q, what, 0, v))) return rc;
        if (*v >= lo && *v <= hi && (!integral || *v == floor(*v))) return LM_GO;
        if ((rc = calc_reject(c, &m, what, q, CS(AGAIN), CS(RANGE), range)))
            return rc;
    }
}

static int stop_cb(void *ctx) { (void)ctx; return lm_stop_requested() != 0; }

/* ---- the session's state ---------------------------------------------------------- */

typedef struct cs {
    calc cc;
    const rig_api *rg;
    const topo_api *tp;
    rg_rig rig;
    int have_rig;
    char rigname[WORD], log[WORD], report[WORD], camera[WORD], save[WORD];
    char *text;                 /* the report as said, for NAME.txt */
    cn_kc kt;                   /* the true surface's indices (tk 1) */
    int tk;
    int eye;                    /* the maps' eye: 0 not named, 1 OD, 2 OS */
    tp_iso iso;                 /* the zone pattern on a synthetic eye (have_iso 1) */
    int have_iso;
    int real_clock;             /* the scan runs on a chip: its machine time varies */
    size_t len, cap;
} cs;

static const rig_api *volatile hook_api;
static void laser_off_hook(void *ctx)      /* async-signal-safe: the engine's path */
{
    (void)ctx;
    if (hook_api && hook_api->emergency_off) hook_api->emergency_off();
}

/* Said on stdout and in the record, and kept for the report file. */
static void say(cs *s, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void say(cs *s, const char *fmt, ...)
{
    char line[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    calc_say(&s->cc, "%s", line);
    fflush(stdout);                     /* each line as it is computed, also in a pipe */
    size_t n = strlen(line);
    if (s->len + n + 1 > s->cap) {
        size_t cap = (s->cap + n + 1) * 2;
        char *t = realloc(s->text, cap);
        if (!t) return;                 /* the report file then says less; never crash */
        s->text = t;
        s->cap = cap;
    }
    memcpy(s->text + s->len, line, n + 1);
    s->len += n;
}

/* ---- answers checked as they come ----------------------------------------------- */

static int check_rig(void *ctx, const char *word, char *msg, size_t cap)
{
    cs *s = ctx;
    s->have_rig = 0;
    if (!strcmp(word, "-")) return 0;
    if (lm_check_input(s->cc.io, word, "the rig file", msg, cap)) return -1;
    if (s->rg->rig_load(word, &s->rig, msg, cap)) return -1;
    s->have_rig = 1;
    return 0;
}

static int same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    return !stat(a, &sa) && !stat(b, &sb) && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

static int check_log(void *ctx, const char *word, char *msg, size_t cap)
{
    cs *s = ctx;
    static const char *const ext[] = {"", ".part"};
    char name[WORD + 16];
    if (!strcmp(word, "-")) return 0;
    for (int i = 0; i < 2; i++) {
        snprintf(name, sizeof name, "%s%s", word, ext[i]);
        if (same_file(name, s->rig.path)) { snprintf(msg, cap, CS(LOG_IS_RIG), name); return -1; }
        if (lm_check_output(s->cc.io, name, msg, cap)) return -1;
    }
    return 0;
}

/* The report's name: "-", or one whose files (NAME.txt, .csv, .json, the maps, their
 * .part) are none of this session's inputs: the answers, the record (cs_check_name),
 * the rig file or the simulator's log. */
static int check_report(void *ctx, const char *word, char *msg, size_t cap)
{
    cs *s = ctx;
    char name[WORD + 32];
    if (cs_check_name(s->cc.io, word, msg, cap)) return -1;
    if (!strcmp(word, "-")) return 0;
    for (int k = 0; cs_out_suffix[k]; k++)
        for (int i = 0; i < 2; i++) {
            snprintf(name, sizeof name, "%s%s%s", word, cs_out_suffix[k], i ? ".part" : "");
            if (s->have_rig && same_file(name, s->rig.path)) {
                snprintf(msg, cap, CS(REPORT_IS_RIG), name);
                return -1;
            }
            if (s->log[0] && strcmp(s->log, "-") && !strcmp(name, s->log)) {
                snprintf(msg, cap, CS(REPORT_IS_LOG), name);
                return -1;
            }
        }
    return 0;
}

/* A pattern for saved frames: one %d (flags 0, width up to 2 digits), no other
 * conversion, a picture extension the writer knows; the first name not an input. */
static int check_save(void *ctx, const char *word, char *msg, size_t cap)
{
    cs *s = ctx;
    int conv = 0;
    const char *dot = strrchr(word, '.');
    if (!strcmp(word, "-")) return 0;
    for (const char *p = word; *p; p++) {
        if (*p != '%') continue;
        if (p[1] == '%') { p++; continue; }
        p++;
        if (*p == '0') p++;
        for (int k = 0; k < 2 && *p >= '0' && *p <= '9'; k++) p++;
        if (*p != 'd') { conv = -1; break; }
        conv++;
    }
    if (conv != 1 || !dot || (strcmp(dot, ".png") && strcmp(dot, ".tif") && strcmp(dot, ".raw"))) {
        snprintf(msg, cap, CS(SAVE_BAD), word);
        return -1;
    }
    char name[WORD + 16];
    snprintf(name, sizeof name, word, 1);
    return lm_check_output(s->cc.io, name, msg, cap);
}

static int threads_wanted(void)
{
    const char *e = getenv("LENSMAT_THREADS");
    long n = e && *e ? strtol(e, NULL, 10) : sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : n > 16 ? 16 : (int)n;
}

/* The check's tolerance (um): LENSMAT_CORNEA_CHECK_TOL_UM overrides it (tests make
 * the check fail with 0). */
static double check_tol_um(void)
{
    const char *e = getenv("LENSMAT_CORNEA_CHECK_TOL_UM");
    return e && *e ? strtod(e, NULL) : CHECK_TOL_UM;
}

/* The fit's iteration cap per solve: LENSMAT_CORNEA_MAX_ITER overrides the engine's
 * 1000 (tests make a fit stop at its cap). */
static int max_iter_env(void)
{
    const char *e = getenv("LENSMAT_CORNEA_MAX_ITER");
    long n = e && *e ? strtol(e, NULL, 10) : 0;
    return n > 0 && n < 1000000 ? (int)n : 0;
}

/* ---- the dialogue ----------------------------------------------------------------- */

static int run(cs *s, tp_run *r, rg_machine **m);
static int scan_end(cs *s, const tp_run *r, int rc);
static void say_surface(cs *s, tp_run *r);
static void say_passes(cs *s, const tp_run *r);
static void say_zone(cs *s, tp_run *r);

/* What the report adds beside the engine's numbers: the scan's settings and, for a
 * synthetic eye, its truth and the errors. */
typedef struct cs_truth {
    const rg_cornea *eye;
    const cn_params *t;
    const cn_bump *cone;
    double km, cyl, axis_err, np, zone, noise, pitch, seed;
} cs_truth;

static void say_line(void *ctx, const char *line) { say(ctx, CS(LINE), line); }

/* The maps (when asked: their lines join the report) and the report under s->report,
 * from the fitted spots of the run whatever their source (frames, model, camera). */
static int cs_files(cs *s, const tp_run *r, int maps, const cs_truth *tr)
{
    const cornea_api *cn = r->cn;
    const cn_clinical *k = &r->res.k;
    const cn_params *t = tr->t;
    const rg_cornea *eye = tr->eye;
    char msg[512];
    int n = 0, rc = LM_GO;
    cn_spot *sp = malloc(sizeof *sp * (size_t)(r->npoints ? r->npoints : 1));
    if (!sp) return calc_fail(&s->cc, CS(NO_MEMORY));
    for (int i = 0; i < r->npoints; i++)    /* the fit's spots, in the fit's order */
        if (r->pt[i].planned) sp[n++] = r->pt[i].spot;
    const cs_row rows[] = {
        {"scan_points", tr->np, NAN, ""}, {"scan_zone", tr->zone, NAN, "deg"},
        {"scan_source", r->source, NAN, ""}, {"scan_pattern", r->pattern, NAN, ""},
        {"scan_noise", tr->noise, NAN, "px"}, {"scan_pitch", tr->pitch, NAN, "um"},
        {"scan_seed", tr->seed, NAN, ""},
        {"true_R", t->p[CN_R], NAN, "mm"}, {"true_R_flat", eye->R, NAN, "mm"},
        {"true_R_steep", eye->R2, NAN, "mm"}, {"true_Q", eye->Q, NAN, ""},
        {"true_Km", tr->km, NAN, "D"}, {"true_cyl", tr->cyl, NAN, "D"},
        {"true_dx", t->p[CN_DX], NAN, "mm"}, {"true_dy", t->p[CN_DY], NAN, "mm"},
        {"true_tilt_x", t->p[CN_TX] / DEG, NAN, "deg"},
        {"true_tilt_y", t->p[CN_TY] / DEG, NAN, "deg"},
        {"true_cone_h", tr->cone->h * 1e3, NAN, "um"}, {"true_cone_w", tr->cone->w, NAN, "mm"},
        {"true_cone_x", tr->cone->x0, NAN, "mm"}, {"true_cone_y", tr->cone->y0, NAN, "mm"},
        {"err_R", (k->R - t->p[CN_R]) * 1e3, k->sd_R * 1e3, "um"},
        {"err_R_flat", (k->R_flat - eye->R) * 1e3, k->sd_R_flat * 1e3, "um"},
        {"err_R_steep", (k->R_steep - eye->R2) * 1e3, k->sd_R_steep * 1e3, "um"},
        {"err_Q", k->Q - eye->Q, k->sd_Q, ""},
        {"err_Km", k->Km - tr->km, k->sd_Km, "D"},
        {"err_cyl", r->model == CN_BICONIC ? k->cyl - tr->cyl : NAN, k->sd_cyl, "D"},
        {"err_axis", r->model == CN_BICONIC && tr->cyl > 0 ? tr->axis_err : NAN, k->sd_axis,
         "deg"},
        {"err_dx", (k->dx - t->p[CN_DX]) * 1e3, k->sd_dx * 1e3, "um"},
        {"err_dy", (k->dy - t->p[CN_DY]) * 1e3, k->sd_dy * 1e3, "um"},
        {"err_tilt_x", k->tx - t->p[CN_TX] / DEG, k->sd_tx, "deg"},
        {"err_tilt_y", k->ty - t->p[CN_TY] / DEG, k->sd_ty, "deg"},
    };
    /* a camera's eye is unknown: the scan's settings only */
    int nrows = r->have_truth ? (int)(sizeof rows / sizeof *rows) : 7;
    /* the surface from the data: its indices, and the true surface's */
    const cn_kc *k2 = &r->kc;
    const cn_kc kt = s->kt;
    int tk = s->tk;
    const cs_row zrows[] = {
        {"topo_order", r->have_z ? r->zf->order : NAN, NAN, ""},
        {"topo_chi2_dof", r->have_z ? r->zf->chi2_dof : NAN, NAN, ""},
        {"topo_zone_r", r->have_z ? r->zf->rho : NAN, NAN, "mm"},
        {"kmax", k2->kmax, k2->sd_kmax, "D"}, {"kmax_x", k2->kmax_x, k2->sd_kmax_loc, "mm"},
        {"kmax_y", k2->kmax_y, k2->sd_kmax_loc, "mm"}, {"central_K", k2->ck, k2->sd_ck, "D"},
        {"I_S", k2->is, k2->sd_is, "D"}, {"I_S_r", k2->is_r, NAN, "mm"},
        {"simk1", k2->simk1, k2->sd_simk, "D"}, {"simk2", k2->simk2, k2->sd_simk, "D"},
        {"AST", k2->ast, k2->sd_ast, "D"}, {"SRAX", k2->srax, k2->sd_srax, "deg"},
        {"KISA", k2->kisa, k2->sd_kisa, "%"}, {"kc_screen", k2->screen, NAN, ""},
        {"true_kmax", tk ? kt.kmax : NAN, NAN, "D"}, {"true_kmax_x", tk ? kt.kmax_x : NAN, NAN, "mm"},
        {"true_kmax_y", tk ? kt.kmax_y : NAN, NAN, "mm"}, {"true_central_K", tk ? kt.ck : NAN, NAN, "D"},
        {"true_I_S", tk ? kt.is : NAN, NAN, "D"}, {"true_SRAX", tk ? kt.srax : NAN, NAN, "deg"},
        {"true_KISA", tk ? kt.kisa : NAN, NAN, "%"},
    };
    int nz = !r->have_z ? 0 : tk ? (int)(sizeof zrows / sizeof *zrows) : 15;
    /* the zone pattern: its coverage per zone and the ISO 19980 figures */
    const tp_cover *cv = &r->cover;
    const tp_iso_zone *iz = s->iso.z;
#define ISO_ROWS(k, nm) {"iso_" nm "_mean", iz[k].mean_um, NAN, "um"}, \
        {"iso_" nm "_2sd", iz[k].sd2_um, NAN, "um"}, {"iso_" nm "_mean_D", iz[k].mean_D, NAN, "D"}, \
        {"iso_" nm "_2sd_D", iz[k].sd2_D, NAN, "D"}
    const cs_row crows[] = {
        {"zone_mm", cv->zone_mm, NAN, "mm"}, {"cover_0_3", cv->frac[0], NAN, ""},
        {"cover_3_6", cv->frac[1], NAN, ""}, {"cover_6_9", cv->frac[2], NAN, ""},
        {"cover_9_10", cv->frac[3], NAN, ""},
        ISO_ROWS(0, "0_3"), ISO_ROWS(1, "3_6"), ISO_ROWS(2, "6_9"), ISO_ROWS(3, "0_6"),
    };
#undef ISO_ROWS
    int nc = !cv->valid ? 0 : s->have_iso ? (int)(sizeof crows / sizeof *crows) : 5;
    cs_row *all = malloc(sizeof *all * (size_t)(nrows + nz + nc));
    if (!all) { free(sp); return calc_fail(&s->cc, CS(NO_MEMORY)); }
    memcpy(all, rows, sizeof *all * (size_t)nrows);
    memcpy(all + nrows, zrows, sizeof *all * (size_t)nz);
    memcpy(all + nrows + nz, crows, sizeof *all * (size_t)nc);
    nz += nc;
    if (maps && s->eye)
        say(s, CS(EYE), s->eye == 1 ? CS(EYE_OD) : CS(EYE_OS), s->eye == 1 ? "right" : "left");
    if (maps && cs_write_maps(cn, r->g, s->report, &r->res, sp, n, r->have_z ? r->zf : NULL,
                              &r->kc, s->eye, stop_cb, say_line, s, msg, sizeof msg)) {
        rc = lm_stop_requested() ? LM_FAIL : calc_fail(&s->cc, CS(NO_REPORT));
        fprintf(stderr, "lensmat: ");
        fprintf(stderr, CS(REPORT_FAILED), s->report, msg);
    } else if (cs_write_report(cn, s->report, s->text, s->len, &r->res, sp, n, all,
                               nrows + nz, msg, sizeof msg)) {
        rc = lm_stop_requested() ? LM_FAIL : calc_fail(&s->cc, CS(NO_REPORT));
        fprintf(stderr, "lensmat: ");
        fprintf(stderr, CS(REPORT_FAILED), s->report, msg);
    } else {
        char shown[4 * sizeof s->report + 4];   /* the name, control bytes escaped */
        lm_escape(s->report, shown, sizeof shown);
        lm_say(s->cc.io, LM_OUT, CS(REPORT_WRITTEN), shown, shown, shown);
    }
    free(all);
    free(sp);
    return rc;
}

int lm_cornea_scan(lm_io *io)
{
    static const char *const models[] = {"sphere", "conic", "biconic", "asphere", NULL};
    static const char *const chips[] = {"none", "sim", "gpiod", NULL};
    static const char *const patterns[] = {"spiral", "rings", "grid", "zone", NULL};
    static const char *const map_answers[] = {"n", "y", "OD", "OS", "no", "yes", NULL};
    static const char *const sources[] = {"frames", "model", "camera", NULL};
    cs *s = calloc(1, sizeof *s);
    tp_run *r = calloc(1, sizeof *r);
    rg_machine *m = NULL;
    int rc = LM_FAIL;
    if (!s || !r) { free(s); free(r); fprintf(stderr, "lensmat: out of memory\n"); return LM_FAIL; }
    s->cc = (calc){io, PX_MM, "mm"};
    calc *c = &s->cc;
    rig_get_api_fn rget;
    cornea_get_api_fn cget;
    topo_get_api_fn pget;
    *(void **)&rget = lm_engine_symbol("rig", RIG_API_SYMBOL);
    *(void **)&cget = lm_engine_symbol("cornea", CORNEA_API_SYMBOL);
    *(void **)&pget = lm_engine_symbol("topo", TOPO_API_SYMBOL);
    const rig_api *rg = rget ? rget(RIG_ABI) : NULL;
    const cornea_api *cn = cget ? cget(CORNEA_ABI) : NULL;
    const topo_api *tp = pget ? pget(TOPO_ABI) : NULL;
    if (!rg || !cn || !tp) { rc = calc_fail(c, CS(NO_ENGINE)); goto out; }
    s->rg = rg;
    s->tp = tp;
    int model, chip = 0, pattern, source;
    double np, zone, R = 7.8, Q = 0, cyl = 0, axis = 0, dx = 0, dy = 0, tx = 0, ty = 0,
           noise = 0, pitch, seed = 0, w = 0, h = 0, ms = 0;
    if ((rc = calc_choice(c, CS(MODEL), CS(MODEL_WHAT), models, &model)) ||
        (rc = lm_ask_file(io, CS(RIG_FILE), CS(RIG_FILE), CS(RIG_FILE_WHAT), check_rig, s,
                          s->rigname, sizeof s->rigname)))
        goto out;
    if (s->have_rig) {
        if ((rc = calc_choice(c, CS(CHIP), CS(CHIP_WHAT), chips, &chip))) goto out;
        s->real_clock = chip == 2;
        if ((chip == 1 &&
             (rc = lm_ask_file(io, CS(SIM_LOG), CS(SIM_LOG), CS(SIM_LOG_WHAT), check_log, s,
                               s->log, sizeof s->log))) ||
            (chip >= 1 &&
             (rc = ranged(c, CS(EXPOSE), CS(EXPOSE_WHAT), CS(EXPOSE_RANGE),
                          0.01, s->rig.max_on_ms, 0, &ms))))
            goto out;
    }
    if ((rc = calc_choice(c, CS(PATTERN), CS(PATTERN_WHAT), patterns, &pattern)) ||
        (rc = ranged(c, CS(POINTS), CS(POINTS_WHAT), CS(POINTS_RANGE), 10, 10000, 1, &np)))
        goto out;
    double zone_mm = 0;                /* the zone pattern: its diameter (mm) */
    if (pattern == 3) {
        if ((rc = ranged(c, CS(ZONE_MM), CS(ZONE_MM_WHAT), CS(ZONE_MM_RANGE), 2, 12, 0,
                         &zone_mm)))
            goto out;
        zone = 0;
    } else if ((rc = ranged(c, CS(ZONE), CS(ZONE_WHAT), CS(ZONE_RANGE), 0.5, 12, 0, &zone)))
        goto out;
    if ((rc = calc_choice(c, CS(SOURCE), CS(SOURCE_WHAT), sources, &source))) goto out;
    if (source == TP_SRC_CAMERA && pattern == 3) {
        rc = calc_fail(c, CS(ZONE_CAMERA));
        goto out;
    }
    if (source == TP_SRC_CAMERA &&
        (rc = lm_ask_file(io, CS(CAMERA), CS(CAMERA), CS(CAMERA_WHAT), NULL, NULL, s->camera,
                          sizeof s->camera)))
        goto out;
    if (source != TP_SRC_CAMERA &&      /* a real eye is what the camera sees */
        ((rc = ranged(c, CS(R), CS(R_WHAT), CS(R_RANGE), 5, 12, 0, &R)) ||
        (rc = ranged(c, CS(Q), CS(Q_WHAT), CS(Q_RANGE), -1, 1, 0, &Q)) ||
        (rc = ranged(c, CS(CYL), CS(CYL_WHAT), CS(CYL_RANGE), 0, 8, 0, &cyl)) ||
        (rc = ranged(c, CS(AXIS), CS(AXIS_WHAT), CS(AXIS_RANGE), -360, 360, 0, &axis)) ||
        (rc = ranged(c, CS(DX), CS(DX_WHAT), CS(DEC_RANGE), -1, 1, 0, &dx)) ||
        (rc = ranged(c, CS(DY), CS(DY_WHAT), CS(DEC_RANGE), -1, 1, 0, &dy)) ||
        (rc = ranged(c, CS(TX), CS(TX_WHAT), CS(TILT_RANGE), -10, 10, 0, &tx)) ||
        (rc = ranged(c, CS(TY), CS(TY_WHAT), CS(TILT_RANGE), -10, 10, 0, &ty))))
        goto out;
    if (source == TP_SRC_MODEL &&
        (rc = ranged(c, CS(NOISE), CS(NOISE_WHAT), CS(NOISE_RANGE), 0, 10, 0, &noise)))
        goto out;
    if ((rc = ranged(c, CS(PITCH), CS(PITCH_WHAT), CS(PITCH_RANGE), 0.1, 100, 0, &pitch)))
        goto out;
    if (source == TP_SRC_FRAMES &&
        ((rc = ranged(c, CS(WIDTH), CS(WIDTH_WHAT), CS(PX_RANGE), 16, 4096, 1, &w)) ||
         (rc = ranged(c, CS(HEIGHT), CS(HEIGHT_WHAT), CS(PX_RANGE), 16, 4096, 1, &h)) ||
         (rc = lm_ask_file(io, CS(SAVE), CS(SAVE), CS(SAVE_WHAT), check_save, s, s->save,
                           sizeof s->save))))
        goto out;
    cn_bump cone = {0, 0, 0, 0};       /* a cone on the synthetic eye (not a camera's) */
    if (source != TP_SRC_CAMERA &&
        ((rc = ranged(c, CS(SEED), CS(SEED_WHAT), CS(SEED_RANGE), 0, 1e15, 1, &seed)) ||
         (rc = ranged(c, CS(CONE), CS(CONE_WHAT), CS(CONE_RANGE), 0, 50, 0, &cone.h))))
        goto out;
    if (cone.h > 0 &&
        ((rc = ranged(c, CS(CONE_W), CS(CONE_W_WHAT), CS(CONE_W_RANGE), 0.2, 3, 0, &cone.w)) ||
         (rc = ranged(c, CS(CONE_X), CS(CONE_X_WHAT), CS(CONE_XY_RANGE), -2, 2, 0, &cone.x0)) ||
         (rc = ranged(c, CS(CONE_Y), CS(CONE_Y_WHAT), CS(CONE_XY_RANGE), -2, 2, 0, &cone.y0))))
        goto out;
    double cone_um = cone.h;
    cone.h *= 1e-3;                    /* um -> mm */
    int maps = 0;
    if ((rc = lm_ask_file(io, CS(REPORT), CS(REPORT), CS(REPORT_WHAT), check_report, s,
                          s->report, sizeof s->report)) ||
        (strcmp(s->report, "-") && (rc = calc_choice(c, CS(MAPS), CS(MAPS_WHAT), map_answers,
                                                     &maps))))
        goto out;
    /* n y OD OS no yes: maps 0 none, else drawn; the eye 1 OD, 2 OS, 0 not named */
    s->eye = maps == 2 ? 1 : maps == 3 ? 2 : 0;
    maps = maps != 0 && maps != 4;

    /* the rig's geometry: the rig file's, or the example */
    static rg_geometry g;
    if (s->have_rig) g = s->rig.geom;
    else rg->geometry_default(&g);
    rg_cornea eye = g.cornea;
    double km = 337.5 / R;
    eye.model = RG_BICONIC;
    eye.R = 337.5 / (km - cyl / 2);
    eye.R2 = 337.5 / (km + cyl / 2);
    eye.Q = eye.Q2 = Q;
    eye.axis = axis * DEG;
    eye.zone = 0;
    double at[3] = {g.cornea.trans[0] + dx, g.cornea.trans[1] + dy, g.cornea.trans[2]};
    rg->eye_pose(&eye, tx * DEG, ty * DEG, 0, at);

    r->rg = rg;
    r->cn = cn;
    r->g = &g;
    r->truth = eye;
    r->have_truth = source != TP_SRC_CAMERA;
    cn_params t;                       /* the true eye as the engine's parameters */
    cn->params_from_cornea(&eye, g.cornea.trans, tx * DEG, ty * DEG, &t);
    if (cone.h > 0) {
        r->bump = &cone;
        r->truth_p = t;
    }
    r->camera = source == TP_SRC_CAMERA ? s->camera : NULL;
    r->save = source == TP_SRC_FRAMES && s->save[0] && strcmp(s->save, "-") ? s->save : NULL;
    r->pattern = pattern == 3 ? TP_SPIRAL : pattern;
    r->npoints = (int)np;
    r->zone = zone * DEG;
    r->zone_h = zone_mm / 2;           /* > 0: measure_zone */
    r->sensor_cut = zone_mm > 0;       /* its quick model loses spots off the sensor */
    r->source = source;
    r->sigma = noise * pitch * 1e-3;
    r->cam = (tp_camera){(int)w, (int)h, pitch * 1e-3, 3, 1000, 100, 50};
    r->seed = (uint64_t)seed;
    r->threads = threads_wanted();
    r->expose_ms = ms;
    r->stop = stop_cb;
    r->model = model;
    r->check_tol = check_tol_um() * 1e-3;
    r->max_iter = max_iter_env();
    r->rig = &s->rig;
    if (!(r->zf = calloc(1, sizeof *r->zf)) ||
        !(r->pt = calloc((size_t)r->npoints, sizeof *r->pt))) {
        rc = calc_fail(c, CS(NO_MEMORY));
        goto out;
    }
    if (s->have_rig) say(s, CS(RIG_LOADED), s->rig.path, g.cornea.R);
    if (cone.h > 0) say(s, CS(CONE_ON), cone_um, cone.w, cone.x0, cone.y0);
    {
        trace_get_api_fn tget =
            (trace_get_api_fn)lm_engine_symbol("trace", TRACE_API_SYMBOL);
        r->tr = tget ? tget(TRACE_ABI) : NULL;
        if (!r->tr) say(s, "%s", CS(NO_TRACER));
    }
    if (source != TP_SRC_MODEL) {
        imaging_get_api_fn iget =
            (imaging_get_api_fn)lm_engine_symbol("imaging", IMAGING_API_SYMBOL);
        r->im = iget ? iget(IMAGING_ABI) : NULL;
        if (!r->im || !r->im->frame) { rc = calc_fail(c, CS(NO_IMAGING)); goto out; }
        if (source == TP_SRC_CAMERA)
            say(s, CS(CAMERA_ON), s->camera, pitch);
        else
            say(s, CS(FRAMES_ON), r->cam.width, r->cam.height, pitch, r->cam.spot_w,
                r->cam.peak, r->cam.bias, r->cam.read_noise);
    } else {
        say(s, CS(MODEL_ON), noise, r->sigma * 1e3);
    }
    if (chip >= 1) {
        rg_open_opts o = {RG_BACKEND_SIM, NULL, strcmp(s->log, "-") ? s->log : NULL, NULL, 0};
        if (chip == 2) o = (rg_open_opts){RG_BACKEND_GPIOD, NULL, NULL, NULL, 1};
        char err[RG_ERRMAX];
        rg_pose p;
        hook_api = rg;
        lm_on_stop(laser_off_hook, NULL);
        if (rg->open(&s->rig, &o, &m, err, sizeof err) ||
            rg->home(m, stop_cb, NULL, err, sizeof err)) {
            say(s, CS(MACHINE_FAILED), err);
            rc = LM_FAIL;
            goto out;
        }
        rg->position(m, NULL, &p);
        char buf[256];
        snprintf(buf, sizeof buf, "m1a %.4g deg, m1b %.4g deg, u %.4g mm, v %.4g mm, "
                 "m2a %.4g deg, m2b %.4g deg", p.j[0] / DEG, p.j[1] / DEG, p.j[2], p.j[3],
                 p.j[4] / DEG, p.j[5] / DEG);
        say(s, CS(OPENED), chip == 2 ? s->rig.chip : "the simulator", buf);
        lm_say(io, LM_OUT, "%s\n", rg->sched_note(m));   /* varies: not recorded */
        r->m = m;
    }
    rc = run(s, r, &m);
    rc = scan_end(s, r, rc);
    double axis_err = model == CN_BICONIC
                      ? remainder(r->res.k.K1_axis - fmod(axis + 360, 180), 180.0) : 0.0;
    if (rc == LM_GO && r->have_truth) {
        say(s, CS(TRUTH), eye.R, eye.R2, km, cyl);
        s->tk = r->have_z &&
                !cn->kc_model_in(CN_BICONIC, &t, cone.h > 0 ? &cone : NULL, &r->zf->ref,
                                 r->zf->rho, &s->kt);
        if (s->tk) {
            char srax[40] = "not defined", kisa[40] = "not defined";
            if (isfinite(s->kt.srax)) snprintf(srax, sizeof srax, "%.0f deg", s->kt.srax);
            if (isfinite(s->kt.kisa)) snprintf(kisa, sizeof kisa, "%.0f %%", s->kt.kisa);
            say(s, CS(TOPO_TRUTH), s->kt.kmax, s->kt.kmax_x, s->kt.kmax_y, s->kt.ck, s->kt.is,
                srax, kisa);
        }
        if (!r->res.rejected_model && r->res.converged)   /* else no numbers to compare */
            say(s, CS(ERRORS), (r->res.k.R - t.p[CN_R]) * 1e3, r->res.k.Km - km, axis_err);
    }
    if (rc == LM_GO && r->fitted && !r->res.converged) {
        fprintf(stderr, "lensmat: ");
        fprintf(stderr, CS(NOT_CONVERGED), r->res.iterations);
        rc = LM_FAIL;
    }
    if (rc == LM_GO) {
        if (r->check_max > r->check_tol) {
            fprintf(stderr, "lensmat: ");
            fprintf(stderr, CS(CHECK_FAILED), r->check_max * 1e3, r->check_tol * 1e3);
            rc = LM_FAIL;
        }
    }
    if (m) {                                  /* laser off, then drivers disabled */
        if (rg->close(m) && strcmp(s->log, "-")) {
            fprintf(stderr, CS(LOG_FAILED), s->log);
            rc = LM_FAIL;
        }
        m = NULL;
    }
    if (rc == LM_GO && strcmp(s->report, "-")) {
        const cs_truth tr = {&eye, &t, &cone, km, cyl, axis_err, np, zone, noise, pitch, seed};
        rc = cs_files(s, r, maps, &tr);
    }
    if (rc == LM_GO) rc = calc_done(c);
out:
    if (m) rg->close(m);
    if (hook_api) { lm_on_stop_remove(laser_off_hook, NULL); hook_api = NULL; }
    free(r->pt);
    free(r->zf);
    free(r);
    free(s->text);
    free(s);
    return rc;
}

/* After the loop: an interruption says where it stopped (stdout, the record and
 * stderr); saved frames get their manifest, so that frames an earlier scan left under
 * the same pattern are never taken for this one's.  rc, or LM_FAIL. */
static int scan_end(cs *s, const tp_run *r, int rc)
{
    int sig = lm_stop_requested(), nm = 0, ns = 0;
    int *seq = r->save ? malloc(sizeof *seq * (size_t)(r->npoints ? r->npoints : 1)) : NULL;
    char status[200], msg[1200], man[1100];
    for (int k = 0; k < r->npoints; k++) {
        nm += r->pt[k].measured;
        if (r->pt[k].saved && seq) seq[ns++] = r->pt[k].seq;
    }
    if (sig) {
        char line[400];
        snprintf(line, sizeof line, CS(INTERRUPTED), sig, r->phase ? r->phase : "planning",
                 r->nexposed, r->nplanned, nm, r->nplanned, ns);
        say(s, "%s", line);
        fprintf(stderr, "lensmat: %s", line);
        snprintf(status, sizeof status, "interrupted (signal %d) during %s", sig,
                 r->phase ? r->phase : "planning");
    } else snprintf(status, sizeof status, "%s", rc == LM_GO ? "complete" : "failed");
    if (r->save) {
        cs_manifest_name(r->save, man, sizeof man);
        if (!seq || cs_write_manifest(r->save, seq, ns, r->nplanned, status, msg, sizeof msg)) {
            fprintf(stderr, CS(MANIFEST_FAILED), man, seq ? msg : "out of memory");
            rc = LM_FAIL;
        } else if (rc == LM_GO) say(s, CS(SAVED), r->save, r->nplanned, man);
    }
    free(seq);
    return rc;
}

/* The surface from the data and the keratoconus indices; sd scaled by the root of
 * the slope fit's chi2/dof when that is above 1.5. */
static void say_surface(cs *s, tp_run *r)
{
    if (!r->have_z) { say(s, CS(TOPO_NONE), r->zwhy[0] ? r->zwhy : "no fit"); return; }
    const cn_zfit *z = r->zf;
    cn_kc *k = &r->kc;
    say(s, CS(TOPO_SURFACE), z->order, z->nused, z->chi2_dof, z->rho, r->zref_R);
    if (z->chi2_dof > 4) {      /* it does not follow its own data: no index of it */
        say(s, CS(TOPO_UNFIT), z->chi2_dof);
        r->have_z = 0;
        return;
    }
    if (z->chi2_dof > 1.5) {
        double f = sqrt(z->chi2_dof);
        say(s, CS(TOPO_POOR), z->chi2_dof, f);
        k->sd_kmax *= f; k->sd_kmax_loc *= f; k->sd_ck *= f; k->sd_is *= f;
        k->sd_simk *= f; k->sd_ast *= f; k->sd_srax *= f; k->sd_kisa *= f;
    }
    say(s, CS(TOPO_KMAX), k->kmax, k->sd_kmax, k->kmax_x, k->kmax_y, k->sd_kmax_loc);
    if (s->eye)     /* +x is the examiner's right: nasal on OD, temporal on OS */
        say(s, CS(KMAX_WHERE), fabs(k->kmax_y), k->kmax_y < 0 ? "inferior" : "superior",
            fabs(k->kmax_x), (k->kmax_x >= 0) == (s->eye == 1) ? "nasal" : "temporal",
            s->eye == 1 ? CS(EYE_OD) : CS(EYE_OS));
    say(s, CS(TOPO_CK), k->ck, k->sd_ck, k->ck_rings, k->simk1, k->simk2, k->simk_axis,
        fmin(1.5, 0.9 * k->zone_r), k->ast, k->sd_ast);
    /* SRAX and KISA may be undefined (cn_kc.c): said so, not printed as nan */
    char srax[160], kisa[80];
    if (isfinite(k->srax)) snprintf(srax, sizeof srax, CS(TOPO_SRAX), k->srax, k->sd_srax);
    else snprintf(srax, sizeof srax, "%s", CS(TOPO_SRAX_NONE));
    if (isfinite(k->kisa)) snprintf(kisa, sizeof kisa, CS(TOPO_KISA), k->kisa, k->sd_kisa);
    else snprintf(kisa, sizeof kisa, "%s", CS(TOPO_KISA_NONE));
    say(s, CS(TOPO_IS), k->is, k->sd_is, k->is_r, k->is_r < 3 ? CS(TOPO_IS_SHORT) : "",
        srax, kisa);
    if (k->screen == CN_KC_KERATOCONUS)
        say(s, CS(TOPO_SCREEN_KC), k->why, k->kmax_x, k->kmax_y);
    else if (k->screen == CN_KC_SUSPECT)
        say(s, CS(TOPO_SCREEN_SUSPECT), k->why, k->kmax_x, k->kmax_y);
    else if (k->ck > 47.2)   /* steep but regular: cn_kc.c says why it is not screened */
        say(s, CS(TOPO_SCREEN_STEEP), k->why);
    else
        say(s, "%s", CS(TOPO_SCREEN_NORMAL));
}

/* The zone pattern's passes: each coarse one with the fit the next was planned on. */
static void say_passes(cs *s, const tp_run *r)
{
    for (int p = 0; p + 1 < r->npass; p++) {
        const tp_pass *q = &r->pass[p];
        char fit[200] = "";
        if (isfinite(q->R))
            snprintf(fit, sizeof fit, CS(ZONE_PASS_FIT), q->R, q->Km, q->cyl,
                     q->used ? "" : CS(ZONE_PASS_UNUSED));
        say(s, CS(ZONE_PASS), p + 1, q->npoints, q->zone_h, q->nplanned, q->nok, fit);
    }
    int fitted = 0;
    for (int p = 0; p + 1 < r->npass; p++) fitted |= r->pass[p].used;
    say(s, CS(ZONE_PLANNED), r->npoints, r->zone_h, 2 * r->zone_h,
        fitted ? "last pass's fit" : "nominal cornea", r->nplanned, r->nexposed);
}

/* The zone pattern: the coverage per zone and, on a synthetic eye, the ISO 19980
 * statistics against its true surface (kept for the report's rows). */
static void say_zone(cs *s, tp_run *r)
{
    static const char *const zn[TP_ISO_NZONE] = {"0-3", "3-6", "6-9", "0-6"};
    const tp_cover *c = &r->cover;
    if (!c->valid) { say(s, "%s", CS(ZONE_COVER_NONE)); return; }
    say(s, CS(ZONE_COVER), 100 * c->frac[0], c->nspots[0], 100 * c->frac[1], c->nspots[1],
        100 * c->frac[2], c->nspots[2], 100 * c->frac[3], c->nspots[3], c->zone_mm);
    tp_truth tt = {r->rg, &r->truth, r->bump};
    s->have_iso = r->have_truth && r->have_z &&
                  !s->tp->iso(r, s->tp->truth_sag, &tt, &r->truth, &s->iso);
    if (!s->have_iso) return;
    say(s, "%s", CS(ISO_HEAD));
    for (int k = 0; k < TP_ISO_NZONE; k++) {
        const tp_iso_zone *q = &s->iso.z[k];
        if (!q->n) say(s, CS(ISO_EMPTY), zn[k]);
        else say(s, CS(ISO_ZONE), zn[k], 100 * q->frac, q->mean_um, q->sd2_um, q->mean_D,
                 q->sd2_D);
    }
}

/* The scan on the machine: its order and time, the smear of its exposures. */
static void say_machine(cs *s, const tp_run *r)
{
    const tp_scan *c = &r->sc;
    if (s->real_clock) {        /* the real clock's times: stdout only (replays) */
        lm_say(s->cc.io, LM_OUT, CS(MACHINE_SCAN), r->nexposed,
               c->on_fly ? "on the fly" : "stop and go",
               c->reordered ? "the planner's" : "the pattern's", c->sim_s, c->pred_s,
               c->pred_own_s, c->limit);
        return;
    }
    say(s, CS(MACHINE_SCAN), r->nexposed, c->on_fly ? "on the fly" : "stop and go",
        c->reordered ? "the planner's" : "the pattern's", c->sim_s, c->pred_s, c->pred_own_s,
        c->limit);
    say(s, CS(MACHINE_SMEAR), c->blur_det_max * 1e3, c->blur_tol * 1e3, c->blur_over,
        c->blur_cornea_max * 1e3, c->step_det_max * 1e3);
}

/* The fixation test (tp_drift.c): the eye's pose per time segment. */
static void say_fixation(cs *s, const tp_run *r)
{
    const tp_drift *d = &r->drift;
    if (!d->segments) return;
    if (!d->flagged && d->p < 1e-3 && d->range > 2e-3) {
        say(s, CS(FIXATION_MISFIT), d->segments, d->chi2, d->dof, d->joint_chi2_dof);
        return;
    }
    say(s, d->flagged ? CS(FIXATION_BAD) : CS(FIXATION_OK), d->segments, d->chi2, d->dof, d->p,
        d->range * 1e3);
    for (int i = 0; d->flagged && i < d->segments; i++)
        say(s, CS(FIXATION_SEG), i + 1, d->t0[i], d->t1[i], d->d[i][0] * 1e3, d->d[i][1] * 1e3,
            d->d[i][2] * 1e3, d->sd[i][0] * 1e3, d->sd[i][1] * 1e3, d->sd[i][2] * 1e3);
    if (d->flagged && d->joint_fitted)
        say(s, CS(FIXATION_JOINT), d->joint.par.p[CN_R], d->joint.k.Km, d->joint.k.cyl,
            d->joint.k.K2_axis, d->joint.chi2_dof);
}

/* The measurement and its report. */
static int run(cs *s, tp_run *r, rg_machine **m)
{
    static const char *const pname[] = {"spiral", "rings", "grid"};
    calc *c = &s->cc;
    const cornea_api *cn = r->cn;
    char err[256];
    static char buf[8192];
    int rc = r->zone_h > 0 ? s->tp->measure_zone(r, err, sizeof err)
                           : s->tp->measure(r, err, sizeof err);
    int counts[6];
    s->tp->counts(r, counts);
    if (rc == CN_ESTOP || lm_stop_requested()) return LM_FAIL;
    if (rc == CN_EINVAL || rc == CN_ENOMEM) {   /* the machine, the camera or saving */
        if (*m) { r->rg->close(*m); *m = NULL; }
        say(s, CS(MACHINE_FAILED), err);
        fprintf(stderr, "lensmat: %s\n", err);
        return LM_FAIL;
    }
    if (r->zone_h > 0) say_passes(s, r);
    else say(s, CS(PLANNED), pname[r->pattern], r->npoints, r->zone / DEG, r->nplanned,
             r->nexposed);
    if (*m)                     /* the order, the machine's time, the smear (tp_order.c) */
        say_machine(s, r);
    double ssum = 0;
    int sn = 0;
    for (int k = 0; k < r->npoints; k++)
        if (r->pt[k].planned && isfinite(r->pt[k].spot.u)) { ssum += r->pt[k].spot.sigma; sn++; }
    say(s, CS(SCANNED), r->nplanned, sn, (r->source == TP_SRC_MODEL || !sn ? r->sigma
                                           : ssum / sn) * 1e3);
    if (r->source == TP_SRC_CAMERA && r->shot.n >= 3) {
        if (isfinite(r->gain)) say(s, CS(CAMERA_GAIN), r->shot.n, r->gain, r->shot_factor);
        else say(s, CS(CAMERA_GAIN_NONE), r->shot.n);
    }
    if (rc) {
        calc_say(c, CS(FAILED), err);
        return LM_FAIL;
    }
    cn->report(&r->res, buf, sizeof buf);
    for (char *l = buf, *e; *l; l = e + 1) {     /* line by line into the record */
        e = strchr(l, '\n');
        if (!e) { say(s, CS(LINE), l); break; }
        *e = 0;
        say(s, CS(LINE), l);
    }
    if (r->have_dose)      /* the margin the scan kept to the limit (doc/rig-safety.md) */
        say(s, CS(DOSE), (int)r->dose.n, r->expose_ms, r->rig->laser_power_mw,
            r->rig->wavelength_nm, r->rig->beam_diameter_mm, r->dose.H_one, r->dose.H_total,
            r->dose.mpe_total, r->dose.limit, r->dose.fraction, 1 / r->dose.fraction);
    say_fixation(s, r);
    say(s, CS(SPOTS), counts[CN_S_OK],
        counts[CN_S_NONE] + counts[CN_S_SEVERAL] + counts[CN_S_OUTLIER] + counts[CN_S_MISS],
        counts[CN_S_NONE], counts[CN_S_SEVERAL], counts[CN_S_OUTLIER], counts[CN_S_MISS],
        counts[5]);
    for (int k = 0; k < r->npoints; k++) {
        const tp_point *q = &r->pt[k];
        if (q->planned && q->spot.status == CN_S_OK) continue;
        if (r->zone_h > 0) say(s, CS(REJECTED_H), k + 1, q->t.a, q->t.b / DEG, q->why);
        else say(s, CS(REJECTED), k + 1, q->t.a / DEG, q->t.b / DEG, q->why);
    }
    say_surface(s, r);
    if (r->zone_h > 0) say_zone(s, r);
    if (r->tr)
        say(s, CS(CHECK), r->check_n, r->check_max * 1e3, r->check_tol * 1e3,
            r->check_max <= r->check_tol ? CS(CHECK_OK) : CS(CHECK_BAD));
    else
        say(s, "%s", CS(CHECK_NONE));
    /* times vary from run to run: stdout only, never in the record or the report */
    lm_say(c->io, LM_OUT, CS(TIMES), r->threads, r->tm.plan, r->tm.machine, r->tm.frames,
           r->tm.fit, r->tm.check, r->tm.total, r->tm.cpu);
    return LM_GO;
}

const char *lm_cornea_scan_example(void) { return CS(EXAMPLE); }
