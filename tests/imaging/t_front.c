/* t_front.c -- the imaging front end of a topographer (issue 19 item 7) against frames
 * from an INDEPENDENT forward model written here (not im_synth.c): a Gaussian spot
 * A exp(-2 r^2 / w^2) sampled at pixel centres, Poisson electrons at a known gain,
 * Gaussian read noise (Box-Muller on SplitMix64), rounding, and a clip at the level of
 * the camera's ADC or full well, stored in a frame of the file's width.  Checks:
 *  - saturation narrower than the file: 12-bit data in a 16-bit frame (plain and
 *    MSB-aligned) and a full well below the ADC's range are found and the spots
 *    flagged; unsaturated spots just under the level and a noiseless spot on a pixel
 *    corner are not; with the file's level the same frames pass unflagged with a
 *    sigma too small for their scatter (what the detection is for);
 *  - detection by the spot's integrated SNR: the probability of detection against
 *    amplitude matches the matched filter's closed form Phi(d - threshold), d the
 *    filter's SNR computed here; false spots on noise-only frames against the
 *    Euler-characteristic expectation; "none" always quotes a best SNR at or below
 *    the threshold and a spot always one above;
 *  - the camera gain from photon transfer (src/topo/tp_shot.c, compiled in) on frames
 *    of known gain whose background noise is clipped at zero.
 * Prints PASS/FAIL lines and, for scripts/bench_imaging.sh, BENCH lines. */
#include "it.h"
#include "topo/tp_shot.c"

static const im_frame_api *fa;
static char err[256];

/* ---- the independent forward model ----------------------------------------------- */
typedef struct cam {
    int width, height, bits;   /* the file */
    double bias, read, gain;   /* counts, counts rms, e-/count (0: no shot noise) */
    double clip;               /* the camera's clip level in counts (ADC or full well) */
    int shift;                 /* the samples stored << shift (MSB-aligned) */
} cam;
typedef struct spot { double x, y, a, w; } spot;

