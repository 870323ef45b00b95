/* t_seqfold.c -- the sequential aimed trace (rx_trace, rx_aim) through mirrors and
 * coordinate breaks, each against a closed form written here: a spherical concave
 * mirror's real-ray spherical aberration (the reflected ray at height h crosses the
 * axis |R| / (2 cos theta) from the centre, sin theta = h / |R|); a parabolic mirror
 * (k = -1) focusing an on-axis beam to a point; a classical Cassegrain (parabolic
 * primary, hyperbolic secondary k = -((m + 1) / (m - 1))^2) with its efl f1 m and
 * back focus from the mirror equation, and its on-axis spot; a flat fold giving the
 * image the unfolded lens gives; a decentred lens deviating a collimated beam by d/f;
 * a tilted plate displacing a ray by t sin(a) (1 - cos(a) / sqrt(n^2 - sin^2(a)));
 * a break and its inverse restoring the axis; bad breaks refused. */
#include <stdio.h>
#include "unit.h"
#include "tt.h"

#define DEG (3.14159265358979323846 / 180)

static void rx_set(trace_rx *rx, trace_rx_surface *s, int n, int stop, double rs, double zi)
{
    memset(rx, 0, sizeof *rx);
    rx->n_object = 1;
    rx->nsurf = n;
    rx->surf = s;
    rx->stop = stop;
    rx->stop_radius = rs;
    rx->z_image = zi;
}

static trace_rx_surface surf(double z, double radius, double n)
{
    trace_rx_surface s;
    memset(&s, 0, sizeof s);
    s.z = z;
    s.radius = radius;
    s.n_right = n;
    return s;
}

/* where a traced ray's image-space line crosses the y = 0 plane (meridional) */
static double axis_z(const trace_aim_ray *r)
{
    return r->img[2] - r->img[1] * r->img_dir[2] / r->img_dir[1];
}

static void spherical_mirror(const trace_api *tr)
{
    trace_rx_surface s[1];
    trace_rx rx;
    trace_aim_ray out;
    char err[256];
    double R = -200, worst = 0;
    s[0] = surf(0, R, 1);
    s[0].mirror = 1;
    rx_set(&rx, s, 1, 0, 30, R / 2);
    for (double h = 2; h <= 30; h += 4) {
        double o[3] = {0, h, -50}, d[3] = {0, 0, 1};
        int rc = tr->rx_trace(&rx, o, d, NULL, &out, err, sizeof err);
        if (rc != TRACE_OK || out.status != TRACE_AIM_OK) { worst = INFINITY; break; }
        double ct = sqrt(1 - h * h / (R * R)), zc = R + fabs(R) / (2 * ct);
        worst = fmax(worst, fabs(axis_z(&out) - zc) / fabs(R));
        if (h == 30)
            printf("  sphere R -200, h 30: axis crossing %.12g (closed form %.12g), "
                   "longitudinal SA %.6g\n", axis_z(&out), zc, zc - R / 2);
    }
    CHECK(worst < 1e-13, "concave sphere R -200: reflected rays cross the axis at R + "
          "|R|/(2 cos theta) to %.2g of R (h 2..30)", worst);
    CHECK(out.img_dir[2] < 0, "the reflected ray travels -z (%.6g)", out.img_dir[2]);
}

static void parabola(const trace_api *tr)
{
    trace_rx_surface s[1];
    trace_rx rx;
    trace_aim_ray out;
    char err[256];
    double worst = 0, wr = 0;
    int bad = 0;
    s[0] = surf(0, -200, 1);
    s[0].mirror = 1;
    s[0].conic = -1;
    rx_set(&rx, s, 1, 0, 40, -100);
    for (int ring = 1; ring <= 4; ring++)
        for (int k = 0; k < 6 * ring; k++) {
            trace_aim_req rq;
            double a = 2 * 3.14159265358979323846 * k / (6 * ring), rr = ring / 4.0;
            memset(&rq, 0, sizeof rq);
            rq.infinite = 1;
            rq.dir[2] = 1;
            rq.z_ref = 0;
            rq.px = rr * cos(a);
            rq.py = rr * sin(a);
            rq.guess[0] = 40 * rq.px;
            rq.guess[1] = 40 * rq.py;
            if (tr->rx_aim(&rx, &rq, &out, err, sizeof err) != TRACE_OK ||
                out.status != TRACE_AIM_OK) { bad++; continue; }
            worst = fmax(worst, hypot(out.img[0], out.img[1]));
            wr = fmax(wr, out.residual);
        }
    CHECK(!bad && worst < 1e-12, "parabolic mirror k -1, R -200, EPD 80: 60 aimed rays "
          "meet at the focus z -100 within %.2g mm (stop residual %.2g)", worst, wr);
}

