/* bench_aim.c -- the cost of aiming rays at the stop (rx_aim, tr_aim.c), run by
 * scripts/bench_pupil.sh.  The Cooke triplet (tt.h), stop at surface 4, a 20-degree
 * field from infinity, a 32 x 32 grid of pupil points (812 inside the pupil); the
 * baseline is the same rays, once found, traced once each by rx_trace (what a tracer
 * that does not aim costs).  One thread, median of five runs.
 *   aim_rays_per_s       aimed rays a second
 *   aim_vs_trace         time per aimed ray / time per traced ray
 *   aim_traces_per_ray   rays traced per aimed ray (Newton steps, Jacobians, halvings)
 *   aim_iterations_max   Newton steps of the worst ray
 *   aim_residual_max_mm  the largest stop miss */
#include <stdio.h>
#include "tt.h"
#include "bench_util.h"

#define N 32
#define RUNS 5

int main(void)
{
    const trace_api *tr = tt_api();
    trace_lens_surface ls[TT_NSURF];
    trace_lens l;
    trace_rx_surface s[TT_NSURF];
    static trace_aim_req rq[N * N];
    static trace_aim_ray out[N * N];
    char err[256];
    double ta[RUNS], tt[RUNS], th = 20 * 3.14159265358979323846 / 180;
    long traces = 0;
    int n = 0, maxit = 0;
    double maxres = 0;
    tt_triplet(ls, &l, 0);
    memset(s, 0, sizeof s);
    for (int i = 0; i < TT_NSURF; i++) {
        s[i].z = ls[i].z; s[i].radius = ls[i].radius; s[i].n_right = ls[i].n_right;
    }
    /* paraxial base rays to the stop: its size for EPD 12.5 and the EP position */
    double y[2] = {1, 0}, u[2] = {0, 1}, nn = 1;
    for (int k = 0; k <= 3; k++) {
        if (k) for (int j = 0; j < 2; j++) y[j] += u[j] * (s[k].z - s[k - 1].z);
        if (k == 3) break;
        double c = 1 / s[k].radius;
        for (int j = 0; j < 2; j++) u[j] = (nn * u[j] - y[j] * c * (s[k].n_right - nn)) / s[k].n_right;
        nn = s[k].n_right;
    }
    trace_rx rx = {1, TT_NSURF, s, 3, TT_EPD / 2 * fabs(y[0]), tt_paraxial_image(&l, -INFINITY)};
    double z_ep = y[1] / y[0];
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++) {
            double px = -1 + (2.0 * j + 1) / N, py = -1 + (2.0 * i + 1) / N;
            if (px * px + py * py > 1) continue;
            memset(&rq[n], 0, sizeof rq[n]);
            rq[n].infinite = 1;
            rq[n].dir[1] = sin(th);
            rq[n].dir[2] = cos(th);
            rq[n].px = px;
            rq[n].py = py;
            rq[n].guess[0] = px * TT_EPD / 2;
            rq[n].guess[1] = -z_ep * tan(th) + py * TT_EPD / 2;
            n++;
        }
    for (int r = 0; r < RUNS; r++) {
        double t0 = now();
        for (int i = 0; i < n; i++)
            if (tr->rx_aim(&rx, &rq[i], &out[i], err, sizeof err)) { printf("aim: %s\n", err); return 1; }
        ta[r] = (now() - t0) / n;
        t0 = now();
        for (int i = 0; i < n; i++) {
            trace_aim_ray o;
            double p[3];
            for (int k = 0; k < 3; k++) p[k] = out[i].o[k] - 5 * out[i].d[k];
            tr->rx_trace(&rx, p, out[i].d, NULL, &o, err, sizeof err);
        }
        tt[r] = (now() - t0) / n;
    }
    for (int i = 0; i < n; i++) {
        traces += out[i].traces;
        if (out[i].iterations > maxit) maxit = out[i].iterations;
        if (out[i].residual > maxres) maxres = out[i].residual;
    }
    qsort(ta, RUNS, sizeof *ta, cmp);
    qsort(tt, RUNS, sizeof *tt, cmp);
    printf("BENCH aim_rays_per_s %.0f rays/s\n", 1 / ta[RUNS / 2]);
    printf("BENCH aim_vs_trace %.1f x\n", ta[RUNS / 2] / tt[RUNS / 2]);
    printf("BENCH aim_traces_per_ray %.1f rays\n", (double)traces / n);
    printf("BENCH aim_iterations_max %d steps\n", maxit);
    printf("BENCH aim_residual_max_mm %.2g mm\n", maxres);
    return 0;
}
