/* t_scan.c -- the scan planner (rig_api.scan_order, scan_time; doc/scan-time.md) on
 * the simulated chip: the planned order visits every target exactly once and is the
 * same on a second call; run through move_steps and expose, the simulator's log shows
 * every target reached once (its "motors at" counts), no step with the laser on, and
 * no move faster than the axes allow: a move of n steps in D seconds needs
 * n <= speed*D and n <= accel*D^2/4 (the most a profile bounded by the speed and
 * acceleration can cover: an independent bound from kinematics, not the planner's
 * formulas); the predicted time agrees with the simulated clock; the ordered scan
 * takes less time than the spiral's own order.  argv[1]: the example rig file. */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "rig/rig.h"
#include "unit.h"

#define N 40
static const rig_api *rg;
static rg_rig rig;
static long steps[N * RG_NJOINTS];

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    char *buf;
    long n;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    rewind(f);
    buf = malloc((size_t)n + 1);
    if (buf) { n = (long)fread(buf, 1, (size_t)n, f); buf[n] = 0; }
    fclose(f);
    return buf;
}

/* Run the scan in order (NULL: as given) with a log; its simulated time, or -1. */
static double run(const long *order, const char *log, double ms)
{
    rg_open_opts o = {RG_BACKEND_SIM, NULL, NULL, NULL, 0};
    rg_machine *m;
    char err[RG_ERRMAX];
    double t0, t1;
    o.sim_log = log;
    if (rg->open(&rig, &o, &m, err, sizeof err) || rg->home(m, NULL, NULL, err, sizeof err)) {
        printf("FAIL open/home: %s\n", err);
        return -1;
    }
    t0 = rg->clock_s(m);
    for (long k = 0; k < N; k++)
        if (rg->move_steps(m, steps + (order ? order[k] : k) * RG_NJOINTS, NULL, NULL, err,
                           sizeof err) || rg->expose(m, ms, NULL, NULL, err, sizeof err)) {
            printf("FAIL point %ld: %s\n", k, err);
            rg->close(m);
            return -1;
        }
    t1 = rg->clock_s(m);
    rg->close(m);
    return t1 - t0;
}

/* The log's moves: each "moved" line's pulses and motor positions, against the time
 * since the motion could start (the previous exposure's end, or homing's end). */
