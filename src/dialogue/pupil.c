/* pupil.c -- the --pupil dialogue: a lens file (a thickness prescription or a Zemax
 * .zmx, read by src/lens) with its stop, aperture, fields and wavelengths (asked when
 * the file has none); per wavelength the first-order pupil data and the paraxial
 * marginal and chief rays (src/paraxial/pupil.c), then per field the real chief ray,
 * the spot of real rays aimed at the stop (grid or hexapolar pupil sampling; RMS
 * about the chief ray and about the centroid) and, if asked, ray fans (the trace
 * module's rx_aim, loaded on first use).  Texts in prompts/pupil.txt. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "calcio.h"
#include "lensrx.h"
#include "dialogues.h"
#include "engine.h"
#include "../lens/lens.h"
#include "../paraxial/paraxial.h"
#include "../trace/trace.h"
#include "prompts_pupil.h"

#define P(k) pupil_prompts[PUPIL_##k]
#define CL(v) lm_clean(d->io, snap(d, (v)))
#define MAXFIELD 16
#define MAXSAMPLE 4096
#define DEG (3.14159265358979323846 / 180)

typedef struct pdlg {
    lm_io *io;
    calc c;
    lr_lens L;                 /* the lens file, read and completed by lensrx.c */
    lr_texts t;
    const trace_api *tr;
    int sampling, nsamp_arg, fans, fan_rays;
    int nsamp;
    double spx[MAXSAMPLE], spy[MAXSAMPLE];
    double scale;              /* the lens's size: below 1e-13 of it a result is 0 */
    /* A folded lens (mirrors): first-order data from it unfolded (ln_unfold), real rays
     * traced folded.  unf: the unfolded lens (nsurf 0: no mirror), map[k] its surface
     * k's surface in the file; zl, zl_u: the last surface's z, folded and unfolded;
     * sig: -1 when light leaves it going -z. */
    ln_lens unf;
    int *map;
    double zl, zl_u, sig;
} pdlg;

/* The lens the paraxial engine sees. */
static const ln_lens *plens(const pdlg *d) { return d->unf.nsurf ? &d->unf : &d->L.lens; }
/* An image-space position along the unfolded axis as the folded lens's z. */
static double real_z(const pdlg *d, double u) { return d->zl + d->sig * (u - d->zl_u); }

/* A centroid or a height that is zero but for rounding (1e-17 on the axis) prints as
 * 0: the same on every build and in every replay. */
static double snap(const pdlg *d, double v)
{
    return fabs(v) <= 1e-13 * d->scale ? 0.0 : v;
}

/* ---- small questions -------------------------------------------------------------- */

static int ask_count(pdlg *d, const char *q, const char *bad, int lo, int hi, int *v)
{
    return lr_ask_count(&d->L, q, bad, lo, hi, v);
}

/* Grid: cell centres of n x n across [-1, 1]^2 inside the unit circle; hexapolar: the
 * centre and rings k = 1..n of 6k points at radius k/n. */
static void make_samples(pdlg *d)
{
    int n = d->nsamp_arg;
    d->nsamp = 0;
    if (d->sampling == 0) {
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) {
                double x = -1 + (2.0 * j + 1) / n, y = -1 + (2.0 * i + 1) / n;
                if (x * x + y * y > 1) continue;
                d->spx[d->nsamp] = x;
                d->spy[d->nsamp++] = y;
            }
    } else {
        d->spx[0] = d->spy[0] = 0;
        d->nsamp = 1;
        for (int k = 1; k <= n; k++)
            for (int j = 0; j < 6 * k; j++) {
                double a = 2 * 3.14159265358979323846 * j / (6 * k), r = (double)k / n;
                d->spx[d->nsamp] = r * sin(a);
                d->spy[d->nsamp++] = r * cos(a);
            }
    }
}

static int ask_sampling(pdlg *d)
{
    static const char *const kinds[] = {"grid", "hex", NULL};
    int rc;
    if ((rc = calc_choice(&d->c, P(SAMPLING), P(SAMPLING_WHAT), kinds, &d->sampling)))
        return rc;
    if (d->sampling == 0) rc = ask_count(d, P(GRID), P(COUNT_BAD), 2, 64, &d->nsamp_arg);
    else rc = ask_count(d, P(HEX), P(COUNT_BAD), 1, 32, &d->nsamp_arg);
    if (rc) return rc;
    if ((rc = calc_yn(&d->c, P(FANS_Q), P(FANS_Q_WHAT), &d->fans))) return rc;
    if (d->fans && (rc = ask_count(d, P(FAN_RAYS), P(COUNT_BAD), 3, 101, &d->fan_rays)))
        return rc;
    make_samples(d);
    return LM_GO;
}

