/* bench_geom.c -- the rig geometry's figures (scripts/bench_rig.sh):
 *   rig_solution_err_um   largest miss (target or detector point) of the traced beam
 *                         over a 1000-point scan of the example rig, unquantised
 *                         joints, every pose traced through the trace engine;
 *   rig_quantised_err_um  the same scan quantised to the example rig's steps (200 per
 *                         degree, 400 per mm): largest landing error on the cornea
 *                         (and _det_ on the detector), by the forward model, the
 *                         tracer agreeing to 1e-12 mm (t_geom);
 *   the resolution table  landing error against steps per degree and per mm;
 *   rig_plan_points_per_s solve + quantise + plan (step counts and a coordinated
 *                         trapezoidal move from the previous point) + forward check
 *                         of the commanded pose, one thread, the points in scan order
 *                         (a 12-turn spiral); baseline in the same run: the closed
 *                         form alone (mirrors on their axes, no checks);
 *   rig_plan_points_per_cpu_s  the same per second of this thread's CPU time (what
 *                         the code costs when other jobs share the machine);
 *   rig_scan_move_ms_per_point  the mean move time of that scan at 2000 steps/s.
 * Targets: a Fermat spiral out to theta 12 deg (heights to 1.6 mm; the zone the example
 * rig reaches within its travel).  "quick" as argv[1]: fewer repetitions. */
#include <time.h>
#include "rig/rt.h"
#include "bench_util.h"

static const rig_api *rg;
static char err[1024];

/* CPU time of this thread: what the code costs when the machine is shared */
static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return t.tv_sec + t.tv_nsec * 1e-9;
}
static double median3(double a, double b, double c)
{
    return a > b ? (b > c ? b : (a > c ? c : a)) : (a > c ? a : (b > c ? c : b));
}

#define NPTS 1000
#define THMAX (12 * RT_DEG)

/* Coordinated trapezoidal move: the slowest axis sets the time, the others scale
 * their speed and acceleration so all arrive together.  Speeds and accelerations
 * of golden/rig/example.rig: 2000 steps/s, 20000 steps/s^2 on every axis. */
static double plan_move(const int64_t from[RG_NJOINTS], const int64_t to[RG_NJOINTS],
                        double vpk[RG_NJOINTS])
{
    const double v = 2000, a = 20000;
    double dmax = 0;
    for (int k = 0; k < RG_NJOINTS; k++)
        dmax = fmax(dmax, fabs((double)(to[k] - from[k])));
    double T = dmax >= v * v / a ? dmax / v + v / a : 2 * sqrt(dmax / a);
    double vtop = dmax >= v * v / a ? v : sqrt(dmax * a);
    for (int k = 0; k < RG_NJOINTS; k++)
        vpk[k] = dmax > 0 ? vtop * fabs((double)(to[k] - from[k])) / dmax : 0;
    return T;
}

/* One point the way a scan takes it; returns 0 when commanded. */
static int point(const rg_geometry *g, int i, int64_t prev[RG_NJOINTS], double *move_s,
                 double *ec)
{
    rg_target t = rt_scan_path(i, NPTS, THMAX, 12);
    rg_solution s;
    rg_quantised q;
    rg_beam b;
    double vpk[RG_NJOINTS];
    if (rg->solve(g, &t, NULL, &s, err, sizeof err)) return -1;
    if (rg->quantise(g, &t, &s, &q, err, sizeof err)) return -1;
    *move_s += plan_move(prev, q.steps, vpk);
    memcpy(prev, q.steps, sizeof q.steps);
    if (rg->forward(g, &q.pose, &b, err, sizeof err)) return -1;
    *ec = fmax(*ec, rt_dist(b.spot, s.target));
    return 0;
}

static void resolution(const rg_geometry *g0, double spd, double spmm, double *ec,
                       double *ed, int *bad)
{
    rg_geometry g = *g0;
    for (int j = 0; j < RG_NJOINTS; j++)
        g.joint[j].steps_per = (j == RG_J_U || j == RG_J_V) ? spmm : spd / RT_DEG;
    *ec = *ed = 0;
    *bad = 0;
    for (int i = 0; i < NPTS; i += 5) {
        rg_target t = rt_scan(i, NPTS, THMAX);
        rg_solution s;
        rg_quantised q;
        if (rg->solve(&g, &t, NULL, &s, err, sizeof err) ||
            rg->quantise(&g, &t, &s, &q, err, sizeof err)) { (*bad)++; continue; }
        *ec = fmax(*ec, q.err_cornea);
        *ed = fmax(*ed, q.err_detector);
    }
}

