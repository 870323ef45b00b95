/* wv_psf.c -- the PSF by FFT (FFTW 3, one in-place plan per field size, made once and
 * kept in the context), its quality figures and its encircled and ensquared energy.
 * The pupil function is amp * exp(-i 2 pi W): W > 0 leads the reference sphere, so
 * the field there is the one the wavefront had W earlier (phase k s grows along the
 * ray).  U(u) = sum P(x) exp(-i k x u / R) is FFTW's forward transform. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "wv_int.h"

wave_ctx *wv_ctx_new(void) { return calloc(1, sizeof(wave_ctx)); }

void wv_ctx_free(wave_ctx *c)
{
    if (!c) return;
    if (c->plan) fftw_destroy_plan(c->plan);
    fftw_free(c->buf);
    free(c->psf);
    free(c);
}

/* FFTW_ESTIMATE: the plan does not depend on timings, so a run and its replay do the
 * same arithmetic (FFTW_MEASURE may pick another algorithm each time). */
int wv_plan(wave_ctx *c, int m)
{
    if (c->m == m && c->plan) return WAVE_OK;
    if (c->plan) fftw_destroy_plan(c->plan);
    fftw_free(c->buf);
    free(c->psf);
    c->plan = NULL;
    c->m = 0;
    c->have = 0;
    c->buf = fftw_alloc_complex((size_t)m * m);
    c->psf = malloc(sizeof(double) * (size_t)m * m);
    if (!c->buf || !c->psf) return WAVE_ENOMEM;
    c->plan = fftw_plan_dft_2d(m, m, c->buf, c->buf, FFTW_FORWARD, FFTW_ESTIMATE);
    if (!c->plan) return WAVE_ENOMEM;
    c->m = m;
    return WAVE_OK;
}

int wv_psf(wave_ctx *c, const wave_pupil *p, int m, double defocus, double *psf,
           wave_quality *q)
{
    int n, rc, h;
    double sa = 0, sa2 = 0;
    if (!c || !p || p->n < 2 || m < p->n || m % 2 || !p->w || !p->amp) return WAVE_EINVAL;
    if ((rc = wv_plan(c, m)) != WAVE_OK) return rc;
    n = p->n;
    h = m / 2;
    memset(c->buf, 0, sizeof(fftw_complex) * (size_t)m * m);
    for (int i = 0; i < n; i++)
        for (int k = 0; k < n; k++) {
            size_t at = (size_t)i * n + k;
            double a = p->amp[at];
            if (!(a > 0)) continue;
            double w = p->w[at];
            if (defocus != 0) {
                double x = wv_cell(n, k), y = wv_cell(n, i);
                w += defocus * (x * x + y * y);
            }
            if (!isfinite(w)) return WAVE_EINVAL;
            double ph = -2 * WV_PI * w;
            c->buf[(size_t)i * m + k][0] = a * cos(ph);
            c->buf[(size_t)i * m + k][1] = a * sin(ph);
            sa += a;
            sa2 += a * a;
        }
    if (!(sa > 0)) return WAVE_EINVAL;
    fftw_execute(c->plan);
    double norm = 1 / (sa * sa), best = -1, tot = 0, sx = 0, sy = 0, edge = 0;
    int bi = h, bk = h, band = m / 16;
    for (int i = 0; i < m; i++)
        for (int k = 0; k < m; k++) {
            const double *u = c->buf[(size_t)((i + h) % m) * m + (k + h) % m];
            double v = (u[0] * u[0] + u[1] * u[1]) * norm;
            c->psf[(size_t)i * m + k] = v;
            tot += v;
            sx += v * (k - h);
            sy += v * (i - h);
            if (i < band || i >= m - band || k < band || k >= m - band) edge += v;
            if (v > best) { best = v; bi = i; bk = k; }
        }
    c->n = n;
    c->total = tot;
    c->cx = sx / tot;
    c->cy = sy / tot;
    c->have = 1;
    if (psf) memcpy(psf, c->psf, sizeof(double) * (size_t)m * m);
    if (q) {
        q->strehl = best;
        q->strehl_centre = c->psf[(size_t)h * m + h];
        q->peak_x = bk - h;
        q->peak_y = bi - h;
        q->cx = sx / tot;
        q->cy = sy / tot;
        q->edge = edge / tot;
    }
    (void)sa2;
    return WAVE_OK;
}

typedef struct rad_e { double r, e; } rad_e;
static int by_r(const void *a, const void *b)
{
    double x = ((const rad_e *)a)->r, y = ((const rad_e *)b)->r;
    return x < y ? -1 : x > y;
}

/* Every sample within the largest radius split into 4 x 4 parts, each at its own
 * distance from the centre, sorted once: each radius is then a binary search. */
int wv_energy(wave_ctx *c, const double *r, int nr, int square, double *frac)
{
    double rmax = 0;
    int m, h;
    if (!c || !c->have || nr < 1 || !r || !frac) return WAVE_EINVAL;
    m = c->m;
    h = m / 2;
    for (int i = 0; i < nr; i++) {
        if (!(r[i] >= 0)) return WAVE_EINVAL;
        rmax = fmax(rmax, r[i]);
    }
    int lim = (int)ceil(rmax) + 1;
    if (lim > h - 1) lim = h - 1;
    size_t cap = (size_t)(2 * lim + 1) * (2 * lim + 1) * 16, ne = 0;
    rad_e *a = malloc(sizeof *a * cap);
    if (!a) return WAVE_ENOMEM;
    for (int i = -lim; i <= lim; i++)
        for (int k = -lim; k <= lim; k++) {
            double v = c->psf[(size_t)(i + h) * m + (k + h)] / 16;
            for (int s = 0; s < 4; s++)
                for (int t = 0; t < 4; t++) {
                    double dy = i + (2 * s - 3) / 8.0, dx = k + (2 * t - 3) / 8.0;
                    a[ne].r = square ? fmax(fabs(dx), fabs(dy)) : hypot(dx, dy);
                    a[ne++].e = v;
                }
        }
    qsort(a, ne, sizeof *a, by_r);
    for (size_t i = 1; i < ne; i++) a[i].e += a[i - 1].e;
    for (int j = 0; j < nr; j++) {
        size_t lo = 0, hi = ne;                 /* first entry beyond r[j] */
        while (lo < hi) {
            size_t mid = (lo + hi) / 2;
            if (a[mid].r <= r[j]) lo = mid + 1; else hi = mid;
        }
        frac[j] = lo ? a[lo - 1].e / c->total : 0;
    }
    free(a);
    return WAVE_OK;
}
