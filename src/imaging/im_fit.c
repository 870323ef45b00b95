/* im_fit.c -- locating one detected spot: a window around its peak, intensity-weighted
 * moments (raw, or above the background), and the 2-D Gaussian
 *     I(x, y) = B + A exp(-2 ((x-x0)^2 + (y-y0)^2) / w^2)
 * fitted by weighted least squares with GSL's multifit_nlinear (trust region,
 * Levenberg-Marquardt, Cholesky), optionally on a tilted background
 * B + Bx (x - xc) + By (y - yc).  Weights come from the noise model (read noise sigma
 * and, when the gain is known, shot noise), so the covariance (J'J)^-1 is the
 * uncertainty of the centre.  Saturated pixels are left out (the fit uses the wings);
 * pixels beyond the frame are simply absent (the spot is flagged as cut).
 * The two baselines: raw moments over the window (IM_CM_MOMENTS) and background-
 * subtracted moments of the connected pixels above threshold (IM_CM_MOMENTS_BG). */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <gsl/gsl_vector.h>
#include "im_centroid.h"

#define MAXWIN 51              /* window side at most 2*25+1 */
#define NPAR 5                 /* x0 y0 A w B; with a tilted background also Bx By */
#define MAXPAR 7

void im_fit_ws_free(im_fit_ws *ws)
{
    if (ws->w) gsl_multifit_nlinear_free(ws->w);
    if (ws->covar) gsl_matrix_free(ws->covar);
    free(ws->data);
    memset(ws, 0, sizeof *ws);
}

typedef struct fitdata {
    int nx, ny, x0, y0;        /* window origin and size */
    int np;                    /* parameters: 5, or 7 with the background's slopes */
    double xc, yc;             /* the slopes' origin: the window's centre */
    int n;                     /* pixels used */
    uint8_t ix[MAXWIN * MAXWIN], iy[MAXWIN * MAXWIN];  /* window column and row of each */
    double v[MAXWIN * MAXWIN], iw[MAXWIN * MAXWIN];    /* value, 1/sigma */
    double ex[MAXWIN], ey[MAXWIN], dx[MAXWIN], dy[MAXWIN];
} fitdata;

/* exp(-2 d^2 / w^2) along each axis of the window: the model is separable. */
static void axes(fitdata *d, const gsl_vector *p)
{
    double x0 = gsl_vector_get(p, 0), y0 = gsl_vector_get(p, 1), w = gsl_vector_get(p, 3);
    double k = 2 / (w * w);
    for (int i = 0; i < d->nx; i++) {
        d->dx[i] = d->x0 + i - x0;
        d->ex[i] = exp(-k * d->dx[i] * d->dx[i]);
    }
    for (int j = 0; j < d->ny; j++) {
        d->dy[j] = d->y0 + j - y0;
        d->ey[j] = exp(-k * d->dy[j] * d->dy[j]);
    }
}

static int model_f(const gsl_vector *p, void *vd, gsl_vector *f)
{
    fitdata *d = vd;
    double A = gsl_vector_get(p, 2), B = gsl_vector_get(p, 4), *out = f->data;
    double bx = d->np > NPAR ? gsl_vector_get(p, 5) : 0, by = d->np > NPAR ? gsl_vector_get(p, 6) : 0;
    size_t st = f->stride;
    axes(d, p);
    for (int k = 0; k < d->n; k++) {
        int i = d->ix[k], j = d->iy[k];
        double b = B + bx * (d->x0 + i - d->xc) + by * (d->y0 + j - d->yc);
        out[k * st] = (b + A * d->ex[i] * d->ey[j] - d->v[k]) * d->iw[k];
    }
    return GSL_SUCCESS;
}

static int model_df(const gsl_vector *p, void *vd, gsl_matrix *J)
{
    fitdata *d = vd;
    double A = gsl_vector_get(p, 2), w = gsl_vector_get(p, 3);
    double k2 = 4 / (w * w), k3 = 4 / (w * w * w);
    axes(d, p);
    for (int k = 0; k < d->n; k++) {
        int i = d->ix[k], j = d->iy[k];
        double E = d->ex[i] * d->ey[j], s = d->iw[k], aE = A * E * s;
        double *row = J->data + (size_t)k * J->tda;
        row[0] = aE * k2 * d->dx[i];
        row[1] = aE * k2 * d->dy[j];
        row[2] = E * s;
        row[3] = aE * k3 * (d->dx[i] * d->dx[i] + d->dy[j] * d->dy[j]);
        row[4] = s;
        if (d->np > NPAR) {
            row[5] = s * (d->x0 + i - d->xc);
            row[6] = s * (d->y0 + j - d->yc);
        }
    }
    return GSL_SUCCESS;
}

/* Moments over the window, raw (bg = 0) or above the background; uncertainty from the
 * noise model. */
