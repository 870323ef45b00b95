/* it.h -- shared by the imaging engine's tests and benches (tests/imaging/): the
 * table, a monotonic clock, the benchmark sensor and spot, and small checks. */
#ifndef IT_H
#define IT_H
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "imaging/imaging.h"

#pragma GCC diagnostic ignored "-Wunused-function"

static int it_failed __attribute__((unused));
#define CHECK(cond, ...) do { if (cond) { printf("PASS "); } else { printf("FAIL "); \
    it_failed++; } printf(__VA_ARGS__); printf("\n"); } while (0)

static const im_frame_api *it_api(void)
{
    const imaging_api *im = imaging_get_api(IMAGING_ABI);
    if (!im || !im->frame) { printf("FAIL no imaging table\n"); exit(1); }
    return im->frame;
}

static double it_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

/* Issue 10's benchmark model: 640x480 16-bit, B = 100 counts, additive Gaussian read
 * noise sigma = 50 counts, spot B + A exp(-2 r^2/w^2), w = 3 px, A = 1000, sampled at
 * pixel centres.  Cramer-Rao bound per coordinate sqrt(2/pi) sigma / A. */
#define IT_SIGMA 50.0
#define IT_AMP 1000.0
#define IT_W 3.0
static im_sensor it_sensor(void)
{
    im_sensor s;
    memset(&s, 0, sizeof s);
    s.width = 640; s.height = 480; s.pitch = 0.0048; s.bits = 16;
    s.xdir[0] = 1; s.ydir[1] = 1;
    s.exposure = 1e-3; s.qe = 1; s.gain = 1; s.bias = 100; s.read_noise = IT_SIGMA;
    return s;
}
static im_spot_src it_spot(double x, double y)
{
    im_spot_src sp;
    memset(&sp, 0, sizeof sp);
    sp.kind = IM_SPOT_ANALYTIC; sp.x = x; sp.y = y; sp.w = IT_W; sp.peak = IT_AMP;
    return sp;
}
static double it_crb(void) { return sqrt(2 / M_PI) * IT_SIGMA / IT_AMP; }

/* Deterministic uniform numbers for test positions (SplitMix64). */
static double it_uniform(uint64_t *z)
{
    uint64_t r = (*z += 0x9e3779b97f4a7c15ull);
    r = (r ^ (r >> 30)) * 0xbf58476d1ce4e5b9ull;
    r = (r ^ (r >> 27)) * 0x94d049bb133111ebull;
    return (double)((r ^ (r >> 31)) >> 11) * 0x1.0p-53;
}

static int it_cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}
static double it_median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, it_cmp);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
#endif
