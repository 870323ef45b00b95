/* tp_loop.c -- the topography pipeline's measurement loop: plan (rig engine: solve and
 * quantise every target of the pattern), run (the machine: move, expose; optional),
 * detect (the trace engine's hit through the true eye, a full synthetic frame from the
 * imaging engine and its centroid fit, or the quick model: the hit plus Gaussian
 * noise), fit (cornea engine) and check (the fitted cornea traced for every fitted
 * pose against the fit's analytic model).  The per-point work runs on r->threads
 * workers; each point's result depends only on its index and the seed, so the output
 * is the same bit for bit whatever the thread count. */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "tp_int.h"
#include "common/lm_rand.h"
#include "imaging/imaging.h"
#include "trace/trace.h"

#define PI 3.14159265358979323846
#define PLANCK_HC 1.98644586e-25        /* h c, J m */
#define LAMBDA_M 633e-9

static int progress_tty;         /* stderr is a terminal: show how far a scan is */

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

/* ---- per-point work ---------------------------------------------------------------- */


static double dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* Where the ray from p along d crosses the plane, in its (u, v); 0 or -1 (never). */
static int on_plane(const cn_plane *pl, const double p[3], const double d[3], double *u,
                    double *v, double hit[3])
{
    double rel[3], dn = dot(d, pl->w), h[3];
    if (!(dn > 0)) return -1;
    for (int i = 0; i < 3; i++) rel[i] = pl->at[i] - p[i];
    double k = dot(rel, pl->w) / dn;
    for (int i = 0; i < 3; i++) { hit[i] = p[i] + k * d[i]; h[i] = hit[i] - pl->at[i]; }
    *u = dot(h, pl->e1);
    *v = dot(h, pl->e2);
    return 0;
}

/* The traced path of pose p through geometry gt: the hit on the plane.  The tracer
 * when there is one (its cornea point and detector hit give the reflected ray),
 * else the rig's forward model.  0, or -1 with why. */
static int traced_hit(const tp_run *r, const rg_geometry *gt, const cn_plane *pl,
                      const rg_pose *p, double *u, double *v, double hit[3], char *why,
                      size_t cap)
{
    char e[RG_ERRMAX];
    rg_beam b;
    double d[3];
    if (r->rg->forward(gt, p, &b, e, sizeof e) || (b.diag & RG_D_MISS_CORNEA) ||
        !isfinite(b.spot[0])) {
        snprintf(why, cap, "the beam misses the cornea");
        return -1;
    }
    if (r->tr) {
        rg_verify vf;
        if (r->rg->verify(r->tr, gt, p, b.spot, &vf, e, sizeof e) || !vf.hit) {
            snprintf(why, cap, "the traced beam misses the detector");
            return -1;
        }
        for (int i = 0; i < 3; i++) d[i] = vf.det[i] - vf.spot[i];
        double n = sqrt(dot(d, d));
        for (int i = 0; i < 3; i++) d[i] /= n;
        if (on_plane(pl, vf.spot, d, u, v, hit)) {
            snprintf(why, cap, "the reflected beam never reaches the detector plane");
            return -1;
        }
        return 0;
    }
    if (on_plane(pl, b.spot, b.d3, u, v, hit)) {
        snprintf(why, cap, "the reflected beam never reaches the detector plane");
        return -1;
    }
    return 0;
}

/* The spot of one frame (synthetic or read), located by the imaging engine's
 * Gaussian fit; read_noise 0: measured from the frame.  off_sensor: the traced hit
 * lies outside the sensor (the reason given when no spot is found). */