/* ---- computing --------------------------------------------------------------------- */

/* A length that may be at infinity (a telecentric pupil): the word, never "inf". */
static const char *fmt_len(char *buf, size_t cap, double v)
{
    if (isinf(v)) snprintf(buf, cap, "%s", v > 0 ? "infinity" : "-infinity");
    else if (isnan(v)) snprintf(buf, cap, "-");
    else snprintf(buf, cap, "%.6g", v == 0 ? 0.0 : v);
    return buf;
}

/* A ratio that may be undefined (the f-number of an entrance pupil at infinity). */
static const char *fmt_num(char *buf, size_t cap, double v)
{
    if (!isfinite(v)) snprintf(buf, cap, "-");
    else snprintf(buf, cap, "%.4g", v == 0 ? 0.0 : v);
    return buf;
}

static const char *status_word(int st)
{
    switch (st) {
    case TRACE_AIM_VIGNETTED: return "vignetted";
    case TRACE_AIM_MISSED: return "misses a surface";
    case TRACE_AIM_TIR: return "totally reflected";
    case TRACE_AIM_NOCONV: return "Newton did not converge";
    default: return "ok";
    }
}

typedef struct wl_ctx {
    px_pupil p;                /* unit field: 45 degrees (tan 1) or height 1 */
    trace_rx rx;
    trace_rx_surface surf[PX_PUPIL_MAXSURF];
    double s;                  /* marginal-ray scale: primary stop size / this one */
} wl_ctx;

static int pupil_at(pdlg *d, const px_csurf *cs, const char *obj, double lambda, px_pupil *p,
                    char *why, size_t cap)
{
    const ln_lens *l = plens(d);
    px_pupil_in in = {cs, l->nsurf, l->stop, obj, lambda, PX_AP_EPD, l->ap_value,
                      isinf(l->object) ? INFINITY : l->object, isinf(l->object) ? 45 : 1};
    in.aperture = l->ap_kind == LN_AP_FNUM ? PX_AP_FNUM : l->ap_kind == LN_AP_NA ? PX_AP_NA
                                                                              : PX_AP_EPD;
    if (px_pupil_run(&in, p) != PX_OK) {
        snprintf(why, cap, "%s", p->why);
        return -1;
    }
    return 0;
}

static int build_rx(pdlg *d, wl_ctx *w, double lambda, double r_stop, double z_image,
                    char *why, size_t cap)
{
    const ln_lens *l = &d->L.lens;
    double z = 0;
    memset(w->surf, 0, sizeof w->surf);
    if (ln_index(l, -1, lambda, &w->rx.n_object, NULL, why, cap) != LN_OK) return -1;
    for (int i = 0; i < l->nsurf; i++) {
        const ln_surface *s = &l->surf[i];
        trace_rx_surface *t = &w->surf[i];
        lr_rx_surface(s, z, t);
        if (ln_index(l, i, lambda, &t->n_right, NULL, why, cap) != LN_OK) return -1;
        z += s->t;
    }
    w->rx.nsurf = l->nsurf;
    w->rx.surf = w->surf;
    w->rx.stop = l->stop;
    w->rx.stop_radius = r_stop;
    w->rx.z_image = z_image;
    return 0;
}

/* The request for pupil point (px, py) of field f. */
static void request(const pdlg *d, const wl_ctx *w, const ln_field *f, double px, double py,
                    trace_aim_req *rq)
{
    const px_pupil *p = &w->p;
    memset(rq, 0, sizeof *rq);
    rq->px = px;
    rq->py = py;
    if (isinf(d->L.lens.object)) {
        double tx = tan(f->x * DEG), ty = tan(f->y * DEG), n = sqrt(tx * tx + ty * ty + 1);
        rq->infinite = 1;
        rq->dir[0] = tx / n; rq->dir[1] = ty / n; rq->dir[2] = 1 / n;
        rq->z_ref = 0;
        rq->guess[0] = tx * p->yb[0] + px * p->y[0] * w->s;
        rq->guess[1] = ty * p->yb[0] + py * p->y[0] * w->s;
    } else {
        rq->obj[0] = f->x; rq->obj[1] = f->y; rq->obj[2] = -d->L.lens.object;
        rq->guess[0] = f->x * p->ub[0] + px * p->u[0] * w->s;
        rq->guess[1] = f->y * p->ub[0] + py * p->u[0] * w->s;
    }
}

