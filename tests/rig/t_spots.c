/* t_spots.c -- the beam on the cornea and the detector (rig_api.spots, rg_spots.c)
 * against closed forms written here, not the engine's q-parameter chain: free space
 * w(z) = w0 sqrt(1 + (z/zR)^2), zR = pi w0^2 / (M^2 lambda); a thin lens (and the
 * cornea as a thin lens of focal length -R/2) by Self's formula (S. A. Self, "Focusing
 * of spherical Gaussian beams", Appl. Opt. 22, 658 (1983)): a waist w0 at s before the
 * lens goes to w0' = m w0 at s' = f + (s - f) f^2 / ((s - f)^2 + zR^2) after it, with
 * m = 1 / sqrt((1 - s/f)^2 + (zR/f)^2); the balancing lens against a brute-force scan
 * of the same closed form; the centroid's photons N = P t R lambda / (h c) and its
 * sigma (w/2)/sqrt(N); bad values refused at FILE:LINE.  argv[1]: the example rig file. */
#define _DEFAULT_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "rig/rig.h"
#include "unit.h"

static const rig_api *rg;
static const char *base;

static int load(const char *extra, rg_rig *r, char *err, size_t cap)
{
    static char text[(1 << 20) + 1024];
    snprintf(text, sizeof text, "%s\n%s", base, extra);
    return rg->rig_parse(text, strlen(text), "x.rig", r, err, cap);
}

#include "beam_forms.h"       /* self(), wz(): the closed forms */

/* The chain by the closed forms: radii on the cornea and the detector. */
static void closed(const rg_spots *s, double w0, double z, double f, double at,
                   double *wc, double *wd)
{
    double lm = s->m2 * s->lambda_mm, sc;
    if (f != 0) {
        double d = z + s->path[1] + s->path[2] - at;
        self(f, lm, &w0, &d);
        sc = at - d;
    } else sc = z + s->path[1] + s->path[2];
    *wc = wz(w0, sc, lm);
    self(-s->R / 2, lm, &w0, &sc);
    *wd = wz(w0, s->path[3] - sc, lm);
}

static double rel(double a, double b) { return fabs(a - b) / fabs(b); }