static void locate(const tp_run *r, im_centroider *cz, const im_frame *f, double read_noise,
                   double gain, int off_sensor, tp_point *q)
{
    const im_frame_api *F = r->im->frame;
    const double pitch = r->cam.pitch;
    im_centroid_opt o;
    im_centroid_result res;
    im_spot sp[4];
    char e[256];
    memset(&o, 0, sizeof o);
    o.method = IM_CM_GAUSS;
    o.read_noise = read_noise;
    o.gain = gain;                      /* shot noise in each pixel's variance */
    o.spot_w = r->cam.spot_w >= 0.5 && r->cam.spot_w <= 12 ? r->cam.spot_w : 0;
                                        /* the matched filter's expected spot */
    q->spot.u = q->spot.v = NAN;
    int rc = F->centroid(cz, f, &o, sp, 4, &res, e, sizeof e);
    q->nspots = rc ? 0 : res.ndetected;
    q->snr = rc ? 0 : res.best_snr;
    if (rc || res.outcome == IM_FOUND_NONE) {
        q->spot.status = CN_S_NONE;
        if (rc) snprintf(q->why, sizeof q->why, "no centroid: %.70s", e);
        else if (off_sensor) snprintf(q->why, sizeof q->why, "no spot: it lands off the sensor");
        else snprintf(q->why, sizeof q->why, "no spot (best candidate SNR %.3g, threshold %.3g)",
                      res.best_snr, res.threshold);
        return;
    }
    q->x = sp[0].x;
    q->y = sp[0].y;
    q->snr = sp[0].snr;
    q->amp = sp[0].amp;
    q->w = sp[0].w;
    q->bg = sp[0].bg;
    q->noise = res.noise;
    if (res.outcome == IM_FOUND_SEVERAL) {
        q->spot.status = CN_S_SEVERAL;
        snprintf(q->why, sizeof q->why, "several spots in the frame (%d)", res.ndetected);
        return;
    }
    if (sp[0].flags & (IM_SF_EDGE | IM_SF_FIT_FAILED | IM_SF_SATURATED)) {
        q->spot.status = CN_S_NONE;
        snprintf(q->why, sizeof q->why, "the spot at pixel (%.1f, %.1f) is %s", sp[0].x,
                 sp[0].y, sp[0].flags & IM_SF_EDGE ? "cut by the sensor's edge"
                          : sp[0].flags & IM_SF_SATURATED ? "saturated" : "not fitted");
        return;
    }
    q->spot.u = (sp[0].x - 0.5 * (f->width - 1)) * pitch;
    q->spot.v = (sp[0].y - 0.5 * (f->height - 1)) * pitch;
    q->spot.sigma = pitch * sqrt(0.5 * (sp[0].sx * sp[0].sx + sp[0].sy * sp[0].sy));
    q->spot.status = CN_S_OK;
}

/* One synthetic frame: the traced hit (NULL: none, the frame shows no spot) splatted
 * as the camera's Gaussian spot into a full sensor frame at the detector point, saved
 * when asked, then located.  Returns 0, or -1 when a frame could not be saved (why). */
static int frame_spot(const tp_run *r, im_centroider *cz, const cn_plane *pl, int k,
                      const double *hit, tp_point *q)
{
    const im_frame_api *F = r->im->frame;
    const tp_camera *c = &r->cam;
    im_sensor s;
    im_spot_src src;
    im_hit h;
    im_frame *f = NULL;
    char e[256];
    memset(&s, 0, sizeof s);
    s.width = c->width;
    s.height = c->height;
    s.pitch = c->pitch;
    memcpy(s.origin, pl->at, sizeof s.origin);
    memcpy(s.xdir, pl->e1, sizeof s.xdir);
    memcpy(s.ydir, pl->e2, sizeof s.ydir);
    s.bits = 16;
    s.exposure = 1e-3;
    s.qe = 1;
    s.gain = 1;
    s.bias = c->bias;
    s.read_noise = c->read_noise;
    s.shot_noise = 1;                   /* photons arrive one by one: Poisson */
    s.wavelength = LAMBDA_M;
    /* the electrons that give `peak` counts at the centre of a Gaussian of 1/e^2
       radius w pixels: peak * pi w^2 / 2 */
    double electrons = c->peak * s.gain * PI * c->spot_w * c->spot_w / 2;
    memset(&h, 0, sizeof h);
    if (hit) memcpy(h.p, hit, sizeof h.p);
    h.power = electrons / s.exposure * PLANCK_HC / LAMBDA_M;
    memset(&src, 0, sizeof src);
    src.kind = IM_SPOT_HITS_GAUSS;
    src.hits = &h;
    src.nhits = 1;
    src.waist = c->spot_w * c->pitch;   /* path 0: the waist is the spot */
    src.beam_lambda = LAMBDA_M * 1e3;
    if (F->synth(&s, &src, hit ? 1 : 0, r->seed + (uint64_t)k, 1, &f, e, sizeof e)) {
        if (hit) {
            q->spot.status = CN_S_NONE;
            q->spot.u = q->spot.v = NAN;
            snprintf(q->why, sizeof q->why, "no frame: %.70s", e);
        }
        return 0;
    }
    if (r->save && q->seq > 0) {
        char name[4200], we[256];
        snprintf(name, sizeof name, r->save, q->seq);
        if (F->write(f, name, we, sizeof we)) {
            snprintf(q->why, sizeof q->why, "frame not saved: %.70s", we);
            F->frame_free(f);
            return -1;
        }
        q->saved = 1;
    }
    if (hit)
        locate(r, cz, f, c->read_noise / s.gain, s.gain,
               fabs(q->hit_u) > 0.5 * c->width * c->pitch ||
               fabs(q->hit_v) > 0.5 * c->height * c->pitch, q);
    F->frame_free(f);
    return 0;
}

