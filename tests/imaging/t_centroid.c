/* t_centroid.c -- laser-spot centroids against the synthetic truth: accuracy near the
 * Cramer-Rao bound, honest uncertainties, and every outcome (none with the best
 * candidate's SNR, one, several sorted by power, saturated, cut by the edge). */
#include <pthread.h>
#include "it.h"

static const im_frame_api *fa;
static char err[256];

static im_frame *frame_of(const im_sensor *s, const im_spot_src *sp, int n, uint64_t seed)
{
    im_frame *f = NULL;
    if (fa->synth(s, sp, n, seed, 1, &f, err, sizeof err)) {
        printf("FAIL synth: %s\n", err);
        exit(1);
    }
    return f;
}

static void accuracy(void)
{
    im_sensor s = it_sensor();
    im_centroider *c = fa->centroider_new();
    double se = 0, sm = 0, sig = 0;
    int n = 200, ok = 0;
    uint64_t z = 777;
    for (int k = 0; k < n; k++) {
        double x = 30 + 580 * it_uniform(&z), y = 30 + 420 * it_uniform(&z);
        im_spot_src sp = it_spot(x, y);
        im_frame *f = frame_of(&s, &sp, 1, 5000 + (uint64_t)k);
        im_spot o[2];
        im_centroid_result r;
        im_centroid_opt opt = {0};
        if (!fa->centroid(c, f, &opt, o, 2, &r, err, sizeof err) && r.outcome == IM_FOUND_ONE &&
            !(o[0].flags & (IM_SF_FIT_FAILED | IM_SF_EDGE | IM_SF_SATURATED))) {
            ok++;
            se += (o[0].x - x) * (o[0].x - x) + (o[0].y - y) * (o[0].y - y);
            sig += 0.5 * (o[0].sx * o[0].sx + o[0].sy * o[0].sy);
        }
        opt.method = IM_CM_MOMENTS_BG;
        if (!fa->centroid(c, f, &opt, o, 2, &r, err, sizeof err) && r.nspots == 1)
            sm += (o[0].x - x) * (o[0].x - x) + (o[0].y - y) * (o[0].y - y);
        fa->frame_free(f);
    }
    double rms = sqrt(se / (2.0 * (ok ? ok : 1))), crb = it_crb();
    double rms_m = sqrt(sm / (2.0 * n)), sx = sqrt(sig / (ok ? ok : 1));
    CHECK(ok == n, "one clean spot found and fitted in each of %d frames (%d)", n, ok);
    CHECK(rms <= 1.15 * crb && rms >= 0.8 * crb,
          "Gaussian fit RMS %.4f px per coordinate within [0.8, 1.15] x CRB %.4f", rms, crb);
    CHECK(fabs(sx / rms - 1) < 0.15, "reported sigma %.4f px matches the scatter %.4f", sx, rms);
    CHECK(rms_m > 1.4 * rms, "the fit beats thresholded background-subtracted moments (%.3f px) by > 1.4x", rms_m);
    fa->centroider_free(c);
}

static void shot_noise_uncertainty(void)
{
    /* Shot noise dominant: gain 2 e/count, bright spot; the noise model in the options. */
    im_sensor s = it_sensor();
    s.shot_noise = 1; s.gain = 2; s.read_noise = 10; s.background = 2e5; s.exposure = 1e-3;
    double se = 0, sig = 0;
    int n = 120, ok = 0;
    uint64_t z = 99;
    for (int k = 0; k < n; k++) {
        double x = 100 + 400 * it_uniform(&z), y = 100 + 280 * it_uniform(&z);
        im_spot_src sp = it_spot(x, y);
        sp.peak = 2000;
        im_frame *f = frame_of(&s, &sp, 1, 90 + (uint64_t)k);
        im_spot o[2];
        im_centroid_result r;
        im_centroid_opt opt = {0};
        opt.gain = 2;
        if (!fa->centroid(NULL, f, &opt, o, 2, &r, err, sizeof err) && r.nspots == 1 &&
            !(o[0].flags & IM_SF_FIT_FAILED)) {
            ok++;
            se += (o[0].x - x) * (o[0].x - x) + (o[0].y - y) * (o[0].y - y);
            sig += 0.5 * (o[0].sx * o[0].sx + o[0].sy * o[0].sy);
        }
        fa->frame_free(f);
    }
    double rms = sqrt(se / (2.0 * ok)), sx = sqrt(sig / ok);
    CHECK(ok == n && fabs(sx / rms - 1) < 0.2,
          "shot-noise frames: reported sigma %.4f px vs scatter %.4f (%d/%d)", sx, rms, ok, n);
}

