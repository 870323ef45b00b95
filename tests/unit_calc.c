/* unit_calc.c -- the paraxial engine's calculations against every worked number of
 * the document (sections 4, 13, 16-21, 23, 31.7-31.13, 37, 41, 56-58 and the captions
 * of Figures 4, 5, 6 and 9).  The document prints rounded numbers: DOC(x, printed,
 * decimals) accepts |x - printed| <= half a unit of the last printed decimal.  Where
 * the document itself is wrong the test asserts the right value and says so. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "unit.h"
#include "paraxial/paraxial.h"
#include "dialogue/ask.h"

/* x rounds to `printed` at `dec` decimals (with a little slack for binary ties). */
static int doc(double x, double printed, int dec)
{
    return fabs(x - printed) <= 0.5 * pow(10, -dec) * (1 + 1e-9) + 1e-12;
}
#define DOC(x, printed, dec, ...) \
    CHECK(doc((x), (printed), (dec)), __VA_ARGS__ " (got %.10g, document %.*f)", \
          (double)(x), (dec), (double)(printed))

static void gauss(void)
{
    px_gauss g;
    /* Example 1: n1 = 1, n2 = 1.4, R = 3, z1 = -20 */
    CHECK(px_gauss_surface(1, 1.4, 3, -20, &g) == PX_OK, "gauss example 1 solves");
    DOC(g.z2, 16.8, 1, "gauss example 1: z2");
    DOC(g.focal_obj, -7.5, 1, "gauss example 1: first focal point");
    DOC(g.focal_img, 10.5, 1, "gauss example 1: second focal point 3.5R");
    DOC(g.focal_img / 3, 3.5, 1, "gauss example 1: n2/(n2-n1) = 3.5");
    CHECK(g.mag < 0, "gauss example 1: real image is inverted (m = %g)", g.mag);
    /* Example 2: z1 = -5, left of the focal point -> virtual image */
    px_gauss_surface(1, 1.4, 3, -5, &g);
    DOC(g.z2, -21, 0, "gauss example 2: z2 (virtual)");
    /* Example 3: R = -3, z1 = -20.  The document prints -7.63 (truncated: the value
     * is -7.636..., which rounds to -7.64); and it repeats the focal points of
     * Examples 1-2 (-7.5, 10.5) although for R = -3 they are +7.5 and -10.5. */
    px_gauss_surface(1, 1.4, -3, -20, &g);
    DOC(g.z2, -7.64, 2, "gauss example 3: z2 (document: -7.63, truncated)");
    CHECK(g.z2 < -7.63 && g.z2 > -7.64, "gauss example 3: -7.64 < z2 < -7.63");
    DOC(g.focal_obj, 7.5, 1, "gauss example 3: first focal point +7.5 (document: -7.5)");
    DOC(g.focal_img, -10.5, 1, "gauss example 3: second focal point -10.5 (document: 10.5)");
    CHECK(px_gauss_surface(1, 1.4, 3, -7.5, &g) == PX_AT_INFINITY,
          "gauss: object at the first focal point images at infinity");
    CHECK(px_gauss_surface(1, 1.4, 3, -INFINITY, &g) == PX_OK && fabs(g.z2 - 10.5) < 1e-14,
          "gauss: object at infinity images at the second focal point");
    CHECK(px_gauss_surface(1, 1.5, INFINITY, -10, &g) == PX_OK && fabs(g.z2 + 15) < 1e-12,
          "gauss: plane surface, apparent depth n2 z1/n1");
}

static px_lens lens(double r1, double t, double n, double r2)
{
    px_lens l;
    int rc = px_thick_lens(1, r1, t, n, r2, 1, &l);
    CHECK(rc == PX_OK, "lens %g %g %g %g computes (rc %d)", r1, t, n, r2, rc);
    return l;
}

static void image(px_lens *l, double z_obj, double h, double *z_img, double *h_img)
{
    px_conj c;
    CHECK(px_conjugate(&l->sys, z_obj, &c) == PX_OK, "object at %g has an image", z_obj);
    *z_img = c.z_img.v;
    *h_img = h * c.lateral.v;
}

