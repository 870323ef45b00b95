/* rg_motion.c -- poses to step counts, coordinated trapezoidal moves and homing.
 * Motion runs on a fixed control step (tick_us): at each tick every axis due a step
 * raises its STEP line in one bulk call, half a tick later they all fall, so an
 * axis makes at most one step per tick (the rig file refuses faster speeds).  A move
 * is one normalised trapezoid s(t) in [0, 1] shared by all axes (axis j at
 * floor(N_j s(t))): the axes start, accelerate, cruise and arrive together, each
 * within its own speed and acceleration.  Deadlines are absolute (the chip's
 * sleep_until: clock_nanosleep TIMER_ABSTIME on the real clock), so lateness never
 * accumulates.  Every move is checked against travel before its first pulse. */
#define _DEFAULT_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "rig/rg_hw.h"

static const char *const jname[RG_NJOINTS] = {"m1a", "m1b", "u", "v", "m2a", "m2b"};

int64_t rg_tick_ns(const rg_rig *rig) { return (int64_t)llround(rig->tick_us * 1e3); }

static double unit_of(const rg_axis *x) { return x->linear ? 1 : M_PI / 180; }

void rg_wait(rg_machine *m, int64_t deadline) { m->chip->ops->sleep_until(m->chip, deadline); }

/* After an edge: how late it came (real-clock backends only). */
static void edge_done(rg_machine *m, int64_t deadline)
{
    int64_t late;
    if (!m->measure || !m->late) return;
    late = m->chip->ops->now(m->chip) - deadline;
    m->late[m->late_n++ % RG_TIMING_MAX] = (float)(late / 1e3);
}

static int check_travel(const rg_rig *rig, int j, long steps, char *err, size_t cap)
{
    const rg_axis *x = &rig->axis[j];
    double v = steps / x->steps_per;
    double eps = 1e-9 * (fabs(x->min) + fabs(x->max) + 1);
    if (v < x->min - eps || v > x->max + eps) {
        snprintf(err, cap, "axis %s: %.6g %s is outside its travel [%g, %g]", jname[j], v,
                 x->linear ? "mm" : "deg", x->min, x->max);
        return RG_ETRAVEL;
    }
    return 0;
}

int rg_pose_steps(const rg_rig *rig, const rg_pose *p, long steps[RG_NJOINTS], char *err,
                  size_t cap)
{
    for (int j = 0; j < RG_NJOINTS; j++) {
        const rg_axis *x = &rig->axis[j];
        double v = p->j[j] / unit_of(x) * x->steps_per;
        int rc;
        if (!isfinite(v) || fabs(v) > 1e15) {
            snprintf(err, cap, "axis %s: the value is not a finite position", jname[j]);
            return RG_ETRAVEL;
        }
        steps[j] = lround(v);
        if ((rc = check_travel(rig, j, steps[j], err, cap))) return rc;
    }
    return 0;
}

void rg_position(const rg_machine *m, long steps[RG_NJOINTS], rg_pose *p)
{
    for (int j = 0; j < RG_NJOINTS; j++) {
        const rg_axis *x = &m->rig.axis[j];
        if (steps) steps[j] = m->pos[j];
        if (p) p->j[j] = m->pos[j] / x->steps_per * unit_of(x);
    }
}

/* The normalised trapezoid: accelerate at A to V, cruise, decelerate; distance 1. */
typedef struct trap { double A, V, ta, tc, T; } trap;

static void trap_plan(trap *t, double V, double A)
{
    if (V * V / A >= 1) {               /* never reaches V: a triangle */
        t->ta = sqrt(1 / A);
        t->V = A * t->ta;
        t->tc = 0;
    } else {
        t->ta = V / A;
        t->V = V;
        t->tc = (1 - V * V / A) / V;
    }
    t->A = A;
    t->T = 2 * t->ta + t->tc;
}

static double trap_s(const trap *t, double x)
{
    if (x <= 0) return 0;
    if (x >= t->T) return 1;
    if (x < t->ta) return 0.5 * t->A * x * x;
    if (x < t->ta + t->tc) return 0.5 * t->A * t->ta * t->ta + t->V * (x - t->ta);
    return 1 - 0.5 * t->A * (t->T - x) * (t->T - x);
}

static int stopped(rg_stop_fn stop, void *ctx) { return stop && stop(ctx); }

