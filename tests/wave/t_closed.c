/* t_closed.c -- the wave engine against closed forms computed here (GSL Bessel
 * functions): the Airy pattern and its encircled energy by the direct Fraunhofer
 * quadrature, the aberration-free MTF of a circular pupil by the FFT path, the FFT PSF
 * against section 43's Kirchhoff integral, Strehl against Marechal, Rayleigh's and
 * Sparrow's separations of the Airy pattern, the FFT's encircled energy and Airy
 * peak, and Zernike orderings (ANSI Z80.28 and Noll's table), orthonormality and a
 * fit that recovers known coefficients. */
#include <stdio.h>
#include "unit.h"
#include "wv_closed.h"

/* Sparrow's separation of two Airy patterns: twice the Airy profile's inflection
 * radius (where (2J1(x)/x)^2 has zero second derivative), by bisection on a central
 * difference of the closed form. */
static double airy_sparrow(void)
{
    double lo = 0.3, hi = 0.6, h = 1e-4;
    for (int i = 0; i < 60; i++) {
        double mid = 0.5 * (lo + hi);
        double d2 = airy(mid + h) - 2 * airy(mid) + airy(mid - h);
        if (d2 < 0) lo = mid; else hi = mid;
    }
    return lo + hi;
}

int main(void)
{
    const wave_api *wv = wave_get_api(WAVE_ABI);
    wave_ctx *c;
    CHECK(wv != NULL, "wave_get_api(WAVE_ABI) gives the table");
    if (!wv) return 1;
    CHECK(wave_get_api(WAVE_ABI + 1) == NULL, "another ABI is refused");
    c = wv->ctx_new();

    double ep = 1, ee = 1, e = airy_err(wv, &ep, &ee);
    CHECK(e <= 1e-6, "direct Fraunhofer quadrature = (2 J1(x)/x)^2 within %.2g (peak 1), "
          "EE = 1 - J0^2 - J1^2 within %.2g relative", ep, ee);

    e = mtf_err(wv, c, 512);
    CHECK(e <= 1e-4, "FFT MTF of a 512-cell circular pupil = (2/pi)(phi - cos phi sin phi) "
          "within %.2g at every sample", e);
    e = mtf_err(wv, c, 64);
    CHECK(e > 1e-4 && e < 1e-2, "a 64-cell pupil's MTF is off by %.2g: the grid matters", e);

    e = kirchhoff_err(wv, c, 32, 5, 100, 0.5e-3, 0);
    CHECK(e <= 1e-3, "FFT PSF = Kirchhoff (section 43) within %.2g of the peak, F/10, "
          "32-cell pupil", e);
    double e2 = kirchhoff_err(wv, c, 32, 5, 100, 0.5e-3, 0.3);
    CHECK(e2 <= 1e-3, "... and with 0.3 waves of coma: %.2g", e2);
    double e3 = kirchhoff_err(wv, c, 32, 25, 100, 0.5e-3, 0.3);
    CHECK(e3 > e2, "at F/2 the Kirchhoff integral's obliquity and 1/r depart more: %.2g", e3);

    const int terms[] = {11, 5, 7, 22};
    for (int i = 0; i < 4; i++) {
        double s = 0;
        e = marechal_err(wv, c, terms[i], &s);
        CHECK(e <= 0.01, "Strehl %.6f of 0.02 waves RMS of Noll Z%d (%s) vs Marechal: %.2g",
              s, terms[i], wv->zernike_name(WAVE_Z_NOLL, terms[i]), e);
    }

    /* the FFT path's Airy pattern: peak, first zero, EE, resolution */
    {
        int n = 128, m = 1024, Q = m / n, h = m / 2;
        wave_pupil p;
        wave_quality q;
        pupil_alloc(&p, n);
        wv->pupil_mask(&p, 0, 0);
        double *psf = malloc(sizeof(double) * m * m), d = 0;
        wv->psf(c, &p, m, 0, psf, &q);
        CHECK(fabs(q.strehl - 1) < 1e-12 && q.peak_x == 0 && q.peak_y == 0,
              "aberration-free FFT PSF: peak 1 at the centre (%.15f)", q.strehl);
        for (int k = 0; k < 5 * Q; k++) d = fmax(d, fabs(psf[(size_t)h * m + h + k] - airy((double)k / Q)));
        CHECK(d < 2e-3, "FFT PSF along x = Airy within %.2g (n %d, Q %d)", d, n, Q);
        double r[3] = {1.21967 * Q, 2.233 * Q, 3.238 * Q}, fr[3], worst = 0;
        wv->energy(c, r, 3, 0, fr);
        for (int i = 0; i < 3; i++) worst = fmax(worst, fabs(fr[i] - airy_ee(r[i] / Q)));
        CHECK(worst < 3e-3, "FFT encircled energy at the first three dark rings = closed form "
              "within %.2g (%.4f %.4f %.4f)", worst, fr[0], fr[1], fr[2]);
        double ra = 0, sp = 0;
        int rc = wv->resolution(c, 0, &ra, &sp);
        double ra0 = 3.8317059702075125 / PI_, sp0 = airy_sparrow();
        CHECK(rc == WAVE_OK && fabs(ra / Q - ra0) < 2e-3 && fabs(sp / Q - sp0) < 2e-3,
              "Rayleigh %.5f (j1,1/pi %.5f) and Sparrow %.5f (closed form %.5f) lambda F",
              ra / Q, ra0, sp / Q, sp0);
        double sq[1] = {1.0 * Q}, fsq[1];
        wv->energy(c, sq, 1, 1, fsq);
        wv->energy(c, sq, 1, 0, fr);
        CHECK(fsq[0] > fr[0], "ensquared energy (half-width 1) %.4f > encircled (radius 1) %.4f",
              fsq[0], fr[0]);
        double t[129], s[129];
        wv->mtf(c, n + 1, t, s);
        double dre[129], dim[129], e45 = 0;
        wv->otf_dir(c, PI_ / 4, n + 1, dre, dim);
        for (int k = 0; k <= n; k++) e45 = fmax(e45, fabs(hypot(dre[k], dim[k]) - difflimit((double)k / n)));
        CHECK(e45 < 3e-3, "MTF along 45 degrees (bilinear between samples) = the closed form "
              "within %.2g", e45);
        CHECK(fabs(t[n / 2] - difflimit(0.5)) < 1e-3 && t[n] < 1e-6,
              "MTF at half the cutoff %.5f (closed form %.5f), %.2g at the cutoff", t[n / 2],
              difflimit(0.5), t[n]);
        /* defocus: a quarter wave of W020 lowers the Strehl to about 0.8 (Rayleigh's
         * quarter-wave rule: (sin(pi/4)/(pi/4))^2 = 0.8106 for pure W020) */
        wv->psf(c, &p, m, 0.25, NULL, &q);
        CHECK(fabs(q.strehl_centre - 0.8106) < 2e-3, "W020 = 1/4 wave: centre intensity %.4f "
              "(sinc^2(pi/4) = 0.8106)", q.strehl_centre);
        free(psf);
        pupil_release(&p);
    }

    /* the OTF's phase: a tilt that moves the PSF by exactly s samples along x (Noll Z2
     * = 2 rho cos theta: W = 2c x, a phase ramp of 4 pi c / n per cell, which the
     * FFT of size m turns into a shift of -4 c m / n samples) multiplies the sagittal
     * OTF by exp(-2 pi i k s / m); the tangential cut keeps phase 0 */
    {
        int n = 64, m = 256, s = -8;
        double c2 = -s * n / (4.0 * m), tr[65], ti[65], sr[65], si[65], worst = 0;
        wave_pupil p;
        wave_quality q;
        pupil_alloc(&p, n);
        wv->pupil_mask(&p, 0, 0);
        wv->pupil_add_zernike(&p, WAVE_Z_NOLL, 2, c2);
        wv->psf(c, &p, m, 0, NULL, &q);
        wv->otf(c, n + 1, tr, ti, sr, si);
        for (int k = 0; k < n / 2; k++) {
            double a = -2 * PI_ * k * s / m, mag = hypot(sr[k], si[k]);
            worst = fmax(worst, fabs(sr[k] - mag * cos(a)) + fabs(si[k] - mag * sin(a)));
            worst = fmax(worst, fabs(ti[k]));
        }
        CHECK(q.peak_x == s && q.peak_y == 0 && worst < 1e-9, "a tilt of %.3g waves moves the PSF "
              "to x = %g samples; the OTF's phase is exp(-2 pi i k s/m) within %.2g", c2, q.peak_x, worst);
        double dr[65], di[65], e0 = 0, e90 = 0;
        wv->otf_dir(c, 0, n + 1, dr, di);
        for (int k = 0; k <= n; k++) e0 = fmax(e0, fabs(dr[k] - sr[k]) + fabs(di[k] - si[k]));
        wv->otf_dir(c, PI_ / 2, n + 1, dr, di);
        for (int k = 0; k <= n; k++) e90 = fmax(e90, fabs(dr[k] - tr[k]) + fabs(di[k] - ti[k]));
        CHECK(e0 == 0 && e90 == 0, "otf_dir at 0 and 90 degrees = the sagittal and tangential cuts");
        pupil_release(&p);
    }

    /* Zernike orderings */
    {
        int n, m, ok = 1;
        static const int noll[][3] = {{1, 0, 0}, {2, 1, 1}, {3, 1, -1}, {4, 2, 0}, {5, 2, -2},
                                      {6, 2, 2}, {7, 3, -1}, {8, 3, 1}, {11, 4, 0}, {22, 6, 0},
                                      {12, 4, 2}, {13, 4, -2}};
        static const int ansi[][3] = {{0, 0, 0}, {1, 1, -1}, {2, 1, 1}, {3, 2, -2}, {4, 2, 0},
                                      {5, 2, 2}, {12, 4, 0}, {24, 6, 0}, {7, 3, -1}};
        static const int fringe[][3] = {{4, 2, 0}, {9, 4, 0}, {16, 6, 0}, {25, 8, 0},
                                        {36, 10, 0}, {37, 12, 0}, {7, 3, 1}, {8, 3, -1}};
        for (size_t i = 0; i < sizeof noll / sizeof *noll; i++)
            ok &= wv->zernike_nm(WAVE_Z_NOLL, noll[i][0], &n, &m) == 0 && n == noll[i][1] &&
                  m == noll[i][2];
        CHECK(ok, "Noll indices as Noll (1976) Table 1");
        ok = 1;
        for (size_t i = 0; i < sizeof ansi / sizeof *ansi; i++)
            ok &= wv->zernike_nm(WAVE_Z_ANSI, ansi[i][0], &n, &m) == 0 && n == ansi[i][1] &&
                  m == ansi[i][2];
        CHECK(ok, "ANSI Z80.28 indices j = (n(n+2)+m)/2");
        ok = 1;
        for (size_t i = 0; i < sizeof fringe / sizeof *fringe; i++)
            ok &= wv->zernike_nm(WAVE_Z_FRINGE, fringe[i][0], &n, &m) == 0 && n == fringe[i][1] &&
                  m == fringe[i][2];
        CHECK(ok && wv->zernike_nm(WAVE_Z_FRINGE, 38, &n, &m) != 0, "Fringe 1..37, 38 refused");
        CHECK(fabs(wv->zernike(WAVE_Z_FRINGE, 9, 1, 0) - 1) < 1e-14 &&
              fabs(wv->zernike(WAVE_Z_NOLL, 11, 1, 0) - sqrt(5)) < 1e-13,
              "Fringe Z9 is 1 at the rim, Noll Z11 sqrt(5)");
        /* orthonormality over the disc: polar Gauss-Legendre x trapezoid */
        double worst = 0;
        for (int a = 1; a <= 22; a++)
            for (int b = a; b <= 22; b++) {
                double s = 0;
                for (int i = 0; i < 400; i++) {
                    double rho = (i + 0.5) / 400;
                    for (int j = 0; j < 64; j++) {
                        double th = 2 * PI_ * j / 64;
                        s += wv->zernike(WAVE_Z_NOLL, a, rho, th) *
                             wv->zernike(WAVE_Z_NOLL, b, rho, th) * rho;
                    }
                }
                s *= (1.0 / 400) * (2 * PI_ / 64) / PI_;
                worst = fmax(worst, fabs(s - (a == b)));
            }
        CHECK(worst < 1e-3, "Noll Z1..Z22 orthonormal on the disc within %.2g (midpoint "
              "rule, 400 radii)", worst);
        /* a fit recovers what was put in */
        wave_pupil p;
        wave_zfit f;
        pupil_alloc(&p, 96);
        wv->pupil_mask(&p, 0, 0);
        const int put[] = {4, 5, 8, 9, 16, 21};
        const double val[] = {0.3, -0.12, 0.05, 0.2, -0.07, 0.01};
        for (int i = 0; i < 6; i++) wv->pupil_add_zernike(&p, WAVE_Z_FRINGE, put[i], val[i]);
        int rc = wv->zernike_fit(&p, WAVE_Z_FRINGE, 37, &f);
        double ce = 0;
        for (int j = 1; j <= 37; j++) {
            double want = 0;
            for (int i = 0; i < 6; i++) if (put[i] == j) want = val[i];
            ce = fmax(ce, fabs(f.c[j - 1] - want));
        }
        CHECK(rc == 0 && ce < 1e-10 && f.resid_rms < 1e-10, "Fringe fit of 37 terms recovers 6 "
              "put in within %.2g, residual %.2g waves RMS", ce, f.resid_rms);
        rc = wv->zernike_fit(&p, WAVE_Z_NOLL, 11, &f);
        CHECK(rc == 0 && f.resid_rms > 1e-3, "an 11-term Noll fit leaves the Fringe Z16/Z21 "
              "content as residual: %.4g waves RMS", f.resid_rms);
        CHECK(wv->zernike_fit(&p, WAVE_Z_NOLL, 0, &f) == WAVE_EINVAL &&
              wv->zernike_fit(&p, WAVE_Z_FRINGE, 38, &f) == WAVE_EINVAL, "bad term counts refused");
        pupil_release(&p);
    }
    wv->ctx_free(c);
    return unit_failed();
}
