/* wv_closed.h -- the closed forms and the engine measurements the wave tests
 * (t_closed.c) and the benchmark (bench_wave.c) share: each returns the error of the
 * engine against a formula computed here with GSL's Bessel functions, not by the
 * engine. */
#ifndef WV_CLOSED_H
#define WV_CLOSED_H
#include <gsl/gsl_sf_bessel.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "wave/wave.h"

#define PI_ 3.14159265358979323846

static double airy(double r)            /* (2 J1(x)/x)^2, x = pi r, r in lambda F */
{
    double x = PI_ * r;
    if (x < 1e-8) return 1;
    double v = 2 * gsl_sf_bessel_J1(x) / x;
    return v * v;
}
static double airy_ee(double r)         /* 1 - J0^2 - J1^2 */
{
    double x = PI_ * r, a = gsl_sf_bessel_J0(x), b = gsl_sf_bessel_J1(x);
    return 1 - a * a - b * b;
}
static double difflimit(double v)       /* (2/pi)(phi - cos phi sin phi) */
{
    if (v >= 1) return 0;
    double p = acos(v);
    return 2 / PI_ * (p - cos(p) * sin(p));
}

static int pupil_alloc(wave_pupil *p, int n)
{
    p->n = n;
    p->w = calloc((size_t)n * n, sizeof(double));
    p->amp = calloc((size_t)n * n, sizeof(double));
    return p->w && p->amp ? 0 : -1;
}
static void pupil_release(wave_pupil *p) { free(p->w); free(p->amp); }

/* The direct Fraunhofer integral against the Airy pattern (max |PSF - Airy| over
 * 0..6 lambda F, the peak being 1) and its encircled energy against 1 - J0^2 - J1^2
 * (relative, r = 0.25..5 lambda F): the larger. */
static double airy_err(const wave_api *wv, double *psf_err, double *ee_err)
{
    enum { NP = 241, NE = 20 };
    double u[NP], v[NP], out[NP], r[NE], ee[NE], e1 = 0, e2 = 0;
    for (int i = 0; i < NP; i++) {
        double rr = 6.0 * i / (NP - 1), a = 0.7 * i;
        u[i] = rr * cos(a);
        v[i] = rr * sin(a);
    }
    if (wv->fraunhofer(WAVE_Z_NOLL, NULL, 0, 48, 96, u, v, NP, out) != WAVE_OK) return 1;
    for (int i = 0; i < NP; i++) e1 = fmax(e1, fabs(out[i] - airy(hypot(u[i], v[i]))));
    for (int i = 0; i < NE; i++) r[i] = 0.25 * (i + 1);
    if (wv->fraunhofer_ee(48, 96, r, NE, ee) != WAVE_OK) return 1;
    for (int i = 0; i < NE; i++) e2 = fmax(e2, fabs(ee[i] - airy_ee(r[i])) / airy_ee(r[i]));
    if (psf_err) *psf_err = e1;
    if (ee_err) *ee_err = e2;
    return fmax(e1, e2);
}

/* The FFT path's MTF of an aberration-free n-cell pupil (m = 2n) against the closed
 * form at every sample k = 0..n (frequency k/n of the cutoff), both axes: the largest
 * difference (the MTF is 1 at 0). */
static double mtf_err(const wave_api *wv, wave_ctx *c, int n)
{
    wave_pupil p;
    double e = 1, *t = malloc(sizeof(double) * (n + 1)), *s = malloc(sizeof(double) * (n + 1));
    if (t && s && pupil_alloc(&p, n) == 0) {
        wv->pupil_mask(&p, 0, 0);
        if (wv->psf(c, &p, 2 * n, 0, NULL, NULL) == WAVE_OK &&
            wv->mtf(c, n + 1, t, s) == WAVE_OK) {
            e = 0;
            for (int k = 0; k <= n; k++) {
                double d = difflimit((double)k / n);
                e = fmax(e, fmax(fabs(t[k] - d), fabs(s[k] - d)));
            }
        }
        pupil_release(&p);
    }
    free(t);
    free(s);
    return e;
}

/* The FFT PSF (n-cell pupil, Q = 4) of a pupil with `coma` waves of Noll coma y
 * against section 43's Kirchhoff integral on the same cells at the central 16 x 16
 * samples, for an exit pupil of radius a and a sphere of radius R (F = R / 2a),
 * wavelength lambda: max difference over the Kirchhoff peak. */
static double kirchhoff_err(const wave_api *wv, wave_ctx *c, int n, double a, double R,
                            double lambda, double coma)
{
    enum { S = 16 };
    int m = 4 * n, h = m / 2;
    wave_pupil p;
    double e = 1, x[S * S], y[S * S], k[S * S], pitch = lambda * (R / (2 * a)) / 4;
    double *psf = malloc(sizeof(double) * m * m);
    if (!psf || pupil_alloc(&p, n)) { free(psf); return 1; }
    wv->pupil_mask(&p, 0, 0);
    if (coma != 0) wv->pupil_add_zernike(&p, WAVE_Z_NOLL, 7, coma);
    if (wv->psf(c, &p, m, 0, psf, NULL) == WAVE_OK) {
        for (int i = 0; i < S; i++)
            for (int j = 0; j < S; j++) {
                x[i * S + j] = (j - S / 2) * pitch;
                y[i * S + j] = (i - S / 2) * pitch;
            }
        if (wv->kirchhoff(&p, a, R, lambda, x, y, S * S, k) == WAVE_OK) {
            double peak = 0, d = 0;
            for (int i = 0; i < S * S; i++) peak = fmax(peak, k[i]);
            for (int i = 0; i < S; i++)
                for (int j = 0; j < S; j++) {
                    double f = psf[(size_t)(i - S / 2 + h) * m + (j - S / 2 + h)];
                    d = fmax(d, fabs(f - k[i * S + j]));
                }
            e = d / peak;
        }
    }
    pupil_release(&p);
    free(psf);
    return e;
}

/* Strehl ratio of 0.02 waves RMS of Noll term j (n = 256, m = 512) against the
 * Marechal approximation exp(-(2 pi sigma)^2): the relative difference. */
static double marechal_err(const wave_api *wv, wave_ctx *c, int j, double *strehl)
{
    wave_pupil p;
    wave_quality q;
    double e = 1, sig = 0.02, mar = exp(-(2 * PI_ * sig) * (2 * PI_ * sig));
    if (pupil_alloc(&p, 256)) return 1;
    wv->pupil_mask(&p, 0, 0);
    wv->pupil_add_zernike(&p, WAVE_Z_NOLL, j, sig);
    if (wv->psf(c, &p, 512, 0, NULL, &q) == WAVE_OK) {
        e = fabs(q.strehl - mar) / mar;
        if (strehl) *strehl = q.strehl;
    }
    pupil_release(&p);
    return e;
}

#endif
