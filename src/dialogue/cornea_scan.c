/* cornea_scan.c -- the --cornea-scan dialogue (issue 12): a simulated measurement.
 * The example rig geometry scans a synthetic eye the user describes (radius, Q,
 * cylinder and axis, decentration, tilt), spots with centroid noise, the cornea
 * engine fits the chosen model and the report is printed: Sim K, radii, Q, pose,
 * singular values, what is not determined.  Texts in prompts/cornea_scan.txt; the
 * rig and cornea engines are loaded here only. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "calcio.h"
#include "dialogues.h"
#include "engine.h"
#include "../rig/rig.h"
#include "../cornea/cornea.h"
#include "prompts_cornea_scan.h"
#include "cornea_out.h"

#define CS(k) cornea_scan_prompts[CORNEA_SCAN_##k]
#define DEG (3.14159265358979323846 / 180)

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

static void say_line(void *ctx, const char *line) { calc_say(ctx, CS(LINE), line); }

/* The report file (scan settings, truth and errors beside the engine's numbers) and,
 * when asked, the maps. */
static int cs_files(calc *c, const cornea_api *cn, const rg_geometry *g, const char *name,
                    int maps, const cn_result *r, const cn_spot *sp, int n,
                    const rg_cornea *eye, const cn_params *t, const cn_bump *cone,
                    double km, double cyl,
                    double axis_err, double np, double zone, double noise, double pitch,
                    double seed)
{
    char msg[512];
    const cn_clinical *k = &r->k;
    const cs_row rows[] = {
        {"scan_points", np, NAN, ""}, {"scan_zone", zone, NAN, "deg"},
        {"scan_noise", noise, NAN, "px"}, {"scan_pitch", pitch, NAN, "um"},
        {"scan_seed", seed, NAN, ""},
        {"true_R", t->p[CN_R], NAN, "mm"}, {"true_R_flat", eye->R, NAN, "mm"},
        {"true_R_steep", eye->R2, NAN, "mm"}, {"true_Q", eye->Q, NAN, ""},
        {"true_Km", km, NAN, "D"}, {"true_cyl", cyl, NAN, "D"},
        {"true_dx", t->p[CN_DX], NAN, "mm"}, {"true_dy", t->p[CN_DY], NAN, "mm"},
        {"true_tilt_x", t->p[CN_TX] / DEG, NAN, "deg"},
        {"true_tilt_y", t->p[CN_TY] / DEG, NAN, "deg"},
        {"true_cone_h", cone->h * 1e3, NAN, "um"}, {"true_cone_w", cone->w, NAN, "mm"},
        {"true_cone_x", cone->x0, NAN, "mm"}, {"true_cone_y", cone->y0, NAN, "mm"},
        {"err_R", (k->R - t->p[CN_R]) * 1e3, k->sd_R * 1e3, "um"},
        {"err_R_flat", (k->R_flat - eye->R) * 1e3, k->sd_R_flat * 1e3, "um"},
        {"err_R_steep", (k->R_steep - eye->R2) * 1e3, k->sd_R_steep * 1e3, "um"},
        {"err_Q", k->Q - eye->Q, k->sd_Q, ""},
        {"err_Km", k->Km - km, k->sd_Km, "D"},
        {"err_cyl", r->model == CN_BICONIC ? k->cyl - cyl : NAN, k->sd_cyl, "D"},
        {"err_axis", r->model == CN_BICONIC && cyl > 0 ? axis_err : NAN, k->sd_axis, "deg"},
        {"err_dx", (k->dx - t->p[CN_DX]) * 1e3, k->sd_dx * 1e3, "um"},
        {"err_dy", (k->dy - t->p[CN_DY]) * 1e3, k->sd_dy * 1e3, "um"},
        {"err_tilt_x", k->tx - t->p[CN_TX] / DEG, k->sd_tx, "deg"},
        {"err_tilt_y", k->ty - t->p[CN_TY] / DEG, k->sd_ty, "deg"},
    };
    if (cs_write_report(cn, name, r, sp, n, rows, (int)(sizeof rows / sizeof *rows), msg,
                        sizeof msg))
        return calc_fail(c, msg);
    calc_say(c, CS(WROTE), name, name);
    if (maps && cs_write_maps(cn, g, name, r, sp, n, stop_cb, say_line, c, msg, sizeof msg)) {
        if (lm_stop_requested()) return LM_FAIL;
        return calc_fail(c, msg);
    }
    return LM_GO;
}

