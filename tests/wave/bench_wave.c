/* bench_wave.c -- the wave engine's figures (scripts/bench_wave.sh): accuracy against
 * closed forms (wv_closed.h, wv_calc.h), the time of a 512 x 512 PSF and its MTF on
 * one core against its floor (two bare FFTW transforms of the same size, measured
 * here), and the error-against-run-time table: pupil grid n (Q = 4) against the
 * FFT PSF's, MTF's and encircled energy's errors and the time of PSF + MTF. */
#include <stdio.h>
#include <time.h>
#include <fftw3.h>
#include "wv_calc.h"
#include "wv_closed.h"

/* The thread's CPU time: "one core" on a machine that other jobs share (wall time
 * there counts their turns too). */
static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}
static double median(double *v, int n) { qsort(v, n, sizeof *v, cmp); return v[n / 2]; }

/* Median time of PSF + MTF of an n-cell aberrated pupil in an m-field (plan made
 * before: "plan once, reuse"). */
static double time_psf_mtf(const wave_api *wv, wave_ctx *c, int n, int m, int reps)
{
    wave_pupil p;
    double t[31], *tan = malloc(sizeof(double) * (n + 1)), *sag = malloc(sizeof(double) * (n + 1));
    pupil_alloc(&p, n);
    wv->pupil_mask(&p, 0, 0);
    wv->pupil_add_zernike(&p, WAVE_Z_NOLL, 8, 0.1);
    wv->psf(c, &p, m, 0, NULL, NULL);
    if (reps > 31) reps = 31;
    for (int r = 0; r < reps; r++) {
        double t0 = now_ms();
        wv->psf(c, &p, m, 0, NULL, NULL);
        wv->mtf(c, n + 1, tan, sag);
        t[r] = now_ms() - t0;
    }
    pupil_release(&p);
    free(tan);
    free(sag);
    return median(t, reps);
}

static double time_fft(int m, int reps)
{
    fftw_complex *b = fftw_alloc_complex((size_t)m * m);
    fftw_plan pl = fftw_plan_dft_2d(m, m, b, b, FFTW_FORWARD, FFTW_ESTIMATE);
    double t[31];
    for (size_t i = 0; i < (size_t)m * m; i++) { b[i][0] = (double)(i % 7); b[i][1] = 0; }
    for (int r = 0; r < reps; r++) {
        double t0 = now_ms();
        fftw_execute(pl);
        t[r] = now_ms() - t0;
    }
    fftw_destroy_plan(pl);
    fftw_free(b);
    return median(t, reps);
}

int main(void)
{
    const wave_api *wv = wave_get_api(WAVE_ABI);
    wave_ctx *c;
    if (!wv) return 1;
    c = wv->ctx_new();
    printf("# %s\n", wv->version());
    double ep, ee;
    double a = airy_err(wv, &ep, &ee);
    printf("# Airy by direct Fraunhofer quadrature (48 x 96 nodes): PSF %.2g of the peak, "
           "EE %.2g relative\n", ep, ee);
    printf("BENCH wave_airy_rel_err %.3g ratio\n", a);
    printf("BENCH wave_mtf_difflimit_rel_err %.3g ratio\n", mtf_err(wv, c, 512));
    printf("# (512-cell pupil, 1024 FFT; largest |MTF - closed form| over k/n, k = 0..n)\n");
    printf("BENCH wave_psf_fft_vs_kirchhoff_rel_err %.3g ratio\n",
           fmax(kirchhoff_err(wv, c, 32, 5, 100, 0.5e-3, 0), kirchhoff_err(wv, c, 32, 5, 100, 0.5e-3, 0.3)));
    printf("# (F/10, 32-cell pupil, Q 4, central 16 x 16 samples, aberration-free and 0.3 waves coma)\n");
    double ms = 0;
    const int terms[] = {11, 5, 7, 22};
    for (int i = 0; i < 4; i++) ms = fmax(ms, marechal_err(wv, c, terms[i], NULL));
    printf("BENCH wave_strehl_marechal_rel_err %.3g ratio\n", ms);
    printf("# (0.02 waves RMS of Noll Z11, Z5, Z7, Z22 each; the largest)\n");
    double R;
    printf("BENCH wave_coating_R_rel_err %.3g ratio\n", coating_err(wv, &R));
    printf("BENCH wave_tir_phase_abs_err_rad %.3g rad\n", tir_err(wv));

    double t512 = time_psf_mtf(wv, c, 256, 512, 21), f512 = time_fft(512, 21);
    printf("BENCH wave_psf512_ms %.3f ms\n", t512);
    printf("BENCH wave_fft512_ms %.3f ms\n", f512);
    printf("BENCH wave_psf512_vs_2fft %.2f ratio\n", t512 / (2 * f512));
    printf("# (256-cell pupil with coma, 512 x 512 PSF and both MTF cuts; baseline: two bare\n"
           "#  512 x 512 complex FFTW transforms, the floor of PSF + MTF; medians of 21, CPU time)\n");

    printf("# pupil n | FFT m | PSF err (peak 1) | MTF err | EE err (1st ring) | PSF+MTF ms\n");
    const int ns[] = {32, 64, 128, 256, 512};
    for (int i = 0; i < 5; i++) {
        int n = ns[i], m = 4 * n, h = m / 2;
        wave_pupil p;
        double *psf = malloc(sizeof(double) * m * m), pe = 0, r = 1.2196698912665045 * 4, fr;
        pupil_alloc(&p, n);
        wv->pupil_mask(&p, 0, 0);
        wv->psf(c, &p, m, 0, psf, NULL);
        for (int y = -20; y <= 20; y++)
            for (int x = -20; x <= 20; x++)
                pe = fmax(pe, fabs(psf[(size_t)(y + h) * m + x + h] - airy(hypot(x, y) / 4)));
        wv->energy(c, &r, 1, 0, &fr);
        double ee_e = fabs(fr - airy_ee(r / 4)), me = mtf_err(wv, c, n);
        double t = time_psf_mtf(wv, c, n, m, n >= 512 ? 5 : 11);
        printf("# %7d | %5d | %16.2e | %7.2e | %17.2e | %10.2f\n", n, m, pe, me, ee_e, t);
        free(psf);
        pupil_release(&p);
    }
    wv->ctx_free(c);
    return 0;
}