int main(int argc, char **argv)
{
    rg_rig r;
    rg_spots s;
    char err[RG_ERRMAX];
    double wc, wd;
    const char *t;
    if (argc < 2 || !(t = unit_slurp(argv[1]))) { printf("FAIL usage: t_spots RIG\n"); return 1; }
    base = t;
    rg = rig_get_api(RIG_ABI);
    CHECK(rg && rg->spots, "the engine has rig_api.spots");
    if (!rg || !rg->spots) return 1;

    /* 1. no beam keys: the waist reproduces beam_diameter_mm at the cornea */
    CHECK(load("", &r, err, sizeof err) == 0 && rg->spots(&r, &s, err, sizeof err) == 0,
          "example rig: %s", err);
    CHECK(s.waist_from_diameter && rel(s.w_cornea, r.beam_diameter_mm / 2) < 1e-12,
          "no beam_waist: cornea radius %.15g = beam_diameter_mm/2 %.15g", s.w_cornea,
          r.beam_diameter_mm / 2);
    closed(&s, s.w0, s.waist_before_m1, 0, 0, &wc, &wd);
    CHECK(rel(s.w_det, wd) < 1e-9, "no lens: detector %.12g mm, Self %.12g mm", s.w_det, wd);
    CHECK(rel(s.w_m1, wz(s.w0, s.waist_before_m1, s.lambda_mm)) < 1e-12,
          "free space at m1: %.12g mm", s.w_m1);
    CHECK(s.path[0] > 0 && s.path[1] > 0 && s.path[2] > 0 && s.path[3] > 0,
          "path %g %g %g %g mm", s.path[0], s.path[1], s.path[2], s.path[3]);

    /* 2. a given waist, M^2 and a positive lens; 3. a negative lens */
    static const char *const cases[] = {
        "beam_waist 0.3\nbeam_waist_at_mm 20\nbeam_m2 1.3\nfocus_lens_mm 50 30\n",
        "beam_waist 0.25\nbeam_m2 1\nfocus_lens_mm -40 20\n",
        "beam_waist 0.5\nbeam_waist_at_mm -100\nbeam_m2 2\n"};
    for (int k = 0; k < 3; k++) {
        int ok = load(cases[k], &r, err, sizeof err) == 0 &&
                 rg->spots(&r, &s, err, sizeof err) == 0;
        CHECK(ok, "case %d loads and runs: %s", k, ok ? "" : err);
        if (!ok) continue;
        closed(&s, r.beam_waist, s.waist_before_m1, r.lens_line ? r.lens_f : 0, r.lens_at,
               &wc, &wd);
        CHECK(rel(s.w_cornea, wc) < 1e-9 && rel(s.w_det, wd) < 1e-9,
              "case %d: cornea %.12g (Self %.12g), detector %.12g (Self %.12g) mm", k,
              s.w_cornea, wc, s.w_det, wd);
        if (k == 1)
            CHECK(rel(s.waist_before_m1, s.path[0]) < 1e-15,
                  "no beam_waist_at_mm: the waist at the laser (%g mm before m1)",
                  s.waist_before_m1);
        /* the balancing lens: Self at best_f, and no scanned f does better */
        double bc, bd, best = INFINITY;
        closed(&s, r.beam_waist, s.waist_before_m1, s.best_is_none ? 0 : s.best_f,
               s.scan_at, &bc, &bd);
        CHECK(rel(s.best_cornea, bc) < 1e-9 && rel(s.best_det, bd) < 1e-9,
              "case %d: balanced f %.8g mm: cornea %.8g, detector %.8g mm (Self)", k,
              s.best_f, bc, bd);
        for (int i = 0; i <= 40000; i++)
            for (int sg = -1; sg <= 1; sg += 2) {
                double f = sg * s.scan_at / 20 * pow(2e6 / s.scan_at, i / 40000.0);
                closed(&s, r.beam_waist, s.waist_before_m1, f, s.scan_at, &bc, &bd);
                best = fmin(best, fmax(bc, bd));
            }
        CHECK(fmax(s.best_cornea, s.best_det) <= best * (1 + 1e-6),
              "case %d: balanced max %.10g mm <= brute force %.10g mm", k,
              fmax(s.best_cornea, s.best_det), best);
    }

    /* 4. the centroid: the rig file's max_on_ms is within the dose (the reader checks
     * it, with the heartbeat's hold), so one exposure is max_on_ms long */
    CHECK(load("", &r, err, sizeof err) == 0 && rg->spots(&r, &s, err, sizeof err) == 0,
          "example: %s", err);
    {
        double P = r.laser_power_mw * 1e-3, tt = r.max_on_ms * 1e-3, n1 = 0.376 / 2.376;
        double N = P * tt * n1 * n1 * 632.8e-9 / (6.62607015e-34 * 299792458.0);
        CHECK(s.have_dose && rel(s.expose_ms, r.max_on_ms) < 1e-12, "exposure %.8g ms = "
              "max_on_ms", s.expose_ms);
        CHECK(rel(s.photons, N) < 1e-12 && rel(s.sigma_um, 1e3 * s.w_det / 2 / sqrt(N)) < 1e-12,
              "photons %.6g (closed form %.6g), sigma %.4g um", s.photons, N, s.sigma_um);
    }
    CHECK(load("laser_power_mw 5\n", &r, err, sizeof err) != 0, "a second laser_power_mw is "
          "refused (%s)", err);

    /* 5. bad values at FILE:LINE */
    {
        int nl = 1;
        for (const char *c = base; *c; c++) nl += *c == '\n';
        static const char *const bad[][2] = {
            {"beam_m2 0.5\n", "'beam_m2' must be from 1 to 1000"},
            {"focus_lens_mm 0 10\n", "the focal length 0 mm"},
            {"focus_lens_mm 50\n", "needs F and AT"},
            {"focus_lens_mm 50 -3\n", "more than 0"},
            {"beam_waist -1\n", "'beam_waist' must be greater than 0"},
            {"beam_waist_at_mm x\n", "'x' is not a number"}};
        char want[64];
        snprintf(want, sizeof want, "x.rig:%d: ", nl + 1);
        for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++)
            CHECK(load(bad[k][0], &r, err, sizeof err) != 0 && strstr(err, want) &&
                  strstr(err, bad[k][1]), "refused: %s", err);
        CHECK(load("focus_lens_mm 50 500\n", &r, err, sizeof err) == 0 &&
              rg->spots(&r, &s, err, sizeof err) == RG_EINVAL && strstr(err, want) &&
              strstr(err, "not on the m2-cornea leg"), "a lens beyond the leg: %s", err);
    }
    return unit_failed();
}