typedef struct aim_tally { int maxit; double maxres; } aim_tally;

static int aim(pdlg *d, const wl_ctx *w, const ln_field *f, double px, double py,
               trace_aim_ray *out, aim_tally *t)
{
    trace_aim_req rq;
    char err[256];
    request(d, w, f, px, py, &rq);
    if (d->tr->rx_aim(&w->rx, &rq, out, err, sizeof err) != TRACE_OK) {
        calc_say(&d->c, P(FAIL_TRACE), err);
        return -1;
    }
    if (out->status == TRACE_AIM_OK || out->status == TRACE_AIM_VIGNETTED) {
        if (out->iterations > t->maxit) t->maxit = out->iterations;
        if (out->residual > t->maxres) t->maxres = out->residual;
    }
    return 0;
}

static void fan_cell(char *buf, size_t cap, const trace_aim_ray *r, double v)
{
    if (r->status == TRACE_AIM_OK) snprintf(buf, cap, "%.6g", v == 0 ? 0.0 : v);
    else snprintf(buf, cap, "%s@%d", r->status == TRACE_AIM_VIGNETTED ? "vign" : "fail",
                  r->surface + 1);
}

/* The wave aberration of an aimed ray (Welford's W): the chief ray's optical path to
 * the reference sphere minus the ray's, positive where the wavefront leads the
 * sphere.  The sphere is centred on the chief ray's image point and passes through
 * the chief ray's crossing of the paraxial exit pupil's plane; paths count from the
 * object point, or (object at infinity) from the incoming plane wavefront through
 * the origin (rx_aim's paths start on the plane z = 0: the ray's o . d added). */
typedef struct wavefront {
    int ok, inf;
    double c[3], R, sign, n0, ni, w0, lambda;   /* lambda: in the lens's unit */
} wavefront;

static double ray_path(const wavefront *wf, const trace_aim_ray *r)
{
    double o = r->opl, pc[3], b, cc, disc;
    if (wf->inf) o += wf->n0 * (r->o[0] * r->d[0] + r->o[1] * r->d[1] + r->o[2] * r->d[2]);
    for (int k = 0; k < 3; k++) pc[k] = r->img[k] - wf->c[k];
    b = r->img_dir[0] * pc[0] + r->img_dir[1] * pc[1] + r->img_dir[2] * pc[2];
    cc = pc[0] * pc[0] + pc[1] * pc[1] + pc[2] * pc[2] - wf->R * wf->R;
    disc = b * b - cc;
    if (disc < 0) return NAN;
    return o - wf->ni * (b + wf->sign * sqrt(disc));
}

/* W of ray r in waves (NaN: no sphere, or the ray misses it). */
static double wave(const wavefront *wf, const trace_aim_ray *r)
{
    if (!wf->ok || r->status != TRACE_AIM_OK) return NAN;
    return (wf->w0 - ray_path(wf, r)) / wf->lambda;
}

static double unit_mm(const char *u)
{
    return !strcmp(u, "cm") ? 10 : !strcmp(u, "m") ? 1000 : !strcmp(u, "in") ? 25.4 : 1;
}

static void wavefront_init(const pdlg *d, const wl_ctx *w, const trace_aim_ray *chief,
                           double lambda_um, wavefront *wf)
{
    const px_pupil *p = &w->p;
    memset(wf, 0, sizeof *wf);
    if (!isfinite(p->z_xp) || chief->img_dir[2] == 0) return;
    double t = (real_z(d, p->z_xp) - chief->img[2]) / chief->img_dir[2];
    if (!(fabs(t) > 0)) return;
    wf->inf = isinf(d->L.lens.object);
    memcpy(wf->c, chief->img, sizeof wf->c);
    wf->R = fabs(t);
    wf->sign = t < 0 ? 1 : -1;
    wf->n0 = w->rx.n_object;
    wf->ni = w->surf[w->rx.nsurf - 1].n_right;
    wf->lambda = lambda_um * 1e-3 / unit_mm(d->c.uname);
    wf->ok = 1;
    wf->w0 = ray_path(wf, chief);
    if (!isfinite(wf->w0)) wf->ok = 0;
}