static void figures(void)
{
    double zi, hi;
    /* Section 13 (the program's example) and 21: thin convex lens 3, -3, n = 1.5 */
    px_lens l = lens(3, 0, 1.5, -3);
    DOC(l.first.efl.v, 3, 0, "section 21: F = R1 = 3");
    DOC(1 / l.maker_power, 3, 0, "section 21: lens maker's equation F = 3");
    DOC(l.first.z_f1.v, -3, 0, "section 13: first focal point -3");
    DOC(l.first.z_f2.v, 3, 0, "section 13: second focal point 3");
    DOC(l.first.z_h1.v, 0, 0, "section 13: principal plane 1 at 0");
    DOC(l.first.m.c, -0.3333, 4, "section 13: C = -0.3333");
    image(&l, -2, 1, &zi, &hi);
    DOC(zi, -6, 0, "section 13: object -2 -> image -6");
    DOC(hi, 3, 0, "section 13: magnification 3");
    image(&l, -4, 1, &zi, &hi);
    DOC(zi, 12, 0, "section 13: object -4 -> image 12");
    DOC(hi, -3, 0, "section 13: magnification -3");
    px_system_free(&l.sys);

    /* Figure 4: r1 = 3, r2 = 4, t = 5, n = 1.4 */
    l = lens(3, 5, 1.4, 4);
    DOC(l.first.z_f1.v, -16.76, 2, "figure 4: f1");
    DOC(l.first.z_f2.v, 11.47, 2, "figure 4: f2");
    DOC(l.first.z_h1.v, -4.41, 2, "figure 4: h1");
    DOC(l.first.z_h2.v, -0.88, 2, "figure 4: h2");
    DOC(l.first.efl.v, 12.35, 2, "figure 4: focal length");
    DOC(1 / l.maker_power, 12.35, 2, "figure 4: lens maker's equation");
    image(&l, -10, 0.5, &zi, &hi);
    DOC(zi, -11.09, 2, "figure 4: image of the object at -10");
    /* The caption's "height 1.83" is the magnification (the height of the image of
     * an object of height 1); for the stated object height .5 the image is .913. */
    DOC(hi / 0.5, 1.83, 2, "figure 4: magnification 1.83");
    DOC(hi, 0.913, 3, "figure 4: image height .913 (document: 1.83, the magnification)");
    px_system_free(&l.sys);

    /* Figure 5: r1 = -3, r2 = 3, t = 1, n = 1.4 */
    l = lens(-3, 1, 1.4, 3);
    DOC(l.first.efl.v, -3.58, 2, "figure 5: focal length");
    CHECK(l.first.z_f1.v > 1 && l.first.z_f2.v < 0, "figure 5: f1 right, f2 left");
    CHECK(l.first.z_h1.v > 0 && l.first.z_h1.v < 1 && l.first.z_h2.v > 0 &&
          l.first.z_h2.v < 1, "figure 5: principal planes inside the lens");
    image(&l, -10, 0.5, &zi, &hi);
    DOC(zi, -2, 0, "figure 5: virtual image at -2");
    DOC(hi, 0.129, 3, "figure 5: image height .129");
    px_system_free(&l.sys);

    /* Figure 6: r1 = 1, r2 = -3, t = 8, n = 1.4 */
    l = lens(1, 8, 1.4, -3);
    DOC(l.first.z_f1.v, -1.04, 2, "figure 6: f1");
    DOC(l.first.z_f2.v, 2.375, 3, "figure 6: f2");
    DOC(l.first.z_h1.v, 3.33, 2, "figure 6: h1");
    DOC(l.first.z_h2.v, -2.0, 1, "figure 6: h2");
    CHECK(l.first.z_h1.v > l.first.z_h2.v, "figure 6: principal planes reversed");
    DOC(l.first.efl.v, 4.375, 3, "figure 6: focal length");
    image(&l, -10, 0.5, &zi, &hi);
    DOC(zi, 4.51, 2, "figure 6: image at 4.51");
    /* The caption's -2.44 has its decimal point misplaced: the image of the object of
     * height .5 has height -.244 (magnification -.488). */
    DOC(hi, -0.244, 3, "figure 6: image height -.244 (document: -2.44)");
    DOC(hi * 10, -2.44, 2, "figure 6: the document's digits 2.44 are -10 x height");
    px_system_free(&l.sys);

    /* Section 58: R1 = .6, R2 = -.6, t = 1.2 mm, n = 1.5.  The document prints
     * f = 1.2 mm and 250/1.2 = 208.33; its own lens maker's equation gives
     * 1/f = .5 (1/.6 + 1/.6 - .5*1.2/(1.5*.36)) = 1.111, f = 0.9 mm (a ball lens:
     * n D/(4 (n - 1)) = 0.9), hence 277.78x.  The 208.33 is 250/1.2. */
    l = lens(0.6, 1.2, 1.5, -0.6);
    DOC(l.first.efl.v, 0.9, 1, "section 58: f = 0.9 mm (document: 1.2, wrong)");
    DOC(1 / l.maker_power, 0.9, 1, "section 58: lens maker's equation, f = 0.9 mm");
    DOC(250 / l.first.efl.v, 277.78, 2, "section 58: 250/f = 277.78 (document: 208.33)");
    px_system_free(&l.sys);
    {
        px_magnifier m;
        px_magnify(1.2, 250, 1.0, &m);
        DOC(m.angular_limit, 208.33, 2, "section 58: 250/1.2 = 208.33, the document's f");
    }

    /* Section 57, Example 2 through the thick-lens limit: convex 20, concave 35,
     * n = 1.5: in the matrix convention R1 = 20, R2 = 35. */
    l = lens(20, 0, 1.5, 35);
    DOC(l.first.efl.v, 93.3333, 4, "section 57 example 2: f = 93.3333 cm");
    DOC(1 / l.thin_power, 93.3333, 4, "section 57 example 2: thin lens maker's");
    px_system_free(&l.sys);
}

