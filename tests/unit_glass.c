/* unit_glass.c -- the glass catalogue (data/glass.txt) and first-order optics per
 * wavelength (src/paraxial/glass.c, colour.c). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "paraxial/paraxial.h"
#include "unit.h"

/* Half a unit in the last printed place of s ("1.51680" -> 5e-6). */
static double half_ulp(const char *s)
{
    const char *dot = strchr(s, '.');
    int dec = dot ? (int)strlen(dot + 1) : 0;
    return 0.5 * pow(10, -dec);
}

/* Every catalogue entry with a published nd (and Vd) reproduces it to the digits
 * printed.  Tolerance: half a unit in the last place, plus 1e-6 on nd and 0.01 on Vd
 * for the data sheets' own rounding of the coefficients. */
static void published_values(void)
{
    int n = px_glass_count(), checked = 0;
    for (int i = 0; i < n; i++) {
        const px_glass_rec *g = px_glass_at(i);
        double nd, vd, pub;
        if (!strcmp(g->nd, "-")) continue;
        CHECK(px_glass_index(g->name, PX_LAMBDA_D, &nd) == PX_OK, "%s: nd computed", g->name);
        pub = atof(g->nd);
        CHECK(fabs(nd - pub) <= half_ulp(g->nd) + 1e-6, "%s: nd %.6f against published %s",
              g->name, nd, g->nd);
        checked++;
        if (!strcmp(g->vd, "-")) continue;
        CHECK(px_glass_abbe(g->name, &vd) == PX_OK, "%s: Vd computed", g->name);
        pub = atof(g->vd);
        CHECK(fabs(vd - pub) <= half_ulp(g->vd) + 0.01, "%s: Vd %.3f against published %s",
              g->name, vd, g->vd);
    }
    CHECK(checked >= 14, "%d catalogue entries checked against their published nd", checked);
    {   /* the glasses issue 14 names are all there */
        const char *need[] = {"N-BK7", "N-SF5", "N-SF6", "N-LAK9", "N-SK16", "N-F2", "F2",
                              "SF2", "N-BAF10", "F_SILICA", "CAF2", "water", "diamond",
                              "silicon"};
        for (size_t i = 0; i < sizeof need / sizeof *need; i++)
            CHECK(px_glass_find(need[i]) != NULL, "%s in the catalogue", need[i]);
    }
}

static void other_wavelengths(void)
{
    double n;
    /* SCHOTT's N-BK7 data sheet: nF 1.52238, nC 1.51432, ne 1.51872, ng 1.52668,
     * n(632.8) 1.51509. */
    static const struct { const char *wl; double n; } bk7[] = {
        {"F", 1.52238}, {"C", 1.51432}, {"e", 1.51872}, {"g", 1.52668},
        {"hene", 1.51509}, {"632.8", 1.51509}, {"0.6328", 1.51509},
    };
    for (size_t i = 0; i < sizeof bk7 / sizeof *bk7; i++) {
        double l = 0;
        CHECK(px_wavelength(bk7[i].wl, &l) == PX_OK, "wavelength '%s' read", bk7[i].wl);
        CHECK(px_glass_index("n-bk7", l, &n) == PX_OK && fabs(n - bk7[i].n) < 1e-5 + 1e-6,
              "N-BK7 at %s: %.6f, data sheet %.5f", bk7[i].wl, n, bk7[i].n);
    }
    /* Silicon at 1.55 um: 3.476 (Salzberg & Villa; Li 1980 gives 3.4757). */
    CHECK(px_glass_index("silicon", 1.55, &n) == PX_OK && fabs(n - 3.476) < 2e-3,
          "silicon at 1.55 um: %.4f", n);
    /* Water, 20 C: Daimon & Masumura's 4-term fit lies 4e-4 above the handbook
     * values (CRC: 1.33299 at 589 nm, 1.33169 at 632.8 nm): checked to 5e-4. */
    CHECK(px_glass_index("water", PX_LAMBDA_D, &n) == PX_OK && fabs(n - 1.33299) < 5e-4,
          "water at d: %.5f", n);
    CHECK(px_glass_index("water", PX_LAMBDA_HENE, &n) == PX_OK && fabs(n - 1.33169) < 5e-4,
          "water at 632.8 nm: %.5f", n);
}

