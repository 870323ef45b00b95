/* rig.c -- the cornea-rig dialogue (lensmat --rig): choose a rig file and a chip
 * (the simulator, with its event log, or a GPIO chip through libgpiod), then home,
 * move the joints, move to a target point on the cornea, expose, or scan N points;
 * in the simulator every point is checked in closed loop (the simulated motors'
 * pose through the exact forward model must land within the quantisation bound of
 * the detector point).  The engine (build/lib/lensmat-rig.so) is loaded when the
 * dialogue starts; its emergency_off is a stop hook, so a signal switches the laser
 * off, then the drivers, before lensmat exits; every other way out closes the
 * machine the same way.  Texts: prompts/rig.txt. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <errno.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "ask.h"
#include "dialogues.h"
#include "engine.h"
#include "../rig/rig.h"
#include "../trace/trace.h"
#include "prompts_rig.h"
#include "rigframe.h"

#define P(k) rig_prompts[RIG_##k]
#define WORD 4096
#define DEG (3.14159265358979323846 / 180)

typedef struct rdlg {
    lm_io *io;
    const rig_api *api;
    rg_rig rig;
    int have_rig, sim;
    rg_machine *m;
    char log[WORD], state[WORD + 8];
    double worst_um, worst_bound_um;
    int outside;
    const trace_api *tr;        /* the independent check, loaded with the first point */
    int tr_tried;
    lm_rigcam cam;              /* rig file "camera frames": the imaging engine's frames */
    int cam_off;                /* frames wanted but the imaging engine is missing */
    int nframes;
    double fworst_um, fworst_lim_um, fsigma_um, foff_um;
    char *dose_log;             /* the session's dose log (written at the end) */
    size_t dose_len, dose_cap;
} rdlg;

static const rig_api *volatile hook_api;

/* Stop hook (async-signal-safe: the engine's emergency path only). */
static void laser_off_hook(void *ctx)
{
    (void)ctx;
    if (hook_api && hook_api->emergency_off) hook_api->emergency_off();
}

static int stop_cb(void *ctx) { (void)ctx; return lm_stop_requested(); }

static const char *const jname[RG_NJOINTS] = {"m1a", "m1b", "u", "v", "m2a", "m2b"};
static int linear(int j) { return j == RG_J_U || j == RG_J_V; }

/* "m1a 1 deg, m1b ..." of a pose (rad, mm). */
static const char *pose_text(const rg_pose *p, char *buf, size_t cap)
{
    size_t n = 0;
    buf[0] = 0;
    for (int j = 0; j < RG_NJOINTS && n < cap; j++) {
        double v = linear(j) ? p->j[j] : p->j[j] / DEG;
        if (fabs(v) < 5e-13) v = 0;     /* no "-0" */
        n += (size_t)snprintf(buf + n, cap - n, P(POSITION), j ? ", " : "", jname[j], v,
                              linear(j) ? "mm" : "deg");
    }
    return buf;
}

/* ---- answers ------------------------------------------------------------------- */

static int check_rig(void *ctx, const char *word, char *msg, size_t cap)
{
    rdlg *d = ctx;
    d->have_rig = 0;
    if (lm_check_input(d->io, word, "the rig file", msg, cap)) return -1;
    if (d->api->rig_load(word, &d->rig, msg, cap)) return -1;
    d->have_rig = 1;
    return 0;
}

static int same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    return !stat(a, &sa) && !stat(b, &sb) && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

static int check_log(void *ctx, const char *word, char *msg, size_t cap)
{
    rdlg *d = ctx;
    static const char *const ext[] = {"", ".part", ".state", ".state.part"};
    char name[WORD + 16];
    if (!strcmp(word, "-")) return 0;
    /* the log, the file it grows in and the shared state: none may be an input */
    for (int i = 0; i < 4; i++) {
        snprintf(name, sizeof name, "%s%s", word, ext[i]);
        if (same_file(name, d->rig.path)) { snprintf(msg, cap, P(LOG_IS_RIG), name); return -1; }
        if (lm_check_output(d->io, name, msg, cap)) return -1;
    }
    return 0;
}

static int ask_num(rdlg *d, const char *q, const char *what, unsigned flags, double min,
                   double *v)
{
    lm_numspec spec = {what, flags, min};
    return lm_ask_number(d->io, q, q, &spec, v);
}

/* An engine refusal: said (and recorded); in a replay it ends the session.  A latched
 * fault ends it everywhere (non-zero exit): the machine is stopped until reset. */