/* ---- workers ----------------------------------------------------------------------- */

typedef struct job {
    tp_run *r;
    int phase;                  /* 0: measure, 1: check */
    pthread_mutex_t mu;
    int next;
    int stopped;
    cn_plane pl, plf;
    rg_geometry gt, gf;         /* true eye; fitted eye */
    int err;                    /* a worker could not start its centroider (1) or
                                   save a frame (2) */
    int done;                   /* points finished (progress) */
    double shown;               /* when progress was last shown (s; 0: never) */
} job;

static void fail_job(job *j)
{
    pthread_mutex_lock(&j->mu);
    if (!j->err) j->err = 2;
    j->stopped = 1;
    pthread_mutex_unlock(&j->mu);
}

/* The next point to work on (-1: none).  On a terminal, every ~0.2 s, how far the
 * phase is (stderr only: the record and stdout stay as a replay makes them). */
static int take(job *j, int finished)
{
    pthread_mutex_lock(&j->mu);
    j->done += finished;
    if (progress_tty && j->r->npoints >= 50) {
        double t = now();
        if (t - j->shown > 0.2) {
            fprintf(stderr, "\rlensmat: %s: point %d of %d ", j->phase ? "checking" :
                    "measuring", j->done, j->r->npoints);
            j->shown = t;
        }
    }
    int k = j->stopped ? -1 : j->next < j->r->npoints ? j->next++ : -1;
    pthread_mutex_unlock(&j->mu);
    return k;
}

/* With a cone: the hit of point q's beam through the true eye with the cone, by the
 * cornea engine's analytic model (equal to the tracer's on the eye without it to
 * 1e-12 mm); 0, or -1 (status NONE, why said) when the beam misses. */
static int cone_hit(const tp_run *r, const cn_plane *pl, const cn_params *truth, tp_point *q,
                    double hit[3])
{
    cn_spot b = q->spot;
    if (r->cn->reimage(r->g, CN_BICONIC, truth, r->bump, 0, 0, &b, 1) != 1) {
        q->spot.status = CN_S_NONE;
        q->spot.u = q->spot.v = NAN;
        snprintf(q->why, sizeof q->why, "the beam misses the cornea with its cone");
        return -1;
    }
    q->hit_u = b.u;
    q->hit_v = b.v;
    for (int i = 0; i < 3; i++) hit[i] = pl->at[i] + b.u * pl->e1[i] + b.v * pl->e2[i];
    return 0;
}