static void refusals(void)
{
    double n = -1, l;
    CHECK(px_glass_index("N-BK7", 3.0, &n) == PX_GLASS_RANGE && n == -1,
          "N-BK7 at 3 um is outside its range, n untouched");
    CHECK(px_glass_index("N-BK7", 0.25, &n) == PX_GLASS_RANGE, "N-BK7 at 250 nm refused");
    CHECK(px_glass_index("silicon", PX_LAMBDA_D, &n) == PX_GLASS_RANGE,
          "silicon's formula does not reach the visible");
    CHECK(px_glass_index("diamond", PX_LAMBDA_C, &n) == PX_GLASS_RANGE,
          "diamond: C (656.3 nm) is outside Peter's 226-644 nm");
    CHECK(px_glass_abbe("diamond", &l) == PX_GLASS_RANGE, "so diamond has no Vd");
    CHECK(px_glass_index("unobtainium", PX_LAMBDA_D, &n) == PX_NO_GLASS, "unknown name");
    CHECK(px_glass_index("N-BK7", -1, &n) == PX_BAD, "negative wavelength");
    CHECK(px_glass_index("N-BK7", NAN, &n) == PX_BAD, "nan wavelength");
    CHECK(px_glass_index("1.5/", PX_LAMBDA_D, &n) == PX_NO_GLASS, "'1.5/' is no model glass");
    CHECK(px_glass_index("1.5/64x", PX_LAMBDA_D, &n) == PX_NO_GLASS, "'1.5/64x' neither");
    CHECK(px_glass_index("0.9/64", PX_LAMBDA_D, &n) == PX_NO_GLASS, "nd 0.9 refused");
    CHECK(px_glass_index("1.5/2", PX_LAMBDA_D, &n) == PX_NO_GLASS, "Vd 2 refused");
    CHECK(px_glass_index("1.5/60", 2.0, &n) == PX_GLASS_RANGE, "model glass at 2 um refused");
    CHECK(px_wavelength("x", &l) == PX_BAD && px_wavelength("0", &l) == PX_BAD &&
          px_wavelength("-5", &l) == PX_BAD && px_wavelength("1e9", &l) == PX_BAD &&
          px_wavelength("632.8nm", &l) == PX_BAD, "bad wavelengths refused");
    /* the seed's constants stay reachable for a prescription */
    CHECK(px_glass_index("cornea", PX_LAMBDA_F, &n) == PX_OK && n == PX_N_CORNEA,
          "cornea: the seed's constant 1.376 at any wavelength");
}

static void model_glass(void)
{
    double nd, nf, nc, ng;
    CHECK(px_glass_index("1.5168/64.17", PX_LAMBDA_D, &nd) == PX_OK &&
          fabs(nd - 1.5168) < 1e-15, "model 1.5168/64.17: nd %.10f", nd);
    px_glass_index("1.5168/64.17", PX_LAMBDA_F, &nf);
    px_glass_index("1.5168/64.17", PX_LAMBDA_C, &nc);
    CHECK(fabs((nd - 1) / (nf - nc) - 64.17) < 1e-9, "model Vd %.10f", (nd - 1) / (nf - nc));
    /* close to the real N-BK7 between F and C (a line in 1/l^2, not a Sellmeier) */
    px_glass_index("1.5168/64.17", PX_LAMBDA_F, &nf);
    CHECK(fabs(nf - 1.52238) < 1e-4, "model nF %.5f near N-BK7's 1.52238", nf);
    px_glass_index("1.5168/64.17", PX_LAMBDA_G, &ng);
    CHECK(ng > nf, "normal dispersion: ng %.5f > nF", ng);
}