/* One tick's pulse on the axes in mask: STEP up at deadline, down half a tick later. */
static void pulse(rg_machine *m, unsigned mask, int64_t at, int64_t tick)
{
    const rg_chip_ops *o = m->chip->ops;
    rg_wait(m, at);
    o->set(m->chip, RG_G_STEP, mask, mask);
    edge_done(m, at);
    rg_wait(m, at + tick / 2);
    o->set(m->chip, RG_G_STEP, mask, 0);
    edge_done(m, at + tick / 2);
}

static void set_dirs(rg_machine *m, const int sign[RG_NJOINTS])
{
    unsigned mask = 0, val = 0;
    for (int j = 0; j < RG_NJOINTS; j++) {
        if (!sign[j]) continue;
        mask |= 1u << j;
        if ((sign[j] > 0) ^ m->rig.axis[j].dir_invert) val |= 1u << j;
    }
    if (mask) m->chip->ops->set(m->chip, RG_G_DIR, mask, val);
}

static void note(rg_machine *m, const char *what)
{
    if (m->chip->ops->note) m->chip->ops->note(m->chip, what);
}

/* The shared trapezoid of a move: V and A of the normalised profile (the tightest
 * axis's speed and acceleration over its distance).  0, or RG_ETRAVEL. */
static int plan(const rg_rig *rig, const long from[RG_NJOINTS], const long to[RG_NJOINTS],
                long n[RG_NJOINTS], int sign[RG_NJOINTS], trap *tp, char *err, size_t cap)
{
    double V = INFINITY, A = INFINITY;
    int any = 0, rc;
    for (int j = 0; j < RG_NJOINTS; j++)
        if ((rc = check_travel(rig, j, to[j], err, cap))) return rc;
    for (int j = 0; j < RG_NJOINTS; j++) {
        const rg_axis *x = &rig->axis[j];
        long d = to[j] - from[j];
        n[j] = labs(d);
        sign[j] = d > 0 ? 1 : d < 0 ? -1 : 0;
        if (!n[j]) continue;
        any = 1;
        V = fmin(V, x->speed * x->steps_per / n[j]);
        A = fmin(A, x->accel * x->steps_per / n[j]);
    }
    if (any) trap_plan(tp, V, A);
    else memset(tp, 0, sizeof *tp);
    return 0;
}

int rg_plan_move(const rg_rig *rig, const long from[RG_NJOINTS], const long to[RG_NJOINTS],
                 double *seconds, char *err, size_t cap)
{
    long n[RG_NJOINTS];
    int sign[RG_NJOINTS];
    trap tp;
    int rc = plan(rig, from, to, n, sign, &tp, err, cap);
    *seconds = rc ? 0 : tp.T;
    return rc;
}

int rg_move_steps(rg_machine *m, const long target[RG_NJOINTS], rg_stop_fn stop, void *ctx,
                  char *err, size_t cap)
{
    const rg_rig *rig = &m->rig;
    long n[RG_NJOINTS], done[RG_NJOINTS] = {0};
    int sign[RG_NJOINTS];
    int64_t tick = rg_tick_ns(rig), t0;
    trap tp;
    int rc;
    long k, K;

    if (!m->homed) { snprintf(err, cap, "the machine is not homed: home it first"); return RG_EINVAL; }
    if ((rc = plan(rig, m->pos, target, n, sign, &tp, err, cap))) return rc;
    if (m->laser_on) rg_laser_off(m);   /* never: expose returns with it off */
    if (tp.T == 0) return 0;
    set_dirs(m, sign);
    t0 = m->chip->ops->now(m->chip) + tick;      /* DIR set up a tick before the first edge */
    K = (long)ceil(tp.T * 1e9 / tick);
    for (k = 1; k <= K; k++) {
        double s = k == K ? 1 : trap_s(&tp, k * (tick / 1e9));
        unsigned mask = 0;
        if (stopped(stop, ctx)) {
            for (int j = 0; j < RG_NJOINTS; j++) m->pos[j] += sign[j] * done[j];
            m->homed = 0;   /* a stepper stopped at speed may lose steps */
            note(m, "stopped (position no longer known: home again)");
            snprintf(err, cap, "the move was stopped");
            return RG_ESTOP;
        }
        for (int j = 0; j < RG_NJOINTS; j++) {
            long want = k == K ? n[j] : (long)floor(n[j] * s);
            if (want > done[j]) { mask |= 1u << j; done[j]++; }
        }
        if (mask) pulse(m, mask, t0 + k * tick, tick);
        /* rounding may leave an axis a step behind at the end: finish it */
        if (k == K) {
            int behind;
            do {
                behind = 0; mask = 0;
                for (int j = 0; j < RG_NJOINTS; j++)
                    if (done[j] < n[j]) { mask |= 1u << j; done[j]++; behind = 1; }
                if (behind) { K++; pulse(m, mask, t0 + K * tick, tick); }
            } while (behind);
        }
    }
    for (int j = 0; j < RG_NJOINTS; j++) m->pos[j] = target[j];
    if (rig->settle_ms > 0)
        rg_wait(m, m->chip->ops->now(m->chip) + (int64_t)llround(rig->settle_ms * 1e6));
    note(m, "moved");
    return 0;
}