static void moments(const fitdata *d, double bg, im_spot *o)
{
    double s = 0, sx = 0, sy = 0;
    for (int k = 0; k < d->n; k++) {
        double v = d->v[k] - bg;
        s += v;
        sx += v * (d->x0 + d->ix[k]);
        sy += v * (d->y0 + d->iy[k]);
    }
    if (!(fabs(s) > 0)) return;
    o->x = sx / s;
    o->y = sy / s;
    double vx = 0, vy = 0;
    for (int k = 0; k < d->n; k++) {
        double ax = d->x0 + d->ix[k] - o->x, ay = d->y0 + d->iy[k] - o->y;
        double var = 1 / (d->iw[k] * d->iw[k]);
        vx += ax * ax * var;
        vy += ay * ay * var;
    }
    o->sx = sqrt(vx) / fabs(s);
    o->sy = sqrt(vy) / fabs(s);
    o->power = s;
}

/* Background-subtracted moments over the spot's connected pixels above threshold (the
 * classic thresholded centre of gravity); variances from the noise model. */
static void moments_above(const im_spot_in *in, im_spot *o)
{
    const im_frame *f = in->f;
    double s = 0, sx = 0, sy = 0, var0 = in->noise * in->noise, vx = 0, vy = 0;
    int W = f->width;
    for (int k = 0; k < in->npix; k++) {
        int p = in->list[k];
        double v = f->px[p] - in->bg;
        s += v; sx += v * (p % W); sy += v * (p / W);
    }
    if (!(s > 0)) return;
    o->x = sx / s;
    o->y = sy / s;
    for (int k = 0; k < in->npix; k++) {
        int p = in->list[k];
        double v = f->px[p], ax = p % W - o->x, ay = p / W - o->y;
        double var = var0 + (in->gain > 0 && v > in->bg ? (v - in->bg) / in->gain : 0);
        vx += ax * ax * var;
        vy += ay * ay * var;
    }
    o->sx = sqrt(vx) / s;
    o->sy = sqrt(vy) / s;
    o->power = s;
}

/* GSL's default error handler aborts the process; every GSL result here is checked,
 * so the handler is turned off, once (it is process-wide: switching it off and back
 * around each fit would race between threads). */
static pthread_once_t gsl_quiet = PTHREAD_ONCE_INIT;
static void quiet_gsl(void) { gsl_set_error_handler_off(); }

/* The window's scratch lives in the centroider: one per caller, no per-thread state. */
static fitdata *scratch(im_fit_ws *ws)
{
    if (!ws->data) ws->data = malloc(sizeof(fitdata));
    return ws->data;
}

