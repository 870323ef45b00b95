/* bench_step_jitter.c -- BENCH rig_step_jitter_us: p99 lateness of the STEP edges of
 * a 10 s move at 2 kHz (one axis, a step every 500 us control step, both edges
 * timed) on the real clock with a do-nothing chip (the null backend), with
 * SCHED_FIFO and mlockall when permitted.  Baseline, same run: a bare
 * clock_nanosleep loop on the same deadlines (the timer's own lateness).
 * argv[1]: seconds (default 10). */
#define _GNU_SOURCE
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "rig/rig.h"

static const char *rig_text(double seconds)
{
    static char buf[8192];
    static const char *const names[RG_NJOINTS] = {"m1a", "m1b", "u", "v", "m2a", "m2b"};
    /* max_late_us: this bench measures the lateness, so it must not stop the move for
     * it (the null chip drives no motor) */
    int n = snprintf(buf, sizeof buf, "chip null\ntick_us 500\nlaser 30\ninterlock 31\n"
                     "max_on_ms 10\nmax_late_us 1000000000\n");
    for (int j = 0; j < RG_NJOINTS; j++)
        n += snprintf(buf + n, sizeof buf - n, "axis %s\nstep %d\ndir %d\nsteps_per 100\n"
                      "min -1e6\nmax 1e6\nspeed 20\naccel 1e5\nhome_at 0\n", names[j], j,
                      6 + j);
    (void)seconds;
    return buf;
}

static int cmpd(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static int64_t now_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000000000 + t.tv_nsec;
}

/* The timer alone: sleep to each edge deadline (every 250 us), note the lateness. */
static double baseline_p99(double seconds)
{
    long n = (long)(seconds * 4000);
    double *late = malloc(n * sizeof *late), p;
    int64_t t0 = now_ns() + 1000000;
    for (long k = 0; k < n; k++) {
        int64_t d = t0 + k * 250000;
        struct timespec ts = {(time_t)(d / 1000000000), (long)(d % 1000000000)};
        while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == EINTR) {}
        late[k] = (now_ns() - d) / 1e3;
    }
    qsort(late, n, sizeof *late, cmpd);
    p = late[(long)(n * 0.99)];
    free(late);
    return p;
}

int main(int argc, char **argv)
{
    double seconds = argc > 1 ? atof(argv[1]) : 10;
    const rig_api *rg = rig_get_api(RIG_ABI);
    rg_rig rig;
    rg_machine *m;
    rg_open_opts o = {RG_BACKEND_NULL, NULL, NULL, NULL, 1};
    char err[RG_ERRMAX];
    long t[RG_NJOINTS] = {0};
    rg_timing tm;
    const char *txt = rig_text(seconds);
    double base;
    int64_t t0;
    if (rg->rig_parse(txt, strlen(txt), "bench.rig", &rig, err, sizeof err) ||
        rg->open(&rig, &o, &m, err, sizeof err) || rg->home(m, NULL, NULL, err, sizeof err)) {
        fprintf(stderr, "bench_step_jitter: %s\n", err);
        return 1;
    }
    t[0] = (long)(seconds * 2000);
    t0 = now_ns();
    if (rg->move_steps(m, t, NULL, NULL, err, sizeof err)) {
        fprintf(stderr, "bench_step_jitter: %s\n", err);
        return 1;
    }
    rg->timing(m, &tm);
    printf("# rig step timing: %ld edges in %.2f s, p50 %.1f us, p99 %.1f us, max %.1f us; "
           "%s\n", tm.edges, (now_ns() - t0) / 1e9, tm.p50_us, tm.p99_us, tm.max_us,
           rg->sched_note(m));
    rg->close(m);
    base = baseline_p99(seconds);
    printf("BENCH rig_step_jitter_us %.1f us\n", tm.p99_us);
    printf("BENCH rig_step_jitter_max_us %.1f us\n", tm.max_us);
    printf("BENCH rig_step_jitter_timer_p99_us %.1f us\n", base);
    printf("BENCH rig_step_jitter_vs_timer %.2f ratio\n", base > 0 ? tm.p99_us / base : 0);
    return 0;
}
