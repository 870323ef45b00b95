/* unit_pupil.c -- first-order pupil data (src/paraxial/pupil.c) against cases worked
 * by hand: a thin lens with the stop at it, in front of it and behind it (pupils at
 * the stop's images, by Gauss's formula), telecentric stops, afocal and conjugate
 * stops refused, finite objects by NA, the Lagrange invariant at every surface of a
 * triplet, and apertures from 1e-9 to 1e6. */
#include <math.h>
#include <string.h>
#include "paraxial/paraxial.h"
#include "unit.h"

#define DEG (3.14159265358979323846 / 180)
static int near(double a, double b, double tol) { return fabs(a - b) <= tol * fmax(1, fabs(b)); }

/* a thin lens f = 50 (n 1.5, radii 50, -50, no thickness) at surfaces i, i+1 */
static void thin(px_csurf *s, int i)
{
    s[i] = (px_csurf){50, 0, "1.5"};
    s[i + 1] = (px_csurf){-50, 0, "air"};
}

static px_pupil_in input(const px_csurf *s, int n, int stop, int ap, double v, double L,
                         double field)
{
    px_pupil_in in = {s, n, stop, "air", PX_LAMBDA_D, ap, v, L, field};
    in.obj_glass = "1";
    return in;
}

static void stop_at_lens(void)
{
    px_csurf s[2];
    px_pupil p;
    thin(s, 0);
    px_pupil_in in = input(s, 2, 0, PX_AP_EPD, 10, INFINITY, 5);
    CHECK(px_pupil_run(&in, &p) == PX_OK, "thin lens, stop at it: computed (%s)", p.why);
    CHECK(near(p.efl, 50, 1e-14), "efl 50: %.17g", p.efl);
    CHECK(fabs(p.z_ep) < 1e-14 && near(p.r_ep, 5, 1e-14), "EP at the lens, r 5: z %g r %g",
          p.z_ep, p.r_ep);
    CHECK(fabs(p.z_xp) < 1e-14 && near(p.r_xp, 5, 1e-14), "XP at the lens, r 5: z %g r %g",
          p.z_xp, p.r_xp);
    CHECK(near(p.fnum, 5, 1e-14) && near(p.work_fnum, 5, 1e-14), "f/5, working f/5: %g %g",
          p.fnum, p.work_fnum);
    CHECK(near(p.z_img, 50, 1e-14), "image at the focus z=50: %.17g", p.z_img);
    CHECK(near(p.h_img, 50 * tan(5 * DEG), 1e-14), "image height f tan 5 deg: %.17g",
          p.h_img);
    CHECK(near(p.lagrange, 5 * tan(5 * DEG), 1e-14), "H = y ubar = 5 tan 5 deg: %.17g",
          p.lagrange);
    CHECK(near(p.na_img, 0.1, 1e-14) && p.na_obj == 0, "image NA 0.1, object NA 0: %g %g",
          p.na_img, p.na_obj);
    CHECK(near(p.u[2], -0.1, 1e-14) && near(p.y[0], 5, 1e-14) && p.yb[0] == 0 &&
          near(p.ub[2], tan(5 * DEG), 1e-14),
          "marginal y 5 -> u' -0.1, chief through the centre undeviated");
    /* the same by f-number and by the stop's size */
    in.aperture = PX_AP_FNUM; in.ap_value = 5;
    px_pupil q;
    CHECK(px_pupil_run(&in, &q) == PX_OK && near(q.r_ep, 5, 1e-14), "f/5 gives EPD 10");
    in.aperture = PX_AP_STOP; in.ap_value = 5;
    CHECK(px_pupil_run(&in, &q) == PX_OK && near(q.r_ep, 5, 1e-14) &&
          near(q.r_stop, 5, 1e-14), "stop semi-diameter 5 gives EPD 10");
    in.aperture = PX_AP_NA; in.ap_value = 0.1;
    CHECK(px_pupil_run(&in, &q) == PX_BAD && strstr(q.why, "finite"),
          "NA with the object at infinity refused: %s", q.why);
}

/* Stop 25 in front of the lens: EP is the stop; XP its image: 1/s' = 1/50 - 1/25,
 * s' = -50 (z = 25 - 50 = -25), magnification s'/s = 2.  Stop 25 behind: EP at z = 50
 * (virtual, seen from the object side), magnification 2; XP the stop. */