void im_spot_locate(im_fit_ws *ws, const im_spot_in *in, im_spot *o)
{
    const im_frame *f = in->f;
    fitdata *d = scratch(ws);
    int W = f->width, H = f->height, px = in->peak_i % W, py = in->peak_i / W;
    double A0 = in->peak - in->bg, T = in->thr - in->bg, w0, h;

    memset(o, 0, sizeof *o);
    o->npix = in->npix;
    o->bg = in->bg;
    o->x = px;
    o->y = py;
    o->amp = A0;
    o->snr = in->snr_mf;       /* the detection statistic */
    if (in->edge) o->flags |= IM_SF_EDGE;
    if (!d) { o->flags |= IM_SF_FIT_FAILED | IM_SF_MOMENTS; return; }

    /* Width from the area above threshold: pi r_T^2 = npix, r_T^2 = (w^2/2) ln(A/T);
     * a spot with fewer than 3 pixels above it (found by its integrated SNR, its
     * peak hidden in the noise) starts from the matched filter's width and
     * amplitude instead. */
    int faint = in->npix < 3 && in->w_hint > 0;
    if (faint) {
        w0 = in->w_hint;
        if (in->a_hint > 0) A0 = in->a_hint;
    } else if (A0 > 1.05 * T && T > 0) w0 = sqrt(2 * in->npix / (M_PI * log(A0 / T)));
    else w0 = sqrt(in->npix / M_PI);
    if (!(w0 >= 0.7)) w0 = 0.7;
    if (w0 > 20) w0 = 20;
    h = in->window > 0 ? in->window : ceil(2 * w0 + 1);
    if (h < 3) h = 3;
    if (h > (MAXWIN - 1) / 2) h = (MAXWIN - 1) / 2;

    /* The window, clipped to the frame; saturated pixels left out. */
    int hw = (int)h;
    int x0 = px - hw, y0 = py - hw, x1 = px + hw, y1 = py + hw;
    if (x0 < 0 || y0 < 0 || x1 >= W || y1 >= H) o->flags |= IM_SF_EDGE;
    x0 = x0 < 0 ? 0 : x0; y0 = y0 < 0 ? 0 : y0;
    x1 = x1 >= W ? W - 1 : x1; y1 = y1 >= H ? H - 1 : y1;
    d->x0 = x0; d->y0 = y0; d->nx = x1 - x0 + 1; d->ny = y1 - y0 + 1;
    d->n = 0;
    double var0 = in->noise * in->noise;
    for (int y = y0; y <= y1; y++)
        for (int x = x0; x <= x1; x++) {
            double v = f->px[(size_t)y * W + x];
            if (v >= in->sat) { o->nsat++; continue; }
            double var = var0 + (in->gain > 0 && v > in->bg ? (v - in->bg) / in->gain : 0);
            d->ix[d->n] = (uint8_t)(x - x0);
            d->iy[d->n] = (uint8_t)(y - y0);
            d->v[d->n] = v;
            d->iw[d->n] = 1 / sqrt(var);
            d->n++;
        }
    if (o->nsat) o->flags |= IM_SF_SATURATED;

    if (in->method == IM_CM_MOMENTS || in->method == IM_CM_MOMENTS_BG || d->n <= MAXPAR + 2) {
        if (in->method == IM_CM_MOMENTS) moments(d, 0, o);
        else moments_above(in, o);
        o->w = w0;
        o->flags |= IM_SF_MOMENTS;
        if (in->method == IM_CM_GAUSS) o->flags |= IM_SF_FIT_FAILED;
        return;
    }
    /* Start from the background-subtracted moments of the pixels above threshold. */
    double s = 0, sx = 0, sy = 0;
    for (int k = 0; k < in->npix; k++) {
        int p = in->list[k];
        double v = f->px[p] - in->bg;
        s += v; sx += v * (p % W); sy += v * (p / W);
    }
    if (faint || !(s > 0)) { s = 1; sx = faint ? in->x_hint : px; sy = faint ? in->y_hint : py; }
    double start[MAXPAR] = {sx / s, sy / s,
                            o->nsat ? 2 * A0 : A0, w0, in->bg, 0, 0};
    int np = in->plane ? MAXPAR : NPAR;
    d->np = np;
    d->xc = px;
    d->yc = py;

    if (!ws->w || ws->n != (size_t)d->n || ws->p != (size_t)np) {
        if (ws->w) gsl_multifit_nlinear_free(ws->w);
        gsl_multifit_nlinear_parameters par = gsl_multifit_nlinear_default_parameters();
        par.trs = gsl_multifit_nlinear_trs_lm;
        par.solver = gsl_multifit_nlinear_solver_cholesky;
        par.scale = gsl_multifit_nlinear_scale_more;
        ws->w = gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, &par, (size_t)d->n,
                                           (size_t)np);
        ws->n = ws->w ? (size_t)d->n : 0;
        ws->p = (size_t)np;
        if (ws->covar) gsl_matrix_free(ws->covar);
        ws->covar = gsl_matrix_alloc((size_t)np, (size_t)np);
    }
    gsl_multifit_nlinear_workspace *w = ws->w;
    if (!w || !ws->covar) {
        moments(d, in->bg, o);
        o->flags |= IM_SF_FIT_FAILED | IM_SF_MOMENTS;
        return;
    }
    gsl_multifit_nlinear_fdf fdf = {model_f, model_df, NULL, (size_t)d->n, (size_t)np, d, 0, 0, 0};
    gsl_vector_view x = gsl_vector_view_array(start, (size_t)np);
    pthread_once(&gsl_quiet, quiet_gsl);
    int info = 0, st = gsl_multifit_nlinear_init(&x.vector, &fdf, w);
    if (st == GSL_SUCCESS) st = gsl_multifit_nlinear_driver(50, 1e-6, 1e-8, 0, NULL, NULL, &info, w);
    gsl_vector *p = gsl_multifit_nlinear_position(w);
    double X = gsl_vector_get(p, 0), Y = gsl_vector_get(p, 1), A = gsl_vector_get(p, 2);
    double Wd = fabs(gsl_vector_get(p, 3)), B = gsl_vector_get(p, 4);
    int ok = (st == GSL_SUCCESS || st == GSL_EMAXITER) && isfinite(X) && isfinite(Y) &&
             A > 0 && Wd > 0.3 && Wd < 4 * h && fabs(X - start[0]) < h && fabs(Y - start[1]) < h;
    if (ok) {
        gsl_matrix *J = gsl_multifit_nlinear_jac(w);
        ok = gsl_multifit_nlinear_covar(J, 0.0, ws->covar) == GSL_SUCCESS;
    }
    if (!ok) {
        moments(d, in->bg, o);
        o->flags |= IM_SF_FIT_FAILED | IM_SF_MOMENTS;
        return;
    }
    double chi = gsl_blas_dnrm2(gsl_multifit_nlinear_residual(w));
    o->x = X;
    o->y = Y;
    o->amp = A;
    o->w = Wd;
    o->bg = B;
    o->sx = sqrt(gsl_matrix_get(ws->covar, 0, 0));
    o->sy = sqrt(gsl_matrix_get(ws->covar, 1, 1));
    o->power = A * M_PI * Wd * Wd / 2;
    o->chi2 = chi * chi / (d->n - np);
    o->iter = (int)gsl_multifit_nlinear_niter(w);
    /* Cut by the edge: the 1/e^2 disc reaches beyond the frame. */
    if (X - Wd < -0.5 || Y - Wd < -0.5 || X + Wd > W - 0.5 || Y + Wd > H - 0.5)
        o->flags |= IM_SF_EDGE;
}
