/* rg_scan.c -- the scan planner (doc/scan-time.md): order a scan's targets to shorten
 * the machine's time, and predict that time split by what sets it.  The cost of a
 * leg is the move's own duration under the rig's profiles (rg_move_time: the same
 * shared trapezoid rg_move_steps runs), not a distance, because the joints differ by
 * orders of magnitude: the stage that carries m2 is slow, the mirrors fast.  The
 * planner only chooses the order: every move and exposure still goes through
 * rig_api.move_steps and expose and their safety checks. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "rig/rg_hw.h"

static const char *const jname[RG_NJOINTS] = {"m1a", "m1b", "u", "v", "m2a", "m2b"};

/* Names for st->limit (static strings: the stats struct is plain data). */
static const char *const speed_name[RG_NJOINTS] = {
    "the speed of m1a", "the speed of m1b", "the speed of the stage u",
    "the speed of the stage v", "the speed of m2a", "the speed of m2b"};
static const char *const accel_name[RG_NJOINTS] = {
    "the acceleration of m1a", "the acceleration of m1b", "the acceleration of the stage u",
    "the acceleration of the stage v", "the acceleration of m2a", "the acceleration of m2b"};

static double leg(const rg_rig *rig, const long *a, const long *b)
{
    return rg_move_time(rig, a, b, NULL, NULL, NULL, NULL);
}

int rg_check_targets(const rg_rig *rig, const long *steps, long n, char *err, size_t cap)
{
    for (long i = 0; i < n; i++)
        for (int j = 0; j < RG_NJOINTS; j++) {
            const rg_axis *x = &rig->axis[j];
            double v = steps[i * RG_NJOINTS + j] / x->steps_per;
            if (v < x->min - 1e-9 || v > x->max + 1e-9) {
                snprintf(err, cap, "target %ld: axis %s at %.6g %s is outside its travel "
                         "[%g, %g]", i + 1, jname[j], v, x->linear ? "mm" : "deg", x->min,
                         x->max);
                return RG_ETRAVEL;
            }
        }
    return 0;
}

/* Path positions 0..n: node 0 is the start pose, node i+1 target i.  A cost matrix
 * when it fits (n <= 2048: 32 MB) and 2-opt on it; else the nearest neighbour alone,
 * its legs recomputed (n = 20000: 2e8 legs, about 5 s). */
typedef struct tour {
    const rg_rig *rig;
    const long *start, *steps;
    long n;
    double *c;                  /* (n+1)^2 or NULL */
} tour;

static const long *row(const tour *t, long node)
{
    return node ? t->steps + (node - 1) * RG_NJOINTS : t->start;
}

static double cost(const tour *t, long a, long b)
{
    if (t->c) return t->c[a * (t->n + 1) + b];
    return leg(t->rig, row(t, a), row(t, b));
}

int rg_scan_order(const rg_rig *rig, const long start[RG_NJOINTS], const long *steps, long n,
                  long *order, char *err, size_t cap)
{
    tour t = {rig, start, steps, n, NULL};
    long *p, cur;
    char *used;
    int rc, better;
    if (n < 0 || (n && (!steps || !order)) || !start) {
        snprintf(err, cap, "scan_order: no targets");
        return RG_EINVAL;
    }
    if (n == 0) return 0;
    if ((rc = rg_check_targets(rig, steps, n, err, cap))) return rc;
    if (n > RG_SCAN_ORDER_MAX) {        /* O(n^2): beyond this, the given order */
        for (long k = 0; k < n; k++) order[k] = k;
        return 0;
    }
    p = malloc((size_t)(n + 1) * sizeof *p);
    used = calloc((size_t)n + 1, 1);
    if (!p || !used) {
        free(p); free(used);
        snprintf(err, cap, "scan_order: out of memory");
        return RG_ENOMEM;
    }
    if (n <= 2048 && (t.c = malloc((size_t)(n + 1) * (size_t)(n + 1) * sizeof *t.c)))
        for (long a = 0; a <= n; a++) {
            t.c[a * (n + 1) + a] = 0;
            for (long b = a + 1; b <= n; b++)   /* a move takes as long either way */
                t.c[a * (n + 1) + b] = t.c[b * (n + 1) + a] = leg(rig, row(&t, a), row(&t, b));
        }
    /* greedy nearest neighbour from the start pose (ties: the lower index) */
    p[0] = cur = 0;
    used[0] = 1;
    for (long k = 1; k <= n; k++) {
        long best = -1;
        double bc = INFINITY;
        for (long b = 1; b <= n; b++)
            if (!used[b]) {
                double c = cost(&t, cur, b);
                if (c < bc) { bc = c; best = b; }
            }
        p[k] = cur = best;
        used[best] = 1;
    }
    /* 2-opt on the open path (node 0 stays first): reverse p[i+1..j] when the two
     * new legs are shorter than the two old ones (j = n: the path's end, one leg) */
    for (int pass = 0; pass < (t.c ? 200 : 0); pass++) {
        better = 0;
        for (long i = 0; i + 2 <= n; i++)
            for (long j = i + 2; j <= n; j++) {
                double d = cost(&t, p[i], p[j]) - cost(&t, p[i], p[i + 1]);
                if (j < n) d += cost(&t, p[i + 1], p[j + 1]) - cost(&t, p[j], p[j + 1]);
                if (d < -1e-12) {
                    for (long a = i + 1, b = j; a < b; a++, b--) {
                        long s = p[a]; p[a] = p[b]; p[b] = s;
                    }
                    better = 1;
                }
            }
        if (!better) break;
    }
    for (long k = 1; k <= n; k++) order[k - 1] = p[k] - 1;
    free(t.c);
    free(p);
    free(used);
    return 0;
}