int main(int argc, char **argv)
{
    int quick = argc > 1 && !strcmp(argv[1], "quick");
    rg = rt_rig();
    const trace_api *tr = rt_trace();
    rg_geometry g;
    rg->geometry_default(&g);
    if (rg->geometry_check(&g, err, sizeof err)) { fprintf(stderr, "%s\n", err); return 1; }

    /* exactness: every pose of the scan traced */
    double worst = 0, tt = now(), cmin = INFINITY, cmax = 0;
    int unreach = 0, missed = 0;
    for (int i = 0; i < NPTS; i++) {
        rg_target t = rt_scan(i, NPTS, THMAX);
        rg_solution s;
        rg_verify v;
        if (rg->solve(&g, &t, NULL, &s, err, sizeof err)) { unreach++; continue; }
        if (rg->verify(tr, &g, &s.pose, s.target, &v, err, sizeof err) || !v.hit) {
            missed++;
            continue;
        }
        worst = fmax(worst, fmax(v.err_target, v.err_detector));
        cmin = fmin(cmin, s.cond);
        cmax = fmax(cmax, s.cond);
    }
    tt = now() - tt;
    if (unreach || missed) {
        fprintf(stderr, "bench_geom: %d unreachable, %d missed by the tracer\n", unreach, missed);
        return 1;
    }
    printf("BENCH rig_solution_err_um %.3g um\n", worst * 1e3);
    printf("BENCH rig_trace_check_points_per_s %.0f points/s\n", NPTS / tt);
    /* the joints-to-spot map's condition number (one step per joint) over the scan */
    printf("BENCH rig_cond_min %.0f ratio\n", cmin);
    printf("BENCH rig_cond_max %.0f ratio\n", cmax);

    /* quantised, the example rig's steps */
    double ec, ed;
    int bad;
    resolution(&g, 200, 400, &ec, &ed, &bad);
    double ecf = 0, edf = 0;
    for (int i = 0; i < NPTS; i++) {
        rg_target t = rt_scan(i, NPTS, THMAX);
        rg_solution s;
        rg_quantised q;
        if (rg->solve(&g, &t, NULL, &s, err, sizeof err) ||
            rg->quantise(&g, &t, &s, &q, err, sizeof err)) { bad++; continue; }
        ecf = fmax(ecf, q.err_cornea);
        edf = fmax(edf, q.err_detector);
    }
    printf("BENCH rig_quantised_err_um %.3f um\n", ecf * 1e3);
    printf("BENCH rig_quantised_det_err_um %.2f um\n", edf * 1e3);

    /* the resolution table (every 5th point of the scan) */
    static const double spd[] = {50, 100, 200, 500, 1000, 2000, 5000};
    static const double spmm[] = {100, 400, 1600, 6400};
    printf("# rig resolution table: largest landing error over 200 targets (theta <= 12 deg),\n"
           "# cornea um / detector um; rows steps per degree, columns steps per mm\n");
    printf("# %-9s", "steps/deg");
    for (size_t c = 0; c < sizeof spmm / sizeof *spmm; c++) printf(" %17.0f/mm", spmm[c]);
    printf("\n");
    for (size_t r = 0; r < sizeof spd / sizeof *spd; r++) {
        printf("# %-9.0f", spd[r]);
        for (size_t c = 0; c < sizeof spmm / sizeof *spmm; c++) {
            resolution(&g, spd[r], spmm[c], &ec, &ed, &bad);
            printf(" %9.3f / %8.2f", ec * 1e3, ed * 1e3);
            if (spmm[c] == 400)
                printf("%s", "");
        }
        printf("\n");
    }
    for (size_t r = 0; r < sizeof spd / sizeof *spd; r++) {
        resolution(&g, spd[r], 400, &ec, &ed, &bad);
        printf("BENCH rig_res_%.0fspd_cornea_um %.3f um\n", spd[r], ec * 1e3);
        printf("BENCH rig_res_%.0fspd_detector_um %.2f um\n", spd[r], ed * 1e3);
    }

    /* speed: the path a scan takes, one thread */
    int reps = quick ? 3 : 20;
    double rate[3], base[3], crate[3], move_s = 0;
    rg_geometry z = g;
    z.m1.offset = z.m2.offset = 0;
    rg_solve_opts fast = {0};
    fast.no_checks = 1;
    for (int k = 0; k < 3; k++) {
        int64_t prev[RG_NJOINTS] = {0};
        double e = 0, t0 = now(), c0 = cpu_now();
        int n = 0;
        move_s = 0;
        for (int r = 0; r < reps; r++)
            for (int i = 0; i < NPTS; i++) n += point(&g, i, prev, &move_s, &e) == 0;
        rate[k] = n / (now() - t0);
        crate[k] = n / (cpu_now() - c0);
        if (n != reps * NPTS) { fprintf(stderr, "bench_geom: %d points failed\n", reps * NPTS - n); return 1; }
        t0 = now();
        n = 0;
        for (int r = 0; r < reps; r++)
            for (int i = 0; i < NPTS; i++) {
                rg_target t = rt_scan(i, NPTS, THMAX);
                rg_solution s;
                n += rg->solve(&z, &t, &fast, &s, err, sizeof err) == 0;
            }
        base[k] = n / (now() - t0);
    }
    double pr = median3(rate[0], rate[1], rate[2]), br = median3(base[0], base[1], base[2]);
    printf("BENCH rig_plan_points_per_s %.0f points/s\n", pr);
    printf("BENCH rig_plan_points_per_cpu_s %.0f points/s\n", median3(crate[0], crate[1], crate[2]));
    printf("BENCH rig_closed_form_points_per_s %.0f points/s\n", br);
    printf("BENCH rig_plan_vs_closed_form %.2f ratio\n", pr / br);
    /* the moves of that path at the example rig's speeds: the pitfall of section 39 */
    printf("BENCH rig_scan_move_ms_per_point %.2f ms\n", move_s / reps / NPTS * 1e3);
    return 0;
}