static void stop_front_back(void)
{
    px_csurf s[3];
    px_pupil p;
    s[0] = (px_csurf){0, 25, "air"};
    thin(s, 1);
    px_pupil_in in = input(s, 3, 0, PX_AP_EPD, 10, INFINITY, 10);
    CHECK(px_pupil_run(&in, &p) == PX_OK, "stop in front: computed (%s)", p.why);
    CHECK(fabs(p.z_ep) < 1e-13 && near(p.r_ep, 5, 1e-14), "stop in front: EP = stop: %g %g",
          p.z_ep, p.r_ep);
    CHECK(near(p.z_xp, -25, 1e-13) && near(p.r_xp, 10, 1e-13),
          "stop in front: XP at its image z=-25, r 10: %.17g %.17g", p.z_xp, p.r_xp);
    CHECK(near(p.z_img, 75, 1e-13) && near(p.h_img, 50 * tan(10 * DEG), 1e-13),
          "stop in front: image height still f tan(10 deg): %.17g", p.h_img);
    CHECK(fabs(p.yb[0]) < 1e-15 && near(p.yb[1], 25 * tan(10 * DEG), 1e-14),
          "chief ray: through the stop centre, at 25 tan 10 deg on the lens");

    px_csurf b[3];
    thin(b, 0);
    b[1].t = 25;
    b[2] = (px_csurf){0, 0, "air"};
    in = input(b, 3, 2, PX_AP_EPD, 10, INFINITY, 10);
    CHECK(px_pupil_run(&in, &p) == PX_OK, "stop behind: computed (%s)", p.why);
    CHECK(near(p.z_ep, 50, 1e-13) && near(p.r_ep, 5, 1e-14),
          "stop behind: EP at its image z=50: %.17g %.17g", p.z_ep, p.r_ep);
    CHECK(near(p.r_stop, 2.5, 1e-13), "stop behind: the stop's semi-diameter is r_ep/2: %.17g",
          p.r_stop);
    CHECK(near(p.z_xp, 25, 1e-13) && near(p.r_xp, 2.5, 1e-13), "stop behind: XP = stop");
    CHECK(fabs(p.yb[2]) < 1e-14, "stop behind: chief ray at height 0 at the stop: %g", p.yb[2]);
}

/* Telecentric: stop in the front focal plane -> XP at infinity, chief ray parallel to
 * the axis after the lens; stop in the back focal plane with a finite object -> EP at
 * infinity (given by NA); and with the object at infinity the stop is conjugate. */
static void telecentric(void)
{
    px_csurf s[3];
    px_pupil p;
    s[0] = (px_csurf){0, 50, "air"};
    thin(s, 1);
    px_pupil_in in = input(s, 3, 0, PX_AP_EPD, 10, INFINITY, 3);
    CHECK(px_pupil_run(&in, &p) == PX_OK, "image-space telecentric: computed (%s)", p.why);
    CHECK(isinf(p.z_xp) && isinf(p.r_xp), "image-space telecentric: XP at infinity");
    CHECK(fabs(p.ub[3]) < 1e-16, "image-space telecentric: chief ray parallel: %g", p.ub[3]);
    CHECK(near(p.h_img, 50 * tan(3 * DEG), 1e-13), "image-space telecentric: h f tan 3 deg");

    px_csurf b[3];
    thin(b, 0);
    b[1].t = 50;
    b[2] = (px_csurf){0, 0, "air"};
    in = input(b, 3, 2, PX_AP_NA, 0.05, 100, 2);
    CHECK(px_pupil_run(&in, &p) == PX_OK, "object-space telecentric: computed (%s)", p.why);
    CHECK(isinf(p.z_ep) && isinf(p.r_ep), "object-space telecentric: EP at infinity");
    CHECK(p.ub[0] == 0 && p.yb[0] == 2, "object-space telecentric: chief ray parallel at h 2");
    CHECK(near(p.z_img, 100, 1e-13) && near(p.h_img, -2, 1e-13) && near(p.mag, -1, 1e-13),
          "object-space telecentric: image at 100, height -2, m -1: %g %g %g", p.z_img,
          p.h_img, p.mag);
    CHECK(near(p.r_stop, 0.05 * 50, 1e-13), "object-space telecentric: stop r = f NA = 2.5: %g",
          p.r_stop);
    in.aperture = PX_AP_EPD; in.ap_value = 5;
    CHECK(px_pupil_run(&in, &p) == PX_NO_PUPIL && strstr(p.why, "telecentric"),
          "object-space telecentric: an EPD is refused: %s", p.why);
    in = input(b, 3, 2, PX_AP_EPD, 10, INFINITY, 2);
    CHECK(px_pupil_run(&in, &p) == PX_NO_PUPIL && strstr(p.why, "focal plane"),
          "stop in the back focal plane, object at infinity: refused: %s", p.why);
}