/* A thin N-BK7 singlet: f(F) - f(C) = -f/V to first order in the thickness. */
static void singlet(void)
{
    px_csurf s[2] = {{100, 0.01, "N-BK7"}, {-100, 0, "air"}};
    px_colour c;
    double vd, f;
    CHECK(px_colour_fdc(s, 2, "air", &c) == PX_OK, "singlet per wavelength");
    px_glass_abbe("N-BK7", &vd);
    f = c.first[1].efl.v;
    /* P(F) - P(C) = P(d)/V for a thin lens, so f(F) - f(C) = -f(F) f(C)/(f V) */
    CHECK(fabs(c.first[0].efl.v - c.first[2].efl.v + c.first[0].efl.v * c.first[2].efl.v /
               (f * vd)) < 1e-3 * f / vd,
          "singlet f(F)-f(C) %.6f = -f(F)f(C)/(f V) %.6f", c.first[0].efl.v - c.first[2].efl.v,
          -c.first[0].efl.v * c.first[2].efl.v / (f * vd));
    CHECK(c.first[0].efl.v < c.first[1].efl.v && c.first[1].efl.v < c.first[2].efl.v,
          "blue focuses shorter: %.4f < %.4f < %.4f", c.first[0].efl.v, c.first[1].efl.v,
          c.first[2].efl.v);
    s[1].glass = "unobtainium";
    CHECK(px_colour_fdc(s, 2, "air", &c) == PX_NO_GLASS && c.bad_surface == 1,
          "an unknown glass names its surface");
    s[1].glass = "air";
    s[0].glass = "silicon";
    CHECK(px_colour_fdc(s, 2, "air", &c) == PX_GLASS_RANGE && c.bad_surface == 0,
          "silicon at the d line refused, surface named");
}

/* Thorlabs AC254-100-A.  Prescription from Thorlabs' own Zemax file for the part
 * (www.thorlabs.com, item AC254-100-A, "Zemax file"; a copy is in DCC-Lab/RayTracing,
 * raytracing/specifications/AC254-100-A-Zemax(ZMX).zmx): CURV 1.5936255e-2,
 * -2.1877051e-2, -7.7984871e-3 /mm (R 62.75, -45.71, -128.23 mm), DISZ 4.0 N-BK7,
 * 2.5 SF5, wavelengths F d C with d primary.  Thorlabs' product page: f = 100.1 mm,
 * BFL 97.1 mm at 587.6 nm, design wavelengths 486.1, 587.6, 656.3 nm. */
static const px_csurf ac254_100_a[3] = {
    {1 / 1.593625498007969800E-002, 4.0, "N-BK7"},
    {1 / -2.187705097352880100E-002, 2.5, "SF5"},
    {1 / -7.798487093503899700E-003, 0, "air"},
};

static void achromat(void)
{
    px_csurf bk7[2] = {{51.68, 2.0, "N-BK7"}, {INFINITY, 0, "air"}};
    px_colour c, single;
    CHECK(px_colour_fdc(ac254_100_a, 3, "air", &c) == PX_OK, "AC254-100-A per wavelength");
    CHECK(fabs(c.first[1].efl.v - 100.1) < 0.05, "AC254-100-A efl(d) %.3f mm, Thorlabs 100.1",
          c.first[1].efl.v);
    /* Thorlabs' BFL is the design's focus (the Zemax file puts the image 97.068 mm
     * behind the last surface: best focus with the spherical aberration), the
     * paraxial one lies 0.06 mm further: checked to 0.1 mm. */
    CHECK(fabs(c.first[1].bfd.v - 97.1) < 0.1, "AC254-100-A bfd(d) %.3f mm, Thorlabs 97.1",
          c.first[1].bfd.v);
    px_colour_fdc(bk7, 2, "air", &single);
    CHECK(fabs(single.first[1].efl.v - 100) < 0.5, "N-BK7 singlet f %.2f", single.first[1].efl.v);
    CHECK(fabs(c.long_colour) < 0.1 * fabs(single.long_colour),
          "achromat's F-C focal shift %.4f mm is under 10%% of a singlet's %.4f mm",
          c.long_colour, single.long_colour);
}