static uint64_t sm_state;
static double u01(void)
{
    uint64_t z = (sm_state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return ((double)((z ^ (z >> 31)) >> 11) + 0.5) * 0x1.0p-53;
}
static double gauss(void)
{
    return sqrt(-2 * log(u01())) * cos(2 * M_PI * u01());
}
static double poisson(double m)
{
    if (m <= 0) return 0;
    if (m > 50) return floor(m + sqrt(m) * gauss() + 0.5);
    double L = exp(-m), p = 1;
    int k = -1;
    do { k++; p *= u01(); } while (p > L);
    return k;
}

static im_frame *render(const cam *c, const spot *s, int ns, uint64_t seed)
{
    im_frame *f = fa->frame_new(c->width, c->height, c->bits);
    if (!f) { printf("FAIL no frame\n"); exit(1); }
    sm_state = seed * 0x2545f4914f6cdd1dull + 1;
    double top = (double)((1u << c->bits) - 1);
    for (int j = 0; j < c->height; j++)
        for (int i = 0; i < c->width; i++) {
            double sig = 0;
            for (int k = 0; k < ns; k++) {
                double dx = i - s[k].x, dy = j - s[k].y;
                sig += s[k].a * exp(-2 * (dx * dx + dy * dy) / (s[k].w * s[k].w));
            }
            if (c->gain > 0) sig = poisson(sig * c->gain) / c->gain;
            double v = floor(c->bias + sig + c->read * gauss() + 0.5);
            if (v < 0) v = 0;
            if (c->clip > 0 && v > c->clip) v = c->clip;
            v = ldexp(v, c->shift);
            if (v > top) v = top;
            f->px[(size_t)j * c->width + i] = (uint16_t)v;
        }
    return f;
}

static double Phi(double z) { return 0.5 * erfc(-z / sqrt(2)); }

/* The matched filter's SNR for a spot of peak a centred on a pixel, with the
 * background unknown (the kernel less its mean over the square of half-width
 * ceil(2 w)): d = (a / sigma) sqrt(sum (g - gbar)^2). */
static double mf_d(double a, double w, double sigma)
{
    int R = (int)ceil(2 * w);
    double s1 = 0, s2 = 0, n = (2.0 * R + 1) * (2 * R + 1);
    for (int j = -R; j <= R; j++)
        for (int i = -R; i <= R; i++) {
            double g = exp(-2 * (i * i + j * j) / (w * w));
            s1 += g;
            s2 += g * g;
        }
    return a / sigma * sqrt(s2 - s1 * s1 / n);
}

/* ---- saturation ------------------------------------------------------------------ */
static void saturation(void)
{
    im_centroider *cz = fa->centroider_new();
    /* 12-bit data in a 16-bit frame: 63 spots at peaks 1.5-6 x the ADC's 4095 */
    cam c12 = {128, 128, 16, 100, 20, 1, 4095, 0};
    cam c12m = c12;
    c12m.shift = 4;                       /* the same, MSB-aligned: 65520 */
    cam cfw = {128, 128, 12, 100, 20, 1, 3000, 0};   /* full well at 3000 counts */
    const cam *cams[3] = {&c12, &c12m, &cfw};
    const char *name[3] = {"12-bit data in a 16-bit frame", "the same MSB-aligned (<< 4)",
                           "a full well at 3000 counts in a 12-bit frame"};
    const double level[3] = {4095, 65520, 3000};
    for (int m = 0; m < 3; m++) {
        int n = 63, flagged = 0, at_level = 0;
        for (int k = 0; k < n; k++) {
            spot s = {60 + 8 * u01(), 60 + 8 * u01(), level[m] / (1 << cams[m]->shift) *
                                                          (1.5 + 4.5 * k / n), 3};
            im_frame *f = render(cams[m], &s, 1, 100 + (uint64_t)k);
            im_spot o[4];
            im_centroid_result r;
            if (!fa->centroid(cz, f, NULL, o, 4, &r, err, sizeof err) && r.nspots >= 1) {
                flagged += (o[0].flags & IM_SF_SATURATED) != 0;
                at_level += r.saturation == level[m] && r.sat_source == IM_SAT_PILEUP;
            }
            fa->frame_free(f);
        }
        CHECK(flagged == n && at_level == n, "%s: %d of %d saturated spots flagged, the "
              "level %.0f found in %d", name[m], flagged, n, level[m], at_level);
    }
    /* unsaturated: peaks 0.6-0.99 of the level, shot noise at 1 e-/count */
    c12.gain = 1;
    int n = 63, flagged = 0;
    for (int k = 0; k < n; k++) {
        spot s = {60 + 8 * u01(), 60 + 8 * u01(), (4095 - 100) * (0.6 + 0.39 * k / n), 3};
        im_frame *f = render(&c12, &s, 1, 300 + (uint64_t)k);
        im_spot o[4];
        im_centroid_result r;
        if (!fa->centroid(cz, f, NULL, o, 4, &r, err, sizeof err) && r.nspots >= 1)
            flagged += (o[0].flags & IM_SF_SATURATED) != 0 || r.sat_source != IM_SAT_FULL_SCALE;
        fa->frame_free(f);
    }
    CHECK(flagged == 0, "unsaturated spots up to 0.99 of 4095 in a 16-bit frame: %d of %d "
          "flagged", flagged, n);
    /* noiseless, centred on a pixel corner: the top four pixels tie */
    cam quiet = {64, 64, 16, 100, 0, 0, 0, 0};
    spot sc = {31.5, 31.5, 1000, 3};
    im_frame *f = render(&quiet, &sc, 1, 1);
    im_spot o[4];
    im_centroid_result r;
    fa->centroid(cz, f, NULL, o, 4, &r, err, sizeof err);
    CHECK(r.nspots == 1 && !(o[0].flags & IM_SF_SATURATED) && r.sat_source == IM_SAT_FULL_SCALE,
          "a noiseless spot on a pixel corner (four tied top pixels): not saturated");
    fa->frame_free(f);
    /* between two pixels, its top two exactly 1023 (2^10 - 1) in a 16-bit frame: a tie
       at a value that is some ADC's full scale is not a clip (a frame of t_91's scan
       was rejected so) */
    spot st = {31.5, 31, 923 / exp(-2 * 0.25 / 9), 3};
    f = render(&quiet, &st, 1, 1);
    int ntop = 0;
    for (size_t i = 0; i < (size_t)64 * 64; i++) ntop += f->px[i] == 1023;
    fa->centroid(cz, f, NULL, o, 4, &r, err, sizeof err);
    CHECK(ntop == 2 && r.nspots == 1 && !(o[0].flags & IM_SF_SATURATED),
          "an unclipped spot whose top two pixels are exactly 1023 in a 16-bit frame: not "
          "saturated (%d pixels at 1023)", ntop);
    fa->frame_free(f);

    /* What the level is for: the same 12-bit frames told the file's level (65535)
       pass unflagged, and their reported sigma is smaller than their scatter. */
    cam c = {128, 128, 16, 100, 20, 1, 4095, 0};
    double e2 = 0, s2 = 0, e2d = 0, s2d = 0, chi = 0, chid = 0;
    int m0 = 0, md = 0, unfl = 0;
    n = 63;
    for (int k = 0; k < n; k++) {
        spot s = {60 + 8 * u01(), 60 + 8 * u01(), 4095 * 2.5, 3};
        im_frame *g = render(&c, &s, 1, 500 + (uint64_t)k);
        im_centroid_opt opt = {0};
        opt.saturation = 65535;
        opt.gain = 1;
        if (!fa->centroid(cz, g, &opt, o, 4, &r, err, sizeof err) && r.nspots == 1) {
            unfl += !(o[0].flags & IM_SF_SATURATED);
            e2 += (o[0].x - s.x) * (o[0].x - s.x) + (o[0].y - s.y) * (o[0].y - s.y);
            s2 += o[0].sx * o[0].sx + o[0].sy * o[0].sy;
            chi += o[0].chi2 / n;
            m0++;
        }
        opt.saturation = 0;
        if (!fa->centroid(cz, g, &opt, o, 4, &r, err, sizeof err) && r.nspots == 1 &&
            (o[0].flags & IM_SF_SATURATED)) {
            e2d += (o[0].x - s.x) * (o[0].x - s.x) + (o[0].y - s.y) * (o[0].y - s.y);
            s2d += o[0].sx * o[0].sx + o[0].sy * o[0].sy;
            chid += o[0].chi2 / n;
            md++;
        }
        fa->frame_free(g);
    }
    double ratio = m0 ? sqrt(e2 / s2) : 0, ratio_d = md ? sqrt(e2d / s2d) : 0;
    CHECK(unfl == n && chi > 3 * chid, "told 65535: %d of %d saturated spots unflagged, their "
          "plateau fitted as a Gaussian (chi2/dof %.1f; %.2f with the level found), scatter "
          "%.2f x the sigma they report", unfl, n, chi, chid, ratio);
    CHECK(md == n && ratio_d < 1.3, "the level found: all %d flagged, the wings' fit scatter "
          "%.2f x its formal sigma (not a confident one: the spots are left out downstream)",
          md, ratio_d);
    printf("BENCH imaging_sat_flagged %.3f fraction\n", (double)md / n);
    fa->centroider_free(cz);
}

/* ---- detection ------------------------------------------------------------------- */
static void detection(void)
{
    im_centroider *cz = fa->centroider_new();
    const double sigma = 20, w = 3, thr = 5;
    cam c = {96, 96, 16, 200, sigma, 0, 0, 0};
    double dpt[6] = {-1.5, -0.75, 0, 0.75, 1.5, 2.5};
    int n = 300, worst_k = 0, incons = 0;
    double worst = 0;
    for (int q = 0; q < 6; q++) {
        double d = thr + dpt[q], a = d / mf_d(1, w, sigma);
        int hit = 0;
        for (int k = 0; k < n; k++) {
            spot s = {48, 48, a, w};      /* on a pixel centre: d is the filter's mean */
            im_frame *f = render(&c, &s, 1, 10000 * (uint64_t)(q + 1) + (uint64_t)k);
            im_spot o[4];
            im_centroid_result r;
            im_centroid_opt opt = {0};
            opt.threshold = thr;
            opt.spot_w = w;
            if (fa->centroid(cz, f, &opt, o, 4, &r, err, sizeof err)) {
                printf("FAIL centroid: %s\n", err);
                break;
            }
            for (int i = 0; i < r.nspots; i++)
                if (hypot(o[i].x - s.x, o[i].y - s.y) < 3) { hit++; break; }
            incons += r.outcome == IM_FOUND_NONE ? !(r.best_snr <= thr) : !(r.best_snr > thr);
            fa->frame_free(f);
        }
        double p = (double)hit / n, pe = Phi(d - thr);
        double se = sqrt(pe * (1 - pe) / n + 1e-4);
        double z = fabs(p - pe) / se;
        printf("  d = %.2f (A = %.2f sigma): detected %.3f, closed form %.3f\n", d, a / sigma,
               p, pe);
        if (z > worst) { worst = z; worst_k = q; }
    }
    CHECK(worst < 3.5 && incons == 0, "detection probability against amplitude within 3.5 "
          "standard errors of Phi(d - threshold) at 6 amplitudes x %d frames (worst %.1f at d "
          "= %.2f); \"none\" always below the threshold, a spot always above (%d not)", n,
          worst, thr + dpt[worst_k], incons);

    /* the case: A = 5 sigma spots at threshold 5, uniform sub-pixel positions */
    int found = 0, m = 204;
    for (int k = 0; k < m; k++) {
        spot s = {40 + 16 * u01(), 40 + 16 * u01(), 5 * sigma, w};
        im_frame *f = render(&c, &s, 1, 77000 + (uint64_t)k);
        im_spot o[4];
        im_centroid_result r;
        im_centroid_opt opt = {0};
        opt.threshold = 5;
        if (!fa->centroid(cz, f, &opt, o, 4, &r, err, sizeof err) && r.nspots >= 1 &&
            hypot(o[0].x - s.x, o[0].y - s.y) < 1)
            found++;
        fa->frame_free(f);
    }
    CHECK(found >= m - 2, "A = 5 sigma, w = 3 px, threshold 5: %d of %d spots found (their "
          "integrated SNR is %.1f)", found, m, mf_d(5 * sigma, w, sigma));
    printf("BENCH imaging_detect_snr %.3f fraction\n", (double)found / m);

    /* false spots on noise-only frames at the default threshold and at 4.5 */
    cam big = {320, 240, 16, 300, sigma, 0, 0, 0};
    int nf = 150, fa45 = 0, fadef = 0;
    double udef = 0;
    for (int k = 0; k < nf; k++) {
        im_frame *f = render(&big, NULL, 0, 90000 + (uint64_t)k);
        im_spot o[8];
        im_centroid_result r;
        im_centroid_opt opt = {0};
        fa->centroid(cz, f, &opt, o, 8, &r, err, sizeof err);
        fadef += r.ndetected;
        udef = r.threshold;
        opt.threshold = 4.5;
        fa->centroid(cz, f, &opt, o, 8, &r, err, sizeof err);
        fa45 += r.ndetected;
        fa->frame_free(f);
    }
    double area = 320.0 * 240, lam = 2 / (w * w), k0 = area * lam / pow(2 * M_PI, 1.5);
    double e45 = nf * k0 * 4.5 * exp(-4.5 * 4.5 / 2), edef = nf * k0 * udef * exp(-udef * udef / 2);
    CHECK(fa45 > 0.6 * e45 && fa45 < 1.5 * e45 && fadef <= 3,
          "noise only, %d frames 320x240: %d false spots at threshold 4.5 (expected %.1f), %d "
          "at the default %.2f (expected %.2f)", nf, fa45, e45, fadef, udef, edef);
    fa->centroider_free(cz);
}

/* ---- the camera gain ------------------------------------------------------------- */
/* n spots of peak 1000 counts at gain g, bias 100 counts, read noise 50 counts (2.3 %
 * of the background clipped at 0), into the photon transfer sums *all as well. */
static double gain_of(double g, int n, uint64_t seed, double *se, tp_shot *all)
{
    im_centroider *cz = fa->centroider_new();
    cam c = {64, 64, 16, 100, 50, g, 0, 0};
    tp_shot sh;
    memset(&sh, 0, sizeof sh);
    for (int k = 0; k < n; k++) {
        spot s = {28 + 8 * u01(), 28 + 8 * u01(), 1000, 3};
        im_frame *f = render(&c, &s, 1, seed + (uint64_t)k);
        im_spot o[2];
        im_centroid_result r;
        if (!fa->centroid(cz, f, NULL, o, 2, &r, err, sizeof err) && r.outcome == IM_FOUND_ONE &&
            !o[0].flags) {
            tp_shot_add(&sh, f, o[0].x, o[0].y, o[0].amp, o[0].w, o[0].bg, r.noise);
            if (all) tp_shot_add(all, f, o[0].x, o[0].y, o[0].amp, o[0].w, o[0].bg, r.noise);
        }
        fa->frame_free(f);
    }
    fa->centroider_free(cz);
    *se = tp_shot_gain_se(&sh);
    return tp_shot_gain(&sh);
}
static void camera_gain(void)
{
    tp_shot all;
    memset(&all, 0, sizeof all);
    /* the spread over independent scans of 300 spots against the error each states */
    double m = 0, q = 0, sem = 0;
    int nr = 10;
    for (int k = 0; k < nr; k++) {
        double se, gk = gain_of(1, 300, (uint64_t)(3 + k) << 20, &se, &all);
        m += gk / nr;
        q += gk * gk / nr;
        sem += se / nr;
    }
    double sd = sqrt(fmax(0, q - m * m) * nr / (nr - 1));
    CHECK(sd < 2 * sem && sd > 0.5 * sem, "%d scans of 300 spots at 1 e-/count: gains %.3f "
          "on average, spread %.3f, each stating %.3f", nr, m, sd, sem);
    double g1 = tp_shot_gain(&all), se1 = tp_shot_gain_se(&all);
    CHECK(fabs(g1 - 1) < 3 * se1 && se1 < 0.05, "photon transfer over the %d spots (1 e-/count, "
          "the background clipped at 0): gain %.3f +- %.3f", all.n, g1, se1);
    double se4, g4 = gain_of(4, 2000, 2 << 20, &se4, NULL);
    CHECK(fabs(g4 - 4) < 3 * se4 && se4 < 1, "2000 spots at 4 e-/count (shot noise a tenth of "
          "the read noise): gain %.2f +- %.2f", g4, se4);
    printf("BENCH imaging_gain_bias %.3f ratio\n", g1);
}

/* Files for tests/t_73_front.sh: a 16-bit PNG holding a 12-bit camera's frame with a
 * saturated spot, and one with a spot found only by its integrated SNR (peak 2.2
 * sigma, matched-filter SNR 5.4 against the threshold 5). */
static void files(const char *dir)
{
    char name[4096];
    cam c12 = {128, 96, 16, 100, 20, 1, 4095, 0};
    spot s = {64.3, 47.6, 9000, 3};
    im_frame *f = render(&c12, &s, 1, 4242);
    snprintf(name, sizeof name, "%s/sat12.png", dir);
    CHECK(!fa->write(f, name, err, sizeof err), "wrote %s", name);
    fa->frame_free(f);
    cam faint = {128, 96, 16, 200, 20, 0, 0, 0};
    spot sf = {70, 40, 2.2 * 20, 3};
    f = render(&faint, &sf, 1, 4343);
    snprintf(name, sizeof name, "%s/faint.png", dir);
    CHECK(!fa->write(f, name, err, sizeof err), "wrote %s", name);
    fa->frame_free(f);
}

/* ---- the screen against the exact statistic everywhere ---------------------------- */
/* T at every pixel by the closed form in imaging.h (written here: the kernel's square
 * clipped to the frame, its mean taken out, sigma known), then the 8-connected regions
 * where T > thr: a spot per region (a region always holds a local maximum, so it is
 * what "a local maximum above the threshold" finds).  Each region's local maxima of T
 * are kept for matching the engine's spots (their snr is T at the maximum reached). */
typedef struct bregion { int nmax; double tmax[8]; int used; } bregion;
static int brute(const im_frame *f, double w, double sigma, double thr, double *T, int *lab,
                 bregion *reg, int maxreg)
{
    int W = f->width, H = f->height, R = (int)ceil(2 * w);
    if (R > 24) R = 24;
    for (int cy = 0; cy < H; cy++)
        for (int cx = 0; cx < W; cx++) {
            double s1 = 0, s0 = 0, s2 = 0, sv = 0, n = 0;
            for (int y = cy - R; y <= cy + R; y++)
                for (int x = cx - R; x <= cx + R; x++) {
                    if (x < 0 || y < 0 || x >= W || y >= H) continue;
                    double g = exp(-2.0 * ((x - cx) * (x - cx) + (y - cy) * (y - cy)) / (w * w));
                    double v = f->px[(size_t)y * W + x];
                    s1 += g * v; s0 += g; s2 += g * g; sv += v; n++;
                }
            double den = s2 - s0 * s0 / n;
            T[(size_t)cy * W + cx] = den > 1e-12 ? (s1 - s0 * sv / n) / (sigma * sqrt(den)) : 0;
        }
    int nreg = 0, *stack = malloc(sizeof(int) * (size_t)W * H);
    for (int i = 0; i < W * H; i++) lab[i] = -1;
    for (int i = 0; i < W * H; i++) {
        if (!(T[i] > thr) || lab[i] >= 0) continue;
        if (nreg == maxreg) { free(stack); return -1; }
        bregion *g = &reg[nreg];
        g->nmax = 0; g->used = 0;
        int sp = 0;
        stack[sp++] = i;
        lab[i] = nreg;
        while (sp) {
            int q = stack[--sp], x = q % W, y = q / W, ismax = 1;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    int xx = x + dx, yy = y + dy, r = yy * W + xx;
                    if ((!dx && !dy) || xx < 0 || yy < 0 || xx >= W || yy >= H) continue;
                    if (T[r] > T[q]) ismax = 0;
                    if (T[r] > thr && lab[r] < 0) { lab[r] = nreg; stack[sp++] = r; }
                }
            if (ismax && g->nmax < 8) g->tmax[g->nmax++] = T[q];
        }
        nreg++;
    }
    free(stack);
    return nreg;
}