static int refused(rdlg *d, int rc, const char *err)
{
    char why[RG_ERRMAX];
    lm_say(d->io, LM_BOTH, P(FAILED), err);
    if (d->m && d->api->fault && d->api->fault(d->m, why, sizeof why)) {
        lm_say(d->io, LM_BOTH, P(FAULT), why);
        fprintf(stderr, "lensmat: %s:%ld: fault latched: %s\n", d->io->src, d->io->line, why);
        return LM_FAIL;
    }
    if (rc == RG_ESTOP || lm_stop_requested()) return LM_FAIL;
    if (!d->io->interactive) {
        fprintf(stderr, "lensmat: %s:%ld: %s\n", d->io->src, d->io->line, err);
        return LM_FAIL;
    }
    return LM_GO;
}

/* ---- actions ------------------------------------------------------------------- */

static int do_home(rdlg *d)
{
    char err[RG_ERRMAX], buf[512];
    rg_pose p;
    int rc = d->api->home(d->m, stop_cb, NULL, err, sizeof err);
    if (rc) return refused(d, rc, err);
    d->api->position(d->m, NULL, &p);
    lm_say(d->io, LM_BOTH, P(HOMED), pose_text(&p, buf, sizeof buf));
    return LM_GO;
}

static int do_joints(rdlg *d)
{
    char err[RG_ERRMAX], buf[512], q[256];
    rg_pose p;
    int rc;
    for (int j = 0; j < RG_NJOINTS; j++) {
        double v;
        snprintf(q, sizeof q, P(JOINT), jname[j], linear(j) ? "mm" : "degrees");
        if ((rc = ask_num(d, q, P(JOINT_WHAT), 0, 0, &v))) return rc;
        p.j[j] = linear(j) ? v : v * DEG;
    }
    if ((rc = d->api->move(d->m, &p, stop_cb, NULL, err, sizeof err))) return refused(d, rc, err);
    d->api->position(d->m, NULL, &p);
    lm_say(d->io, LM_BOTH, P(MOVED), pose_text(&p, buf, sizeof buf));
    return LM_GO;
}

/* One line of the session's dose log. */
static void dose_note(rdlg *d, const char *fmt, double a, double b, double c, double e,
                      double f)
{
    char line[256];
    int n = snprintf(line, sizeof line, fmt, a, b, c, e, f);
    if (n <= 0) return;
    if (d->dose_len + (size_t)n + 1 > d->dose_cap) {
        size_t cap = d->dose_cap ? d->dose_cap * 2 : 4096;
        char *p;
        while (cap < d->dose_len + (size_t)n + 1) cap *= 2;
        if (!(p = realloc(d->dose_log, cap))) return;
        d->dose_log = p;
        d->dose_cap = cap;
    }
    memcpy(d->dose_log + d->dose_len, line, (size_t)n + 1);
    d->dose_len += (size_t)n;
}

static int do_expose_ms(rdlg *d, double ms)
{
    char err[RG_ERRMAX];
    rg_dose z;
    int rc = d->api->expose(d->m, ms, stop_cb, NULL, err, sizeof err);
    if (rc) return refused(d, rc, err);
    lm_say(d->io, LM_BOTH, P(EXPOSED), ms);
    if (d->api->dose_plan && d->api->dose_plan(d->m, ms, 0, &z, err, sizeof err) != RG_EINVAL)
        dose_note(d, "exposure %.0f: %g ms, %.6g J/m^2; session %.6g J/m^2 in %.6g s\n",
                  (double)z.n, ms, z.H_one, z.H_total, z.t_total);
    return LM_GO;
}

/* The dose log beside the record (RECORD.dose), written like the simulator's log: a
 * temporary name, renamed when complete; never over an input. */
static void write_dose_log(rdlg *d)
{
    char name[WORD + 16], part[WORD + 48], msg[512];
    FILE *f;
    if (!d->dose_log || !d->io->rec_name || !strcmp(d->io->rec_name, "-")) return;
    snprintf(name, sizeof name, "%s.dose", d->io->rec_name);
    if (lm_check_output(d->io, name, msg, sizeof msg)) {
        fprintf(stderr, "lensmat: %s\n", msg);
        return;
    }
    snprintf(part, sizeof part, "%s.part.%ld", name, (long)getpid());
    if (!(f = fopen(part, "w"))) return;
    fprintf(f, "# lensmat --rig dose log: rig %s, %g mW, %g nm, %g mm beam at the cornea; "
            "radiant exposure averaged over the 7 mm aperture (doc/rig-safety.md)\n",
            d->rig.path, d->rig.laser_power_mw, d->rig.wavelength_nm, d->rig.beam_diameter_mm);
    fputs(d->dose_log, f);
    if (fclose(f) || rename(part, name)) { unlink(part); return; }
    lm_say(d->io, LM_OUT, P(DOSE_LOG_OUT), name);
}