static void outcomes(void)
{
    im_sensor s = it_sensor();
    im_spot o[8];
    im_centroid_result r;
    im_centroid_opt opt = {0};
    im_frame *f;

    /* No spot at all. */
    f = frame_of(&s, NULL, 0, 1);
    int rc = fa->centroid(NULL, f, &opt, o, 8, &r, err, sizeof err);
    CHECK(rc == 0 && r.outcome == IM_FOUND_NONE && r.nspots == 0 && r.best_snr > 3 &&
          r.best_snr <= r.threshold, "empty frame: none, best candidate (a noise peak) SNR "
          "%.2f, at or below the threshold %.2f", r.best_snr, r.threshold);
    /* The truth of this frame: B = 100, sigma = 50 clipped at 0 by the unsigned samples. */
    double m = 0, q = 0, np = (double)f->width * f->height;
    for (int i = 0; i < f->width * f->height; i++) { m += f->px[i]; q += (double)f->px[i] * f->px[i]; }
    m /= np;
    q = sqrt(q / np - m * m);
    CHECK(fabs(r.background - m) < 0.5 && fabs(r.noise / q - 1) < 0.02,
          "background %.2f (frame mean %.2f) and noise %.2f (frame sigma %.2f) estimated",
          r.background, m, r.noise, q);
    fa->frame_free(f);

    /* A faint spot below threshold: none, and its SNR is said (the matched filter's:
     * a 1-sigma spot of w = 3 px has an integrated SNR of 2.4; 2 sigma, 4.9, would be
     * found about one time in three). */
    im_spot_src faint = it_spot(200.3, 150.6);
    faint.peak = 1.0 * IT_SIGMA;
    f = frame_of(&s, &faint, 1, 2);
    fa->centroid(NULL, f, &opt, o, 8, &r, err, sizeof err);
    CHECK(r.outcome == IM_FOUND_NONE && r.best_snr <= r.threshold, "faint spot (1 sigma): none, "
          "best SNR %.2f, at or below the threshold %.2f", r.best_snr, r.threshold);
    fa->frame_free(f);

    /* Several spots: all returned, brightest first, flagged. */
    im_spot_src three[3] = {it_spot(100.2, 100.7), it_spot(400.5, 300.1), it_spot(550.8, 60.4)};
    three[0].peak = 300; three[1].peak = 1500; three[2].peak = 700;
    f = frame_of(&s, three, 3, 3);
    fa->centroid(NULL, f, &opt, o, 8, &r, err, sizeof err);
    CHECK(r.outcome == IM_FOUND_SEVERAL && r.nspots == 3 && r.ndetected == 3,
          "three spots: several (%d returned)", r.nspots);
    CHECK(r.nspots == 3 && fabs(o[0].x - 400.5) < 0.2 && fabs(o[1].x - 550.8) < 0.2 &&
          fabs(o[2].x - 100.2) < 0.3 && o[0].power > o[1].power && o[1].power > o[2].power,
          "sorted by power: %.2f %.2f %.2f", o[0].x, o[1].x, o[2].x);
    CHECK(r.nspots == 3 && (o[0].flags & o[1].flags & o[2].flags & IM_SF_SEVERAL),
          "each spot flagged as one of several");
    /* Only room for one: the brightest, the count still says three. */
    fa->centroid(NULL, f, &opt, o, 1, &r, err, sizeof err);
    CHECK(r.nspots == 1 && r.ndetected == 3 && fabs(o[0].x - 400.5) < 0.2,
          "cap 1: the brightest of %d", r.ndetected);
    fa->frame_free(f);

    /* Saturated: located from the unsaturated wings. */
    im_spot_src hot = it_spot(321.37, 222.81);
    hot.peak = 300000;                   /* far beyond 65535 */
    f = frame_of(&s, &hot, 1, 4);
    fa->centroid(NULL, f, &opt, o, 8, &r, err, sizeof err);
    CHECK(r.outcome == IM_FOUND_ONE && (o[0].flags & IM_SF_SATURATED) && o[0].nsat > 5 &&
          !(o[0].flags & IM_SF_FIT_FAILED) && fabs(o[0].x - 321.37) < 0.05 &&
          fabs(o[0].y - 222.81) < 0.05 && fabs(o[0].amp / 300000 - 1) < 0.1,
          "saturated spot: flagged, %d pixels left out, at (%.3f, %.3f), peak %.0f", o[0].nsat,
          o[0].x, o[0].y, o[0].amp);
    fa->frame_free(f);
    im_sensor s12 = s;
    s12.bits = 12;
    hot.peak = 20000;
    f = frame_of(&s12, &hot, 1, 5);
    fa->centroid(NULL, f, &opt, o, 8, &r, err, sizeof err);
    CHECK(r.nspots == 1 && (o[0].flags & IM_SF_SATURATED) && fabs(o[0].x - 321.37) < 0.1,
          "12-bit saturation at 4095 detected, spot at %.3f", o[0].x);
    fa->frame_free(f);

    /* Cut by the edge. */
    im_spot_src edge = it_spot(1.3, 240.2);
    f = frame_of(&s, &edge, 1, 6);
    fa->centroid(NULL, f, &opt, o, 8, &r, err, sizeof err);
    CHECK(r.nspots == 1 && (o[0].flags & IM_SF_EDGE) && fabs(o[0].x - 1.3) < 0.3 &&
          fabs(o[0].y - 240.2) < 0.3, "spot at the edge: flagged, at (%.2f, %.2f)", o[0].x, o[0].y);
    fa->frame_free(f);
    im_spot_src mid = it_spot(320.4, 240.6);
    f = frame_of(&s, &mid, 1, 7);
    fa->centroid(NULL, f, &opt, o, 8, &r, err, sizeof err);
    CHECK(r.nspots == 1 && o[0].flags == 0, "a spot in the middle has no flags (%d)", o[0].flags);
    fa->frame_free(f);

    /* Bad calls. */
    CHECK(fa->centroid(NULL, NULL, &opt, o, 8, &r, err, sizeof err) == IM_EINVAL,
          "no frame: %s", err);
    f = frame_of(&s, NULL, 0, 8);
    opt.method = 9;
    CHECK(fa->centroid(NULL, f, &opt, o, 8, &r, err, sizeof err) == IM_EINVAL,
          "unknown method: %s", err);
    opt.method = 0;
    opt.threshold = NAN;
    CHECK(fa->centroid(NULL, f, &opt, o, 8, &r, err, sizeof err) == IM_EINVAL,
          "NaN threshold refused: %s", err);
    fa->frame_free(f);
    im_frame *tiny = fa->frame_new(1, 1, 16);
    memset(&opt, 0, sizeof opt);
    CHECK(tiny && fa->centroid(NULL, tiny, &opt, o, 8, &r, err, sizeof err) == 0 &&
          r.outcome == IM_FOUND_NONE, "a 1x1 frame: none, no crash");
    fa->frame_free(tiny);
}

