/* bench_scan.c -- the scan time (doc/scan-time.md, issue 19 item 6):
 *   BENCH rig_scan1000_stopgo_sim_s  1000 targets of the sunflower spiral (height
 *       zone*sqrt((k+0.5)/n), meridian k * the golden angle), solved and quantised,
 *       ordered by rig_api.scan_order and run on the simulated machine through
 *       rig_api.move_steps and expose: simulated seconds from the first move to the
 *       end of the last exposure (target <= 10);
 *   baseline in the same run: the same targets in the spiral's own order.  Also the
 *   predicted times (rig_api.scan_time) and where the time goes.
 * argv: RIG [N [ZONE_MM [EXPOSE_MS [TAG]]]] (defaults 1000, 1.8, 1); with TAG the
 * BENCH names are rig_scan1000_TAG_sim_s (a variant rig, scripts/bench_rig.sh). */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "rig/rig.h"

static double wall(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + t.tv_nsec / 1e9;
}

/* Home, then visit the targets in order (NULL: as given): simulated seconds from the
 * first move to the last exposure's end, or -1. */
static double run(const rig_api *rg, const rg_rig *rig, const long *steps, const long *order,
                  long n, double ms)
{
    rg_open_opts o = {RG_BACKEND_SIM, NULL, NULL, NULL, 0};
    rg_machine *m;
    char err[RG_ERRMAX];
    double t0, t1;
    if (rg->open(rig, &o, &m, err, sizeof err) || rg->home(m, NULL, NULL, err, sizeof err)) {
        fprintf(stderr, "bench_scan: %s\n", err);
        return -1;
    }
    t0 = rg->clock_s(m);
    for (long k = 0; k < n; k++) {
        const long *s = steps + (order ? order[k] : k) * RG_NJOINTS;
        if (rg->move_steps(m, s, NULL, NULL, err, sizeof err) ||
            (ms > 0 && rg->expose(m, ms, NULL, NULL, err, sizeof err))) {
            fprintf(stderr, "bench_scan: point %ld: %s\n", k + 1, err);
            rg->close(m);
            return -1;
        }
    }
    t1 = rg->clock_s(m);
    rg->close(m);
    return t1 - t0;
}