static int ask_ms(rdlg *d, double *ms)
{
    return ask_num(d, P(EXPOSE_MS), P(EXPOSE_MS_WHAT), LM_POSITIVE, 0, ms);
}

/* Closed loop (simulator): the simulated motors' pose, through the exact forward
 * model and through the trace engine (mirrors and cornea as surfaces, independent of
 * the geometry code); the spot's miss at the detector point must be within the bound
 * half a step on every joint can cause (first order, through the Jacobian).  miss
 * (the larger of the two), traced (NAN without the tracer) and bound in um; 0 if the
 * chip has no motor feedback. */
static int closed_loop(rdlg *d, const double target[3], double *miss, double *traced,
                       double *bound, rg_beam *bo, double hit[3])
{
    const rig_api *a = d->api;
    const rg_geometry *g = &d->rig.geom;
    long s[RG_NJOINTS];
    rg_pose p;
    rg_beam b;
    double J[4 * RG_NJOINTS], cond, e[2] = {0, 0};
    char err[RG_ERRMAX];
    if (!a->motors(d->m, s)) return 0;
    for (int j = 0; j < RG_NJOINTS; j++)
        p.j[j] = s[j] / d->rig.axis[j].steps_per * (linear(j) ? 1 : DEG);
    *traced = NAN;
    hit[0] = hit[1] = hit[2] = NAN;
    if (a->forward(g, &p, &b, err, sizeof err) ||
        a->jacobian(g, &p, J, &cond, err, sizeof err)) { *miss = INFINITY; *bound = 0; return 1; }
    for (int r = 0; r < 2; r++)
        for (int j = 0; j < RG_NJOINTS; j++)
            e[r] += fabs(J[(2 + r) * RG_NJOINTS + j]) * 0.5 / g->joint[j].steps_per;
    *miss = 1e3 * sqrt((b.det[0] - g->detector[0]) * (b.det[0] - g->detector[0]) +
                       (b.det[1] - g->detector[1]) * (b.det[1] - g->detector[1]) +
                       (b.det[2] - g->detector[2]) * (b.det[2] - g->detector[2]));
    *bound = 1e3 * sqrt(e[0] * e[0] + e[1] * e[1]) * (1 + 1e-6) + 1e-6;
    *bo = b;
    memcpy(hit, b.det, sizeof b.det);   /* the tracer's hit replaces it below */
    if (!d->tr_tried) {
        trace_get_api_fn get = (trace_get_api_fn)lm_engine_symbol("trace", TRACE_API_SYMBOL);
        d->tr_tried = 1;
        d->tr = get ? get(TRACE_ABI) : NULL;
        if (!d->tr) lm_say(d->io, LM_BOTH, "%s", P(NO_TRACER));
    }
    if (d->tr && a->verify) {
        rg_verify v;
        if (a->verify(d->tr, g, &p, target, &v, err, sizeof err) || !v.hit) *traced = INFINITY;
        else { *traced = v.err_detector * 1e3; memcpy(hit, v.det, sizeof v.det); }
        if (*traced > *miss) *miss = *traced;
    }
    return 1;
}

/* The detected spot (rig file "camera frames"): the landing point made into a camera
 * frame, its centroid located by the imaging engine; it must land within the bound
 * plus three times the centroid's own uncertainty.  1: within. */