int rg_move(rg_machine *m, const rg_pose *p, rg_stop_fn stop, void *ctx, char *err,
            size_t cap)
{
    long steps[RG_NJOINTS];
    int rc = rg_pose_steps(&m->rig, p, steps, err, cap);
    if (rc) return rc;
    return rg_move_steps(m, steps, stop, ctx, err, cap);
}

/* Homing: every axis with a switch at once, at its home speed: first off the switch
 * if it already reads tripped, then toward it until it trips; that step is home_at.
 * Gives up after home_timeout_s (a broken switch or wire must not drive forever). */
static int home_phase(rg_machine *m, unsigned axes, int toward, rg_stop_fn stop, void *ctx,
                      char *err, size_t cap)
{
    const rg_rig *rig = &m->rig;
    const rg_chip_ops *o = m->chip->ops;
    int64_t tick = rg_tick_ns(rig), t0 = o->now(m->chip) + tick, t;
    int64_t limit = (int64_t)llround(rig->home_timeout_s * 1e9);
    double acc[RG_NJOINTS] = {0};
    int sign[RG_NJOINTS] = {0};
    unsigned left = axes;
    for (int j = 0; j < RG_NJOINTS; j++)
        if (axes >> j & 1) sign[j] = toward ? rig->axis[j].home_dir : -rig->axis[j].home_dir;
    set_dirs(m, sign);
    for (long k = 1; left; k++) {
        unsigned lv, ed, mask = 0;
        t = t0 + k * tick;
        if (stopped(stop, ctx)) {
            snprintf(err, cap, "homing was stopped");
            note(m, "stopped (homing)");
            return RG_ESTOP;
        }
        if (t - t0 > limit) {
            int j = __builtin_ctz(left);
            snprintf(err, cap, "axis %s: its home switch (line %d) did not %s within %g s",
                     jname[j], rig->axis[j].home.offset, toward ? "trip" : "release",
                     rig->home_timeout_s);
            note(m, "stopped (homing timed out)");
            return RG_ETIMEOUT;
        }
        o->inputs(m->chip, &lv, &ed);
        for (int j = 0; j < RG_NJOINTS; j++) {
            if (!(left >> j & 1)) continue;
            if (!!(lv >> j & 1) == !!toward) { left &= ~(1u << j); continue; }
            acc[j] += rig->axis[j].home_speed * rig->axis[j].steps_per * (tick / 1e9);
            if (acc[j] >= 1) { acc[j] -= 1; mask |= 1u << j; m->pos[j] += sign[j]; }
        }
        if (mask) pulse(m, mask, t, tick);
        else rg_wait(m, t);
    }
    return 0;
}

int rg_home(rg_machine *m, rg_stop_fn stop, void *ctx, char *err, size_t cap)
{
    const rg_rig *rig = &m->rig;
    unsigned axes = 0, lv, ed, on = 0;
    int rc;
    if (m->laser_on) rg_laser_off(m);
    for (int j = 0; j < RG_NJOINTS; j++) {
        if (rig->axis[j].home.offset >= 0) axes |= 1u << j;
        if (rig->axis[j].enable.offset >= 0) on |= 1u << j;
    }
    m->homed = 0;
    m->chip->ops->set(m->chip, RG_G_ENABLE, on, on);     /* drivers on, and stay on */
    m->chip->ops->inputs(m->chip, &lv, &ed);
    if ((rc = home_phase(m, axes & lv, 0, stop, ctx, err, cap)) ||
        (rc = home_phase(m, axes, 1, stop, ctx, err, cap)))
        return rc;
    for (int j = 0; j < RG_NJOINTS; j++)
        m->pos[j] = lround(rig->axis[j].home_at * rig->axis[j].steps_per);
    m->homed = 1;
    note(m, "homed");
    return 0;
}