/* A stop where the marginal ray has zero height (at the image of the object) is
 * refused; an afocal system is refused; bad inputs are refused. */
static void refusals(void)
{
    px_csurf s[4];
    px_pupil p;
    thin(s, 0);
    s[1].t = 100;
    s[2] = (px_csurf){0, 0, "air"};
    px_pupil_in in = input(s, 3, 2, PX_AP_NA, 0.1, 100, 1);
    CHECK(px_pupil_run(&in, &p) == PX_NO_PUPIL && strstr(p.why, "conjugate"),
          "stop at the image of the object (marginal height 0): refused: %s", p.why);
    /* Kepler telescope: f 50 and f 25, 75 apart */
    px_csurf k[4] = {{50, 0, "1.5"}, {-50, 75, "air"}, {25, 0, "1.5"}, {-25, 0, "air"}};
    in = input(k, 4, 0, PX_AP_EPD, 10, INFINITY, 1);
    CHECK(px_pupil_run(&in, &p) == PX_AT_INFINITY && strstr(p.why, "afocal"),
          "afocal telescope refused: %s", p.why);
    in = input(s, 2, 0, PX_AP_EPD, -1, INFINITY, 1);
    CHECK(px_pupil_run(&in, &p) == PX_BAD, "negative EPD refused: %s", p.why);
    in = input(s, 2, 2, PX_AP_EPD, 1, INFINITY, 1);
    CHECK(px_pupil_run(&in, &p) == PX_BAD, "stop beyond the last surface refused: %s", p.why);
    in = input(s, 2, 0, PX_AP_EPD, 1, INFINITY, 90);
    CHECK(px_pupil_run(&in, &p) == PX_BAD, "field angle 90 refused: %s", p.why);
    in = input(s, 2, 0, PX_AP_NA, 1.2, 100, 1);
    CHECK(px_pupil_run(&in, &p) == PX_BAD, "NA above the object index refused: %s", p.why);
    in = input(s, 2, 0, PX_AP_EPD, NAN, INFINITY, 1);
    CHECK(px_pupil_run(&in, &p) == PX_BAD, "NaN aperture refused");
}

/* Finite object at 100 before the thin lens, NA 0.1, height 2: image at 100, m -1. */
static void finite_object(void)
{
    px_csurf s[2];
    px_pupil p;
    thin(s, 0);
    px_pupil_in in = input(s, 2, 1, PX_AP_NA, 0.1, 100, 2);
    CHECK(px_pupil_run(&in, &p) == PX_OK, "finite object: computed (%s)", p.why);
    CHECK(near(p.y[0], 10, 1e-14) && near(p.z_img, 100, 1e-13) && near(p.mag, -1, 1e-13),
          "finite: marginal y 10, image at 100, m -1: %g %g %g", p.y[0], p.z_img, p.mag);
    CHECK(near(p.h_img, -2, 1e-13) && near(p.na_img, 0.1, 1e-13) &&
          near(p.work_fnum, 5, 1e-13), "finite: h' -2, NA' 0.1, working f/5");
    CHECK(near(p.fnum, 2.5, 1e-13), "finite: f-number efl/EPD = 50/20: %g", p.fnum);
    in.aperture = PX_AP_EPD; in.ap_value = 20;
    px_pupil q;
    CHECK(px_pupil_run(&in, &q) == PX_OK && near(q.na_obj, 0.1, 1e-13),
          "finite: EPD 20 gives NA 0.1: %g", q.na_obj);
}