static void measure_one(job *j, im_centroider *cz, int k)
{
    tp_run *r = j->r;
    tp_point *q = &r->pt[k];
    double hit[3];
    char e[RG_ERRMAX];
    if (!q->planned) return;
    q->hit_u = q->hit_v = NAN;
    if (r->cn->ray_of_pose(r->rg, r->g, &q->pose, &q->spot.ray, e, sizeof e)) {
        q->planned = 0;
        snprintf(q->why, sizeof q->why, "no beam: %.80s", e);
        return;
    }
    if (r->source == TP_SRC_CAMERA) return;       /* located as each frame was read */
    q->spot.sigma = r->sigma > 0 ? r->sigma : 1e-4;
    const rg_geometry *gt = &j->gt;     /* the true eye, moved by a simulated drift */
    rg_geometry *gd = NULL;
    cn_params truth = r->truth_p;
    if (r->drift.kind != TP_DRIFT_NONE && (gd = malloc(sizeof *gd))) {
        *gd = j->gt;
        tp_drift_eye(r, q, gd, &truth);
        gt = gd;
    }
    int miss = r->hit ? tp_outside_hit(r, &j->pl, q, hit)
                      : traced_hit(r, gt, &j->pl, &q->pose, &q->hit_u, &q->hit_v, hit, q->why,
                                   sizeof q->why);
    if (miss) {
        free(gd);
        q->spot.status = CN_S_NONE;
        q->spot.u = q->spot.v = NAN;
        /* the camera still takes the frame: it shows no spot */
        if (r->source == TP_SRC_FRAMES && r->save && frame_spot(r, cz, &j->pl, k, NULL, q))
            fail_job(j);
        return;
    }
    if (!r->hit && r->bump && cone_hit(r, &j->pl, &truth, q, hit)) {
        free(gd);
        if (r->source == TP_SRC_FRAMES && r->save && frame_spot(r, cz, &j->pl, k, NULL, q))
            fail_job(j);
        return;
    }
    free(gd);
    if (r->source == TP_SRC_FRAMES) {
        if (frame_spot(r, cz, &j->pl, k, hit, q)) fail_job(j);
        return;
    }
    if (r->sensor_cut && tp_off_sensor(r, q)) return;      /* tp_adapt.c */
    uint64_t s = r->seed * 0x9E3779B97F4A7C15ull ^ (uint64_t)k * 0xD1B54A32D192ED03ull;
    double nu = lm_gauss(&s), nv = lm_gauss(&s);
    q->spot.u = q->hit_u + (r->sigma > 0 ? r->sigma * nu : 0);
    q->spot.v = q->hit_v + (r->sigma > 0 ? r->sigma * nv : 0);
    q->spot.status = CN_S_OK;
}

/* The fitted cornea traced for pose k against the fit's model: |difference| (mm),
 * or a negative number when the point is not checked. */
static double check_one(job *j, int k)
{
    tp_run *r = j->r;
    tp_point *q = &r->pt[k];
    double u, v, mu, mv, hit[3];
    char why[96];
    if (!q->planned || q->spot.status != CN_S_OK) return -1;
    if (traced_hit(r, &j->gf, &j->plf, &q->pose, &u, &v, hit, why, sizeof why))
        return INFINITY;                 /* fitted, yet the tracer finds no hit */
    if (r->cn->forward(r->model, &r->res.par, r->g->cornea.trans, &j->plf, &q->spot.ray,
                       &mu, &mv, NULL, NULL))
        return INFINITY;
    return hypot(u - mu, v - mv);
}

static void *worker(void *arg)
{
    job *j = arg;
    tp_run *r = j->r;
    im_centroider *cz = NULL;
    if (j->phase == 0 && r->source == TP_SRC_FRAMES && r->im) {
        cz = r->im->frame->centroider_new();
        if (!cz) {
            pthread_mutex_lock(&j->mu);
            j->err = 1;
            j->stopped = 1;
            pthread_mutex_unlock(&j->mu);
            return NULL;
        }
    }
    for (int k, fin = 0; (k = take(j, fin)) >= 0; fin = 1) {
        if (r->stop && r->stop(r->stop_ctx)) {
            pthread_mutex_lock(&j->mu);
            j->stopped = 1;
            pthread_mutex_unlock(&j->mu);
            break;
        }
        if (j->phase == 0) {
            measure_one(j, cz, k);
            r->pt[k].measured = 1;
        } else r->pt[k].spot.nres = check_one(j, k);   /* nres: scratch, reset below */
    }
    if (cz) r->im->frame->centroider_free(cz);
    return NULL;
}