static int one_field(pdlg *d, const wl_ctx *w, int fi, double lambda)
{
    const ln_lens *l = &d->L.lens;
    const ln_field *f = &l->field[fi];
    const px_pupil *p = &w->p;
    trace_aim_ray chief, r;
    aim_tally t = {0, 0};
    int N = plens(d)->nsurf - 1, inf = isinf(l->object), nok = 0, nvig = 0;
    double sx = 0, sy = 0, sc = 0;
    double fx = inf ? tan(f->x * DEG) : f->x, fy = inf ? tan(f->y * DEG) : f->y;
    char dist[32], hp[64], hi[64], hr[64];
    if (f->x == 0) {
        if (inf) calc_say(&d->c, P(FIELD_HEAD_ANGLE), fi + 1, f->y);
        else calc_say(&d->c, P(FIELD_HEAD_HEIGHT), fi + 1, f->y);
    } else {
        if (inf) calc_say(&d->c, P(FIELD_HEAD_ANGLE_XY), fi + 1, f->x, f->y);
        else calc_say(&d->c, P(FIELD_HEAD_HEIGHT_XY), fi + 1, f->x, f->y);
    }
    if (aim(d, w, f, 0, 0, &chief, &t)) return LM_FAIL;
    if (chief.status != TRACE_AIM_OK) {
        calc_say(&d->c, P(CHIEF_BAD), status_word(chief.status), chief.surface + 1);
        return LM_GO;
    }
    /* paraxial chief-ray heights: at the paraxial image, and at the image plane the
     * real rays are carried to (the distortion compares the real one with this,
     * radially); x and y are separate paraxial rays, both the unit chief ray scaled */
    {
        double zi = d->zl_u + d->sig * (w->rx.z_image - d->zl);   /* unfolded */
        double unit = p->yb[N] + p->ub[N + 1] * (zi - p->z[N]);
        double px_ = fx * unit, py_ = fy * unit, rp = hypot(px_, py_);
        double rr = hypot(chief.img[0], chief.img[1]);
        if (snap(d, rp) != 0) snprintf(dist, sizeof dist, "%.4g %%", CL(100 * (rr - rp) / rp));
        else snprintf(dist, sizeof dist, "-");
        if (f->x == 0) {
            snprintf(hp, sizeof hp, "%.6g", CL(fy * p->h_img));
            snprintf(hi, sizeof hi, "%.6g", CL(py_));
            snprintf(hr, sizeof hr, "%.6g", CL(chief.img[1]));
        } else {
            snprintf(hp, sizeof hp, "(%.6g, %.6g)", CL(fx * p->h_img), CL(fy * p->h_img));
            snprintf(hi, sizeof hi, "(%.6g, %.6g)", CL(px_), CL(py_));
            snprintf(hr, sizeof hr, "(%.6g, %.6g)", CL(chief.img[0]), CL(chief.img[1]));
        }
    }
    calc_say(&d->c, P(CHIEF), hp, hi, hr, dist, chief.residual, chief.iterations);
    /* the spot and the wavefront */
    wavefront wf;
    int nw = 0;
    double ws = 0, ws2 = 0, wmin = INFINITY, wmax = -INFINITY;
    wavefront_init(d, w, &chief, lambda, &wf);
    double *xs = malloc(sizeof(double) * 2 * (size_t)d->nsamp);
    if (!xs) return LM_FAIL;
    for (int i = 0; i < d->nsamp; i++) {
        if (lm_stop_requested()) { free(xs); return LM_FAIL; }
        if (aim(d, w, f, d->spx[i], d->spy[i], &r, &t)) { free(xs); return LM_FAIL; }
        if (r.status != TRACE_AIM_OK) { nvig++; continue; }
        xs[2 * nok] = r.img[0];
        xs[2 * nok + 1] = r.img[1];
        double wv = wave(&wf, &r);
        if (isfinite(wv)) {
            nw++;
            ws += wv;
            ws2 += wv * wv;
            wmin = fmin(wmin, wv);
            wmax = fmax(wmax, wv);
        }
        sx += r.img[0];
        sy += r.img[1];
        nok++;
    }
    if (nok) {
        double cx = sx / nok, cy = sy / nok, rc2 = 0, rm2 = 0;
        for (int i = 0; i < nok; i++) {
            double ex = xs[2 * i] - chief.img[0], ey = xs[2 * i + 1] - chief.img[1];
            double mx = xs[2 * i] - cx, my = xs[2 * i + 1] - cy;
            rc2 += ex * ex + ey * ey;
            rm2 += mx * mx + my * my;
        }
        sc = sqrt(rc2 / nok);
        calc_say(&d->c, P(SPOT), nok, nvig, CL(sc), CL(sqrt(rm2 / nok)), CL(cx), CL(cy));
    } else {
        calc_say(&d->c, P(SPOT_NONE), nvig);
    }
    free(xs);
    if (nw) {
        double m = ws / nw, var = ws2 / nw - m * m;
        calc_say(&d->c, P(WAVE), CL(wf.R), CL(p->r_xp * w->s), CL(sqrt(var > 0 ? var : 0)),
                 CL(wmax - wmin));
    } else {
        calc_say(&d->c, "%s", P(WAVE_NONE));
    }
    if (d->fans) {
        calc_say(&d->c, "%s", P(FAN_HEAD));
        for (int i = 0; i < d->fan_rays; i++) {
            double q = -1 + 2.0 * i / (d->fan_rays - 1);
            trace_aim_ray rt, rs;
            char a[32], b[32], c[32];
            if (lm_stop_requested()) return LM_FAIL;
            if (aim(d, w, f, 0, q, &rt, &t) || aim(d, w, f, q, 0, &rs, &t)) return LM_FAIL;
            fan_cell(a, sizeof a, &rt, rt.img[1] - chief.img[1]);
            fan_cell(b, sizeof b, &rs, rs.img[0] - chief.img[0]);
            double wt = wave(&wf, &rt);
            if (isfinite(wt)) snprintf(c, sizeof c, "%.6g", CL(wt));
            else snprintf(c, sizeof c, "-");
            calc_say(&d->c, P(FAN_ROW), q, a, c, b);
        }
    }
    calc_say(&d->c, P(AIM_STATS), t.maxit, t.maxres, d->c.uname);
    return LM_GO;
}