static void media(void)
{
    px_lens l;
    /* a lens in water on the left and air on the right: lens maker's with media
     * equals -C, F2/F1 = n3/n1, and the thin limit is the sum of surface powers */
    CHECK(px_thick_lens(1.333, 10, 2, 1.6, -15, 1, &l) == PX_OK, "lens in water/air");
    CHECK(fabs(l.maker_power - l.first.power.v) < 1e-15, "lens maker's = -C with media");
    CHECK(fabs(l.first.f_back.v / l.first.f_front.v - 1 / 1.333) < 1e-12,
          "F2/F1 = n3/n1");
    CHECK(fabs(l.thin_power - ((1.6 - 1.333) / 10 + (1 - 1.6) / -15)) < 1e-15,
          "thin-lens limit: sum of surface powers");
    px_system_free(&l.sys);
    CHECK(px_thick_lens(1, 3, -1, 1.5, -3, 1, &l) == PX_BAD, "negative thickness is an error");
    /* a thick lens that is exactly afocal: t = n (R1 - R2)/(n - 1), here R1 = 2,
     * R2 = 1, n = 1.5: t = 3 */
    CHECK(px_thick_lens(1, 2, 3, 1.5, 1, 1, &l) == PX_AT_INFINITY && l.first.afocal,
          "afocal thick lens detected");
    px_system_free(&l.sys);
    /* diopters (sections 20 and 23) */
    DOC(px_diopters(1 / -20.0, PX_CM), -5, 6, "section 20: f = -20 cm is -5 diopters");
    DOC(1 / px_power_of_diopters(-5, PX_M), -0.2, 6, "section 20: -5 D is f = -.2 m");
    DOC(px_diopters(1 / 500.0, PX_MM), 2, 6, "f = 500 mm is 2 diopters");
}