/* Tracer hits on a tilted sensor: the Gaussian splat lands where the pose says. */
static void hits_to_centroid(void)
{
    im_sensor s = it_sensor();
    double c = cos(0.3), sn = sin(0.3);
    s.origin[0] = 1; s.origin[1] = 2; s.origin[2] = 50;
    s.xdir[0] = c; s.xdir[1] = sn; s.xdir[2] = 0;
    s.ydir[0] = -sn; s.ydir[1] = c; s.ydir[2] = 0;
    s.wavelength = 632.8e-9; s.exposure = 1e-3;
    im_hit h = {{0}, 2e-11, 100};
    /* 25.4 px along x, -40.7 px along y from the sensor centre */
    for (int k = 0; k < 3; k++)
        h.p[k] = s.origin[k] + 25.4 * s.pitch * s.xdir[k] - 40.7 * s.pitch * s.ydir[k];
    im_spot_src sp = {0};
    sp.kind = IM_SPOT_HITS_GAUSS; sp.hits = &h; sp.nhits = 1;
    sp.waist = 0.012; sp.beam_lambda = 632.8e-6; sp.mirror_d = 10;
    im_frame *f = frame_of(&s, &sp, 1, 11);
    im_spot o[2];
    im_centroid_result r;
    fa->centroid(NULL, f, NULL, o, 2, &r, err, sizeof err);
    double ex = 319.5 + 25.4, ey = 239.5 - 40.7;
    double w = sqrt(0.012 * 0.012 + pow(632.8e-6 / 10 * 100, 2)) / s.pitch;
    CHECK(r.nspots == 1 && fabs(o[0].x - ex) < 0.1 && fabs(o[0].y - ey) < 0.1,
          "hit on a rotated, shifted sensor found at (%.3f, %.3f), expected (%.3f, %.3f)",
          o[0].x, o[0].y, ex, ey);
    CHECK(r.nspots == 1 && fabs(o[0].w / sqrt(w * w + 1.0 / 3) - 1) < 0.05,
          "its 1/e^2 radius %.3f px is the beam's w(z) = %.3f px (pixel-integrated)", o[0].w, w);
    fa->frame_free(f);
}

