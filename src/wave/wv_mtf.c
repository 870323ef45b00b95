/* wv_mtf.c -- from the context's last PSF: the MTF (the PSF's transform by the same
 * FFTW plan, the pupil's autocorrelation) along the tangential and sagittal axes, the
 * diffraction limit of a circular pupil beside it, and the resolving power of section
 * 44 (Rayleigh, Sparrow) from a cut through the PSF.  The cut is band-limited (the
 * PSF's spectrum ends at the cutoff, sample n, and m >= 2n samples it), so its Fourier
 * series interpolates it exactly between samples, with exact derivatives. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "wv_int.h"

/* The PSF's transform, normalised to 1 at frequency 0; the PSF's centre is sample
 * (m/2, m/2), so the raw transform carries (-1)^k, taken off here. */
static int transform(wave_ctx *c)
{
    int m = c->m;
    for (size_t i = 0; i < (size_t)m * m; i++) {
        c->buf[i][0] = c->psf[i];
        c->buf[i][1] = 0;
    }
    fftw_execute(c->plan);
    double z = c->buf[0][0];
    return z > 0 ? WAVE_OK : WAVE_EINVAL;
}

int wv_otf(wave_ctx *c, int nk, double *tr, double *ti, double *sr, double *si)
{
    int m, rc;
    if (!c || !c->have || nk < 1 || nk > c->n + 1) return WAVE_EINVAL;
    if ((rc = transform(c)) != WAVE_OK) return rc;
    m = c->m;
    double z = c->buf[0][0];
    for (int k = 0; k < nk; k++) {
        const double *t = c->buf[(size_t)k * m], *s = c->buf[k];
        double sg = k % 2 ? -1.0 / z : 1.0 / z;
        if (tr) tr[k] = t[0] * sg;
        if (ti) ti[k] = t[1] * sg;
        if (sr) sr[k] = s[0] * sg;
        if (si) si[k] = s[1] * sg;
    }
    return WAVE_OK;
}

/* Sample (kx, ky) of the transform referred to the centre, over its value at 0. */
static void otf_at(const wave_ctx *c, int kx, int ky, double z, double *re, double *im)
{
    int m = c->m;
    const double *v = c->buf[(size_t)((ky % m + m) % m) * m + (kx % m + m) % m];
    double sg = ((kx + ky) % 2 ? -1.0 : 1.0) / z;
    *re = v[0] * sg;
    *im = v[1] * sg;
}

int wv_otf_dir(wave_ctx *c, double angle, int nk, double *re, double *im)
{
    int rc;
    if (!c || !c->have || nk < 1 || nk > c->n + 1 || !isfinite(angle) || !re || !im)
        return WAVE_EINVAL;
    if ((rc = transform(c)) != WAVE_OK) return rc;
    double z = c->buf[0][0], ca = cos(angle), sa = sin(angle);
    /* the axes themselves exactly (cos(pi/2) is 6e-17, not 0) */
    if (fabs(sa) < 1e-12) sa = 0, ca = ca > 0 ? 1 : -1;
    if (fabs(ca) < 1e-12) ca = 0, sa = sa > 0 ? 1 : -1;
    /* Between samples the OTF is interpolated with the PSF's centroid taken out: a
     * PSF off the centre by s samples turns the OTF's phase by 2 pi k s / m per
     * sample, which linear interpolation of re and im would average away (0.3 rad
     * a sample costs 1 % of the modulus); off the ramp the OTF is smooth. */
    double w = 2 * WV_PI / c->m;
    for (int k = 0; k < nk; k++) {
        double fx = k * ca, fy = k * sa, x0 = floor(fx), y0 = floor(fy), tx = fx - x0, ty = fy - y0;
        if (tx == 0 && ty == 0) {
            otf_at(c, (int)x0, (int)y0, z, &re[k], &im[k]);
            continue;
        }
        double vr[4], vi[4], wt[4] = {(1 - tx) * (1 - ty), tx * (1 - ty), (1 - tx) * ty, tx * ty};
        double sr = 0, si = 0;
        for (int q = 0; q < 4; q++) {
            int kx = (int)x0 + (q & 1), ky = (int)y0 + (q >> 1);
            otf_at(c, kx, ky, z, &vr[q], &vi[q]);
            double a = w * (kx * c->cx + ky * c->cy), cs = cos(a), sn = sin(a);
            sr += wt[q] * (vr[q] * cs - vi[q] * sn);
            si += wt[q] * (vr[q] * sn + vi[q] * cs);
        }
        double a = -w * (fx * c->cx + fy * c->cy), cs = cos(a), sn = sin(a);
        re[k] = sr * cs - si * sn;
        im[k] = sr * sn + si * cs;
    }
    return WAVE_OK;
}

int wv_mtf(wave_ctx *c, int nk, double *tan, double *sag)
{
    int m, rc;
    if (!c || !c->have || nk < 1 || nk > c->n + 1) return WAVE_EINVAL;
    if ((rc = transform(c)) != WAVE_OK) return rc;
    m = c->m;
    double z = c->buf[0][0];
    for (int k = 0; k < nk; k++) {
        const double *t = c->buf[(size_t)k * m], *s = c->buf[k];
        if (tan) tan[k] = hypot(t[0], t[1]) / z;
        if (sag) sag[k] = hypot(s[0], s[1]) / z;
    }
    return WAVE_OK;
}