static void thin(void)
{
    px_thin t;
    /* Example 1: f = 7.5, do = 5 */
    CHECK(px_thin_equation(PX_THIN_DI, 7.5, 5, 0, &t) == PX_OK, "thin example 1");
    DOC(t.d_i, -15, 0, "thin example 1: di = -15 (virtual)");
    DOC(t.mag, 3, 0, "thin example 1: m = 3 (erect)");
    /* Example 3: do = 48, di = 102.  The document prints m = -2.8908: that is its
     * script's -fdi/fdo computed with the script's f = 37.5 (inconsistent data);
     * for do = 48, di = 102 the magnification is -102/48 = -2.125. */
    px_thin_equation(PX_THIN_F, 0, 48, 102, &t);
    DOC(t.f, 32.64, 2, "thin example 3: f = 32.64");
    DOC(t.mag, -2.125, 3, "thin example 3: m = -2.125 (document: -2.8908)");
    px_thin_equation(PX_THIN_NONE, 37.5, 48, 102, &t);
    DOC(t.mag, -2.8908, 4, "thin example 3: the script's -2.8908 with f = 37.5");
    DOC(t.f, 32.64, 2, "thin example 3: the script's focallength");
    /* Example 4: object at 25 cm, virtual image at 50 cm: f = 50 cm, 2 D */
    px_thin_equation(PX_THIN_F, 0, 25, -50, &t);
    DOC(t.f, 50, 0, "thin example 4: f = 50 cm");
    DOC(px_diopters(t.power, PX_CM), 2, 6, "thin example 4: 2 diopters");
    DOC(px_diopters(px_vision_near(50, 25), PX_CM), 2, 6, "section 41: near point 50 cm: +2 D");
    /* Example 5: object at infinity, image at -10 m: f = -10 m, -.1 D */
    px_thin_equation(PX_THIN_F, 0, INFINITY, -10, &t);
    DOC(t.f, -10, 0, "thin example 5: f = -10 m");
    DOC(px_diopters(t.power, PX_M), -0.1, 6, "thin example 5: -.1 diopters");
    DOC(px_diopters(px_vision_far(10), PX_M), -0.1, 6, "section 41: far point 10 m: -.1 D");
    /* Examples 6-8 (and Figures 12-14): heights .5, .25, .75 */
    px_thin_equation(PX_THIN_F, 0, 2, 3, &t);
    DOC(t.f, 1.2, 1, "thin example 6: f = 1.2");
    DOC(t.mag, -1.5, 1, "thin example 6: m = -1.5");
    DOC(0.5 * t.mag, -0.75, 2, "thin example 6: image height -.75");
    px_thin_equation(PX_THIN_F, 0, 1, -3, &t);
    DOC(t.f, 1.5, 1, "thin example 7: f = 1.5");
    DOC(t.mag, 3, 0, "thin example 7: m = 3");
    DOC(0.25 * t.mag, 0.75, 2, "thin example 7: image height .75 (document prints 75)");
    px_thin_equation(PX_THIN_F, 0, 3, -1, &t);
    DOC(t.f, -1.5, 1, "thin example 8: f = -1.5 (diverging)");
    DOC(t.mag, 1.0 / 3, 4, "thin example 8: m = 1/3");
    DOC(0.75 * t.mag, 0.25, 2, "thin example 8: image height .25");
    /* the other unknowns reproduce the inputs */
    px_thin_equation(PX_THIN_DO, 1.2, 0, 3, &t);
    DOC(t.d_o, 2, 12, "thin: do from f and di");
    CHECK(px_thin_equation(PX_THIN_DI, 7.5, 7.5, 0, &t) == PX_AT_INFINITY,
          "thin: object at the focal point images at infinity");
    CHECK(px_thin_equation(PX_THIN_DI, 0, 5, 0, &t) == PX_BAD, "thin: f = 0 refused");
}

static void instruments(void)
{
    px_pair p;
    px_magnifier m;
    px_compound c;
    px_telescope t;
    /* Section 56: the formula against the matrix product, and additivity at t = 0 */
    CHECK(px_thin_pair(10, -20, 4, &p) == PX_OK, "pair computes");
    CHECK(fabs(p.power - (1 / 10.0 + 1 / -20.0 - 4 / (10.0 * -20.0))) < 1e-16 &&
          fabs(p.power + p.m.c) < 1e-16, "section 56: 1/f = 1/f1 + 1/f2 - t/(f1 f2) = -C");
    px_thin_pair(10, 15, 0, &p);
    CHECK(fabs(p.power - (0.1 + 1 / 15.0)) < 1e-16, "section 23: powers add for t = 0");
    CHECK(px_thin_pair(10, 5, 15, &p) == PX_AT_INFINITY, "pair t = f1 + f2 is afocal");
    /* Figure 9: f = 18 cm, object at 12 cm, near point 25 cm */
    px_magnify(18, 25, 12, &m);
    DOC(m.d_i, -36, 0, "figure 9: image at -36 cm");
    DOC(m.lateral, 3, 0, "figure 9: magnification 3");
    DOC(m.angular, 2.0833, 4, "figure 9: angular magnification 75/36");
    DOC(m.angular_limit, 1.39, 2, "figure 9: 25/f = 1.39");
    DOC(12 / 18.0, 2.0 / 3, 6, "figure 9: alpha = 2/3");
    DOC(m.best_alpha, 0.5814, 4, "section 31.8: best alpha 25/43 = .5814");
    CHECK(fabs(px_magnify(18, 25, m.best_d_o, &m) == PX_OK ? m.d_i + 25 : 1) < 1e-12,
          "section 31.8: at the best alpha the image is at the near point");
    /* Section 31.10: T = 16 cm, d0 = 25 cm, fo = .2 cm, fe = 2 cm */
    px_compound_microscope(0.2, 2, 16, 25, &c);
    DOC(fabs(c.total), 1000, 6, "section 31.10: compound microscope 1000x");
    CHECK(c.total < 0, "section 31.10: the image is inverted");
    /* Sections 31.11-31.13: afocal, angular magnification -fo/fe, +fo/fe erected */
    CHECK(px_telescope_make(100, 5, 0, &t) == PX_OK && t.afocal, "astronomical afocal");
    DOC(t.angular, -20, 12, "section 31.11: M = fo/fe = 20, inverted");
    CHECK(px_telescope_make(100, 5, 40, &t) == PX_OK && t.afocal, "terrestrial afocal");
    DOC(t.angular, 20, 12, "section 31.12: erector of focal d/4 makes it erect");
    DOC(t.erector_f, 10, 12, "section 31.12: erector focal length d/4");
    CHECK(px_telescope_make(100, -5, 0, &t) == PX_OK && t.afocal, "Galileo afocal");
    DOC(t.angular, 20, 12, "section 31.13: Galileo's telescope is erect");
    CHECK(px_telescope_make(5, -10, 0, &t) == PX_BAD, "Galileo with |fe| > fo refused");
}

