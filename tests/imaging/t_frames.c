/* t_frames.c -- frame synthesis against its model (determinism whatever the thread
 * count, noise statistics, quantisation and saturation, exact pixel-area binning, the
 * Gaussian splat, the sensor pose) and the frame files (PNG/TIFF/raw round trips,
 * sequences, video, cameras; truncated, lying, wrong-depth and zero-size files, atomic
 * writes).  Run in a scratch directory given as argv[1]. */
#include <dlfcn.h>
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>
#include "it.h"
#include "imaging/im_camera.h"

static const im_frame_api *fa;
static char err[512];
static const char *dir;

static char *path_of(const char *name)
{
    static char buf[8][1024];
    static int k;
    k = (k + 1) % 8;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

static int same(const im_frame *a, const im_frame *b)
{
    return a && b && a->width == b->width && a->height == b->height &&
           !memcmp(a->px, b->px, sizeof *a->px * (size_t)a->width * a->height);
}

static void determinism(void)
{
    im_sensor s = it_sensor();
    s.shot_noise = 1; s.background = 3e4; s.dark_current = 500;
    im_spot_src sp = it_spot(100.5, 200.25);
    im_frame *a, *b, *c, *d;
    fa->synth(&s, &sp, 1, 42, 1, &a, err, sizeof err);
    fa->synth(&s, &sp, 1, 42, 2, &b, err, sizeof err);
    fa->synth(&s, &sp, 1, 42, 5, &c, err, sizeof err);
    fa->synth(&s, &sp, 1, 43, 1, &d, err, sizeof err);
    CHECK(same(a, b) && same(a, c), "same seed: the same frame with 1, 2 and 5 threads");
    CHECK(!same(a, d), "another seed: another frame");
    fa->frame_free(a); fa->frame_free(b); fa->frame_free(c); fa->frame_free(d);
}

/* The dark pixels' fast path (no background light: counts from their tabulated law)
 * and the spot's full path in one frame: the same bits whatever the thread count, and a
 * gain that is not 1. */
static void determinism_dark(void)
{
    im_sensor s = it_sensor();
    s.shot_noise = 1; s.gain = 2.5; s.bias = 300;
    im_spot_src sp[2] = {it_spot(100.5, 200.25), it_spot(400.2, 31.7)};
    im_frame *a, *b, *c;
    fa->synth(&s, sp, 2, 42, 1, &a, err, sizeof err);
    fa->synth(&s, sp, 2, 42, 2, &b, err, sizeof err);
    fa->synth(&s, sp, 2, 42, 5, &c, err, sizeof err);
    CHECK(same(a, b) && same(a, c), "dark pixels: the same frame with 1, 2 and 5 threads");
    fa->frame_free(a); fa->frame_free(b); fa->frame_free(c);
}

static double phi(double z) { return 0.5 * erfc(-z / sqrt(2)); }

/* Dark pixels against their exact law: count = clamp(floor(bias + 0.5 + sigma Z), 0,
 * max), so P(count = k) = Phi((k + 1 - c) / sigma) - Phi((k - c) / sigma), c = bias +
 * 0.5, all of the mass below 1 at 0.  Bias 100, sigma 50: 2.3 % of the pixels clip at 0.
 * A Pearson chi-square over every value with 20 or more expected pixels (the tails
 * pooled) on three frames, and the share at 0 on its own. */
static void dark_law(void)
{
    im_sensor s = it_sensor();
    enum { K = 400 };
    static long h[K];
    long tot = 0, n0 = 0;
    double c = s.bias + 0.5, sg = s.read_noise;
    memset(h, 0, sizeof h);
    for (uint64_t seed = 30; seed < 33; seed++) {
        im_frame *f;
        fa->synth(&s, NULL, 0, seed, 2, &f, err, sizeof err);
        for (int i = 0; i < f->width * f->height; i++, tot++) {
            h[f->px[i] < K - 1 ? f->px[i] : K - 1]++;
            n0 += f->px[i] == 0;
        }
        fa->frame_free(f);
    }
    double chi2 = 0, pe = 0, acc = 0;
    long po = 0;
    int dof = -1;
    for (int k = 0; k < K; k++) {
        double p = k == 0 ? phi((1 - c) / sg) : k == K - 1 ? 1 - phi((k - c) / sg)
                 : phi((k + 1 - c) / sg) - phi((k - c) / sg);
        pe += p * tot; po += h[k];                      /* pooled until 20 expected */
        if (pe >= 20 || k == K - 1) {
            chi2 += (po - pe) * (po - pe) / pe;
            dof++;
            acc += pe;
            pe = 0; po = 0;
        }
    }
    double e0 = phi((1 - c) / sg) * tot;
    CHECK(fabs(acc - tot) < 1e-6 * tot && chi2 < dof + 5 * sqrt(2.0 * dof),
          "dark pixels' counts: chi-square %.1f on %d degrees of freedom", chi2, dof);
    CHECK(fabs(n0 - e0) < 4 * sqrt(e0), "dark pixels clipped at 0: %ld (%.0f expected)",
          n0, e0);
}

/* Every pixel's mean and variance over 600 frames against the model, on a small sensor
 * with a bright spot under shot noise (peak 10 000 e-: variance 4x the read noise's),
 * so a pixel drawn from the wrong law -- no Poisson on the spot, a read noise too wide
 * or too narrow, a seam between the spot's full path and the dark pixels' table --
 * fails: mean bias + e, variance e + sigma^2 + 1/12 (e from synth_expected). */
static void pixel_moments(void)
{
    enum { W = 64, H = 48, M = 600 };
    im_sensor s = it_sensor();
    s.width = W; s.height = H; s.bias = 1000; s.shot_noise = 1;
    im_spot_src sp = it_spot(30.3, 20.6);
    sp.peak = 1e4;
    static double e[W * H], sm[W * H], sq[W * H];
    memset(sm, 0, sizeof sm); memset(sq, 0, sizeof sq);
    fa->synth_expected(&s, &sp, 1, e, err, sizeof err);
    for (int k = 0; k < M; k++) {
        im_frame *f;
        fa->synth(&s, &sp, 1, 5000 + (uint64_t)k, 1, &f, err, sizeof err);
        for (int i = 0; i < W * H; i++) {
            double d = f->px[i] - s.bias - e[i];
            sm[i] += d;
            sq[i] += d * d;
        }
        fa->frame_free(f);
    }
    double zm = 0, vr_spot = 0, vr_dark = 0;
    int nspot = 0, ndark = 0;
    for (int i = 0; i < W * H; i++) {
        double v = e[i] + s.read_noise * s.read_noise + 1.0 / 12, mu = sm[i] / M;
        double sv = (sq[i] - M * mu * mu) / (M - 1);
        zm += mu * mu / (v / M);
        if (e[i] > 2500) { vr_spot += sv / v; nspot++; }
        else if (e[i] == 0) { vr_dark += sv / v; ndark++; }
    }
    vr_spot /= nspot; vr_dark /= ndark;
    CHECK(fabs(zm - W * H) < 5 * sqrt(2.0 * W * H),
          "pixel means against bias + e: chi-square %.0f on %d pixels", zm, W * H);
    CHECK(nspot > 10 && fabs(vr_spot - 1) < 5 * sqrt(2.0 / (M - 1) / nspot) &&
          ndark > 1000 && fabs(vr_dark - 1) < 5 * sqrt(2.0 / (M - 1) / ndark),
          "pixel variances against e + sigma^2 + 1/12: %.4f on %d spot pixels, %.4f on %d "
          "dark ones", vr_spot, nspot, vr_dark, ndark);
}

static void stats(const im_frame *f, double *mean, double *var)
{
    double m = 0, q = 0, n = (double)f->width * f->height;
    for (size_t i = 0; i < (size_t)f->width * f->height; i++) {
        m += f->px[i];
        q += (double)f->px[i] * f->px[i];
    }
    *mean = m / n;
    *var = q / n - *mean * *mean;
}

static void noise_model(void)
{
    im_sensor s = it_sensor();
    im_frame *f;
    double m, v;
    s.bias = 1000;
    fa->synth(&s, NULL, 0, 1, 1, &f, err, sizeof err);
    stats(f, &m, &v);
    CHECK(fabs(m - 1000) < 0.3 && fabs(sqrt(v) / sqrt(2500 + 1.0 / 12) - 1) < 0.01,
          "read noise: mean %.3f (1000), sigma %.3f (50)", m, sqrt(v));
    fa->frame_free(f);
    /* The ziggurat's tails: beyond 3 and 4 sigma as often as a normal law says. */
    long n3 = 0, n4 = 0, tot = 0;
    for (uint64_t seed = 20; seed < 23; seed++) {
        fa->synth(&s, NULL, 0, seed, 1, &f, err, sizeof err);
        for (int i = 0; i < f->width * f->height; i++, tot++) {
            double d = fabs(f->px[i] + 0.5 - 1000.5);
            n3 += d > 150;
            n4 += d > 200;
        }
        fa->frame_free(f);
    }
    double p3 = (double)n3 / tot, e4 = 6.334e-5 * tot;
    CHECK(fabs(p3 / 0.0026998 - 1) < 0.06 && n4 > e4 - 4 * sqrt(e4) && n4 < e4 + 4 * sqrt(e4),
          "read-noise tails: %.5f beyond 3 sigma (0.00270), %ld beyond 4 (%.0f)", p3, n4, e4);
    /* Shot noise: Poisson photo-electrons, variance = mean (gain 1, no read noise),
     * both through GSL (mean 4) and the PTRS sampler (mean 400). */
    double means[2] = {4, 400};
    for (int k = 0; k < 2; k++) {
        s = it_sensor();
        s.read_noise = 0; s.bias = 0; s.shot_noise = 1; s.qe = 0.5; s.exposure = 0.01;
        s.background = means[k] / (s.qe * s.exposure);
        fa->synth(&s, NULL, 0, 7, 1, &f, err, sizeof err);
        stats(f, &m, &v);
        CHECK(fabs(m / means[k] - 1) < 0.01 && fabs(v / means[k] - 1) < 0.02,
              "shot noise mean %.1f: measured mean %.3f, variance %.3f", means[k], m, v);
        fa->frame_free(f);
    }
    /* Gain: 4 electrons per count divides the mean and the sigma. */
    s = it_sensor();
    s.read_noise = 40; s.gain = 4; s.bias = 500;
    fa->synth(&s, NULL, 0, 8, 1, &f, err, sizeof err);
    stats(f, &m, &v);
    CHECK(fabs(m - 500) < 0.2 && fabs(sqrt(v) / sqrt(100 + 1.0 / 12) - 1) < 0.02,
          "gain 4 e/count: sigma %.3f counts (10)", sqrt(v));
    fa->frame_free(f);
    /* Dark current: electrons = rate * exposure. */
    s = it_sensor();
    s.read_noise = 0; s.bias = 10; s.dark_current = 2000; s.exposure = 0.05;
    fa->synth(&s, NULL, 0, 9, 1, &f, err, sizeof err);
    stats(f, &m, &v);
    CHECK(fabs(m - 110) < 0.51 && v < 0.3, "dark current without shot noise: %.2f (110)", m);
    fa->frame_free(f);
}

static void quantisation(void)
{
    int bits[3] = {8, 12, 16};
    for (int k = 0; k < 3; k++) {
        im_sensor s = it_sensor();
        s.bits = bits[k];
        s.read_noise = 0;
        im_spot_src sp = it_spot(50, 60);
        sp.peak = 1e6;
        im_frame *f;
        fa->synth(&s, &sp, 1, 1, 1, &f, err, sizeof err);
        unsigned max = 0;
        for (int i = 0; i < f->width * f->height; i++) max = f->px[i] > max ? f->px[i] : max;
        CHECK(f->bits == bits[k] && max == (1u << bits[k]) - 1 && f->px[60 * 640 + 50] == max &&
              f->px[0] == 100, "%d-bit: saturates at %u, background 100", bits[k], max);
        fa->frame_free(f);
    }
    /* Full well clips the electrons before the converter. */
    im_sensor s = it_sensor();
    s.read_noise = 0; s.bias = 0; s.full_well = 5000;
    im_spot_src sp = it_spot(50, 60);
    sp.peak = 1e5;
    im_frame *f;
    fa->synth(&s, &sp, 1, 1, 1, &f, err, sizeof err);
    CHECK(f->px[60 * 640 + 50] == 5000, "full well 5000 e: peak %u", f->px[60 * 640 + 50]);
    fa->frame_free(f);
}

static void binning(void)
{
    /* One hit of footprint 2 px x 2 px centred on a pixel corner: a quarter in each of
     * four pixels; the total is the photon count times the QE. */
    im_sensor s = it_sensor();
    s.width = 40; s.height = 30; s.qe = 0.8; s.gain = 2; s.wavelength = 500e-9; s.exposure = 1;
    const double hc = 6.62607015e-34 * 299792458.0;
    double power = 1e-15, e = power * 500e-9 / hc * 0.8 / 2;      /* counts */
    im_hit h = {{(10.5 - 19.5) * s.pitch, (7.5 - 14.5) * s.pitch, 0}, power, 0};
    im_spot_src sp = {0};
    sp.kind = IM_SPOT_HITS_BIN; sp.hits = &h; sp.nhits = 1; sp.hit_size = 2 * s.pitch;
    double *x = calloc(40 * 30, sizeof *x);
    fa->synth_expected(&s, &sp, 1, x, err, sizeof err);
    double tot = 0;
    for (int i = 0; i < 40 * 30; i++) tot += x[i];
    CHECK(fabs(tot / e - 1) < 1e-12, "binned: total %.6g counts = photons x QE / gain %.6g", tot, e);
    CHECK(fabs(x[7 * 40 + 10] / (e / 4) - 1) < 1e-12 && fabs(x[8 * 40 + 11] / (e / 4) - 1) < 1e-12 &&
          fabs(x[7 * 40 + 11] / (e / 4) - 1) < 1e-12 && x[7 * 40 + 9] == 0,
          "2x2 px footprint on a corner: a quarter in each of the four pixels");
    /* A third-pixel shift: exact overlaps 1/6, 1/2, 1/3 along x. */
    h.p[0] = (10.0 + 1.0 / 3 - 19.5) * s.pitch;
    h.p[1] = (7.0 - 14.5) * s.pitch;
    sp.hit_size = 1.5 * s.pitch;
    fa->synth_expected(&s, &sp, 1, x, err, sizeof err);
    /* x footprint [9.5833, 11.0833]: pixel 9 gets 0.0833+..., pixel 10 one whole, 11 0.5833 */
    /* x: [9.5833, 11.0833] -> pixel 10 gets 0.9167, pixel 11 0.5833; y: [6.25, 7.75] ->
     * pixels 6, 7, 8 get 0.25, 1, 0.25 (all over the side 1.5) */
    double a10 = (10.5 - (10 + 1.0 / 3 - 0.75)) / 1.5, a11 = ((10 + 1.0 / 3 + 0.75) - 10.5) / 1.5;
    CHECK(x[7 * 40 + 9] == 0 && fabs(x[7 * 40 + 10] - e * a10 / 1.5) < 1e-9 * e &&
          fabs(x[7 * 40 + 11] - e * a11 / 1.5) < 1e-9 * e &&
          fabs(x[6 * 40 + 11] - e * a11 * 0.25 / 1.5) < 1e-9 * e,
          "1.5 px footprint at a third of a pixel: exact area overlaps %.4f %.4f", a10, a11);
    /* Off the sensor: nothing. */
    h.p[0] = 1e3;
    fa->synth_expected(&s, &sp, 1, x, err, sizeof err);
    tot = 0;
    for (int i = 0; i < 40 * 30; i++) tot += x[i];
    CHECK(tot == 0, "a hit beyond the sensor adds nothing");
    /* Gaussian splat: the expected image's moments are the beam's. */
    s.width = 200; s.height = 200;
    x = realloc(x, sizeof *x * 200 * 200);
    h.p[0] = 0.3 * s.pitch; h.p[1] = -0.2 * s.pitch; h.path = 0;
    sp.kind = IM_SPOT_HITS_GAUSS; sp.waist = 10 * s.pitch; sp.beam_lambda = 500e-6;
    fa->synth_expected(&s, &sp, 1, x, err, sizeof err);
    double m0 = 0, mx = 0, mxx = 0;
    for (int j = 0; j < 200; j++)
        for (int i = 0; i < 200; i++) { double v = x[j * 200 + i]; m0 += v; mx += v * i; mxx += v * i * i; }
    mx /= m0;
    double w = 2 * sqrt(mxx / m0 - mx * mx - 1.0 / 12);
    CHECK(fabs(m0 / e - 1) < 1e-6 && fabs(mx - 99.8) < 1e-6 && fabs(w - 10) < 1e-3,
          "Gaussian splat: power kept (%.8f), centre %.6f (99.8), 1/e^2 radius %.5f px (10)",
          m0 / e, mx, w);
    free(x);
}

static void analytic(void)
{
    im_sensor s = it_sensor();
    im_spot_src sp = it_spot(100.3, 80.6);
    double *x = calloc(640 * 480, sizeof *x), tot = 0;
    sp.integrate = 1;
    fa->synth_expected(&s, &sp, 1, x, err, sizeof err);
    for (int i = 0; i < 640 * 480; i++) tot += x[i];
    CHECK(fabs(tot / (IT_AMP * M_PI * 9 / 2) - 1) < 1e-9, "integrated analytic spot: volume "
          "%.4f = peak pi w^2 / 2", tot);
    sp.integrate = 0;
    fa->synth_expected(&s, &sp, 1, x, err, sizeof err);
    CHECK(fabs(x[81 * 640 + 100] - IT_AMP * exp(-2 * (0.09 + 0.16) / 9)) < 1e-9,
          "sampled analytic spot: the profile at pixel centres");
    free(x);
    im_frame *f = NULL;
    s.width = 0;
    CHECK(fa->synth(&s, &sp, 1, 1, 1, &f, err, sizeof err) == IM_EINVAL && !f,
          "zero-size sensor refused: %s", err);
    s = it_sensor();
    s.bits = 10;
    CHECK(fa->synth(&s, &sp, 1, 1, 1, &f, err, sizeof err) == IM_EINVAL, "10-bit refused: %s", err);
    s = it_sensor();
    sp.w = 0;
    CHECK(fa->synth(&s, &sp, 1, 1, 1, &f, err, sizeof err) == IM_EINVAL, "zero width refused: %s", err);
}

/* ---- files ---------------------------------------------------------------------- */
static void put(const char *path, const void *b, size_t n)
{
    FILE *o = fopen(path, "wb");
    fwrite(b, 1, n, o);
    fclose(o);
}
static size_t get(const char *path, unsigned char **b)
{
    FILE *i = fopen(path, "rb");
    if (!i) return 0;
    fseek(i, 0, SEEK_END);
    long n = ftell(i);
    fseek(i, 0, SEEK_SET);
    *b = malloc((size_t)n + 1);
    size_t r = fread(*b, 1, (size_t)n, i);
    fclose(i);
    return r;
}
static uint32_t crc(const unsigned char *p, size_t n)
{
    uint32_t c = 0xffffffffu;
    while (n--) {
        c ^= *p++;
        for (int k = 0; k < 8; k++) c = c & 1 ? 0xedb88320u ^ (c >> 1) : c >> 1;
    }
    return ~c;
}
static void be(unsigned char *p, uint32_t v) { p[0] = v >> 24; p[1] = v >> 16; p[2] = v >> 8; p[3] = v; }

/* A minimal uncompressed grey TIFF (little endian) with the given sample format. */
static size_t tiff(unsigned char *b, int w, int h, int bits, int fmt, const void *data)
{
    int bps = bits / 8, n = 10;
    size_t img = (size_t)w * h * bps, ifd = 8 + img;
    memset(b, 0, 8 + img + 2 + 12 * n + 4);
    b[0] = 'I'; b[1] = 'I'; b[2] = 42;
    b[4] = ifd & 0xff; b[5] = (ifd >> 8) & 0xff; b[6] = (ifd >> 16) & 0xff;
    memcpy(b + 8, data, img);
    unsigned char *p = b + ifd;
    p[0] = (unsigned char)n;
    p += 2;
    unsigned tags[10][3] = {{256, 3, (unsigned)w}, {257, 3, (unsigned)h}, {258, 3, (unsigned)bits},
                            {259, 3, 1}, {262, 3, 1}, {273, 4, 8}, {277, 3, 1},
                            {278, 3, (unsigned)h}, {279, 4, (unsigned)img}, {339, 3, (unsigned)fmt}};
    for (int k = 0; k < n; k++, p += 12) {
        p[0] = tags[k][0] & 0xff; p[1] = tags[k][0] >> 8;
        p[2] = (unsigned char)tags[k][1];
        p[4] = 1;
        p[8] = tags[k][2] & 0xff; p[9] = (tags[k][2] >> 8) & 0xff;
        p[10] = (tags[k][2] >> 16) & 0xff; p[11] = (tags[k][2] >> 24) & 0xff;
    }
    return ifd + 2 + 12 * n + 4;
}

static int rejects(const char *path, const char *what)
{
    im_frame *f = (im_frame *)1;
    err[0] = 0;
    int rc = fa->read(path, &f, NULL, err, sizeof err);
    int named = strstr(err, path) != NULL;
    CHECK(rc < 0 && f == NULL && named, "%s refused, naming the file: %s", what, err);
    return rc;
}

static int no_parts(void)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    int n = 0;
    while ((e = readdir(d))) n += strstr(e->d_name, ".part") != NULL;
    closedir(d);
    return n == 0;
}

