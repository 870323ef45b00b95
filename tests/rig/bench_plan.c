/* bench_plan.c -- BENCH rig_plan_machine_points_per_s: what each scan point costs before the
 * motors turn, one thread: solve (section 38), quantise (stage first, angles
 * re-solved), plan the coordinated move from the previous point (travel checked,
 * trapezoid) and the forward check of the quantised pose, over the sunflower scan of
 * the --rig dialogue on the example rig (argv[1]), 1 000 points to 1.8 mm, median of 5.
 * Baseline in the same run: the forward model alone on the same poses. */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "rig/rig.h"

#define N 1000

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + t.tv_nsec / 1e9;
}

static int cmpd(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    const rig_api *rg = rig_get_api(RIG_ABI);
    static rg_rig rig;
    static rg_pose poses[N];
    char err[RG_ERRMAX];
    double runs[5], fwd[5], T = 0;
    int bad = 0;
    if (rg->rig_load(argc > 1 ? argv[1] : "golden/rig/example.rig", &rig, err, sizeof err)) {
        fprintf(stderr, "bench_plan: %s\n", err);
        return 1;
    }
    for (int r = 0; r < 5; r++) {
        long from[RG_NJOINTS] = {0}, to[RG_NJOINTS];
        double t0 = now_s();
        bad = 0;
        for (int k = 0; k < N; k++) {
            rg_target t = {RG_T_HEIGHT, 1.8 * sqrt((k + 0.5) / N),
                           fmod(k * 137.50776405, 360) * M_PI / 180};
            rg_solution s;
            rg_quantised q;
            rg_beam b;
            double secs;
            if (rg->solve(&rig.geom, &t, NULL, &s, err, sizeof err) ||
                rg->quantise(&rig.geom, &t, &s, &q, err, sizeof err)) { bad++; continue; }
            for (int j = 0; j < RG_NJOINTS; j++) to[j] = (long)q.steps[j];
            if (rg->plan_move(&rig, from, to, &secs, err, sizeof err) ||
                rg->forward(&rig.geom, &q.pose, &b, err, sizeof err)) { bad++; continue; }
            T += secs;
            poses[k] = q.pose;
            for (int j = 0; j < RG_NJOINTS; j++) from[j] = to[j];
        }
        runs[r] = N / (now_s() - t0);
        t0 = now_s();
        for (int k = 0; k < N; k++) {
            rg_beam b;
            rg->forward(&rig.geom, &poses[k], &b, err, sizeof err);
        }
        fwd[r] = N / (now_s() - t0);
    }
    qsort(runs, 5, sizeof *runs, cmpd);
    qsort(fwd, 5, sizeof *fwd, cmpd);
    printf("# rig plan: %d points to 1.8 mm, %d refused, motion %.1f s per point, one thread\n", N,
           bad, T / 5 / N);
    printf("BENCH rig_plan_machine_points_per_s %.0f points/s\n", runs[2]);
    printf("BENCH rig_plan_forward_only_per_s %.0f points/s\n", fwd[2]);
    printf("BENCH rig_plan_vs_forward %.3f ratio\n", runs[2] / fwd[2]);
    return bad != 0;
}
