/* t_aim.c -- real rays aimed at the stop (rx_trace, rx_aim): the sequential trace
 * agrees with the independent one of tt.h; on-axis aimed rays tend to the paraxial
 * marginal ray as the aperture shrinks (the difference falls as h^2); off-axis chief
 * rays hit the stop's centre to 1e-9 mm, from infinity and from a near object, and a
 * separate trace of the ray found confirms it; a wide-angle lens shows pupil
 * aberration (the paraxial guess misses the stop's centre by a growing amount) that
 * the aiming removes; vignetted, missed, unconverged rays and bad input are reported. */
#include <stdio.h>
#include "unit.h"
#include "tt.h"

#define DEG (3.14159265358979323846 / 180)

/* y-nu trace of the base rays A (y 1, u 0) and B (y 0, u 1) from surface 1 to the
 * stop: heights ya, yb there. */
static void base_rays(const trace_rx *rx, double *ya, double *yb)
{
    double y[2] = {1, 0}, u[2] = {0, 1}, n = rx->n_object;
    for (int k = 0; k <= rx->stop; k++) {
        const trace_rx_surface *s = &rx->surf[k];
        if (k) for (int j = 0; j < 2; j++) y[j] += u[j] * (s->z - rx->surf[k - 1].z);
        if (k == rx->stop) break;
        double c = (isfinite(s->radius) && s->radius != 0) ? 1 / s->radius : 0;
        for (int j = 0; j < 2; j++) u[j] = (n * u[j] - y[j] * c * (s->n_right - n)) / s->n_right;
        n = s->n_right;
    }
    *ya = y[0];
    *yb = y[1];
}

static void triplet_rx(trace_rx_surface *s, trace_rx *rx, int stop)
{
    trace_lens_surface ls[TT_NSURF];
    trace_lens l;
    tt_triplet(ls, &l, 0);
    memset(s, 0, TT_NSURF * sizeof *s);
    for (int i = 0; i < TT_NSURF; i++) {
        s[i].z = ls[i].z;
        s[i].radius = ls[i].radius;
        s[i].n_right = ls[i].n_right;
    }
    rx->n_object = 1;
    rx->nsurf = TT_NSURF;
    rx->surf = s;
    rx->stop = stop;
    rx->z_image = tt_paraxial_image(&l, -INFINITY);
}

static void against_independent(const trace_api *tr)
{
    trace_rx_surface s[TT_NSURF];
    trace_rx rx;
    trace_lens_surface ls[TT_NSURF];
    trace_lens l;
    trace_aim_ray out;
    char err[256];
    triplet_rx(s, &rx, 3);
    rx.stop_radius = 5;
    tt_triplet(ls, &l, 0);
    double worst = 0;
    for (int i = 0; i < 11; i++) {
        double o[3] = {0.3 * (i - 5), 0.9 * (i - 5), -10}, d[3] = {0.02, 0.05, 1}, ref[3], rd[3];
        double dl = sqrt(d[0] * d[0] + d[1] * d[1] + 1);
        for (int j = 0; j < 3; j++) d[j] /= dl;
        tt_real_trace(&l, o, d, rx.z_image, ref, rd);
        int rc = tr->rx_trace(&rx, o, d, NULL, &out, err, sizeof err);
        if (rc != TRACE_OK || out.status != TRACE_AIM_OK) { worst = INFINITY; break; }
        worst = fmax(worst, fmax(fabs(out.img[0] - ref[0]), fabs(out.img[1] - ref[1])));
    }
    CHECK(worst < 1e-11, "rx_trace agrees with tt.h's independent trace to %.2g mm", worst);
}

static void paraxial_limit(const trace_api *tr)
{
    trace_rx_surface s[TT_NSURF];
    trace_rx rx;
    trace_aim_ray out;
    char err[256];
    double ya, yb, dev[3], p[3] = {1e-1, 1e-2, 1e-3};
    triplet_rx(s, &rx, 3);
    base_rays(&rx, &ya, &yb);
    double r_ep = TT_EPD / 2;
    rx.stop_radius = r_ep * fabs(ya);       /* paraxial stop size for EPD 12.5 */
    for (int i = 0; i < 3; i++) {
        trace_aim_req rq = {0};
        rq.infinite = 1;
        rq.dir[2] = 1;
        rq.py = p[i];
        rq.guess[1] = p[i] * r_ep * (ya > 0 ? 1 : -1);
        int rc = tr->rx_aim(&rx, &rq, &out, err, sizeof err);
        CHECK(rc == TRACE_OK && out.status == TRACE_AIM_OK, "on-axis aim at py %g: %s, %d "
              "iterations, residual %.2g", p[i], rc ? err : "ok", out.iterations, out.residual);
        dev[i] = fabs(fabs(out.o[1]) - p[i] * r_ep) / (p[i] * r_ep);
        printf("# py %g: aimed height %.15g, paraxial %.15g, rel diff %.3g\n", p[i],
               out.o[1], p[i] * r_ep, dev[i]);
    }
    CHECK(dev[2] < 1e-5, "small aperture: aimed ray = paraxial marginal to %.2g", dev[2]);
    CHECK(dev[1] / dev[2] > 80 && dev[1] / dev[2] < 120,
          "the difference falls as h^2: ratio %.1f per 10x", dev[1] / dev[2]);
}