static void files(void)
{
    im_sensor s = it_sensor();
    im_spot_src sp = it_spot(30.2, 40.7);
    im_frame *f, *g;
    s.width = 64; s.height = 48;
    fa->synth(&s, &sp, 1, 3, 1, &f, err, sizeof err);
    const char *names[3] = {"a.png", "a.tif", "a.raw"};
    for (int k = 0; k < 3; k++) {
        int rc = fa->write(f, path_of(names[k]), err, sizeof err);
        g = NULL;
        if (k < 2) fa->read(path_of(names[k]), &g, NULL, err, sizeof err);
        else fa->read_raw(path_of(names[k]), 64, 48, 16, &g, err, sizeof err);
        CHECK(rc == 0 && same(f, g) && g->bits == 16, "16-bit %s round trip", names[k]);
        fa->frame_free(g);
    }
    CHECK(no_parts(), "no temporary files left after writing");
    /* 8-bit. */
    im_sensor s8 = s;
    s8.bits = 8; s8.bias = 20; s8.read_noise = 3;
    im_frame *f8;
    fa->synth(&s8, &sp, 1, 3, 1, &f8, err, sizeof err);
    fa->write(f8, path_of("b.png"), err, sizeof err);
    fa->read(path_of("b.png"), &g, NULL, err, sizeof err);
    CHECK(same(f8, g) && g->bits == 8, "8-bit PNG round trip");
    fa->frame_free(g);
    /* A TIFF from another writer (hand-made, uncompressed 16-bit). */
    unsigned char *buf = malloc(1 << 20);
    size_t n = tiff(buf, 64, 48, 16, 1, f->px);
    put(path_of("hand.tif"), buf, n);
    g = NULL;
    fa->read(path_of("hand.tif"), &g, NULL, err, sizeof err);
    CHECK(same(f, g), "hand-made 16-bit TIFF read");
    fa->frame_free(g);
    /* Wrong depth: 32-bit float samples. */
    float *fl = calloc(64 * 48, sizeof *fl);
    n = tiff(buf, 64, 48, 32, 3, fl);
    put(path_of("float.tif"), buf, n);
    rejects(path_of("float.tif"), "32-bit float TIFF");
    free(fl);
    /* The fuzzer's TIFF: 58892 x 9993 LZW pixels stated in 270 bytes (libtiff spent 6 s
       filling them): refused from its header, before the decoder allocates. */
    if (rejects("tests/imaging/fuzz-corpus/tiff-huge-lzw.tif", "a 270-byte TIFF stating "
                "588 Mpixel") < 0)
        CHECK(strstr(err, "more than") != NULL, "... as more pixels than a frame may hold");
    /* Truncated PNG. */
    unsigned char *png = NULL;
    size_t pn = get(path_of("a.png"), &png);
    put(path_of("trunc.png"), png, pn / 2);
    rejects(path_of("trunc.png"), "PNG cut in half");
    /* Lying PNG: IHDR says 640x480, the data hold 64x48. */
    unsigned char *lie = malloc(pn);
    memcpy(lie, png, pn);
    be(lie + 16, 640); be(lie + 20, 480);
    be(lie + 29, crc(lie + 12, 17));
    put(path_of("lie.png"), lie, pn);
    rejects(path_of("lie.png"), "PNG whose header states 640x480 over 64x48 of data");
    /* Zero size. */
    memcpy(lie, png, pn);
    be(lie + 16, 0);
    be(lie + 29, crc(lie + 12, 17));
    put(path_of("zero.png"), lie, pn);
    rejects(path_of("zero.png"), "0x48 PNG");
    CHECK(strstr(err, "zero-size") != NULL, "... said to be zero-size");
    /* Bad CRC. */
    memcpy(lie, png, pn);
    lie[40] ^= 0x55;
    put(path_of("crc.png"), lie, pn);
    rejects(path_of("crc.png"), "PNG with a damaged chunk");
    put(path_of("empty.png"), "", 0);
    rejects(path_of("empty.png"), "empty file");
    put(path_of("text.png"), "hello, world\n", 13);
    rejects(path_of("text.png"), "text file named .png");
    rejects(path_of("missing.png"), "missing file");
    rejects(dir, "a directory");
    /* Raw: wrong size, too many bits, zero size. */
    g = (im_frame *)1;
    CHECK(fa->read_raw(path_of("a.raw"), 640, 480, 16, &g, err, sizeof err) == IM_EFORMAT && !g &&
          strstr(err, "614400") && strstr(err, "6144 "), "raw stated 640x480 over 64x48: %s", err);
    CHECK(fa->read_raw(path_of("a.raw"), 64, 48, 8, &g, err, sizeof err) == IM_EFORMAT,
          "16-bit data read as 8-bit raw: %s", err);
    CHECK(fa->read_raw(path_of("a.raw"), 0, 48, 16, &g, err, sizeof err) == IM_EINVAL,
          "zero-width raw: %s", err);
    /* Writing: nowhere to write, over a directory, unknown extension; nothing left. */
    CHECK(fa->write(f, path_of("no/such/dir/x.png"), err, sizeof err) == IM_EIO,
          "unwritable path: %s", err);
    mkdir(path_of("d.png"), 0755);
    CHECK(fa->write(f, path_of("d.png"), err, sizeof err) == IM_EIO, "over a directory: %s", err);
    CHECK(fa->write(f, path_of("x.jpg"), err, sizeof err) == IM_EINVAL, "lossy .jpg refused: %s", err);
    CHECK(no_parts() && access(path_of("x.jpg"), F_OK) != 0, "no half-written file left");
    /* The writer replaces a file only when complete: the old one stays until rename. */
    fa->write(f8, path_of("a.png"), err, sizeof err);
    fa->read(path_of("a.png"), &g, NULL, err, sizeof err);
    CHECK(same(f8, g), "rewriting a.png replaces it whole");
    fa->frame_free(g);
    free(png); free(lie); free(buf);
    fa->frame_free(f);
    fa->frame_free(f8);
}