static void report_pupil(pdlg *d, const wl_ctx *w, double fbig)
{
    const px_pupil *p = &w->p;
    const ln_lens *l = &d->L.lens;
    int inf = isinf(l->object), N = plens(d)->nsurf - 1;
    double k = inf ? tan(fbig * DEG) : fbig;
    char a[32], b[32], c[32], e[32];
    calc_say(&d->c, P(FIRST), CL(p->efl), fmt_num(a, sizeof a, p->fnum),
             fmt_num(b, sizeof b, p->work_fnum), CL(p->na_obj), CL(p->na_img));
    calc_say(&d->c, P(PUPILS), fmt_len(a, sizeof a, p->z_ep),
             fmt_len(b, sizeof b, 2 * p->r_ep * w->s),
             fmt_len(c, sizeof c, isfinite(p->z_xp) ? real_z(d, p->z_xp) : p->z_xp),
             fmt_len(e, sizeof e, 2 * p->r_xp * w->s), CL(p->r_stop * w->s));
    if (inf || !isfinite(p->mag)) snprintf(b, sizeof b, "-");
    else snprintf(b, sizeof b, "%.6g", CL(p->mag));
    calc_say(&d->c, P(IMAGE), fmt_len(a, sizeof a, isfinite(p->z_img) ? real_z(d, p->z_img)
                                                   : p->z_img), b, CL(p->lagrange * w->s * k));
    calc_say(&d->c, P(RAYS_HEAD), fbig);
    snprintf(a, sizeof a, "-");
    calc_say(&d->c, P(RAYS_OBJ), a, CL(p->u[0] * w->s), a, CL(p->ub[0] * k));
    for (int i = 0; i <= N; i++) {
        /* a mirror is two unfolded surfaces: its row is the second (the rays leaving it,
         * slopes along the unfolded axis) */
        if (d->map && i < N && d->map[i + 1] == d->map[i]) continue;
        calc_say(&d->c, P(RAYS_ROW), d->map ? d->map[i] + 1 : i + 1, CL(p->y[i] * w->s), CL(p->u[i + 1] * w->s),
                 CL(p->yb[i] * k), CL(p->ub[i + 1] * k));
    }
}