static int frame_check(rdlg *d, const rg_beam *b, const double hit[3], double bound,
                       double ms)
{
    const double *det = d->rig.geom.detector;
    lm_rigcam_spot sp;
    char err[RG_ERRMAX];
    double miss, lim;
    int ok;
    if (lm_rigcam_detect(&d->cam, &d->rig, b, hit, ms > 0 ? ms / 1e3 : 1e-3, &sp, err,
                         sizeof err)) {
        lm_say(d->io, LM_BOTH, P(FRAME_FAILED), err);
        return 0;
    }
    miss = 1e3 * sqrt((sp.det[0] - det[0]) * (sp.det[0] - det[0]) +
                      (sp.det[1] - det[1]) * (sp.det[1] - det[1]) +
                      (sp.det[2] - det[2]) * (sp.det[2] - det[2]));
    lim = bound + 3e3 * sp.sigma;
    ok = miss <= lim;
    lm_say(d->io, LM_BOTH, P(FRAME), sp.x, sp.y, sp.w, sp.snr, miss, sp.sigma * 1e3,
           sp.off * 1e3, bound, lim, ok ? P(CLOSED_OK) : P(CLOSED_BAD));
    d->nframes++;
    if (miss > d->fworst_um) { d->fworst_um = miss; d->fworst_lim_um = lim; }
    if (sp.sigma * 1e3 > d->fsigma_um) d->fsigma_um = sp.sigma * 1e3;
    if (sp.off * 1e3 > d->foff_um) d->foff_um = sp.off * 1e3;
    return ok;
}

/* Frames wanted: load the imaging engine now (first point), say the camera. */
static int want_frames(rdlg *d)
{
    char err[RG_ERRMAX];
    const rg_rig *r = &d->rig;
    if (!r->cam_frames || d->cam_off) return 0;
    if (d->cam.tried) return 1;
    if (lm_rigcam_load(&d->cam, err, sizeof err)) {
        lm_say(d->io, LM_BOTH, P(CAMERA_NONE), err);
        d->cam_off = 1;
        return 0;
    }
    lm_say(d->io, LM_BOTH, P(CAMERA_ON), r->cam_pixels, r->cam_pixels, r->cam_pitch * 1e3,
           r->cam_read_noise, r->beam_waist, r->cam_seed);
    return 1;
}

/* Solve, quantise, move, (expose), check: one target. */
static int visit(rdlg *d, const rg_target *t, double ms)
{
    const rig_api *a = d->api;
    rg_solution s;
    rg_quantised q;
    long steps[RG_NJOINTS];
    char err[RG_ERRMAX], buf[512], dg[512];
    double miss, traced, bound, hit[3];
    rg_beam b;
    int rc = a->solve(&d->rig.geom, t, NULL, &s, err, sizeof err);
    if (rc) return refused(d, rc, err);
    if ((rc = a->quantise(&d->rig.geom, t, &s, &q, err, sizeof err))) return refused(d, rc, err);
    lm_say(d->io, LM_BOTH, P(SOLVED), s.target[0], s.target[1], s.target[2],
           pose_text(&q.pose, buf, sizeof buf));
    if (s.diag & (RG_D_ILLCOND | RG_D_NEAR_PARALLEL))
        lm_say(d->io, LM_BOTH, P(WARN), a->diag_text(s.diag, dg, sizeof dg), s.cond);
    lm_say(d->io, LM_BOTH, P(LANDING), q.err_cornea * 1e3, q.err_detector * 1e3);
    for (int j = 0; j < RG_NJOINTS; j++) steps[j] = (long)q.steps[j];
    if ((rc = a->move_steps(d->m, steps, stop_cb, NULL, err, sizeof err)))
        return refused(d, rc, err);
    if (ms > 0 && (rc = do_expose_ms(d, ms))) return rc;
    if (closed_loop(d, s.target, &miss, &traced, &bound, &b, hit)) {
        int ok = miss <= bound;
        if (isnan(traced))
            lm_say(d->io, LM_BOTH, P(CLOSED_LOOP_MODEL), miss, bound,
                   ok ? P(CLOSED_OK) : P(CLOSED_BAD));
        else
            lm_say(d->io, LM_BOTH, P(CLOSED_LOOP), miss, traced, bound,
                   ok ? P(CLOSED_OK) : P(CLOSED_BAD));
        if (miss > d->worst_um) d->worst_um = miss;
        if (bound > d->worst_bound_um) d->worst_bound_um = bound;
        if (want_frames(d) && isfinite(miss)) ok = frame_check(d, &b, hit, bound, ms) && ok;
        d->outside += !ok;
    } else {
        lm_say(d->io, LM_BOTH, "%s", P(NO_FEEDBACK));
    }
    return LM_GO;
}

static int have_geometry(rdlg *d)
{
    const rig_api *a = d->api;
    if (a->solve && a->quantise && a->forward && a->jacobian && a->diag_text) return 1;
    lm_say(d->io, LM_BOTH, "%s\n", P(NO_GEOMETRY));
    return 0;
}