static void cornea(void)
{
    /* Section 37: n = 1.376, s' = 3.66 R, p = 49 D, dp = .1 D -> dR = 1.14e-5 m */
    DOC(PX_N_CORNEA / (PX_N_CORNEA - 1), 3.66, 2, "section 37: n/(n-1) = 3.66");
    DOC(px_cornea_doc_dradius(49, 0.1, PX_N_CORNEA) * 1e5, 1.14, 2,
        "section 37: dR = 1.14e-5 m");
    /* The usual surface power (n-1)/R gives a different radius for 49 D: */
    DOC(px_cornea_radius(49, PX_N_CORNEA) * 1e3, 7.67, 2, "cornea: 49 D is R = 7.67 mm");
    DOC(px_cornea_dradius(49, 0.1, PX_N_CORNEA) * 1e6, 15.7, 1,
        "cornea: dR = 15.7 um with P = (n-1)/R");
    DOC(px_cornea_power(7.5e-3, PX_N_KERATOMETRIC), 45, 6, "keratometric: 7.5 mm is 45 D");
    CHECK(fabs(px_cornea_radius(px_cornea_power(7.8, 1.376), 1.376) - 7.8) < 1e-14,
          "cornea: radius -> power -> radius");
}

/* The dialogue layer's pieces the calculation dialogues add: indices by name, and
 * a group of answers rejected together (the record cut back to the mark). */
static void answers(void)
{
    double v = 0;
    char dir[] = "/tmp/unit_calcXXXXXX", rec[64], buf[512] = "";
    FILE *in, *f;
    lm_io io;
    lm_mark m;
    lm_numspec spec = {"the index", LM_POSITIVE, 0};
    size_t n;
    int rc;
    CHECK(lm_parse_index("water", &v) == LM_NUM_OK && v == 1.333, "index: water 1.333");
    CHECK(lm_parse_index("AIR", &v) == LM_NUM_OK && v == 1.000293, "index: AIR (any case)");
    CHECK(lm_parse_index("1.5", &v) == LM_NUM_OK && v == 1.5, "index: a number");
    CHECK(lm_parse_index("glass", &v) == LM_NUM_SYNTAX, "index: unknown medium refused");
    CHECK(lm_parse_index("nan", &v) == LM_NUM_NAN, "index: nan refused");
    if (!mkdtemp(dir)) { CHECK(0, "mkdtemp"); return; }
    snprintf(rec, sizeof rec, "%s/r.rec", dir);
    in = fmemopen((void *)"Crown 1.50\n-5\n", 14, "r");
    if (!in || lm_io_open(&io, rec, in, "in", 0)) { CHECK(0, "open a session"); return; }
    rc = lm_ask_index(&io, NULL, "Q1\n", &spec, &v);
    CHECK(rc == LM_GO && v == 1.5168, "ask index: crown");
    lm_mark_set(&io, &m);
    rc = lm_ask_index(&io, NULL, "Q2\n", &spec, &v);
    CHECK(rc == LM_GO && v == 1.5, "ask index: 1.50");
    rc = lm_mark_reject(&io, &m, "the pair", "they do not go together", "again", "Q2\n");
    CHECK(rc == LM_FAIL, "reject in a replay: LM_FAIL");
    lm_io_close(&io);
    fclose(in);
    if ((f = fopen(rec, "r"))) { n = fread(buf, 1, sizeof buf - 1, f); buf[n] = 0; fclose(f); }
    CHECK(!strcmp(buf, "Q1\ninput: crown\n(crown: index 1.5168)\nQ2\n"),
          "reject: the record keeps the accepted answers and ends with the group's "
          "question");
    if (strcmp(buf, "Q1\ninput: crown\n(crown: index 1.5168)\nQ2\n")) printf("record: [%s]\n", buf);
    unlink(rec);
    rmdir(dir);
}

int main(void)
{
    answers();
    gauss();
    figures();
    media();
    thin();
    instruments();
    cornea();
    return unit_failed();
}