static void chief_rays(const trace_api *tr)
{
    trace_rx_surface s[TT_NSURF];
    trace_rx rx;
    trace_aim_ray out, chk;
    char err[256];
    double ya, yb;
    triplet_rx(s, &rx, 3);
    base_rays(&rx, &ya, &yb);
    rx.stop_radius = TT_EPD / 2 * fabs(ya);
    double z_ep = yb / ya;
    for (int k = 0; k < 2; k++) {
        trace_aim_req rq = {0};
        double field = 20 * DEG;
        if (k == 0) {
            rq.infinite = 1;
            rq.dir[1] = sin(field);
            rq.dir[2] = cos(field);
            rq.guess[1] = -z_ep * tan(field);      /* through the paraxial EP centre */
        } else {
            rq.obj[1] = 60;
            rq.obj[2] = -150;
            rq.guess[1] = -60 / (z_ep + 150);
        }
        int rc = tr->rx_aim(&rx, &rq, &out, err, sizeof err);
        double miss = hypot(out.stop[0], out.stop[1]);
        CHECK(rc == TRACE_OK && out.status == TRACE_AIM_OK && miss < 1e-9,
              "%s chief ray hits the stop centre: miss %.2g mm, %d iterations, %d traces",
              k ? "near-object" : "20-degree", miss, out.iterations, out.traces);
        printf("# %s chief ray: stop miss %.3g mm after %d iterations (%d rays traced)\n",
               k ? "object (0, 60, -150)" : "20 deg", miss, out.iterations, out.traces);
        double o[3];
        memcpy(o, out.o, sizeof o);
        if (k == 0) for (int j = 0; j < 3; j++) o[j] -= 5 * out.d[j];
        double pts[3 * TT_NSURF];
        rc = tr->rx_trace(&rx, o, out.d, pts, &chk, err, sizeof err);
        CHECK(rc == TRACE_OK && hypot(pts[3 * 3], pts[3 * 3 + 1]) < 1e-9,
              "traced again, the ray found crosses the stop at %.2g mm from its centre",
              hypot(pts[3 * 3], pts[3 * 3 + 1]));
        /* and an off-axis rim ray lands on the rim */
        rq.py = 1;
        rc = tr->rx_aim(&rx, &rq, &out, err, sizeof err);
        CHECK(rc == TRACE_OK && out.status == TRACE_AIM_OK &&
              fabs(out.stop[1] - rx.stop_radius) < 1e-9 && fabs(out.stop[0]) < 1e-9,
              "%s upper rim ray on the stop's rim: %.3g mm off", k ? "near-object" : "20-deg",
              hypot(out.stop[0], out.stop[1] - rx.stop_radius));
    }
}

/* Wide angle: a negative meniscus, the stop (plane) 20 mm behind, a positive lens. */
static void wide_angle(const trace_api *tr)
{
    trace_rx_surface s[5];
    trace_rx rx = {1, 5, s, 2, 2, NAN};
    memset(s, 0, sizeof s);
    s[0].z = 0;  s[0].radius = 40;  s[0].n_right = 1.6;
    s[1].z = 2;  s[1].radius = 12;  s[1].n_right = 1;
    s[2].z = 22; s[2].radius = 0;   s[2].n_right = 1;
    s[3].z = 27; s[3].radius = 30;  s[3].n_right = 1.6;
    s[4].z = 32; s[4].radius = -30; s[4].n_right = 1;
    double ya, yb;
    base_rays(&rx, &ya, &yb);
    double z_ep = yb / ya, miss[4], deg[4] = {5, 10, 30, 50};
    char err[256];
    for (int i = 0; i < 4; i++) {
        trace_aim_req rq = {0};
        trace_aim_ray out, g;
        double th = deg[i] * DEG;
        rq.infinite = 1;
        rq.dir[1] = sin(th);
        rq.dir[2] = cos(th);
        rq.z_ref = 0;
        rq.guess[1] = -z_ep * tan(th);
        double o[3] = {0, rq.guess[1] - 5 * tan(th), -5};
        tr->rx_trace(&rx, o, rq.dir, NULL, &g, err, sizeof err);
        miss[i] = g.status == TRACE_AIM_OK ? hypot(g.stop[0], g.stop[1]) : INFINITY;
        int rc = tr->rx_aim(&rx, &rq, &out, err, sizeof err);
        CHECK(rc == TRACE_OK && out.status == TRACE_AIM_OK && out.residual < 1e-9,
              "wide angle %g deg: paraxial guess misses the stop centre by %.4g mm, "
              "aimed by %.2g mm in %d iterations", deg[i], miss[i], out.residual,
              out.iterations);
        printf("# wide angle %g deg: paraxial chief ray misses the stop centre by %.4g mm "
               "(stop radius 2); aimed: %.2g mm, %d iterations, %d traces\n", deg[i], miss[i],
               out.residual, out.iterations, out.traces);
    }
    CHECK(miss[0] < 1e-3 * 2 && miss[3] > 0.05 * 2 && miss[3] > 100 * miss[0],
          "pupil aberration: the paraxial chief ray's miss grows from %.3g (5 deg) to %.3g "
          "mm (50 deg)", miss[0], miss[3]);
    CHECK(miss[1] / miss[0] > 6 && miss[1] / miss[0] < 10,
          "and as the field cubed near the axis: miss(10)/miss(5) = %.2f", miss[1] / miss[0]);
}