static int do_point(rdlg *d)
{
    static const char *const kinds[] = {"angles", "height", NULL};
    rg_target t;
    double x, phi;
    int rc, k;
    if (!have_geometry(d)) return refused(d, RG_EINVAL, P(NO_GEOMETRY));
    if ((rc = lm_ask_choice(d->io, P(TARGET_KIND), P(TARGET_KIND), P(TARGET_KIND_WHAT), kinds,
                            &k)))
        return rc;
    if (k == 0) rc = ask_num(d, P(THETA), P(THETA_WHAT), LM_NONNEG, 0, &x);
    else rc = ask_num(d, P(HEIGHT), P(HEIGHT_WHAT), LM_NONNEG, 0, &x);
    if (rc || (rc = ask_num(d, P(PHI), P(PHI_WHAT), 0, 0, &phi))) return rc;
    t.kind = k == 0 ? RG_T_ANGLES : RG_T_HEIGHT;
    t.a = k == 0 ? x * DEG : x;
    t.b = phi * DEG;
    return visit(d, &t, 0);
}

/* The scan's order from the engine's planner (rig_api.scan_order), with its predicted
 * time against the spiral's own order; NULL (spiral order) when a target does not
 * solve, the scan is too long to plan, or the engine has no planner. */
static long *plan_scan(rdlg *d, long n, double hmax, double ms)
{
    const rig_api *a = d->api;
    long *steps, *order, start[RG_NJOINTS];
    char err[RG_ERRMAX], buf[1024];
    rg_scan_stats s0, s1;
    if (!a->scan_order || !a->scan_time || !a->scan_limit_text || n > RG_SCAN_ORDER_MAX)
        return NULL;                /* (the planner keeps the given order there) */
    steps = malloc((size_t)n * RG_NJOINTS * sizeof *steps);
    order = malloc((size_t)n * sizeof *order);
    if (!steps || !order) { free(steps); free(order); return NULL; }
    for (long k = 0; k < n; k++) {
        rg_target t = {RG_T_HEIGHT, hmax * sqrt((k + 0.5) / n),
                       fmod(k * 137.50776405, 360) * DEG};
        rg_solution s;
        rg_quantised q;
        if (a->solve(&d->rig.geom, &t, NULL, &s, err, sizeof err) ||
            a->quantise(&d->rig.geom, &t, &s, &q, err, sizeof err)) {
            free(steps); free(order);
            return NULL;
        }
        for (int j = 0; j < RG_NJOINTS; j++) steps[k * RG_NJOINTS + j] = (long)q.steps[j];
    }
    a->position(d->m, start, NULL);
    if (a->scan_order(&d->rig, start, steps, n, order, err, sizeof err) ||
        a->scan_time(&d->rig, start, steps, NULL, n, ms, &s0, err, sizeof err) ||
        a->scan_time(&d->rig, start, steps, order, n, ms, &s1, err, sizeof err)) {
        free(steps); free(order);
        return NULL;
    }
    lm_say(d->io, LM_BOTH, P(SCAN_ORDER), s1.t_total, s0.t_total,
           a->scan_limit_text(&s1, buf, sizeof buf));
    free(steps);
    return order;
}