/* Internal transmittance (data/glass.txt tau lines) and px_glass_absorption. */
static void transmittance(void)
{
    const px_tau_rec *t;
    double a, b, lo, hi;
    int tables = 0, points = 0, worst_i = 0;
    double worst = 0;
    /* every tabulated point comes back: exp(-alpha d) = t at d = the table's thickness,
     * and Beer-Lambert's scaling to 10 mm: t10 = t^(10/d) */
    for (int i = 0; i < px_glass_count(); i++) {
        const char *name = px_glass_at(i)->name;
        for (int k = 0; (t = px_glass_tau(name, k)); k++, tables++)
            for (int j = 0; j < t->n; j++) {
                if (!(t->t[j] > 0)) continue;
                points++;
                if (px_glass_absorption(name, t->l[j], &a) != PX_OK) { worst = 1; continue; }
                double e;
                if (t->thickness == 0) {    /* a k table: alpha = 4 pi k / lambda */
                    double want = 4 * 3.14159265358979 * t->t[j] / (t->l[j] * 1e-3);
                    e = fabs(a - want) / want;
                } else {
                    double back = exp(-a * t->thickness), t10 = exp(-10 * a);
                    e = fabs(back - t->t[j]) + fabs(t10 - pow(t->t[j], 10 / t->thickness));
                }
                if (e > worst) { worst = e; worst_i = j; }
            }
    }
    CHECK(tables >= 5 && points >= 100, "%d transmittance tables, %d points", tables, points);
    CHECK(worst < 1e-12, "every tabulated transmittance reproduced, and its 10 mm value "
          "consistent (worst error %.2g at point %d)", worst, worst_i);
    /* against an independent reduction of SCHOTT's data: refractiveindex.info's
     * extinction coefficient k of N-BK7 (from the 2017-01-20 SCHOTT catalogue), alpha =
     * 4 pi k / lambda; its 5 digits against the catalogue's 3 */
    {
        static const double lk[][2] = {{0.310, 1.3679e-6}, {0.400, 1.0227e-8},
                                       {1.970, 1.0933e-6}, {2.500, 8.1300e-6}};
        for (int i = 0; i < 4; i++) {
            double ref = 4 * 3.14159265358979 * lk[i][1] / (lk[i][0] * 1e-3);
            CHECK(px_glass_absorption("n-bk7", lk[i][0], &a) == PX_OK &&
                  fabs(a - ref) <= 2e-3 * ref + 1e-6,
                  "N-BK7 alpha(%.3f um) = %.5g /mm, refractiveindex.info %.5g", lk[i][0], a,
                  ref);
        }
    }
    /* between points ln t is linear in lambda: halfway, alpha is the mean */
    CHECK(px_glass_absorption("N-BK7", 0.305, &a) == PX_OK &&
          fabs(a - (-log(0.05) - log(0.25)) / 2 / 25) < 1e-15,
          "N-BK7 alpha(0.305) is the mean of its neighbours' (%.6g /mm)", a);
    CHECK(px_glass_absorption("N-BK7", 0.6328, &a) == PX_OK && a > 0 && a < 1e-3,
          "N-BK7 at the rig's 632.8 nm: alpha %.3g /mm (internal transmittance %.4f over "
          "10 mm)", a, exp(-10 * a));
    /* absorption rises steeply into the UV edge */
    CHECK(px_glass_absorption("N-BK7", 0.33, &a) == PX_OK &&
          px_glass_absorption("N-BK7", 0.5, &b) == PX_OK && a > 20 * b,
          "N-BK7 absorbs more at 330 nm than at 500 nm (%.3g vs %.3g /mm)", a, b);
    /* water from its extinction coefficient (Hale & Querry): 0.025 /m at 500 nm, and
     * the red absorbs some 15 times more than the blue-green */
    CHECK(px_glass_absorption("water", 0.5, &a) == PX_OK &&
          fabs(a - 4 * 3.14159265358979 * 1e-9 / 5e-4) < 1e-18,
          "water at 500 nm: alpha %.4g /m (Hale & Querry's k 1e-9)", a * 1e3);
    CHECK(px_glass_absorption("WATER", 0.6328, &b) == PX_OK && b > 10 * a,
          "water at 632.8 nm: alpha %.4g /m, %.0f times 500 nm's", b * 1e3, b / a);
    CHECK(px_glass_absorption_range("water", &lo, &hi) == PX_OK && lo == 0.2 && hi == 1.2,
          "water's absorption data span 0.2-1.2 um");
    /* the range, and refusals */
    CHECK(px_glass_absorption_range("N-BK7", &lo, &hi) == PX_OK && lo == 0.3 && hi == 2.5,
          "N-BK7 transmittance data span 0.3-2.5 um");
    CHECK(px_glass_absorption_range("F2", &lo, &hi) == PX_OK && lo == 0.334,
          "F2's range starts at its first non-zero point (%.3f um)", lo);
    CHECK(px_glass_absorption("N-BK7", 0.29, &a) == PX_GLASS_RANGE,
          "N-BK7 at 290 nm: outside its data, refused");
    CHECK(px_glass_absorption("N-BK7", 2.6, &a) == PX_GLASS_RANGE, "N-BK7 at 2.6 um refused");
    CHECK(px_glass_absorption("F2", 0.325, &a) == PX_GLASS_RANGE,
          "F2 below its first transparent point refused");
    CHECK(px_glass_absorption("DIAMOND", 0.5, &a) == PX_NO_TAU, "a medium without data: NO_TAU");
    CHECK(px_glass_absorption("1.5168/64.17", 0.5, &a) == PX_NO_TAU, "a model glass: NO_TAU");
    CHECK(px_glass_absorption("unobtainium", 0.5, &a) == PX_NO_GLASS, "an unknown name");
    CHECK(px_glass_absorption("N-BK7", -1, &a) == PX_BAD &&
          px_glass_absorption("N-BK7", NAN, &a) == PX_BAD, "a wavelength that is no number");
}