static int need_engine(pdlg *d)
{
    trace_get_api_fn get;
    if (d->tr) return 0;
    get = (trace_get_api_fn)lm_engine_symbol("trace", TRACE_API_SYMBOL);
    if (get) d->tr = get(TRACE_ABI);
    if (!d->tr) {
        if (get) fprintf(stderr, "lensmat: the trace module's interface does not match\n");
        return -1;
    }
    return 0;
}

static int refuse(pdlg *d, const char *why)
{
    lm_say(d->io, LM_BOTH, P(REFUSED), why);
    fprintf(stderr, "lensmat: %s: %s\n", d->io->src, why);
    return LM_FAIL;
}

/* Field angles with a finite object (a matched pair's file, OpticStudio's FTYP 0 at a
 * finite conjugate): the chief ray's angle in object space, aimed at the centre of
 * the paraxial entrance pupil, so the object point is at -tan(angle) times the
 * distance from the object plane to that pupil.  The fields become those heights
 * (said, field by field), so the rest runs as for heights. */
static int angles_to_heights(pdlg *d, const px_pupil *prim)
{
    ln_lens *l = &d->L.lens;
    double L = l->object + prim->z_ep;
    char z[32];
    if (!isfinite(prim->z_ep) || !(fabs(L) > 0)) return refuse(d, P(ANGLE_FINITE_TELE));
    calc_say(&d->c, P(ANGLE_FINITE), fmt_len(z, sizeof z, CL(prim->z_ep)), d->c.uname);
    for (int i = 0; i < l->nfield; i++) {
        ln_field *f = &l->field[i];
        double hx = -tan(f->x * DEG) * L + 0.0, hy = -tan(f->y * DEG) * L + 0.0;  /* no -0 */
        if (f->x == 0) calc_say(&d->c, P(ANGLE_FINITE_ROW), i + 1, f->y, CL(hy));
        else calc_say(&d->c, P(ANGLE_FINITE_XY), i + 1, f->x, f->y, CL(hx), CL(hy));
        f->x = hx;
        f->y = hy;
    }
    l->field_kind = LN_FIELD_HEIGHT;
    return LM_GO;
}