/* Classical Cassegrain: primary R1 -400 at 0 (f1 200), secondary 150 in front (z
 * -150), image at z +100 (250 behind the secondary): the secondary sees the primary's
 * focus 50 beyond it, 1/(-50) + 1/250 = 2/R2 gives |R2| 125, magnification 5, efl
 * 1000; k2 = -((5 + 1)/(5 - 1))^2 = -2.25. */
static void cassegrain(const trace_api *tr)
{
    trace_rx_surface s[2];
    trace_rx rx;
    trace_aim_ray out;
    char err[256];
    s[0] = surf(0, -400, 1);
    s[0].mirror = 1;
    s[0].conic = -1;
    s[1] = surf(-150, -125, 1);
    s[1].mirror = 1;
    s[1].conic = -2.25;
    rx_set(&rx, s, 2, 0, 50, 100);
    {   /* a ray near the axis: efl = h / slope, back focus where it crosses the axis */
        double h = 1e-3, o[3] = {0, h, -10}, d[3] = {0, 0, 1};
        int rc = tr->rx_trace(&rx, o, d, NULL, &out, err, sizeof err);
        double efl = -h * out.img_dir[2] / out.img_dir[1];
        CHECK(rc == TRACE_OK && out.status == TRACE_AIM_OK && fabs(fabs(efl) - 1000) < 1e-6,
              "Cassegrain: efl from a ray at h 1e-3: %.10g (closed form 1000)", efl);
        CHECK(fabs(axis_z(&out) - 100) < 1e-7, "Cassegrain: back focus at z %.10g "
              "(closed form 100: 250 behind the secondary)", axis_z(&out));
        CHECK(out.img_dir[2] > 0, "light leaves the secondary going +z again");
    }
    /* the on-axis spot of aimed rays on a hexapolar pattern, stop at the primary, then
     * with the stop at the secondary (after a mirror) */
    for (int stop = 0; stop < 2; stop++) {
        double s2 = 0, wr = 0;
        int nok = 0, bad = 0;
        rx.stop = stop;
        rx.stop_radius = stop ? 50 * 0.25 : 50;   /* the secondary's footprint: 50/200 */
        for (int ring = 1; ring <= 5; ring++)
            for (int k = 0; k < 6 * ring; k++) {
                trace_aim_req rq;
                double a = 2 * 3.14159265358979323846 * k / (6 * ring), rr = ring / 5.0;
                memset(&rq, 0, sizeof rq);
                rq.infinite = 1;
                rq.dir[2] = 1;
                rq.px = rr * cos(a);
                rq.py = rr * sin(a);
                rq.guess[0] = 50 * rq.px;
                rq.guess[1] = 50 * rq.py;
                if (tr->rx_aim(&rx, &rq, &out, err, sizeof err) != TRACE_OK ||
                    out.status != TRACE_AIM_OK) { bad++; continue; }
                s2 += out.img[0] * out.img[0] + out.img[1] * out.img[1];
                wr = fmax(wr, out.residual);
                nok++;
            }
        double rms = nok ? sqrt(s2 / nok) : INFINITY;
        CHECK(!bad && nok == 90 && rms < 1e-11, "classical Cassegrain, stop at the %s: RMS "
              "spot on axis %.2g mm over %d aimed rays (residual %.2g)",
              stop ? "secondary" : "primary", rms, nok, wr);
    }
    /* with spherical mirrors instead it is not perfect: the test can fail */
    s[0].conic = s[1].conic = 0;
    rx.stop = 0;
    rx.stop_radius = 50;
    {
        double o[3] = {0, 50, -10}, d[3] = {0, 0, 1};
        tr->rx_trace(&rx, o, d, NULL, &out, err, sizeof err);
        CHECK(out.status == TRACE_AIM_OK && fabs(out.img[1]) > 1e-3,
              "spherical Cassegrain: the marginal ray misses the focus by %.4g mm",
              out.img[1]);
    }
}

/* A singlet (R 51.5 / -51.5, 6 mm of n 1.5168), 30 mm to a flat fold, -18 to the
 * image: the same image as the singlet with 48 mm to the image. */
