/* t_map.c -- the imaging engine's maps (im_draw_api.map, im_draw_map.cpp): the colour
 * scale chosen (the smallest allowed step within the band limit, bands on step
 * multiples, centred on 0 when symmetric, a fixed scale), the range from scattered
 * points alone, and the refusals (SVG asked, nothing finite, a stop, an unwritable
 * folder) leaving no file under the final name and no .part.
 *     t_map DIR   (a scratch folder) */
#include <unistd.h>
#include "it.h"

static const im_draw_api *d;
static char path[1200], err[256];
enum { N = 50 };
static double g[N * N];

static int exists(const char *p) { return access(p, F_OK) == 0; }
static int part_left(const char *dir)
{
    char cmd[1400];
    snprintf(cmd, sizeof cmd, "ls '%s' | grep -q '\\.part'", dir);
    return system(cmd) == 0;
}
static int stop_now(void *c) { (void)c; return 1; }

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : ".";
    const imaging_api *im = imaging_get_api(IMAGING_ABI);
    if (!im || !im->draw || !im->draw->map) { printf("FAIL no map entry\n"); return 1; }
    d = im->draw;
    static const double ds[] = {0.25, 0.5, 1, 1.5, 2.5, 5};
    /* a ramp 42.1 .. 43.9 D across x */
    for (int j = 0; j < N; j++)
        for (int i = 0; i < N; i++) g[j * N + i] = 42.1 + 1.8 * (i + 0.5) / N;
    im_map m = {.title = "ramp", .unit = "D", .nx = N, .ny = N, .v = g, .xmin = -2,
                .xmax = 2, .ymin = -2, .ymax = 2, .disc = 2, .steps = ds, .nsteps = 6};
    im_map_info info;
    snprintf(path, sizeof path, "%s/ramp.png", dir);
    im_out o = {path, NULL, 0, 0, NULL, NULL};
    int rc = d->map(&m, &o, &info, err, sizeof err);
    CHECK(rc == IM_OK && exists(path) && info.step == 0.25 && fabs(info.lo - 42.0) < 1e-12 &&
          fabs(info.hi - 44.0) < 1e-12 && info.nbands == 8 && info.box_x1 > info.box_x0,
          "ramp 42.1-43.9 D: 0.25 D steps, 42 to 44 in %d bands (%s)", info.nbands, err);
    for (int k = 0; k < N * N; k++) g[k] = 40 + 10.0 * (k % N) / N;   /* 10 D */
    rc = d->map(&m, &o, &info, err, sizeof err);
    CHECK(rc == IM_OK && info.step == 0.5 && info.nbands == 20,
          "a 10 D range: 0.5 D steps (%g), %d bands", info.step, info.nbands);
    m.lo = 38; m.hi = 50;
    rc = d->map(&m, &o, &info, err, sizeof err);
    CHECK(rc == IM_OK && info.lo == 38 && info.hi == 50 && info.step == 0.5 &&
          info.nbands == 24,
          "a fixed scale 38-50 D kept (%g-%g in %g steps)", info.lo, info.hi, info.step);
    /* symmetric: elevation -1.7 .. 2.0 um, 0 inside the middle band */
    for (int k = 0; k < N * N; k++) g[k] = -1.7 + 3.7 * (k % N) / (N - 1.0);
    im_map e = m;
    e.lo = e.hi = 0; e.steps = NULL; e.nsteps = 0; e.symmetric = 1; e.unit = "um";
    rc = d->map(&e, &o, &info, err, sizeof err);
    double mid = (info.lo + info.hi) / 2;
    CHECK(rc == IM_OK && fabs(mid) < 1e-12 && info.nbands % 2 == 1 && info.hi >= 2.0 &&
          fabs(info.lo + info.hi) < 1e-12,
          "symmetric scale %g to %g in %g steps: 0 in the middle of band %d of %d",
          info.lo, info.hi, info.step, info.nbands / 2, info.nbands);
    /* points alone (a residual map) */
    for (int k = 0; k < N * N; k++) g[k] = NAN;
    double px[3] = {0, 1, -1}, py[3] = {0, 0, 1}, pv[3] = {0.5, 3.2, 1.1};
    unsigned char mk[3] = {0, 1, 0};
    im_map r = {.title = "residual", .unit = "sigma", .nx = N, .ny = N, .v = g, .xmin = -2,
                .xmax = 2, .ymin = -2, .ymax = 2, .npts = 3, .px = px, .py = py, .pv = pv,
                .mark = mk};
    rc = d->map(&r, &o, &info, err, sizeof err);
    CHECK(rc == IM_OK && info.vmin == 0.5 && info.vmax == 3.2 && info.skipped == N * N,
          "points alone: range %g-%g from them, %d empty cells", info.vmin, info.vmax,
          info.skipped);
    /* refusals: nothing written under the final name, no .part left */
    snprintf(path, sizeof path, "%s/refused.png", dir);
    im_out svg = {path, "x.svg", 0, 0, NULL, NULL};
    rc = d->map(&m, &svg, NULL, err, sizeof err);
    CHECK(rc == IM_EINVAL && !exists(path) && strstr(err, "PNG only"), "SVG refused: %s", err);
    r.npts = 0;
    rc = d->map(&r, &o, NULL, err, sizeof err);
    CHECK(rc == IM_EINVAL && strstr(err, "no finite"), "nothing finite: %s", err);
    for (int k = 0; k < N * N; k++) g[k] = 42 + (k % N) * 0.01;
    im_out st = {path, NULL, 0, 0, stop_now, NULL};
    rc = d->map(&m, &st, NULL, err, sizeof err);
    CHECK(rc == IM_ESTOP && !exists(path), "a stop: IM_ESTOP, no file (%s)", err);
    char bad[1300];
    snprintf(bad, sizeof bad, "%s/no-such-folder/x.png", dir);
    im_out bo = {bad, NULL, 0, 0, NULL, NULL};
    rc = d->map(&m, &bo, NULL, err, sizeof err);
    CHECK(rc != IM_OK && !exists(bad), "an unwritable place refused: %s", err);
    im_out tiny = {path, NULL, 200, 150, NULL, NULL};
    rc = d->map(&m, &tiny, NULL, err, sizeof err);
    CHECK(rc == IM_EINVAL && !exists(path), "a picture too small refused: %s", err);
    m.nx = 1;
    rc = d->map(&m, &o, NULL, err, sizeof err);
    CHECK(rc == IM_EINVAL, "a 1-column grid refused: %s", err);
    CHECK(!part_left(dir), "no .part file left in %s", dir);
    return it_failed != 0;
}