int main(int argc, char **argv)
{
    const rig_api *rg = rig_get_api(RIG_ABI);
    const char *path = argc > 1 ? argv[1] : "golden/rig/example.rig";
    long n = argc > 2 ? atol(argv[2]) : 1000, ok = 0, *steps, *order, start[RG_NJOINTS];
    double zone = argc > 3 ? atof(argv[3]) : 1.8, ms = argc > 4 ? atof(argv[4]) : 1;
    char err[RG_ERRMAX], buf[1024];
    rg_rig rig;
    rg_scan_stats s0, s1;
    rg_dose dz;
    double w, t_plan, sim0, sim1;
    if (!rg || !rg->scan_order || !rg->clock_s || n < 1) { fprintf(stderr, "bench_scan: setup\n"); return 1; }
    if (rg->rig_load(path, &rig, err, sizeof err)) { fprintf(stderr, "%s\n", err); return 1; }
    steps = malloc((size_t)n * RG_NJOINTS * sizeof *steps);
    order = malloc((size_t)n * sizeof *order);
    if (!steps || !order) return 1;
    for (long k = 0; k < n; k++) {
        rg_target t = {RG_T_HEIGHT, zone * sqrt((k + 0.5) / n),
                       fmod(k * 137.50776405003785, 360) * M_PI / 180};
        rg_solution so;
        rg_quantised q;
        if (rg->solve(&rig.geom, &t, NULL, &so, err, sizeof err) ||
            rg->quantise(&rig.geom, &t, &so, &q, err, sizeof err))
            continue;                       /* unreachable: counted, not visited */
        for (int j = 0; j < RG_NJOINTS; j++) steps[ok * RG_NJOINTS + j] = (long)q.steps[j];
        ok++;
    }
    printf("# bench_scan: %s, %ld of %ld spiral targets reachable (zone %g mm), exposure %g ms\n",
           path, ok, n, zone, ms);
    if (ms > 0 && rg->dose_rig(&rig, ms, ok, &dz, err, sizeof err))
        printf("# dose: %s\n", err);
    else if (ms > 0)
        printf("# dose: %ld exposures of %g ms, %.3g of the MPE (%s)\n", ok, ms, dz.fraction,
               dz.limit);
    /* the start: where homing leaves the machine (home_at less the pull-off) */
    for (int j = 0; j < RG_NJOINTS; j++) {
        const rg_axis *x = &rig.axis[j];
        start[j] = lround(x->home_at * x->steps_per);
        if (x->home.offset >= 0) start[j] -= x->home_dir * lround(x->home_pulloff * x->steps_per);
    }
    w = wall();
    if (rg->scan_order(&rig, start, steps, ok, order, err, sizeof err)) {
        fprintf(stderr, "bench_scan: %s\n", err);
        return 1;
    }
    t_plan = wall() - w;
    rg->scan_time(&rig, start, steps, NULL, ok, ms, &s0, err, sizeof err);
    rg->scan_time(&rig, start, steps, order, ok, ms, &s1, err, sizeof err);
    sim0 = run(rg, &rig, steps, NULL, ok, ms);
    sim1 = run(rg, &rig, steps, order, ok, ms);
    if (sim0 < 0 || sim1 < 0) return 1;
    printf("# unordered (spiral order): simulated %.3f s, predicted %.3f s: %s\n", sim0,
           s0.t_total, rg->scan_limit_text(&s0, buf, sizeof buf));
    printf("# ordered (scan_order, %.3f s of planning): simulated %.3f s, predicted %.3f s: %s\n",
           t_plan, sim1, s1.t_total, rg->scan_limit_text(&s1, buf, sizeof buf));
    printf("# stage travel: u %.1f -> %.1f mm, v %.1f -> %.1f mm\n",
           s0.path[RG_J_U] / rig.axis[RG_J_U].steps_per, s1.path[RG_J_U] / rig.axis[RG_J_U].steps_per,
           s0.path[RG_J_V] / rig.axis[RG_J_V].steps_per, s1.path[RG_J_V] / rig.axis[RG_J_V].steps_per);
    printf("# limited by: %s; ordered/unordered %.3f\n", s1.limit, sim1 / sim0);
    {   /* a floor for any order and any speed/acceleration the rig file accepts: each
         * target is entered from some other pose, a leg takes at least its largest
         * joint's steps times the smallest control step (20 us: one step a tick) */
        double lb = 0;
        for (long i = 0; i < ok; i++) {
            double best = INFINITY;
            for (long k = -1; k < ok; k++) {
                const long *a = steps + i * RG_NJOINTS, *b = k < 0 ? start : steps + k * RG_NJOINTS;
                long mx = 0;
                if (k == i) continue;
                for (int j = 0; j < RG_NJOINTS; j++) mx = labs(a[j] - b[j]) > mx ? labs(a[j] - b[j]) : mx;
                if (mx < best) best = (double)mx;
            }
            lb += best * 20e-6;
        }
        printf("# floor for any order, at one step per 20 us control step on every joint and "
               "unbounded acceleration: moves %.3f s + exposures %.3f s = %.3f s\n", lb,
               ok * ms / 1e3, lb + ok * ms / 1e3);
    }
    if (argc > 5) {
        printf("BENCH rig_scan1000_%s_sim_s %.3f s\n", argv[5], sim1);
        printf("BENCH rig_scan1000_%s_unordered_sim_s %.3f s\n", argv[5], sim0);
    } else {
        printf("BENCH rig_scan1000_stopgo_sim_s %.3f s\n", sim1);
        printf("BENCH rig_scan1000_unordered_sim_s %.3f s\n", sim0);
    }
    free(steps);
    free(order);
    return 0;
}