static void flat_fold(const trace_api *tr)
{
    trace_rx_surface f[3], u[2];
    trace_rx rf, ru;
    trace_aim_ray a, b;
    char err[256];
    double worst = 0, wopl = 0;
    int bad = 0;
    f[0] = surf(0, 51.5, 1.5168);
    f[1] = surf(6, -51.5, 1);
    f[2] = surf(36, 0, 1);
    f[2].mirror = 1;
    u[0] = f[0];
    u[1] = f[1];
    rx_set(&rf, f, 3, 0, 10, 18);
    rx_set(&ru, u, 2, 0, 10, 54);
    for (int fi = 0; fi < 3; fi++)
        for (int k = -4; k <= 4; k++) {
            trace_aim_req rq;
            double ang = fi * 2 * DEG;
            memset(&rq, 0, sizeof rq);
            rq.infinite = 1;
            rq.dir[1] = sin(ang);
            rq.dir[2] = cos(ang);
            rq.px = 0.1 * k;
            rq.py = 0.2 * k;
            rq.guess[0] = 10 * rq.px;
            rq.guess[1] = 10 * rq.py;
            if (tr->rx_aim(&rf, &rq, &a, err, sizeof err) != TRACE_OK ||
                tr->rx_aim(&ru, &rq, &b, err, sizeof err) != TRACE_OK ||
                a.status != TRACE_AIM_OK || b.status != TRACE_AIM_OK) { bad++; continue; }
            worst = fmax(worst, fmax(fabs(a.img[0] - b.img[0]), fabs(a.img[1] - b.img[1])));
            worst = fmax(worst, fabs((a.img[2] - 36) + (b.img[2] - 36)));
            wopl = fmax(wopl, fabs(a.opl - b.opl));
        }
    CHECK(!bad && worst < 1e-12 && wopl < 1e-11, "flat fold: 27 aimed rays (0, 2, 4 "
          "degrees) land where the unfolded singlet puts them, to %.2g mm (path %.2g)",
          worst, wopl);
}

static trace_rx_surface brk(double z, double dx, double dy, double tx, double ty, double tz,
                            int order)
{
    trace_rx_surface s = surf(z, 0, 1);
    s.coordbrk = 1;
    s.decenter[0] = dx;
    s.decenter[1] = dy;
    s.tilt[0] = tx;
    s.tilt[1] = ty;
    s.tilt[2] = tz;
    s.order = order;
    return s;
}

/* a plano-convex lens R 500 (n 1.5: f = R / (n - 1) = 1000 whatever its thickness)
 * decentred by d in y: a collimated beam on the old axis leaves with slope d / f */
static void decentred_lens(const trace_api *tr)
{
    trace_rx_surface s[4];
    trace_rx rx;
    trace_aim_ray out;
    char err[256];
    double d = 0.5, o[3] = {0, 0, -10}, dir[3] = {0, 0, 1};
    s[0] = brk(0, 0, d, 0, 0, 0, 0);
    s[1] = surf(0, 500, 1.5);
    s[2] = surf(2, 0, 1);
    s[3] = brk(2, 0, -d, 0, 0, 0, 1);
    rx_set(&rx, s, 4, 1, 5, 100);
    int rc = tr->rx_trace(&rx, o, dir, NULL, &out, err, sizeof err);
    double slope = out.img_dir[1] / out.img_dir[2];
    CHECK(rc == TRACE_OK && out.status == TRACE_AIM_OK && fabs(slope - d / 1000) < 1e-6 * d / 1000,
          "lens decentred 0.5 mm: slope %.12g (closed form d/f = %.12g)", slope, d / 1000);
    CHECK(fabs(out.img[0]) < 1e-15, "decentre in y: no x (%.2g)", out.img[0]);
}

/* a plate 10 mm of n 1.5 tilted by a about x: a ray along the axis comes out parallel,
 * displaced by t sin a (1 - cos a / sqrt(n^2 - sin^2 a)) */