/* A Cooke-type triplet (stop at surface 3): H the same at every surface; h' = -H/(n'u'). */
static void triplet(void)
{
    px_csurf s[6] = {{22.01359, 3.25896, "N-SK16"}, {-435.76044, 6.00755, "air"},
                     {-22.21328, 0.99997, "F2"}, {20.29192, 4.75041, "air"},
                     {79.68360, 2.95208, "N-SK16"}, {-18.39533, 0, "air"}};
    px_pupil p;
    px_pupil_in in = input(s, 6, 2, PX_AP_FNUM, 5, INFINITY, 20);
    in.obj_glass = "air";
    CHECK(px_pupil_run(&in, &p) == PX_OK, "triplet: computed (%s)", p.why);
    double worst = 0;
    for (int k = 0; k < 6; k++) {
        double h = p.n[k + 1] * (p.ub[k + 1] * p.y[k] - p.u[k + 1] * p.yb[k]);
        worst = fmax(worst, fabs(h - p.lagrange) / fabs(p.lagrange));
    }
    CHECK(worst < 1e-13, "triplet: Lagrange invariant at every surface to %.2g", worst);
    CHECK(near(p.h_img, -p.lagrange / (p.n[6] * p.u[6]), 1e-12),
          "triplet: h' = -H/(n'u'): %.15g", p.h_img);
    CHECK(fabs(p.yb[2]) < 1e-14 * fabs(p.yb[0]) + 1e-15, "triplet: chief ray 0 at the stop");
    CHECK(near(p.fnum, 5, 1e-14) && near(p.h_img, p.efl * tan(20 * DEG), 1e-12),
          "triplet: f/5, h' = efl tan(20 deg) at infinity: %.15g %.15g", p.h_img,
          p.efl * tan(20 * DEG));
    /* the stop (z 9.27) seen through the positive front element: virtual, magnified,
     * right of it; through the rear group: left of it */
    CHECK(p.z_ep > 9.27 && p.z_ep < 17.97 && p.z_xp > 0 && p.z_xp < 9.26 &&
          p.r_ep > p.r_stop, "triplet: EP right of the stop, XP left: EP %g XP %g",
          p.z_ep, p.z_xp);
}

/* Apertures 1e-9 and 1e6: positions unchanged, sizes proportional. */
static void extremes(void)
{
    px_csurf s[3];
    px_pupil a, b, c;
    s[0] = (px_csurf){0, 25, "air"};
    thin(s, 1);
    px_pupil_in in = input(s, 3, 0, PX_AP_EPD, 10, INFINITY, 1);
    px_pupil_run(&in, &a);
    in.ap_value = 1e-9;
    CHECK(px_pupil_run(&in, &b) == PX_OK && b.z_xp == a.z_xp && b.z_img == a.z_img &&
          near(b.r_xp, a.r_xp * 1e-10, 1e-13) && near(b.fnum, 5e10, 1e-13),
          "EPD 1e-9: same pupils, f/5e10: %g", b.fnum);
    in.ap_value = 1e6;
    CHECK(px_pupil_run(&in, &c) == PX_OK && c.z_xp == a.z_xp &&
          near(c.r_xp, a.r_xp * 1e5, 1e-13) && near(c.fnum, 5e-5, 1e-13),
          "EPD 1e6: same pupils, f/5e-5 (paraxially): %g", c.fnum);
    in.field = 0;
    CHECK(px_pupil_run(&in, &c) == PX_OK && c.h_img == 0 && c.lagrange == 0 &&
          c.z_xp == a.z_xp, "field 0: image height 0, H 0, pupils still found");
    /* a very distant finite object tends to the object at infinity */
    in = input(s, 3, 0, PX_AP_EPD, 10, 1e12, 1e12 * tan(1 * DEG));
    CHECK(px_pupil_run(&in, &c) == PX_OK && near(c.z_img, a.z_img, 1e-9) &&
          near(c.h_img, -a.h_img, 1e-9),
          "object at 1e12 images where infinity does: %.12g vs %.12g", c.z_img, a.z_img);
}

int main(void)
{
    stop_at_lens();
    stop_front_back();
    telecentric();
    refusals();
    finite_object();
    triplet();
    extremes();
    return unit_failed();
}