int lm_cornea_scan(lm_io *io)
{
    static const char *const models[] = {"sphere", "conic", "biconic", "asphere", NULL};
    calc cc = {io, PX_MM, "mm"}, *c = &cc;
    rig_get_api_fn rget;
    cornea_get_api_fn cget;
    *(void **)&rget = lm_engine_symbol("rig", RIG_API_SYMBOL);
    *(void **)&cget = lm_engine_symbol("cornea", CORNEA_API_SYMBOL);
    const rig_api *rg = rget ? rget(RIG_ABI) : NULL;
    const cornea_api *cn = cget ? cget(CORNEA_ABI) : NULL;
    if (!rg || !cn) return calc_fail(c, CS(NO_ENGINE));
    int model, rc;
    double np, zone, R, Q, cyl, axis, dx, dy, tx, ty, noise, pitch, seed;
    if ((rc = calc_choice(c, CS(MODEL), CS(MODEL_WHAT), models, &model)) ||
        (rc = ranged(c, CS(POINTS), CS(POINTS_WHAT), CS(POINTS_RANGE), 10, 10000, 1, &np)) ||
        (rc = ranged(c, CS(ZONE), CS(ZONE_WHAT), CS(ZONE_RANGE), 0.5, 12, 0, &zone)) ||
        (rc = ranged(c, CS(R), CS(R_WHAT), CS(R_RANGE), 5, 12, 0, &R)) ||
        (rc = ranged(c, CS(Q), CS(Q_WHAT), CS(Q_RANGE), -1, 1, 0, &Q)) ||
        (rc = ranged(c, CS(CYL), CS(CYL_WHAT), CS(CYL_RANGE), 0, 8, 0, &cyl)) ||
        (rc = ranged(c, CS(AXIS), CS(AXIS_WHAT), CS(AXIS_RANGE), -360, 360, 0, &axis)) ||
        (rc = ranged(c, CS(DX), CS(DX_WHAT), CS(DEC_RANGE), -1, 1, 0, &dx)) ||
        (rc = ranged(c, CS(DY), CS(DY_WHAT), CS(DEC_RANGE), -1, 1, 0, &dy)) ||
        (rc = ranged(c, CS(TX), CS(TX_WHAT), CS(TILT_RANGE), -10, 10, 0, &tx)) ||
        (rc = ranged(c, CS(TY), CS(TY_WHAT), CS(TILT_RANGE), -10, 10, 0, &ty)) ||
        (rc = ranged(c, CS(NOISE), CS(NOISE_WHAT), CS(NOISE_RANGE), 0, 10, 0, &noise)) ||
        (rc = ranged(c, CS(PITCH), CS(PITCH_WHAT), CS(PITCH_RANGE), 0.1, 100, 0, &pitch)) ||
        (rc = ranged(c, CS(SEED), CS(SEED_WHAT), CS(SEED_RANGE), 0, 1e15, 1, &seed)))
        return rc;
    cn_bump cone = {0, 0, 0, 0};
    if ((rc = ranged(c, CS(CONE), CS(CONE_WHAT), CS(CONE_RANGE), 0, 50, 0, &cone.h)))
        return rc;
    if (cone.h > 0 &&
        ((rc = ranged(c, CS(CONE_W), CS(CONE_W_WHAT), CS(CONE_W_RANGE), 0.2, 3, 0, &cone.w)) ||
         (rc = ranged(c, CS(CONE_X), CS(CONE_X_WHAT), CS(CONE_XY_RANGE), -2, 2, 0, &cone.x0)) ||
         (rc = ranged(c, CS(CONE_Y), CS(CONE_Y_WHAT), CS(CONE_XY_RANGE), -2, 2, 0, &cone.y0))))
        return rc;
    cone.h *= 1e-3;                    /* um -> mm */
    char name[1024];
    int maps = 0;
    if ((rc = lm_ask_word(io, CS(REPORT), CS(REPORT), CS(REPORT_WHAT), cs_check_name, io,
                          name, sizeof name)))
        return rc;
    if (strcmp(name, "none") && (rc = calc_yn(c, CS(MAPS), CS(MAPS_WHAT), &maps))) return rc;
    rg_geometry g;
    rg->geometry_default(&g);
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
    int n = (int)np;
    cn_spot *sp = malloc(sizeof *sp * n);
    if (!sp) return calc_fail(c, CS(NO_ENGINE));
    double sigma = noise * pitch * 1e-3;
    cn_scan_opts so = {.npoints = n, .theta_max = zone * DEG, .sigma = sigma,
                       .seed = (unsigned long long)seed, .quantise = 1};
    char err[256];
    static char buf[4096];
    int got = cn->simulate(rg, &g, &eye, &so, sp, n, err, sizeof err);
    cn_params t;
    cn->params_from_cornea(&eye, g.cornea.trans, tx * DEG, ty * DEG, &t);
    if (got > 0 && cone.h > 0)         /* the cone: the planned scan re-imaged through the
                                          true eye with the bump (analytic model) */
        cn->reimage(&g, CN_BICONIC, &t, &cone, sigma, (unsigned long long)seed, sp, got);
    int ok = 0;
    for (int i = 0; i < got; i++) ok += sp[i].status == CN_S_OK;
    calc_say(c, CS(SCANNED), n, ok, sigma * 1e3);
    cn_fit_opts fo = {.model = model, .stop = stop_cb};
    cn_result r;
    if (got < 0 || cn->fit(&g, sp, got, NULL, &fo, &r, err, sizeof err)) {
        free(sp);
        if (lm_stop_requested()) return LM_FAIL;
        calc_say(c, CS(FAILED), got < 0 ? "no scan" : err);
        return LM_FAIL;
    }
    cn->report(&r, buf, sizeof buf);
    for (char *l = buf, *e; *l; l = e + 1) {     /* line by line into the record */
        e = strchr(l, '\n');
        if (!e) { calc_say(c, CS(LINE), l); break; }
        *e = 0;
        calc_say(c, CS(LINE), l);
    }
    calc_say(c, CS(TRUTH), eye.R, eye.R2, km, cyl);
    double axis_err = model == CN_BICONIC ? remainder(r.k.K1_axis - fmod(axis + 360, 180), 180.0)
                                          : 0.0;
    calc_say(c, CS(ERRORS), (r.k.R - t.p[CN_R]) * 1e3, r.k.Km - km, axis_err);
    if (strcmp(name, "none")) {
        rc = cs_files(c, cn, &g, name, maps, &r, sp, got, &eye, &t, &cone, km, cyl, axis_err,
                      np, zone, noise, pitch, seed);
        if (rc) { free(sp); return rc; }
    }
    free(sp);
    return calc_done(c);
}
const char *lm_cornea_scan_example(void) { return CS(EXAMPLE); }