static void tilted_plate(const trace_api *tr)
{
    double worst = 0, wdir = 0;
    for (int ai = 1; ai <= 6; ai++) {
        double a = 10.0 * ai, t = 10, n = 1.5, sa = sin(a * DEG), ca = cos(a * DEG);
        double D = t * sa * (1 - ca / sqrt(n * n - sa * sa));
        trace_rx_surface s[5];
        trace_rx rx;
        trace_aim_ray out;
        char err[256];
        double o[3] = {0, 0, -10}, d[3] = {0, 0, 1};
        s[0] = surf(0, 0, 1);                    /* a reference plane, the stop */
        s[1] = brk(5, 0, 0, a, 0, 0, 0);
        s[2] = surf(5, 0, n);
        s[3] = surf(5 + t, 0, 1);
        s[4] = brk(5, 0, 0, -a, 0, 0, 1);        /* back to the old frame, about the same point */
        rx_set(&rx, s, 5, 0, 1, 40);
        if (tr->rx_trace(&rx, o, d, NULL, &out, err, sizeof err) != TRACE_OK ||
            out.status != TRACE_AIM_OK) { worst = INFINITY; break; }
        worst = fmax(worst, fabs(fabs(out.img[1]) - D));
        wdir = fmax(wdir, hypot(out.img_dir[0], out.img_dir[1]));
        if (ai == 3) printf("  plate tilted 30 degrees: displacement %.15g (closed form %.15g)\n",
                            out.img[1], D);
    }
    CHECK(worst < 1e-13 && wdir < 1e-15, "tilted plate 10 mm, n 1.5, 10..60 degrees: "
          "displacement to %.2g mm of the closed form, direction kept to %.2g", worst, wdir);
}

/* a singlet with a break and its inverse (order 1, values negated) in its back gap:
 * rays come out as without them */
static void inverse(const trace_api *tr)
{
    trace_rx_surface s[4], u[2];
    trace_rx rx, ru;
    trace_aim_ray a, b;
    char err[256];
    double worst = 0;
    u[0] = surf(0, 51.5, 1.5168);
    u[1] = surf(6, -51.5, 1);
    s[0] = u[0];
    s[1] = u[1];
    s[2] = brk(20, 0.3, -0.2, 3, -2, 5, 0);
    s[3] = brk(20, -0.3, 0.2, -3, 2, -5, 1);
    rx_set(&rx, s, 4, 0, 10, 50);
    rx_set(&ru, u, 2, 0, 10, 50);
    for (int k = -5; k <= 5; k++) {
        double o[3] = {0.1 * k, 1.7 * k, -20}, d[3] = {0.01, -0.02, 1};
        tr->rx_trace(&rx, o, d, NULL, &a, err, sizeof err);
        tr->rx_trace(&ru, o, d, NULL, &b, err, sizeof err);
        if (a.status != TRACE_AIM_OK || b.status != TRACE_AIM_OK) { worst = INFINITY; break; }
        for (int j = 0; j < 3; j++)
            worst = fmax(worst, fmax(fabs(a.img[j] - b.img[j]), fabs(a.img_dir[j] - b.img_dir[j])));
    }
    CHECK(worst < 1e-13, "a break (decentre 0.3, -0.2, tilts 3, -2, 5) and its inverse: "
          "rays as without them to %.2g", worst);
    /* and the break alone does change them: a test that can fail */
    rx.nsurf = 3;
    {
        double o[3] = {0, 1, -20}, d[3] = {0, 0, 1};
        tr->rx_trace(&rx, o, d, NULL, &a, err, sizeof err);
        tr->rx_trace(&ru, o, d, NULL, &b, err, sizeof err);
        CHECK(fabs(a.img[1] - b.img[1]) > 0.1, "the break alone moves the image (%.4g)",
              a.img[1] - b.img[1]);
    }
    /* refused: a break as the stop, a bad order */
    rx.nsurf = 4;
    rx.stop = 2;
    CHECK(tr->rx_trace(&rx, (double[3]){0, 0, -1}, (double[3]){0, 0, 1}, NULL, &a, err,
                       sizeof err) == TRACE_EINVAL && strstr(err, "stop"),
          "a coordinate break as the stop refused: %s", err);
    rx.stop = 0;
    s[2].order = 2;
    CHECK(tr->rx_trace(&rx, (double[3]){0, 0, -1}, (double[3]){0, 0, 1}, NULL, &a, err,
                       sizeof err) == TRACE_EINVAL && strstr(err, "order"),
          "a break of order 2 refused: %s", err);
}

int main(void)
{
    const trace_api *tr = tt_api();
    spherical_mirror(tr);
    parabola(tr);
    cassegrain(tr);
    flat_fold(tr);
    decentred_lens(tr);
    tilted_plate(tr);
    inverse(tr);
    return unit_failed();
}