/* Stiff and extreme frames: undersampled and very wide spots, no noise at all, a steep
 * background gradient, a frame saturated everywhere, an 8-bit camera below one count
 * of noise. */
static void extremes(void)
{
    im_sensor s = it_sensor();
    im_spot o[4];
    im_centroid_result r;
    im_frame *f;
    double ws[3] = {0.6, 1.0, 15};
    for (int k = 0; k < 3; k++) {
        im_spot_src sp = it_spot(300.3, 200.7);
        sp.w = ws[k];
        sp.integrate = 1;
        sp.peak = 3000;
        f = frame_of(&s, &sp, 1, 20 + (uint64_t)k);
        fa->centroid(NULL, f, NULL, o, 4, &r, err, sizeof err);
        double tol = ws[k] < 1 ? 0.2 : 0.1;
        CHECK(r.outcome == IM_FOUND_ONE && fabs(o[0].x - 300.3) < tol && fabs(o[0].y - 200.7) < tol,
              "w = %.1f px: one spot at (%.3f, %.3f)%s", ws[k], o[0].x, o[0].y,
              o[0].flags & IM_SF_FIT_FAILED ? " (moments)" : "");
        fa->frame_free(f);
    }
    im_sensor quiet = s;
    quiet.read_noise = 0;
    im_spot_src sp = it_spot(123.456, 78.9);
    f = frame_of(&quiet, &sp, 1, 30);
    fa->centroid(NULL, f, NULL, o, 4, &r, err, sizeof err);
    CHECK(r.outcome == IM_FOUND_ONE && fabs(o[0].x - 123.456) < 0.01 && fabs(o[0].y - 78.9) < 0.01,
          "noiseless frame: (%.4f, %.4f), noise taken as %.2f", o[0].x, o[0].y, r.noise);
    fa->frame_free(f);
    /* A ramp of 3000 counts across the frame under the spot. */
    f = frame_of(&s, &sp, 1, 31);
    for (int y = 0; y < f->height; y++)
        for (int x = 0; x < f->width; x++) f->px[y * f->width + x] += (uint16_t)(x * 3000 / 640);
    fa->centroid(NULL, f, NULL, o, 4, &r, err, sizeof err);
    CHECK(r.outcome == IM_FOUND_ONE && fabs(o[0].x - 123.456) < 0.2 && fabs(o[0].y - 78.9) < 0.2,
          "steep background ramp: one spot at (%.3f, %.3f), no false ones (%d)", o[0].x, o[0].y,
          r.ndetected);
    /* The bias a ramp leaves in a constant-background fit, and the tilted fit without
     * it: mean x error over 40 frames (noise alone: 0.04 / sqrt(40) = 0.006 px). */
    double bias[2] = {0, 0};
    for (int k = 0; k < 40; k++) {
        im_frame *g = frame_of(&s, &sp, 1, 100 + (uint64_t)k);
        for (int y = 0; y < g->height; y++)
            for (int x = 0; x < g->width; x++) g->px[y * g->width + x] += (uint16_t)(x * 3000 / 640);
        for (int m = 0; m < 2; m++) {
            im_centroid_opt po = {0};
            po.plane = m;
            fa->centroid(NULL, g, &po, o, 4, &r, err, sizeof err);
            bias[m] += (o[0].x - 123.456) / 40;
        }
        fa->frame_free(g);
    }
    CHECK(fabs(bias[1]) < 0.02 && fabs(bias[0]) > 0.04,
          "ramp: x bias %.4f px with a tilted background in the fit, %.4f with a constant",
          bias[1], bias[0]);
    for (int i = 0; i < f->width * f->height; i++) f->px[i] = 65535;
    int rc = fa->centroid(NULL, f, NULL, o, 4, &r, err, sizeof err);
    CHECK(rc == 0 && r.outcome == IM_FOUND_NONE, "a frame saturated everywhere: no spot, no crash");
    fa->frame_free(f);
    im_sensor cam8 = s;
    cam8.bits = 8; cam8.bias = 10; cam8.read_noise = 0.3;
    sp.peak = 120;
    f = frame_of(&cam8, &sp, 1, 32);
    fa->centroid(NULL, f, NULL, o, 4, &r, err, sizeof err);
    CHECK(r.outcome == IM_FOUND_ONE && fabs(o[0].x - 123.456) < 0.05,
          "8-bit, noise below a count: one spot at %.3f", o[0].x);
    fa->frame_free(f);
    /* Two spots 5 px apart (one blob): still located, flagged neither as edge nor sat. */
    im_spot_src two[2] = {it_spot(300, 200), it_spot(305, 200)};
    f = frame_of(&s, two, 2, 33);
    rc = fa->centroid(NULL, f, NULL, o, 4, &r, err, sizeof err);
    CHECK(rc == 0 && r.nspots >= 1 && o[0].x > 299 && o[0].x < 306,
          "two merged spots: %d found, the first at %.2f", r.nspots, o[0].x);
    fa->frame_free(f);
}