double wv_mtf_diffraction(double v)
{
    if (!(v < 1)) return 0;
    if (v <= 0) return 1;
    double p = acos(v);
    return 2 / WV_PI * (p - cos(p) * sin(p));
}

/* The cut's Fourier series: coefficients q = 0..nq-1 (the rest conjugate). */
typedef struct cut { int nq, m; double *re, *im; } cut;

/* I(x) (d = 0), I'(x) (1), I''(x) (2), x in samples from the centre. */
static double cut_eval(const cut *k, double x, int d)
{
    double s = 0;
    for (int q = 0; q < k->nq; q++) {
        double w = 2 * WV_PI * q / k->m, a = w * x, cs = cos(a), sn = sin(a);
        double v;
        if (d == 0) v = k->re[q] * cs - k->im[q] * sn;
        else if (d == 1) v = -w * (k->re[q] * sn + k->im[q] * cs);
        else v = -w * w * (k->re[q] * cs - k->im[q] * sn);
        s += q == 0 ? v : 2 * v;
    }
    return s / k->m;
}

/* The first root of f beyond x0 in direction dir where f goes from < 0 to >= 0:
 * scanned in steps of 1/20 sample, then bisected.  NaN if none within lim. */
static double first_rise(const cut *k, double x0, int dir, double lim, int d, int sparrow)
{
    double step = 0.05, prev_s = 0, prev = 0;
    for (int i = 0; i * step <= lim; i++) {
        double s = i * step, f;
        if (sparrow) f = cut_eval(k, x0 - s / 2, 2) + cut_eval(k, x0 + s / 2, 2);
        else f = cut_eval(k, x0 + dir * s, d);
        if (i > 0 && prev < 0 && f >= 0) {
            double lo = prev_s, hi = s;
            for (int it = 0; it < 60; it++) {
                double mid = 0.5 * (lo + hi), fm;
                if (sparrow) fm = cut_eval(k, x0 - mid / 2, 2) + cut_eval(k, x0 + mid / 2, 2);
                else fm = cut_eval(k, x0 + dir * mid, d);
                if (fm < 0) lo = mid; else hi = mid;
            }
            return 0.5 * (lo + hi);
        }
        prev = f;
        prev_s = s;
    }
    return NAN;
}

int wv_resolution(wave_ctx *c, int tan, double *rayleigh, double *sparrow)
{
    int m, h, rc = WAVE_EINVAL;
    cut k;
    if (!c || !c->have) return WAVE_EINVAL;
    m = c->m;
    h = m / 2;
    k.m = m;
    k.nq = c->n + 1 < h ? c->n + 1 : h;
    k.re = calloc((size_t)k.nq, sizeof(double));
    k.im = calloc((size_t)k.nq, sizeof(double));
    if (!k.re || !k.im) { free(k.re); free(k.im); return WAVE_ENOMEM; }
    for (int q = 0; q < k.nq; q++)
        for (int t = 0; t < m; t++) {
            double v = tan ? c->psf[(size_t)t * m + h] : c->psf[(size_t)h * m + t];
            double a = -2 * WV_PI * q * (double)(t - h) / m;
            k.re[q] += v * cos(a);
            k.im[q] += v * sin(a);
        }
    /* the peak of the cut: the largest sample, then Newton on I' */
    double x0 = 0, best = -1;
    for (int t = 0; t < m; t++) {
        double v = tan ? c->psf[(size_t)t * m + h] : c->psf[(size_t)h * m + t];
        if (v > best) { best = v; x0 = t - h; }
    }
    for (int it = 0; it < 20; it++) {
        double d2 = cut_eval(&k, x0, 2);
        if (!(d2 < 0)) break;
        double dx = -cut_eval(&k, x0, 1) / d2;
        if (fabs(dx) > 1) dx = dx > 0 ? 1 : -1;
        x0 += dx;
        if (fabs(dx) < 1e-12) break;
    }
    double lim = h - fabs(x0) - 1;
    /* Rayleigh: the first minimum either side (I' rises through 0), their mean */
    double right = first_rise(&k, x0, 1, lim, 1, 0), left = NAN;
    {
        /* leftwards I' falls through 0 at a minimum: the rise of -I'(x0 - s) */
        double step = 0.05, prev = 0;
        for (int i = 1; i * step <= lim; i++) {
            double s = i * step, f = -cut_eval(&k, x0 - s, 1);
            if (i > 1 && prev < 0 && f >= 0) {
                double lo = s - step, hi = s;
                for (int j = 0; j < 60; j++) {
                    double mid = 0.5 * (lo + hi);
                    if (-cut_eval(&k, x0 - mid, 1) < 0) lo = mid; else hi = mid;
                }
                left = 0.5 * (lo + hi);
                break;
            }
            prev = f;
        }
    }
    double sp = first_rise(&k, x0, 1, 2 * lim, 2, 1);
    if (isfinite(right) && isfinite(left) && isfinite(sp)) {
        if (rayleigh) *rayleigh = 0.5 * (left + right);
        if (sparrow) *sparrow = sp;
        rc = WAVE_OK;
    }
    free(k.re);
    free(k.im);
    return rc;
}