static int do_scan(rdlg *d)
{
    double n, hmax, ms;
    int rc;
    if (!have_geometry(d)) return refused(d, RG_EINVAL, P(NO_GEOMETRY));
    if ((rc = ask_num(d, P(SCAN_N), P(SCAN_N_WHAT), LM_POSITIVE, 0, &n))) return rc;
    if (n != floor(n) || n > 1e6) {
        char m[128];
        snprintf(m, sizeof m, "%g points: give a whole number from 1 to 1000000", n);
        return refused(d, RG_EINVAL, m);
    }
    if ((rc = ask_num(d, P(SCAN_H), P(SCAN_H_WHAT), LM_NONNEG, 0, &hmax)) ||
        (rc = ask_ms(d, &ms)))
        return rc;
    /* the whole scan's dose before its first pulse */
    if (ms > 0 && d->api->dose_plan) {
        rg_dose z;
        char err[RG_ERRMAX];
        rc = d->api->dose_plan(d->m, ms, (long)n, &z, err, sizeof err);
        if (rc && rc != RG_EDOSE) return refused(d, rc, err);
        lm_say(d->io, LM_BOTH, P(DOSE), (int)z.n, ms, d->rig.laser_power_mw,
               d->rig.wavelength_nm, d->rig.beam_diameter_mm, z.H_one, z.H_total, z.mpe_total,
               z.limit, z.fraction, 1 / z.fraction);
        dose_note(d, "scan planned: %.0f exposures of %g ms, %.6g J/m^2 in all, %.4g of the "
                  "MPE %.6g J/m^2\n", (double)z.n, ms, z.H_total, z.fraction, z.mpe_total);
        if (rc) return refused(d, rc, err);
    }
    d->worst_um = d->worst_bound_um = 0;
    d->outside = 0;
    d->nframes = 0;
    d->fworst_um = d->fworst_lim_um = d->fsigma_um = d->foff_um = 0;
    /* a sunflower (Vogel) spiral: even cover of the disc, no two points on a ring;
     * visited in the order the engine's scan planner gives (doc/scan-time.md) when
     * every target solves, else in the spiral's order (visit refuses the bad one) */
    {
        long *order = plan_scan(d, (long)n, hmax, ms);
        for (long k = 0; k < (long)n; k++) {
            rg_target t;
            long i = order ? order[k] : k;
            t.kind = RG_T_HEIGHT;
            t.a = hmax * sqrt((i + 0.5) / n);
            t.b = fmod(i * 137.50776405, 360) * DEG;
            lm_say(d->io, LM_BOTH, P(SCAN_POINT), (int)k + 1, (int)n, t.a, t.b / DEG);
            if ((rc = visit(d, &t, ms))) { free(order); return rc; }
        }
        free(order);
    }
    lm_say(d->io, LM_BOTH, P(SCAN_DONE), (int)n, d->worst_um, d->worst_bound_um, d->outside);
    if (d->nframes)
        lm_say(d->io, LM_BOTH, P(FRAMES_DONE), d->nframes, d->fworst_um, d->fworst_lim_um,
               d->fsigma_um, d->foff_um);
    if (d->outside && !d->io->interactive) return LM_FAIL;
    return LM_GO;
}

/* ---- the session ---------------------------------------------------------------- */

/* One pose's extreme spot line: the apex (RG_T_ANGLES 0 0) at height 0. */
static void spot_line(rdlg *d, const char *fmt, const rg_spot_pose *p)
{
    double h = p->target.kind == RG_T_HEIGHT ? p->target.a : 0;
    double ph = p->target.kind == RG_T_HEIGHT ? p->target.b / DEG : 0;
    lm_say(d->io, LM_BOTH, fmt, p->foot_major, p->foot_minor, p->foot_angle / DEG, h, ph,
           p->theta / DEG, p->f_t, p->f_s, p->psi / DEG);
}

/* The cornea's oblique incidence (ABI 2: rg_spots' scan fields): the apex pose, then
 * the scan's incidence, its largest and smallest detector spot and the centroid. */
static void beam_oblique(rdlg *d, const rg_spots *s)
{
    const rg_spot_pose *st = &s->steep;
    if (s->ref_not_apex) lm_say(d->io, LM_BOTH, "%s", P(BEAM_OBLIQUE_NONE));
    else lm_say(d->io, LM_BOTH, P(BEAM_OBLIQUE), s->apex.theta / DEG, s->apex.f_t,
                s->apex.f_s, s->apex.foot_major, s->apex.foot_minor);
    lm_say(d->io, LM_BOTH, P(BEAM_SCAN), s->scan_n, s->scan_n + s->scan_bad, RG_SPOTS_POSES,
           s->scan_h, st->theta / DEG, st->target.kind == RG_T_HEIGHT ? st->target.a : 0,
           st->target.kind == RG_T_HEIGHT ? st->target.b / DEG : 0);
    spot_line(d, P(BEAM_SPOT_LARGE), &s->big);
    spot_line(d, P(BEAM_SPOT_SMALL), &s->small);
    const rg_spot_pose *dm = &s->dim;
    char how[96];
    if (d->rig.laser_pol_set)
        snprintf(how, sizeof how, P(BEAM_FRESNEL_LIN), d->rig.laser_pol[0],
                 d->rig.laser_pol[1], d->rig.laser_pol[2]);
    else snprintf(how, sizeof how, "%s", P(BEAM_FRESNEL_UNPOL));
    double dh = dm->target.kind == RG_T_HEIGHT ? dm->target.a : 0;
    double dph = dm->target.kind == RG_T_HEIGHT ? dm->target.b / DEG : 0;
    if (s->have_dose && s->ref_not_apex)
        lm_say(d->io, LM_BOTH, P(BEAM_FRESNEL_NOAPEX), how, s->reflectance, dm->reflectance,
               dh, dph, dm->theta / DEG, dm->refl_s, dm->refl_p, dm->s_frac);
    else if (s->have_dose)
        lm_say(d->io, LM_BOTH, P(BEAM_FRESNEL), how, s->reflectance, s->apex.reflectance,
               dm->reflectance, dh, dph, dm->theta / DEG, dm->refl_s, dm->refl_p, dm->s_frac);
    if (s->have_dose && s->photons > 0)
        lm_say(d->io, LM_BOTH, P(BEAM_CENTROID_SCAN), s->big.sigma_major_um,
               s->big.sigma_minor_um, s->small.sigma_major_um, s->small.sigma_minor_um,
               dm->sigma_major_um, dm->sigma_minor_um);
    if (s->scan_best_is_none)
        lm_say(d->io, LM_BOTH, P(BEAM_SCAN_LENS_NONE), s->scan_n, s->scan_at,
               s->scan_best_cornea, s->scan_best_det, s->apexlens_worst_cornea,
               s->apexlens_worst_det);
    else
        lm_say(d->io, LM_BOTH, P(BEAM_SCAN_LENS), s->scan_n, s->scan_at, s->scan_best_f,
               s->scan_best_cornea, s->scan_best_det, s->apexlens_worst_cornea,
               s->apexlens_worst_det);
}

