/* t_opd.c -- the trace module's rx_opd (tr_opd.c) against closed forms: a Cartesian
 * ellipsoid (conic -1/n^2, radius R, glass n behind it) images an axial object at
 * infinity without aberration onto its far focus n R / (n - 1), so every aimed ray's
 * W is 0; with the image plane moved by delta the reference sphere's centre moves
 * with it and W at the rim is n delta (1 - cos u') / lambda to second order in
 * delta, positive for delta > 0 (the wavefront, still converging to the old focus,
 * leads the sphere centred farther away); the chief ray's W is 0 by construction. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "unit.h"
#include "trace/trace.h"

static void setup(trace_rx_surface *s, trace_rx *rx, double n, double R, double z_image)
{
    memset(s, 0, sizeof *s);
    s->z = 0;
    s->radius = R;
    s->conic = -1 / (n * n);
    s->n_right = n;
    memset(rx, 0, sizeof *rx);
    rx->n_object = 1;
    rx->nsurf = 1;
    rx->surf = s;
    rx->stop = 0;
    rx->stop_radius = 5;
    rx->z_image = z_image;
}

static int aim_grid(trace_aim_req *rq, double field_deg)
{
    int k = 0;
    double t = tan(field_deg * 3.14159265358979323846 / 180), d = sqrt(1 + t * t);
    for (int i = -1; i <= 20; i++) {
        double px = 0, py = 0;
        if (i >= 0) { double a = 2 * 3.14159265358979323846 * i / 20; px = cos(a); py = sin(a); }
        for (int r = 1; r <= (i < 0 ? 1 : 4); r++) {
            trace_aim_req *q = &rq[k++];
            memset(q, 0, sizeof *q);
            q->infinite = 1;
            q->dir[1] = t / d;
            q->dir[2] = 1 / d;
            q->px = i < 0 ? 0 : px * r / 4;
            q->py = i < 0 ? 0 : py * r / 4;
            q->guess[0] = q->px * 5;
            q->guess[1] = q->py * 5;
        }
    }
    return k;
}

int main(void)
{
    const trace_api *tr = trace_get_api(TRACE_ABI);
    trace_rx_surface s;
    trace_rx rx;
    trace_aim_req rq[128];
    trace_aim_ray chief;
    double w[128], n = 1.5, R = 20, f = n * R / (n - 1), lam = 0.5e-3, Rref = 0;
    int st[128];
    char err[256];
    if (!tr || !tr->rx_opd) { printf("FAIL no rx_opd\n"); return 1; }
    int k = aim_grid(rq, 0);
    setup(&s, &rx, n, R, f);
    int rc = tr->rx_opd(&rx, rq, k, 0, lam, w, st, &chief, &Rref, err, sizeof err);
    double worst = 0;
    int ok = rc == TRACE_OK;
    for (int i = 0; ok && i < k; i++) { ok = st[i] == TRACE_AIM_OK; worst = fmax(worst, fabs(w[i])); }
    CHECK(ok && worst < 1e-8, "Cartesian ellipsoid, n 1.5: W = 0 within %.2g waves over %d rays "
          "(%s), reference sphere radius %.6g (focus %.6g)", worst, k, rc ? err : "ok", Rref, f);
    /* the image plane 0.05 beyond the focus */
    double dz = 0.05;
    setup(&s, &rx, n, R, f + dz);
    rc = tr->rx_opd(&rx, rq, k, 0, lam, w, st, &chief, &Rref, err, sizeof err);
    /* the rim ray (px 1): its angle to the axis in the glass, from its crossing of the
     * surface (sag of the ellipsoid at h = 5) to the focus */
    double h = 5, c = 1 / R, kk = s.conic, sag = c * h * h / (1 + sqrt(1 - (1 + kk) * c * c * h * h));
    double u = atan(h / (f - sag)), want = n * dz * (1 - cos(u)) / lam, wrim = w[k - 1];
    CHECK(rc == TRACE_OK && w[0] == 0 && wrim > 0 && fabs(wrim / want - 1) < 0.02,
          "image plane %g beyond the focus: W at the rim %.6g waves, n delta (1 - cos u')/lambda "
          "= %.6g", dz, wrim, want);
    /* W across the pupil is rho^2-shaped to this order: at half the radius a quarter */
    double whalf = w[k - 3];
    CHECK(fabs(whalf / wrim - 0.25) < 0.01, "at half the pupil W is %.4f of the rim's", whalf / wrim);
    /* off the axis: W of the chief ray 0, the others not (coma of the single surface) */
    k = aim_grid(rq, 2);
    setup(&s, &rx, n, R, f);
    rc = tr->rx_opd(&rx, rq, k, 0, lam, w, st, &chief, NULL, err, sizeof err);
    double big = 0;
    for (int i = 1; i < k; i++) big = fmax(big, fabs(w[i]));
    CHECK(rc == TRACE_OK && w[0] == 0 && big > 0.05, "2 degrees off the axis: W up to %.3g waves",
          big);
    /* refusals: no rays, the exit pupil on the image plane */
    CHECK(tr->rx_opd(&rx, rq, 0, 0, lam, w, NULL, NULL, NULL, err, sizeof err) == TRACE_EINVAL,
          "n = 0 refused: %s", err);
    CHECK(tr->rx_opd(&rx, rq, k, f, lam, w, NULL, NULL, NULL, err, sizeof err) == TRACE_EINVAL,
          "an exit pupil on the image plane refused: %s", err);
    return unit_failed();
}