int rg_scan_time(const rg_rig *rig, const long start[RG_NJOINTS], const long *steps,
                 const long *order, long n, double expose_ms, rg_scan_stats *st, char *err,
                 size_t cap)
{
    const long *from = start;
    double tick = rg_tick_ns(rig) / 1e9, best;
    int rc;
    memset(st, 0, sizeof *st);
    st->n = n;
    if ((rc = rg_check_targets(rig, steps, n, err, cap))) return rc;
    for (long k = 0; k < n; k++) {
        const long *to = steps + (order ? order[k] : k) * RG_NJOINTS;
        int vj, aj;
        double ta, tc, T = rg_move_time(rig, from, to, &vj, &aj, &ta, &tc);
        if (T > 0) {
            /* rg_move_steps: DIR a tick ahead, K = ceil(T / tick) rises, the last
             * pulse's fall half a tick later; then settle_ms */
            st->t_moves += T;
            st->t_ticks += (1 + ceil(T / tick - 1e-9) + 0.5) * tick - T;
            st->t_settle += rig->settle_ms / 1e3;
            if (vj >= 0) st->t_speed[vj] += tc;
            if (aj >= 0) st->t_accel[aj] += ta;
        }
        for (int j = 0; j < RG_NJOINTS; j++) st->path[j] += labs(to[j] - from[j]);
        if (expose_ms > 0)
            st->t_expose += (expose_ms + rig->emission_delay_ms + 2 * rig->shutter_ms) / 1e3;
        from = to;
    }
    st->t_total = st->t_moves + st->t_ticks + st->t_settle + st->t_expose;
    st->limit = "nothing (no move, no exposure)";
    best = 0;
    for (int j = 0; j < RG_NJOINTS; j++) {
        if (st->t_speed[j] > best) { best = st->t_speed[j]; st->limit = speed_name[j]; }
        if (st->t_accel[j] > best) { best = st->t_accel[j]; st->limit = accel_name[j]; }
    }
    if (st->t_settle > best) { best = st->t_settle; st->limit = "the settle time (settle_ms)"; }
    if (st->t_expose > best) { best = st->t_expose; st->limit = "the exposures"; }
    if (st->t_ticks > best) st->limit = "the control step (tick_us)";
    return 0;
}

const char *rg_scan_limit_text(const rg_scan_stats *st, char *buf, size_t cap)
{
    size_t k = 0;
    double T = st->t_total > 0 ? st->t_total : 1;
#define ADD(name, t) do { if ((t) > 0.05 * T && k < cap)                                 \
        k += (size_t)snprintf(buf + k, cap - k, "%s%s %.3g s (%.0f %%)", k ? ", " : "",   \
                              name, (t), 100 * (t) / T); } while (0)
    if (cap) buf[0] = 0;
    for (int j = 0; j < RG_NJOINTS; j++) {
        ADD(accel_name[j], st->t_accel[j]);
        ADD(speed_name[j], st->t_speed[j]);
    }
    ADD("settle", st->t_settle);
    ADD("exposures", st->t_expose);
    ADD("control-step rounding", st->t_ticks);
#undef ADD
    if (k >= cap && cap) buf[cap - 1] = 0;
    return buf;
}