static void screen_exhaustive(void)
{
    im_centroider *cz = fa->centroider_new();
    const double sigma = 20, thr = 5, ws[3] = {1.5, 3, 4.5};
    cam c = {96, 72, 16, 200, sigma, 0, 0, 0};
    double *T = malloc(sizeof(double) * 96 * 72);
    int *lab = malloc(sizeof(int) * 96 * 72), n = 360, bad = 0, nbrute = 0, nnear = 0;
    int first_bad = -1, nmiss = 0;
    bregion reg[64];
    for (int k = 0; k < n; k++) {
        double w = ws[k % 3], t = k % 4 == 3 ? 4 : thr;   /* some at 4: more noise peaks */
        int ns = (k / 3) % 4;
        spot s[3];
        for (int i = 0; i < ns && i < 3; i++) {
            double d = thr - 1.5 + 3 * u01();             /* near the threshold */
            s[i] = (spot){4 + 88 * u01(), 4 + 64 * u01(), d / mf_d(1, w, sigma), w};
            nnear += fabs(d - thr) < 0.5;
        }
        im_frame *f = render(&c, s, ns < 3 ? ns : 3, 130000 + (uint64_t)k);
        im_spot o[64];
        im_centroid_result r;
        im_centroid_opt opt = {0};
        opt.threshold = t;
        opt.spot_w = w;
        opt.read_noise = sigma;
        opt.max_spots = 64;
        int nb = brute(f, w, sigma, t, T, lab, reg, 64), ok = nb >= 0, miss = 0;
        if (fa->centroid(cz, f, &opt, o, 64, &r, err, sizeof err)) ok = 0;
        ok = ok && r.nspots == r.ndetected;
        /* every spot the engine found is one region's local maximum, each region once */
        for (int i = 0; ok && i < r.nspots; i++) {
            int hit = 0;
            for (int g = 0; g < nb && !hit; g++)
                for (int m = 0; m < reg[g].nmax; m++)
                    if (!reg[g].used &&
                        fabs(o[i].snr - reg[g].tmax[m]) < 1e-5 * fabs(reg[g].tmax[m]) + 1e-6) {
                        reg[g].used = hit = 1;
                        break;
                    }
            ok = hit;
        }
        for (int g = 0; ok && g < nb; g++) miss += !reg[g].used;
        if (!ok) { if (first_bad < 0) first_bad = k; bad++; }
        if (ok && miss) {
            nmiss += miss;
            printf("  frame %d (w %.1f, threshold %.0f): %d regions, the engine found %d:", k,
                   w, t, nb, r.ndetected);
            for (int g = 0; g < nb; g++)
                printf(" T %.3f%s", reg[g].tmax[0], reg[g].used ? "" : " (missed)");
            printf("\n");
        }
        nbrute += nb > 0 ? nb : 0;
        fa->frame_free(f);
    }
    CHECK(bad == 0, "every spot the screen leads to is a local maximum of the exact "
          "statistic evaluated at every pixel, one per region above threshold, with its T, on "
          "%d frames 96x72, w = 1.5/3/4.5 px, 0-3 spots of SNR 3.5-6.5 (%d within 0.5 of it), "
          "threshold 5 or 4: %d frames not (first %d)", n, nnear, bad, first_bad);
    /* Not asserted (a finding for issue 19: the screen at threshold - 2 is not complete):
       the regions the exhaustive statistic has and the screen never leads to. */
    printf("NOTE the screen missed %d of the %d regions above threshold the exhaustive "
           "statistic finds (listed above)\n", nmiss, nbrute);
    free(T);
    free(lab);
    fa->centroider_free(cz);
}

int main(int argc, char **argv)
{
    fa = it_api();
    if (argc > 1) files(argv[1]);
    saturation();
    detection();
    screen_exhaustive();
    camera_gain();
    return it_failed != 0;
}