/* Two threads, each with its own centroider, locate the same frames as one thread. */
typedef struct job { im_frame **f; int n; double x[16]; } job;
static void *run_job(void *arg)
{
    job *j = arg;
    im_centroider *c = fa->centroider_new();
    char e[128];
    for (int k = 0; k < j->n; k++) {
        im_spot o[2];
        im_centroid_result r;
        j->x[k] = fa->centroid(c, j->f[k], NULL, o, 2, &r, e, sizeof e) || r.nspots < 1 ? -1 : o[0].x;
    }
    fa->centroider_free(c);
    return NULL;
}
static void threads(void)
{
    im_sensor s = it_sensor();
    im_frame *f[16];
    for (int k = 0; k < 16; k++) {
        im_spot_src sp = it_spot(50 + 30 * k + 0.37, 100 + 10 * k);
        f[k] = frame_of(&s, &sp, 1, 300 + (uint64_t)k);
    }
    job one = {f, 16, {0}}, a = {f, 16, {0}}, b = {f, 16, {0}};
    run_job(&one);
    pthread_t ta, tb;
    pthread_create(&ta, NULL, run_job, &a);
    pthread_create(&tb, NULL, run_job, &b);
    pthread_join(ta, NULL);
    pthread_join(tb, NULL);
    int same = 1;
    for (int k = 0; k < 16; k++) same &= one.x[k] >= 0 && one.x[k] == a.x[k] && one.x[k] == b.x[k];
    CHECK(same, "two threads at once locate 16 frames exactly as one thread does");
    for (int k = 0; k < 16; k++) fa->frame_free(f[k]);
}

int main(void)
{
    fa = it_api();
    accuracy();
    shot_noise_uncertainty();
    outcomes();
    hits_to_centroid();
    extremes();
    threads();
    return it_failed != 0;
}