static void check_log(const char *path, const long *order)
{
    char *log = slurp(path), *line, *save = NULL;
    long moves = 0, seen[N] = {0}, bad_kin = 0, bad_pos = 0, viol = 0, exp_after_move = 0;
    double t_prev = -1, worst = 0;
    int moved_since = 0;
    if (!log) { CHECK(0, "the simulator log %s exists", path); return; }
    for (line = strtok_r(log, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
        double t = atof(line);
        if (strstr(line, "VIOLATION")) viol++;
        if (strstr(line, " homed:") || strstr(line, " laser 0")) t_prev = t;
        if (strstr(line, " laser 1")) { exp_after_move += moved_since; moved_since = 0; }
        if (strstr(line, " moved:")) {
            long pulses[RG_NJOINTS], at[RG_NJOINTS];
            char *p = strstr(line, "pulses");
            double D = t - t_prev - rig.settle_ms / 1e3;
            for (int j = 0; j < RG_NJOINTS; j++) {
                p = strchr(p, '=') + 1;
                pulses[j] = strtol(p, &p, 10);
            }
            p = strstr(p, "motors at") + 9;
            for (int j = 0; j < RG_NJOINTS; j++) at[j] = strtol(p, &p, 10);
            for (int j = 0; j < RG_NJOINTS; j++) {
                const rg_axis *x = &rig.axis[j];
                double vmax = x->speed * x->steps_per * D + 1;
                double amax = x->accel * x->steps_per * D * D / 4 + 1;
                double use = fmax(pulses[j] / vmax, pulses[j] / amax);
                if (use > worst) worst = use;
                if (pulses[j] > vmax || pulses[j] > amax) bad_kin++;
            }
            if (moves < N) {
                long want = order ? order[moves] : moves;
                if (memcmp(at, steps + want * RG_NJOINTS, sizeof at)) bad_pos++;
                else seen[want]++;
            }
            moves++;
            moved_since = 1;
        }
    }
    {
        long once = 0;
        for (long i = 0; i < N; i++) once += seen[i] == 1;
        CHECK(moves == N && once == N && !bad_pos, "%s: %ld moves, every target reached "
              "exactly once (%ld of %d; %ld elsewhere)", path, moves, once, N, bad_pos);
    }
    CHECK(!bad_kin && worst > 0.3, "no move beyond the axes' speed and acceleration "
          "(n <= v D, n <= a D^2/4): worst use %.3f of the bound, %ld over", worst, bad_kin);
    CHECK(!viol && exp_after_move == N, "every exposure after a completed, settled move, "
          "no step with the laser on (%ld violations, %ld of %d)", viol, exp_after_move, N);
    free(log);
}

int main(int argc, char **argv)
{
    char err[RG_ERRMAX], dir[] = "/tmp/t_scan.XXXXXX", l0[64], l1[64], buf[512];
    long order[N], order2[N], start[RG_NJOINTS], count[N] = {0}, perm = 1;
    rg_scan_stats s0, s1;
    double sim0, sim1;
    rg = rig_get_api(RIG_ABI);
    if (!rg || !rg->scan_order || !rg->scan_time || !rg->clock_s) {
        printf("FAIL no scan planner in the table\n");
        return 1;
    }
    if (rg->rig_load(argc > 1 ? argv[1] : "golden/rig/example.rig", &rig, err, sizeof err)) {
        printf("FAIL %s\n", err);
        return 1;
    }
    for (long k = 0; k < N; k++) {
        rg_target t = {RG_T_HEIGHT, 1.8 * sqrt((k + 0.5) / N),
                       fmod(k * 137.50776405003785, 360) * M_PI / 180};
        rg_solution so;
        rg_quantised q;
        if (rg->solve(&rig.geom, &t, NULL, &so, err, sizeof err) ||
            rg->quantise(&rig.geom, &t, &so, &q, err, sizeof err)) {
            printf("FAIL target %ld: %s\n", k, err);
            return 1;
        }
        for (int j = 0; j < RG_NJOINTS; j++) steps[k * RG_NJOINTS + j] = (long)q.steps[j];
    }
    for (int j = 0; j < RG_NJOINTS; j++) {
        const rg_axis *x = &rig.axis[j];
        start[j] = lround(x->home_at * x->steps_per) -
                   x->home_dir * lround(x->home_pulloff * x->steps_per);
    }
    CHECK(rg->scan_order(&rig, start, steps, N, order, err, sizeof err) == RG_OK, "scan_order %s", err);
    for (long k = 0; k < N; k++) {
        if (order[k] < 0 || order[k] >= N) perm = 0;
        else count[order[k]]++;
    }
    for (long k = 0; k < N; k++) perm &= count[k] == 1;
    CHECK(perm, "the order is a permutation: every target exactly once");
    CHECK(rg->scan_order(&rig, start, steps, N, order2, err, sizeof err) == RG_OK &&
          !memcmp(order, order2, sizeof order), "the order is deterministic (a second call)");
    {   /* a target outside travel is refused before anything is ordered */
        long bad[2 * RG_NJOINTS];
        memcpy(bad, steps, sizeof bad);
        bad[RG_NJOINTS + RG_J_U] = lround((rig.axis[RG_J_U].max + 1) * rig.axis[RG_J_U].steps_per);
        CHECK(rg->scan_order(&rig, start, bad, 2, order2, err, sizeof err) == RG_ETRAVEL &&
              strstr(err, "target 2: axis u"), "a target outside travel is refused: %s", err);
    }
    rg->scan_time(&rig, start, steps, NULL, N, 1, &s0, err, sizeof err);
    rg->scan_time(&rig, start, steps, order, N, 1, &s1, err, sizeof err);
    if (!mkdtemp(dir)) { printf("FAIL mkdtemp\n"); return 1; }
    snprintf(l0, sizeof l0, "%s/spiral.log", dir);
    snprintf(l1, sizeof l1, "%s/ordered.log", dir);
    sim0 = run(NULL, l0, 1);
    sim1 = run(order, l1, 1);
    check_log(l0, NULL);
    check_log(l1, order);
    CHECK(sim1 > 0 && sim1 < 0.5 * sim0, "ordered %.3f s against the spiral's order %.3f s "
          "(simulated)", sim1, sim0);
    CHECK(fabs(s0.t_total - sim0) < 1e-3 * sim0 + 1e-3 && fabs(s1.t_total - sim1) < 1e-3 * sim1 + 1e-3,
          "predicted %.4f / %.4f s, simulated %.4f / %.4f s", s0.t_total, s1.t_total, sim0, sim1);
    CHECK(fabs(s1.t_expose - N * 1e-3) < 1e-9 && fabs(s1.t_settle - N * rig.settle_ms / 1e3) < 1e-9,
          "exposures %.4f s, settle %.4f s", s1.t_expose, s1.t_settle);
    rg->scan_limit_text(&s1, buf, sizeof buf);
    /* (the example's stage and m2's mirror axes since its parts were chosen for
       exposure on the fly, doc/scan-time.md: m2 moves, in translation and angle) */
    CHECK((strstr(s1.limit, "stage") || strstr(s1.limit, "m2")) && strstr(buf, "stage"),
          "the example rig is limited by m2 (its stage, its angles): %s; %s", s1.limit, buf);
    unlink(l0);
    unlink(l1);
    rmdir(dir);
    return unit_failed();
}