/* The beam on the cornea and the detector (rig_api.spots): the engine computes,
 * this prints. */
static int do_beam(rdlg *d)
{
    rg_spots s;
    char err[RG_ERRMAX];
    int rc;
    if (!d->api->spots) return refused(d, RG_EINVAL, P(NO_GEOMETRY));
    if ((rc = d->api->spots(&d->rig, &s, err, sizeof err))) return refused(d, rc, err);
    if (s.ref_not_apex) {
        rg_target t0 = {RG_T_ANGLES, 0, 0};
        rg_solution sol;
        d->api->solve(&d->rig.geom, &t0, NULL, &sol, err, sizeof err);
        lm_say(d->io, LM_BOTH, P(BEAM_PATH_REF), err, s.ref.a, s.ref.b / DEG);
    }
    lm_say(d->io, LM_BOTH, s.ref_not_apex ? P(BEAM_PATH_STAND) : P(BEAM_PATH), s.path[0],
           s.path[1], s.path[2], s.path[3], s.R);
    if (s.waist_from_diameter)
        lm_say(d->io, LM_BOTH, P(BEAM_LASER_DERIVED), s.w0, s.m2, s.lambda_mm * 1e6);
    else
        lm_say(d->io, LM_BOTH, P(BEAM_LASER_GIVEN), s.w0, s.waist_before_m1, s.m2,
               s.lambda_mm * 1e6);
    if (s.lens_at > 0) lm_say(d->io, LM_BOTH, P(BEAM_LENS), s.lens_f, s.lens_at);
    else lm_say(d->io, LM_BOTH, "%s", P(BEAM_NO_LENS));
    lm_say(d->io, LM_BOTH, P(BEAM_RADII), s.w_m1, s.w_m2, s.w_cornea, s.w_det);
    if (s.lens_at > 0) lm_say(d->io, LM_BOTH, P(BEAM_NOLENS), s.nolens_cornea, s.nolens_det);
    if (s.best_is_none)
        lm_say(d->io, LM_BOTH, P(BEAM_BEST_NONE), s.scan_at, s.best_cornea, s.best_det);
    else
        lm_say(d->io, LM_BOTH, P(BEAM_BEST), s.scan_at, s.best_f, s.best_cornea, s.best_det);
    if (s.have_dose)
        lm_say(d->io, LM_BOTH, P(BEAM_CENTROID), s.expose_ms, s.reflectance, s.photons,
               s.sigma_um, s.sigma_best_um);
    else lm_say(d->io, LM_BOTH, "%s", P(BEAM_NO_DOSE));
    beam_oblique(d, &s);
    return LM_GO;
}

static int need_engine(rdlg *d)
{
    rig_get_api_fn get = (rig_get_api_fn)lm_engine_symbol("rig", RIG_API_SYMBOL);
    if (get) d->api = get(RIG_ABI);
    if (!d->api || !d->api->open) {
        if (get) fprintf(stderr, "lensmat: the rig module's interface does not match\n");
        return -1;
    }
    return 0;
}