/* The internal transmittance tables against SCHOTT's figures typed here from the
 * source (schott.agf, status 24 April 2013, github.com/nzhagen/zemaxglass: the "IT"
 * lines, 25 mm, of each glass added from it, and of F2 and N-BAF10; LITHOSIL-Q for
 * F_SILICA, LITHOTEC-CAF2 for CAF2),
 * independently of data/glass.txt: the compiled table holds every point (wavelength
 * and value), and px_glass_absorption gives back exp(-25 alpha) = T at each to 1e-12
 * (T = 0: outside the range, refused).  A typo on either side fails. */
typedef struct typed_tau { const char *name; int n; double p[40][2]; } typed_tau;
static const typed_tau schott_it[] = {
    {"F2", 23, {{0.320, 0.000}, {0.334, 0.211}, {0.350, 0.780}, {0.365, 0.921},
     {0.370, 0.940}, {0.380, 0.963}, {0.390, 0.977}, {0.400, 0.985}, {0.405, 0.987},
     {0.420, 0.991}, {0.436, 0.993}, {0.460, 0.994}, {0.500, 0.997}, {0.546, 0.998},
     {0.580, 0.998}, {0.620, 0.998}, {0.660, 0.997}, {0.700, 0.998}, {1.060, 0.998},
     {1.530, 0.989}, {1.970, 0.876}, {2.325, 0.685}, {2.500, 0.589}}},
    {"N-BAF10", 21, {{0.350, 0.010}, {0.365, 0.310}, {0.370, 0.440}, {0.380, 0.660},
     {0.390, 0.800}, {0.400, 0.880}, {0.405, 0.900}, {0.420, 0.940}, {0.436, 0.954},
     {0.460, 0.967}, {0.500, 0.981}, {0.546, 0.990}, {0.580, 0.990}, {0.620, 0.991},
     {0.660, 0.990}, {0.700, 0.994}, {1.060, 0.994}, {1.530, 0.980}, {1.970, 0.920},
     {2.325, 0.680}, {2.500, 0.450}}},
    {"N-SF5", 19, {{0.370, 0.040}, {0.380, 0.330}, {0.390, 0.620}, {0.400, 0.780},
     {0.405, 0.830}, {0.420, 0.910}, {0.436, 0.935}, {0.460, 0.956}, {0.500, 0.976},
     {0.546, 0.988}, {0.580, 0.991}, {0.620, 0.988}, {0.660, 0.987}, {0.700, 0.989},
     {1.060, 0.994}, {1.530, 0.975}, {1.970, 0.880}, {2.325, 0.630}, {2.500, 0.500}}},
    {"SF5", 21, {{0.350, 0.310}, {0.365, 0.730}, {0.370, 0.800}, {0.380, 0.880},
     {0.390, 0.920}, {0.400, 0.950}, {0.405, 0.959}, {0.420, 0.973}, {0.436, 0.982},
     {0.460, 0.988}, {0.500, 0.993}, {0.546, 0.996}, {0.580, 0.996}, {0.620, 0.995},
     {0.660, 0.995}, {0.700, 0.996}, {1.060, 0.996}, {1.530, 0.987}, {1.970, 0.900},
     {2.325, 0.740}, {2.500, 0.660}}},
    {"N-SF6", 19, {{0.370, 0.010}, {0.380, 0.160}, {0.390, 0.410}, {0.400, 0.610},
     {0.405, 0.680}, {0.420, 0.810}, {0.436, 0.870}, {0.460, 0.905}, {0.500, 0.943},
     {0.546, 0.972}, {0.580, 0.980}, {0.620, 0.978}, {0.660, 0.976}, {0.700, 0.983},
     {1.060, 0.996}, {1.530, 0.978}, {1.970, 0.860}, {2.325, 0.590}, {2.500, 0.530}}},
    {"N-SK16", 24, {{0.310, 0.020}, {0.320, 0.110}, {0.334, 0.400}, {0.350, 0.700},
     {0.365, 0.860}, {0.370, 0.890}, {0.380, 0.930}, {0.390, 0.956}, {0.400, 0.970},
     {0.405, 0.974}, {0.420, 0.979}, {0.436, 0.981}, {0.460, 0.984}, {0.500, 0.991},
     {0.546, 0.994}, {0.580, 0.994}, {0.620, 0.993}, {0.660, 0.994}, {0.700, 0.996},
     {1.060, 0.995}, {1.530, 0.973}, {1.970, 0.880}, {2.325, 0.540}, {2.500, 0.260}}},
    {"SF2", 21, {{0.350, 0.370}, {0.365, 0.720}, {0.370, 0.790}, {0.380, 0.870},
     {0.390, 0.920}, {0.400, 0.954}, {0.405, 0.962}, {0.420, 0.975}, {0.436, 0.982},
     {0.460, 0.988}, {0.500, 0.993}, {0.546, 0.995}, {0.580, 0.995}, {0.620, 0.995},
     {0.660, 0.994}, {0.700, 0.996}, {1.060, 0.996}, {1.530, 0.985}, {1.970, 0.880},
     {2.325, 0.710}, {2.500, 0.620}}},
    {"F_SILICA", 29, {{0.250, 0.999}, {0.260, 0.999}, {0.270, 0.999}, {0.280, 0.999},
     {0.290, 0.999}, {0.300, 0.999}, {0.310, 0.999}, {0.320, 0.999}, {0.334, 0.999},
     {0.350, 0.999}, {0.365, 0.999}, {0.370, 0.999}, {0.380, 0.999}, {0.390, 0.999},
     {0.400, 0.999}, {0.405, 0.999}, {0.420, 0.999}, {0.436, 0.999}, {0.460, 0.999},
     {0.500, 0.999}, {0.546, 0.999}, {0.580, 0.999}, {0.620, 0.999}, {0.660, 0.999},
     {0.700, 0.999}, {1.060, 0.999441}, {1.530, 0.999441}, {1.970, 0.985985},
     {2.325, 0.796739}}},
    {"CAF2", 30, {{0.250, 0.998}, {0.260, 0.998}, {0.270, 0.998}, {0.280, 0.998},
     {0.290, 0.998}, {0.300, 0.998}, {0.310, 0.998}, {0.320, 0.998}, {0.334, 0.998},
     {0.350, 0.998}, {0.365, 0.998}, {0.370, 0.998}, {0.380, 0.998}, {0.390, 0.998},
     {0.400, 0.998}, {0.405, 0.998}, {0.420, 0.998}, {0.436, 0.998}, {0.460, 0.998},
     {0.500, 0.999}, {0.546, 0.999}, {0.580, 0.999}, {0.620, 0.999}, {0.660, 0.999},
     {0.700, 0.999}, {1.060, 0.999}, {1.530, 0.999}, {1.970, 0.999}, {2.325, 0.999},
     {2.500, 0.999}}},
};