static int run_workers(job *j)
{
    int nt = j->r->threads < 1 ? 1 : j->r->threads > 16 ? 16 : j->r->threads;
    pthread_t tid[16];
    int started = 0;
    j->next = 0;
    j->done = 0;
    j->shown = 0;
    for (int t = 1; t < nt; t++)
        if (pthread_create(&tid[started], NULL, worker, j) == 0) started++;
    worker(j);
    for (int t = 0; t < started; t++) pthread_join(tid[t], NULL);
    if (j->shown > 0) fputs("\r\033[K", stderr);     /* the progress line cleared */
    return j->stopped;
}

/* ---- the loop ----------------------------------------------------------------------- */

/* The next frame of the camera (or video, or file sequence) for point q: its spot
 * located, the noise measured from the frame.  0, or -1 with why in err. */
static int camera_read(tp_run *r, im_source *src, im_centroider *cz, tp_point *q,
                       int got, char *err, size_t cap)
{
    const im_frame_api *F = r->im->frame;
    im_frame *f = NULL;
    char e[256];
    int rc = F->source_next(src, &f, e, sizeof e);
    if (rc <= 0) {
        if (rc == 0) snprintf(err, cap, "%s gave %d frames for %d exposures", r->camera, got,
                              r->nplanned);
        else snprintf(err, cap, "%s", e);
        return -1;
    }
    locate(r, cz, f, 0, 0, 0, q);
    if (q->spot.status == CN_S_OK)          /* the gain is measured from the spots */
        tp_shot_add(&r->shot, f, q->x, q->y, q->amp, q->w, q->bg, q->noise);
    F->frame_free(f);
    return 0;
}

/* Camera frames: the gain from the spots' photon transfer, and every located spot's
 * sigma widened for the shot noise it implies (the centroider knew only the
 * background's noise). */
static void shot_widen(tp_run *r)
{
    r->gain = tp_shot_gain(&r->shot);
    double sum = 0;
    int m = 0;
    for (int k = 0; k < r->npoints; k++) {
        tp_point *q = &r->pt[k];
        if (!q->planned || q->spot.status != CN_S_OK) continue;
        double f = tp_shot_factor(q->amp, q->w, q->noise, r->gain);
        q->spot.sigma *= f;
        sum += f;
        m++;
    }
    if (m) r->shot_factor = sum / m;
}

static int stopped(const tp_run *r);

/* Camera frames on a machine: one read after each exposure, in scan order. */
typedef struct cam_ctx { im_source *src; im_centroider *cz; int got; } cam_ctx;
static int cam_after(tp_run *r, int k, void *ctx, char *err, size_t cap)
{
    cam_ctx *c = ctx;
    return camera_read(r, c->src, c->cz, &r->pt[k], c->got++, err, cap) ? CN_EINVAL : 0;
}

/* The surface from the data (issue 19): a reference sphere fitted to the measured
 * spots (their statuses before the model's fit: a spot the model calls an outlier
 * may be the cone), the Zernike slope fit in its frame, the keratoconus indices.  A
 * failure here is said in r->zwhy and leaves r->have_z 0; only a stop is an error. */