/* The aimed on-axis rays, traced again by the Embree path (lens_fan, meridional rays
 * at the heights found): the same image heights. */
static void against_fan(const trace_api *tr)
{
    trace_rx_surface s[TT_NSURF];
    trace_rx rx;
    trace_lens_surface ls[TT_NSURF];
    trace_lens l;
    char err[256];
    double ya, yb, h[5], y_aim[5], worst = 0;
    triplet_rx(s, &rx, 3);
    tt_triplet(ls, &l, 0);
    base_rays(&rx, &ya, &yb);
    rx.stop_radius = TT_EPD / 2 * fabs(ya);
    for (int i = 0; i < 5; i++) {
        trace_aim_req rq = {0};
        trace_aim_ray out;
        rq.infinite = 1;
        rq.dir[2] = 1;
        rq.py = -1 + 0.5 * i;
        rq.guess[1] = rq.py * TT_EPD / 2;
        if (tr->rx_aim(&rx, &rq, &out, err, sizeof err) || out.status) { worst = INFINITY; break; }
        h[i] = out.o[1];
        y_aim[i] = out.img[1];
    }
    trace_fan_ray fan[5];
    int rc = isfinite(worst) ? tr->lens_fan(&l, -INFINITY, 0, rx.z_image, 5, h, fan, err,
                                            sizeof err) : -1;
    for (int i = 0; i < 5 && rc == TRACE_OK; i++) worst = fmax(worst, fabs(fan[i].y_image - y_aim[i]));
    CHECK(rc == TRACE_OK && worst < 1e-12,
          "aimed rim and zone rays, traced again through Embree (lens_fan): image heights "
          "agree to %.2g mm", worst);
}

/* A concave first surface (R -20) with the object 10 mm before its vertex, inside
 * the sphere's reach: aimed like any other. */
static void concave_front(const trace_api *tr)
{
    trace_rx_surface s[3];
    trace_rx rx = {1, 3, s, 2, 1, 40};
    trace_aim_ray out;
    trace_aim_req rq = {0};
    char err[256];
    memset(s, 0, sizeof s);
    s[0].z = 0;  s[0].radius = -20; s[0].n_right = 1.5;
    s[1].z = 3;  s[1].radius = -12; s[1].n_right = 1;
    s[2].z = 6;  s[2].radius = 0;   s[2].n_right = 1;
    rq.obj[1] = 2;
    rq.obj[2] = -10;
    rq.py = 0.5;
    rq.guess[1] = -0.1;
    int rc = tr->rx_aim(&rx, &rq, &out, err, sizeof err);
    CHECK(rc == TRACE_OK && out.status == TRACE_AIM_OK && fabs(out.stop[1] - 0.5) < 1e-9,
          "concave front surface, object 10 before it: aimed (%s, residual %.2g)",
          rc ? err : "ok", out.residual);
}

/* The triplet scaled by 1e-3 and 1e4, and a stop of 1e-9 of its size: the 20-degree
 * chief ray and the rim ray still meet their targets to ~1e-14 of the lens's size. */