static void sources(void)
{
    im_sensor s = it_sensor();
    s.width = 32; s.height = 24;
    im_frame *fr[3];
    char name[64];
    for (int k = 0; k < 3; k++) {
        im_spot_src sp = it_spot(10 + k, 12);
        fa->synth(&s, &sp, 1, (uint64_t)k, 1, &fr[k], err, sizeof err);
        snprintf(name, sizeof name, "seq%04d.png", k + 1);
        fa->write(fr[k], path_of(name), err, sizeof err);
    }
    im_source *src;
    int rc = fa->source_open(path_of("seq%04d.png"), 1, 0, &src, err, sizeof err), n = 0, ok = 1;
    im_frame *g;
    if (rc == 0)
        while ((rc = fa->source_next(src, &g, err, sizeof err)) == 1) {
        ok &= n < 3 && same(g, fr[n]);
        n++;
        fa->frame_free(g);
    }
    CHECK(rc == 0 && n == 3 && ok, "sequence seq%%04d.png: 3 frames in order, then the end");
    fa->source_close(src);
    CHECK(fa->source_open(path_of("seq%04d.png"), 7, 0, &src, err, sizeof err) < 0 &&
          strstr(err, "seq0007.png"), "sequence without its first frame: %s", err);
    CHECK(fa->source_open(path_of("seq%s.png"), 1, 0, &src, err, sizeof err) == IM_EINVAL,
          "pattern with %%s refused: %s", err);
    CHECK(fa->source_open(path_of("seq%d%d.png"), 1, 0, &src, err, sizeof err) == IM_EINVAL,
          "pattern with two conversions refused");
    CHECK(!fa->camera_loaded(), "files and sequences do not load lensmat-camera.so");
    /* Video: written by the camera module's writer, read back frame by frame. */
    char lib[1024];
    snprintf(lib, sizeof lib, "%s/lensmat-camera.so", getenv("IM_LIBDIR") ? getenv("IM_LIBDIR") : "build/lib");
    void *h = dlopen(lib, RTLD_NOW | RTLD_LOCAL);
    im_cam_get_fn get = h ? (im_cam_get_fn)dlsym(h, IM_CAMERA_SYMBOL) : NULL;
    const im_cam_api *cam = get ? get(IM_CAMERA_ABI) : NULL;
    CHECK(cam != NULL, "camera module loads (%s)", lib);
    if (cam) {
        const uint16_t *px[3] = {fr[0]->px, fr[1]->px, fr[2]->px};
        int w = cam->write_video(path_of("v.avi"), px, 3, 32, 24, 16, 10, err, sizeof err);
        n = 0;
        rc = w ? w : fa->source_open(path_of("v.avi"), 0, 0, &src, err, sizeof err);
        if (rc == 0)
            while ((rc = fa->source_next(src, &g, err, sizeof err)) == 1) {
            n++;
            ok = g->width == 32 && g->height == 24;
            fa->frame_free(g);
        }
        CHECK(w == 0 && rc == 0 && n == 3 && ok, "MJPG video: 3 frames of 32x24 (%s)", rc ? err : "");
        if (rc == 0) fa->source_close(src);
        CHECK(fa->camera_loaded(), "a video loads lensmat-camera.so");
    }
    put(path_of("bad.avi"), "RIFF....AVI junk", 16);
    rc = fa->source_open(path_of("bad.avi"), 0, 0, &src, err, sizeof err);
    if (rc == 0) {
        rc = fa->source_next(src, &g, err, sizeof err);
        fa->source_close(src);
        if (rc == 1) fa->frame_free(g);
    }
    CHECK(rc < 0 && strstr(err, "bad.avi"), "corrupt video refused: %s", err);
    CHECK(fa->source_open("cam:57", 0, 0, &src, err, sizeof err) < 0 && strstr(err, "cam:57"),
          "absent camera: %s", err);
    CHECK(fa->source_open("/dev/video99", 0, 0, &src, err, sizeof err) < 0 &&
          strstr(err, "/dev/video99"), "absent camera device: %s", err);
    CHECK(fa->source_open("cam:x", 0, 0, &src, err, sizeof err) == IM_EINVAL, "cam:x refused");
    for (int k = 0; k < 3; k++) fa->frame_free(fr[k]);
}

int main(int argc, char **argv)
{
    fa = it_api();
    dir = argc > 1 ? argv[1] : "/tmp";
    determinism();
    determinism_dark();
    noise_model();
    dark_law();
    pixel_moments();
    quantisation();
    binning();
    analytic();
    files();
    sources();
    return it_failed != 0;
}