static int open_machine(rdlg *d)
{
    static const char *const backends[] = {"sim", "gpiod", NULL};
    rg_open_opts o = {RG_BACKEND_SIM, NULL, NULL, NULL, 0};
    char err[RG_ERRMAX];
    int rc, b;
    if ((rc = lm_ask_choice(d->io, P(BACKEND), P(BACKEND), P(BACKEND_WHAT), backends, &b)))
        return rc;
    d->sim = b == 0;
    if (d->sim) {
        if ((rc = lm_ask_file(d->io, P(SIM_LOG), P(SIM_LOG), P(SIM_LOG_WHAT), check_log, d,
                              d->log, sizeof d->log)))
            return rc;
        if (strcmp(d->log, "-")) {
            o.sim_log = d->log;
            snprintf(d->state, sizeof d->state, "%s.state", d->log);
            o.sim_state = d->state;
        }
    } else {
        o.backend = RG_BACKEND_GPIOD;
        o.realtime = 1;
    }
    hook_api = d->api;
    lm_on_stop(laser_off_hook, NULL);
    if ((rc = d->api->open(&d->rig, &o, &d->m, err, sizeof err))) {
        lm_say(d->io, LM_REC, P(OPEN_FAILED), err);
        fprintf(stderr, "lensmat: %s\n", err);
        return LM_FAIL;
    }
    lm_say(d->io, LM_BOTH, P(OPENED), d->sim ? P(OPENED_SIM) : d->rig.chip);
    lm_say(d->io, LM_OUT, P(SCHED_OUT), d->api->sched_note(d->m));
    return LM_GO;
}

int lm_rig(lm_io *io)
{
    static const char *const actions[] = {"home", "joints", "point", "expose", "scan", "beam",
                                          "quit", NULL};
    rdlg *d = calloc(1, sizeof *d);
    char name[WORD];
    int rc, a;
    if (!d) { fprintf(stderr, "lensmat: out of memory\n"); return LM_FAIL; }
    d->io = io;
    lm_say(io, LM_BOTH, "%s", P(INTRO));
    if (need_engine(d)) { free(d); return LM_FAIL; }
    rc = lm_ask_file(io, P(RIG_FILE), P(RIG_FILE), P(RIG_FILE_WHAT), check_rig, d, name,
                     sizeof name);
    if (!rc) {
        const rg_rig *r = &d->rig;
        lm_say(io, LM_BOTH, P(RIG_LOADED), r->path, r->chip, r->laser.offset,
               r->interlock.offset, r->max_on_ms, r->tick_us);
        if (r->heartbeat.offset < 0)
            lm_say(io, LM_BOTH, "%s", r->eye_safe_without_heartbeat ? P(EYE_SAFE) : P(NO_HEARTBEAT));
        rc = open_machine(d);
    }
    while (!rc) {
        double ms;
        if ((rc = lm_ask_choice(io, P(ACTION), P(ACTION), P(ACTION_WHAT), actions, &a))) break;
        if (a == 6) break;
        rc = a == 0 ? do_home(d) : a == 1 ? do_joints(d) : a == 2 ? do_point(d)
           : a == 3 ? ((rc = ask_ms(d, &ms)) ? rc : do_expose_ms(d, ms))
           : a == 5 ? do_beam(d) : do_scan(d);
    }
    /* every way out: laser off, then drivers disabled */
    if (d->m) {
        int lost = d->api->close(d->m) != 0;    /* the simulator's log lost lines */
        d->m = NULL;
        lm_say(io, LM_BOTH, "%s", P(CLOSED));
        if (d->state[0]) unlink(d->state);
        if (d->sim && strcmp(d->log, "-")) {
            char shown[4 * sizeof d->log + 4];
            lm_escape(d->log, shown, sizeof shown);
            if (lost) {                 /* never "Written:" for a log that lost lines */
                fprintf(stderr, P(LOG_FAILED), shown);
                rc = LM_FAIL;
            } else lm_say(io, LM_OUT, P(WRITTEN_OUT), shown);
        }
    }
    lm_on_stop_remove(laser_off_hook, NULL);
    lm_rigcam_free(&d->cam);
    if (rc != LM_QUIT) write_dose_log(d);
    free(d->dose_log);
    free(d);
    if (rc == LM_FAIL || rc == LM_QUIT) return rc;
    lm_check_leftover(io);
    lm_say(io, LM_OUT, P(WRITTEN_OUT), io->rec_shown);
    return LM_GO;
}

const char *lm_rig_example(void) { return P(EXAMPLE); }