static void scales(const trace_api *tr)
{
    double k[3] = {1e-3, 1e4, 1};
    for (int c = 0; c < 3; c++) {
        trace_rx_surface s[TT_NSURF];
        trace_rx rx;
        trace_aim_ray out;
        char err[256];
        double ya, yb, th = 20 * DEG;
        triplet_rx(s, &rx, 3);
        for (int i = 0; i < TT_NSURF; i++) { s[i].z *= k[c]; s[i].radius *= k[c]; }
        base_rays(&rx, &ya, &yb);
        double r_ep = c == 2 ? 1e-9 : TT_EPD / 2 * k[c];
        rx.stop_radius = r_ep * fabs(ya);
        double worst = 0;
        int maxit = 0, ok = 1;
        for (int j = 0; j < 2; j++) {
            trace_aim_req rq = {0};
            rq.infinite = 1;
            rq.dir[1] = sin(th);
            rq.dir[2] = cos(th);
            rq.py = j;
            rq.guess[1] = -yb / ya * tan(th) + j * r_ep;
            int rc = tr->rx_aim(&rx, &rq, &out, err, sizeof err);
            ok &= rc == TRACE_OK && out.status == TRACE_AIM_OK;
            worst = fmax(worst, hypot(out.stop[0], out.stop[1] - j * rx.stop_radius));
            if (out.iterations > maxit) maxit = out.iterations;
        }
        double size = 18 * k[c];
        CHECK(ok && worst < 1e-13 * size, "triplet x %g%s: chief and rim rays on target to "
              "%.2g (%.2g of its size), at most %d iterations", k[c],
              c == 2 ? ", stop 1e-9" : "", worst, worst / size, maxit);
    }
}

static void failures(const trace_api *tr)
{
    trace_rx_surface s[TT_NSURF];
    trace_rx rx;
    trace_aim_ray out;
    trace_aim_req rq = {0};
    char err[256];
    double ya, yb;
    triplet_rx(s, &rx, 3);
    base_rays(&rx, &ya, &yb);
    rx.stop_radius = TT_EPD / 2 * fabs(ya);
    s[3].semi_diameter = rx.stop_radius;
    rq.infinite = 1;
    rq.dir[2] = 1;
    rq.py = 1.5;
    rq.guess[1] = 1.5 * TT_EPD / 2;
    int rc = tr->rx_aim(&rx, &rq, &out, err, sizeof err);
    CHECK(rc == TRACE_OK && out.status == TRACE_AIM_VIGNETTED && out.surface == 3,
          "aimed at 1.5 x the stop's radius: vignetted at surface 4 (status %d, surface %d)",
          out.status, out.surface + 1);
    rq.py = 1;
    rq.guess[1] = TT_EPD / 2;
    rc = tr->rx_aim(&rx, &rq, &out, err, sizeof err);
    CHECK(rc == TRACE_OK && out.status == TRACE_AIM_OK, "the rim itself passes (status %d)",
          out.status);
    s[0].semi_diameter = 3;
    rc = tr->rx_aim(&rx, &rq, &out, err, sizeof err);
    CHECK(rc == TRACE_OK && out.status == TRACE_AIM_VIGNETTED && out.surface == 0,
          "a small first lens vignettes the rim ray at surface 1 (surface %d)",
          out.surface + 1);
    s[0].semi_diameter = 0;
    /* a beam at 85 degrees cannot reach the stop */
    rq.py = 0;
    rq.dir[1] = sin(85 * DEG);
    rq.dir[2] = cos(85 * DEG);
    rq.guess[1] = 0;
    rc = tr->rx_aim(&rx, &rq, &out, err, sizeof err);
    CHECK(rc == TRACE_OK && out.status != TRACE_AIM_OK && out.surface >= 0,
          "85-degree beam: not aimed (status %d at surface %d)", out.status, out.surface + 1);
    /* one Newton step from a poor guess is not enough */
    rq.dir[1] = sin(25 * DEG);
    rq.dir[2] = cos(25 * DEG);
    rq.guess[1] = -yb / ya * tan(25 * DEG) + 0.5;
    rq.max_iter = 1;
    rq.tol = 1e-12;
    rc = tr->rx_aim(&rx, &rq, &out, err, sizeof err);
    CHECK(rc == TRACE_OK && out.status == TRACE_AIM_NOCONV && out.residual > 1e-12,
          "one iteration allowed: not converged, residual %.2g reported", out.residual);
    rq.max_iter = 0;
    rx.stop = 9;
    rc = tr->rx_aim(&rx, &rq, &out, err, sizeof err);
    CHECK(rc == TRACE_EINVAL && strstr(err, "stop"), "stop out of range refused: %s", err);
    rx.stop = 3;
    rq.infinite = 0;
    rq.obj[2] = 5;
    rc = tr->rx_aim(&rx, &rq, &out, err, sizeof err);
    CHECK(rc == TRACE_EINVAL && strstr(err, "left"), "object inside the lens refused: %s", err);
    rq.obj[2] = -100;
    rq.px = NAN;
    rc = tr->rx_aim(&rx, &rq, &out, err, sizeof err);
    CHECK(rc == TRACE_EINVAL, "NaN pupil coordinate refused: %s", err);
}

int main(void)
{
    const trace_api *tr = tt_api();
    against_independent(tr);
    paraxial_limit(tr);
    chief_rays(tr);
    wide_angle(tr);
    against_fan(tr);
    concave_front(tr);
    scales(tr);
    failures(tr);
    return unit_failed();
}