static void transmittance_published(void)
{
    for (size_t g = 0; g < sizeof schott_it / sizeof schott_it[0]; g++) {
        const typed_tau *w = &schott_it[g];
        const px_tau_rec *t = px_glass_tau(w->name, 0);
        int same = t && t->thickness == 25 && t->n == w->n && !px_glass_tau(w->name, 1);
        double worst = 0, a, lo, hi;
        for (int j = 0; same && j < w->n; j++)
            same = t->l[j] == w->p[j][0] && t->t[j] == w->p[j][1];
        CHECK(same, "%s: data/glass.txt's table is SCHOTT's %d IT points (25 mm)", w->name,
              w->n);
        int j0 = 0;
        while (j0 < w->n && w->p[j0][1] == 0) j0++;     /* opaque ends: outside */
        for (int j = 0; j < w->n; j++) {
            int rc = px_glass_absorption(w->name, w->p[j][0], &a);
            if (j < j0) { if (rc != PX_GLASS_RANGE) worst = 1; continue; }
            if (rc != PX_OK) { worst = 1; break; }
            double e = fabs(exp(-25 * a) - w->p[j][1]);
            if (e > worst) worst = e;
        }
        CHECK(worst < 1e-12, "%s: every point reproduced (worst |exp(-25 alpha) - T| %.2g)",
              w->name, worst);
        CHECK(px_glass_absorption_range(w->name, &lo, &hi) == PX_OK &&
              lo == w->p[j0][0] && hi == w->p[w->n - 1][0],
              "%s: absorption data span %.3f-%.3f um", w->name, w->p[j0][0], w->p[w->n - 1][0]);
    }
    /* a few values by hand: alpha = -ln(T)/25 */
    double a;
    CHECK(px_glass_absorption("N-SF6", 0.4, &a) == PX_OK &&
          fabs(a - 0.0197718529) < 1e-9, "N-SF6 at 400 nm: alpha %.9f /mm (-ln 0.610 / 25)", a);
    CHECK(px_glass_absorption("F_SILICA", 2.325, &a) == PX_OK &&
          fabs(a - 0.00908913) < 1e-8, "fused silica at 2325 nm: alpha %.7f /mm (-ln 0.796739 "
          "/ 25)", a);
    CHECK(px_glass_absorption("CAF2", 0.6328, &a) == PX_OK &&
          fabs(a - 4.002001e-5) < 1e-11, "CaF2 at 632.8 nm: alpha %.4g /mm (-ln 0.999 / 25)", a);
}

int main(void)
{
    published_values();
    other_wavelengths();
    refusals();
    model_glass();
    singlet();
    achromat();
    transmittance();
    transmittance_published();
    return unit_failed();
}