static int compute(pdlg *d)
{
    const ln_lens *l = &d->L.lens;
    px_csurf cs[PX_PUPIL_MAXSURF];
    char names[PX_PUPIL_MAXSURF + 1][LN_NAME_MAX], why[LN_ERR_MAX], ob[64];
    const char *obj;
    wl_ctx *w;
    px_pupil prim;
    double lp = ln_primary(l), z_image, zl = 0, fbig = 0;
    int nwl = l->nwl ? l->nwl : 1, rc = LM_GO, nm = ln_mirrors(l), nb = ln_breaks(l);
    d->sig = nm % 2 ? -1 : 1;
    if (nm || nb) {
        if (ln_unfold(l, &d->unf, &d->map, why, sizeof why) != LN_OK) return refuse(d, why);
        if (d->unf.nsurf > PX_PUPIL_MAXSURF) {
            snprintf(why, sizeof why, "%d surfaces unfolded: at most %d", d->unf.nsurf,
                     PX_PUPIL_MAXSURF);
            return refuse(d, why);
        }
        if (nm) calc_say(&d->c, P(UNFOLDED), nm);
        if (nb) calc_say(&d->c, P(BREAKS), nb);
    }
    for (int i = 0; i + 1 < plens(d)->nsurf; i++) d->zl_u += plens(d)->surf[i].t;
    if (ln_to_csurf(plens(d), cs, names, &obj, why, sizeof why) != LN_OK) return refuse(d, why);
    if (pupil_at(d, cs, obj, lp, &prim, why, sizeof why)) return refuse(d, why);
    d->scale = fmax(fabs(prim.efl), prim.r_stop);
    if (!isinf(l->object) && l->nfield && l->field_kind == LN_FIELD_ANGLE &&
        (rc = angles_to_heights(d, &prim)) != LM_GO)
        return rc;
    for (int i = 0; i + 1 < l->nsurf; i++) zl += l->surf[i].t;
    d->zl = zl;
    for (int i = 0; i < l->nfield; i++)
        if (fabs(l->field[i].y) > fabs(fbig)) fbig = l->field[i].y;
    if (isinf(l->object)) snprintf(ob, sizeof ob, "%s", P(OBJ_INF));
    else snprintf(ob, sizeof ob, P(OBJ_AT), l->object, d->c.uname);
    {   /* air in a lens file is 1, not the classic's 1.000293: say which applies */
        int air = !l->obj_glass[0] || !strcasecmp(l->obj_glass, "air");
        for (int i = 0; i < l->nsurf; i++)
            air |= !l->surf[i].glass[0] || !strcasecmp(l->surf[i].glass, "air");
        if (air) calc_say(&d->c, "%s", P(AIR_NOTE));
    }
    calc_say(&d->c, P(HEAD), l->title[0] ? l->title : "(untitled)", l->nsurf, l->stop + 1,
             l->ap_kind == LN_AP_FNUM ? "f-number" : l->ap_kind == LN_AP_NA ? "NA" : "EPD",
             l->ap_value, ob, l->nfield, l->nfield == 1 ? "" : "s", nwl, nwl == 1 ? "" : "s");
    if (l->surf[l->nsurf - 1].t * d->sig > 0) {   /* after odd mirrors: negative */
        z_image = zl + l->surf[l->nsurf - 1].t;
        calc_say(&d->c, P(IMAGE_FILE), z_image, d->c.uname);
    } else {
        if (!isfinite(prim.z_img)) return refuse(d, P(NO_IMAGE));
        z_image = real_z(d, prim.z_img);
        calc_say(&d->c, P(IMAGE_PARAXIAL), CL(z_image), d->c.uname, lp * 1000);
    }
    calc_say(&d->c, P(SAMPLING_ECHO), d->sampling ? "hexapolar" : "grid", d->nsamp);
    if (need_engine(d)) return LM_FAIL;
    if (!(w = malloc(sizeof *w))) return LM_FAIL;
    for (int k = 0; k < nwl && rc == LM_GO; k++) {
        double lambda = l->nwl ? l->wl[k] : lp;
        if (pupil_at(d, cs, obj, lambda, &w->p, why, sizeof why) ||
            build_rx(d, w, lambda, prim.r_stop, z_image, why, sizeof why)) {
            rc = refuse(d, why);
            break;
        }
        w->s = prim.r_stop / w->p.r_stop;
        calc_say(&d->c, P(WL_HEAD), lambda * 1000);
        report_pupil(d, w, fbig);
        for (int f = 0; f < l->nfield && rc == LM_GO; f++) rc = one_field(d, w, f, lambda);
    }
    free(w);
    return rc;
}

int lm_pupil(lm_io *io)
{
    pdlg dd, *d = &dd;
    int rc;
    memset(d, 0, sizeof *d);
    ln_init(&d->unf);
    d->io = io;
    d->c.io = io;
    d->c.unit = PX_MM;
    d->c.uname = "mm";
    d->t = (lr_texts){P(FILE), P(FILE_WHAT), P(NOTE), P(STOP), P(STOP_WHAT), P(STOP_BAD),
                      P(AP_KIND), P(AP_KIND_WHAT), P(AP_VALUE), P(AP_VALUE_WHAT), P(NFIELD),
                      P(NFIELD_WHAT), P(NFIELD_BAD), P(FIELD_ANGLE), P(FIELD_HEIGHT),
                      P(FIELD_WHAT), P(FIELD_BAD), P(AGAIN_FIELD), P(COUNT_WHAT), P(COUNT_BAD)};
    d->L.finite_angles = 1;    /* angles with a finite object become heights */
    rc = lr_ask_lens(&d->L, &d->c, &d->t);
    if (rc == LM_GO && (rc = ask_sampling(d)) == LM_GO)
        rc = lm_stop_requested() ? LM_FAIL : compute(d);
    if (rc == LM_GO) rc = calc_done(&d->c);
    lr_free(&d->L);
    ln_free(&d->unf);
    free(d->map);
    return rc;
}
const char *lm_pupil_example(void) { return P(EXAMPLE); }