static int surface(tp_run *r, int m, const int *of, char *err, size_t cap)
{
    cn_spot *sp = malloc(sizeof *sp * (size_t)(m ? m : 1));
    cn_result *ref = calloc(1, sizeof *ref);
    char e[256];
    int rc = 0;
    r->have_z = 0;
    r->zwhy[0] = 0;
    if (!sp || !ref) { free(sp); free(ref); snprintf(err, cap, "out of memory"); return CN_ENOMEM; }
    for (int i = 0; i < m; i++) sp[i] = r->pt[of[i]].spot;
    /* the reference: the model's own fit when it holds (converged, not rejected: a
       toric, tilted eye is better met by its biconic than by a sphere, which read R
       8.52 for 7.8 there), else a sphere fitted for the purpose */
    int ref_model = CN_SPHERE, frc = 0;
    if (r->res.converged && !r->res.rejected_model && !r->res.poor) {
        *ref = r->res;
        ref_model = r->model;
    } else {
        cn_fit_opts fo = {.model = CN_SPHERE, .stop = r->stop, .stop_ctx = r->stop_ctx,
                          .threads = r->threads, .max_iter = r->max_iter};
        cn_params st, *stp = NULL;
        if (r->fit_start) {             /* tp_adapt.c: the last pass's eye as a sphere */
            st = *r->fit_start;
            for (int i = CN_C0; i < CN_NPARAM; i++)
                if (i < CN_DX || i > CN_DZ) st.p[i] = 0;
            stp = &st;
        }
        frc = r->cn->fit(r->g, sp, m, stp, &fo, ref, e, sizeof e);
    }
    if (frc == CN_ESTOP) { snprintf(err, cap, "stopped"); rc = CN_ESTOP; goto out; }
    if (frc || !ref->converged) {
        snprintf(r->zwhy, sizeof r->zwhy, "no reference sphere: %.200s", frc ? e : "not converged");
        goto out;
    }
    r->zref_R = ref->par.p[CN_R];
    for (int i = 0; i < m; i++) sp[i] = r->pt[of[i]].spot;   /* statuses as measured */
    if (r->cn->zfit(r->g, sp, m, &ref->par, ref_model, 0, r->zf, e, sizeof e)) {
        snprintf(r->zwhy, sizeof r->zwhy, "%.250s", e);
        goto out;
    }
    if (stopped(r)) { snprintf(err, cap, "stopped"); rc = CN_ESTOP; goto out; }
    if (r->cn->kc(r->zf, &r->kc)) {
        snprintf(r->zwhy, sizeof r->zwhy, "the indices could not be computed on the data's zone");
        goto out;
    }
    r->have_z = 1;
out:
    free(sp);
    free(ref);
    return rc;
}

static int stopped(const tp_run *r) { return r->stop && r->stop(r->stop_ctx); }

int tp_measure(tp_run *r, char *err, size_t cap)
{
    const rig_api *rg = r->rg;
    double t0 = now(), c0 = cpu_now(), t;
    char e[RG_ERRMAX];
    rg_target *tg;
    memset(&r->tm, 0, sizeof r->tm);
    r->fitted = 0;
    memset(&r->shot, 0, sizeof r->shot);
    r->check_max = NAN;
    r->check_n = 0;
    r->phase = "planning";
    r->have_dose = 0;
    progress_tty = isatty(2);
    if (r->source == TP_SRC_FRAMES && (!r->im || !r->im->frame)) {
        snprintf(err, cap, "frames need the imaging engine");
        return CN_EINVAL;
    }
    if (!(tg = malloc(sizeof *tg * (size_t)r->npoints))) {
        snprintf(err, cap, "out of memory");
        return CN_ENOMEM;
    }
    int n = tp_pattern(r->pattern, r->npoints, r->zone_h > 0 ? r->zone_h : r->zone, tg);
    for (int k = 0; r->zone_h > 0 && k < n; k++) tg[k].kind = RG_T_HEIGHT;   /* mm */
    const rg_geometry *pg = r->plan_g ? r->plan_g : r->g;    /* tp_adapt.c: the fit's */
    memset(r->pt, 0, sizeof *r->pt * (size_t)r->npoints);
    r->npoints = n;
    /* plan: solve and quantise each target on the nominal cornea */
    r->nplanned = 0;
    for (int k = 0; k < n; k++) {
        tp_point *q = &r->pt[k];
        rg_solution s;
        rg_quantised qu;
        q->t = tg[k];
        q->spot.status = CN_S_NONE;
        q->spot.u = q->spot.v = q->hit_u = q->hit_v = NAN;
        q->t_s = NAN;
        if (rg->solve(pg, &q->t, NULL, &s, e, sizeof e) ||
            rg->quantise(pg, &q->t, &s, &qu, e, sizeof e)) {
            snprintf(q->why, sizeof q->why, "not planned: %.80s", e);
            continue;
        }
        q->pose = qu.pose;
        q->planned = 1;
        r->nplanned++;
    }
    free(tg);
    t = now();
    r->tm.plan = t - t0;
    /* a camera: its frames are read one per exposure, in scan order */
    im_source *src = NULL;
    im_centroider *ccz = NULL;
    int got = 0;
    if (r->source == TP_SRC_CAMERA) {
        if (!r->im || !r->camera) { snprintf(err, cap, "no camera"); return CN_EINVAL; }
        if (r->im->frame->source_open(r->camera, 1, 2000, &src, err, cap))
            return CN_EINVAL;
        if (!(ccz = r->im->frame->centroider_new())) {
            r->im->frame->source_close(src);
            snprintf(err, cap, "out of memory (centroider)");
            return CN_ENOMEM;
        }
    }
#define CAMERA_DONE() do { if (src) { r->im->frame->source_close(src); \
        r->im->frame->centroider_free(ccz); src = NULL; } } while (0)
    /* run: move to each planned point and expose it on the machine; the scan's whole
     * dose is checked against the MPE before the first pulse (doc/rig-safety.md) */
    r->nexposed = 0;
    if (r->m && rg->dose_plan) {
        rg_dose dz;
        long np = 0;
        for (int k = 0; k < n; k++) np += r->pt[k].planned != 0;
        if (rg->dose_plan(r->m, r->expose_ms, np, &dz, e, sizeof e)) {
            CAMERA_DONE();
            snprintf(err, cap, "the scan is refused before its first pulse: %.400s", e);
            return CN_EINVAL;
        }
        r->dose = dz;
        r->have_dose = 1;
    }
    r->phase = "the scan on the machine";
    if (r->m) {                 /* in the planner's order, stop and go or on the fly */
        cam_ctx cc = {src, ccz, 0};
        int rc = tp_scan_machine(r, src ? cam_after : NULL, &cc, err, cap);
        if (rc) {
            CAMERA_DONE();
            if (rc == CN_ESTOP || stopped(r)) { snprintf(err, cap, "stopped"); return CN_ESTOP; }
            return rc == CN_ENOMEM ? CN_ENOMEM : CN_EINVAL;
        }
    }
    for (int k = 0; src && !r->m && k < n; k++) {
        if (!r->pt[k].planned) continue;
        if (stopped(r)) { CAMERA_DONE(); snprintf(err, cap, "stopped"); return CN_ESTOP; }
        if (camera_read(r, src, ccz, &r->pt[k], got++, err, cap)) { CAMERA_DONE(); return CN_EINVAL; }
    }
    CAMERA_DONE();
    r->gain = NAN;
    r->shot_factor = 1;
    if (r->source == TP_SRC_CAMERA) shot_widen(r);
    for (int k = 0, seq = 0; !r->m && k < n; k++) r->pt[k].seq = r->pt[k].planned ? ++seq : 0;
    r->tm.machine = now() - t;
    /* detect: the traced spot of each exposure, its frame and centroid */
    r->phase = r->source == TP_SRC_FRAMES ? "the frames and their centroids"
             : "the traced spots";
    job j;
    memset(&j, 0, sizeof j);
    pthread_mutex_init(&j.mu, NULL);
    j.r = r;
    r->cn->plane(r->g, &j.pl);
    j.gt = *r->g;
    j.gt.cornea = r->truth;
    t = now();
    int st = run_workers(&j);
    r->tm.frames = now() - t;
    if (j.err == 1) { snprintf(err, cap, "out of memory (centroider)"); goto fail; }
    if (j.err == 2) {
        for (int k = 0; k < n; k++)
            if (!strncmp(r->pt[k].why, "frame not saved", 15)) {
                snprintf(err, cap, "%s", r->pt[k].why);
                break;
            }
        pthread_mutex_destroy(&j.mu);
        return CN_EINVAL;
    }
    if (st || stopped(r)) { snprintf(err, cap, "stopped"); goto stop; }
    /* fit */
    r->phase = "the fit";
    t = now();
    cn_spot *sp = malloc(sizeof *sp * (size_t)(n ? n : 1));
    int *of = malloc(sizeof *of * (size_t)(n ? n : 1)), m = 0;
    if (!sp || !of) { free(sp); free(of); snprintf(err, cap, "out of memory"); goto fail; }
    for (int k = 0; k < n; k++)
        if (r->pt[k].planned) { sp[m] = r->pt[k].spot; of[m++] = k; }
    cn_fit_opts fo = {.model = r->model, .stop = r->stop, .stop_ctx = r->stop_ctx,
                      .threads = r->threads, .max_iter = r->max_iter};
    int rc = r->cn->fit(r->g, sp, m, r->fit_start, &fo, &r->res, err, cap);
    if (!rc && r->zf) rc = surface(r, m, of, err, cap);
    for (int i = 0; i < m; i++) {
        tp_point *q = &r->pt[of[i]];
        if (q->spot.status == CN_S_OK && sp[i].status == CN_S_OUTLIER)
            snprintf(q->why, sizeof q->why, "outlier: |r|/sigma %.3g, over the robust limit",
                     sp[i].nres);
        else if (q->spot.status == CN_S_OK && sp[i].status == CN_S_MISS)
            snprintf(q->why, sizeof q->why, "the beam misses the fitted cornea");
        else if (q->spot.status == CN_S_OK && sp[i].status == CN_S_NONE)
            snprintf(q->why, sizeof q->why, "not usable (no finite centroid)");
        q->spot.status = sp[i].status;
        q->spot.nres = sp[i].nres;
    }
    free(sp);
    free(of);
    r->tm.fit = now() - t;
    if (rc) {
        if (rc == CN_ESTOP || stopped(r)) { snprintf(err, cap, "stopped"); goto stop; }
        goto fail;
    }
    r->fitted = 1;
    if (r->m && (rc = tp_drift_test(r))) {     /* a pose per time segment (tp_drift.c) */
        if (rc == CN_ESTOP || stopped(r)) { snprintf(err, cap, "stopped"); goto stop; }
        snprintf(err, cap, "out of memory");
        goto fail;
    }
    /* check: the fitted cornea through the tracer for every fitted pose */
    if (r->tr) {
        r->phase = "the check against the tracer";
        t = now();
        j.phase = 1;
        j.gf = *r->g;
        r->cn->cornea_from_params(rg, r->model, &r->res.par, r->g->cornea.trans, &j.gf.cornea);
        if (r->model == CN_ASPHERE && !(j.gf.cornea.zone > 0)) {
            /* the tracer refuses an unbounded asphere: bound it at the rig's zone,
               else 6 mm (a cornea's semi-diameter), inside its conic's edge */
            const rg_cornea *fc = &j.gf.cornea;
            double edge = 1 + fc->Q > 0 ? 0.999 * fc->R / sqrt(1 + fc->Q) : INFINITY;
            j.gf.cornea.zone = fmin(r->g->cornea.zone > 0 ? r->g->cornea.zone : 6.0, edge);
        }
        r->cn->plane(&j.gf, &j.plf);
        double *keep = malloc(sizeof *keep * (size_t)(n ? n : 1));
        if (!keep) { snprintf(err, cap, "out of memory"); goto fail; }
        for (int k = 0; k < n; k++) keep[k] = r->pt[k].spot.nres;
        st = run_workers(&j);
        r->check_max = 0;
        for (int k = 0; k < n; k++) {
            double d = r->pt[k].spot.nres;
            if (d >= 0) { r->check_n++; if (!(d <= r->check_max)) r->check_max = d; }
            r->pt[k].spot.nres = keep[k];
        }
        free(keep);
        r->tm.check = now() - t;
        if (st || stopped(r)) { snprintf(err, cap, "stopped"); goto stop; }
    }
    pthread_mutex_destroy(&j.mu);
    r->tm.total = now() - t0;
    r->tm.cpu = cpu_now() - c0;
    return 0;
stop:
    pthread_mutex_destroy(&j.mu);
    return CN_ESTOP;
fail:
    pthread_mutex_destroy(&j.mu);
    return CN_EFIT;
}

void tp_counts(const tp_run *r, int counts[6])
{
    memset(counts, 0, sizeof *counts * 6);
    for (int k = 0; k < r->npoints; k++) {
        const tp_point *q = &r->pt[k];
        if (!q->planned) counts[5]++;
        else if (q->spot.status >= 0 && q->spot.status < 5) counts[q->spot.status]++;
    }
}
