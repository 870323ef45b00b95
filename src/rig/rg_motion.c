/* rg_motion.c -- poses to step counts, coordinated trapezoidal moves and homing.
 * Motion runs on a fixed control step (tick_us): at each tick every axis due a step
 * raises its STEP line in one bulk call, half a tick later they all fall, so an
 * axis makes at most one step per tick (the rig file refuses faster speeds).  A move
 * is one normalised trapezoid s(t) in [0, 1] shared by all axes (axis j at
 * floor(N_j s(t))): the axes start, accelerate, cruise and arrive together, each
 * within its own speed and acceleration.  Deadlines are absolute (the chip's
 * sleep_until: clock_nanosleep TIMER_ABSTIME on the real clock), so lateness never
 * accumulates.  Every move is checked against travel before its first pulse.
 * Safety (doc/rig-safety.md): every control step reads the interlock and the limit
 * switches (rg_guard: a fault latches and no further pulse goes out); each rising
 * STEP edge measures its own lateness and one later than max_late_us stops the
 * motion (a latched deadline fault) instead of sending a burst the motor cannot
 * follow; a pulse stays high at least step_pulse_us after its rising edge really
 * happened, however late the fall's deadline is, and low as long before the next
 * rise (catch-up pulses after a preemption are spaced, never back to back); a chip that knows the motors
 * (the simulator) is compared with the commanded steps after every move (a lost step
 * latches).  Homing is GRBL's cycle: fast seek, pull-off, slow locate, debounce,
 * pull-off again, then settle_ms. */
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

/* One tick's pulse on the axes in mask: STEP up at deadline, down half a tick later
 * but never sooner than step_pulse_us after the rise really happened.  First the
 * guard (interlock, limits) and the lateness: a rise later than max_late_us is not
 * sent (the motion stops, latched).  0 or the fault's code. */
int rg_pulse(rg_machine *m, unsigned mask, int64_t at, int64_t tick, char *err, size_t cap)
{
    const rg_chip_ops *o = m->chip->ops;
    int64_t rise, fall, late, maxlate = (int64_t)llround(m->rig.max_late_us * 1e3);
    int rc;
    rg_wait(m, at);
    if ((rc = rg_guard(m, 0, err, cap))) return rc;
    late = o->now(m->chip) - at;
    if (late > maxlate)
        return rg_latch(m, RG_F_DEADLINE, RG_EFAULT, err, cap, "a STEP edge came %.3f ms late "
                        "(max_late_us %g): the motion was stopped rather than send steps "
                        "the motor may not follow", late / 1e6, m->rig.max_late_us);
    /* the drivers' minimum low time too: after a late pulse, catch-up pulses are
     * spaced, never back to back */
    if (o->now(m->chip) < m->last_rise + (int64_t)llround(m->rig.step_pulse_us * 1e3))
        rg_wait(m, m->last_rise + (int64_t)llround(m->rig.step_pulse_us * 1e3));
    o->set(m->chip, RG_G_STEP, mask, mask);
    rise = o->now(m->chip);
    edge_done(m, at);
    fall = at + tick / 2;
    if (fall < rise + (int64_t)llround(m->rig.step_pulse_us * 1e3))
        fall = rise + (int64_t)llround(m->rig.step_pulse_us * 1e3);
    rg_wait(m, fall);
    o->set(m->chip, RG_G_STEP, mask, 0);
    m->last_rise = o->now(m->chip);      /* (the fall: the low time starts here) */
    edge_done(m, at + tick / 2);
    return 0;
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

/* A move's duration without the travel check (the scan planner's cost: called a
 * million times), and what set it: the joint whose speed capped the shared profile
 * (*vj, its cruise time *t_cruise) and the joint whose acceleration did (*aj, the
 * accelerating and braking time *t_acc); -1 for a null move. */
double rg_move_time(const rg_rig *rig, const long from[RG_NJOINTS], const long to[RG_NJOINTS],
                    int *vj, int *aj, double *t_acc, double *t_cruise)
{
    double V = INFINITY, A = INFINITY;
    int jv = -1, ja = -1;
    trap tp;
    for (int j = 0; j < RG_NJOINTS; j++) {
        const rg_axis *x = &rig->axis[j];
        long n = labs(to[j] - from[j]);
        double v, a;
        if (!n) continue;
        v = x->speed * x->steps_per / n;
        a = x->accel * x->steps_per / n;
        if (v < V) { V = v; jv = j; }
        if (a < A) { A = a; ja = j; }
    }
    if (vj) *vj = jv;
    if (aj) *aj = ja;
    if (ja < 0) { if (t_acc) *t_acc = 0; if (t_cruise) *t_cruise = 0; return 0; }
    trap_plan(&tp, V, A);
    if (t_acc) *t_acc = 2 * tp.ta;
    if (t_cruise) *t_cruise = tp.tc;
    return tp.T;
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

/* settle_ms at rest, the guard still read every control step. */
int rg_settle(rg_machine *m, char *err, size_t cap)
{
    const rg_chip_ops *o = m->chip->ops;
    int64_t tick = rg_tick_ns(&m->rig), end = o->now(m->chip) + (int64_t)llround(m->rig.settle_ms * 1e6);
    int rc;
    if (!(m->rig.settle_ms > 0)) return 0;
    for (int64_t t = o->now(m->chip) + tick; ; t += tick) {
        rg_wait(m, t < end ? t : end);
        if ((rc = rg_guard(m, 0, err, cap))) return rc;
        if (t >= end) return 0;
    }
}

/* Where the chip knows the motors (the simulator; an encoder would do the same): a
 * motor that is not where it was sent lost steps. */
int rg_lost_steps(rg_machine *m, char *err, size_t cap)
{
    long real[RG_NJOINTS];
    if (!m->chip->ops->motors || !m->chip->ops->motors(m->chip, real)) return 0;
    for (int j = 0; j < RG_NJOINTS; j++)
        if (real[j] != m->pos[j])
            return rg_latch(m, RG_F_LOSTSTEP, RG_EFAULT, err, cap, "axis %s is %ld steps off "
                            "its commanded position: a lost step", jname[j],
                            real[j] - m->pos[j]);
    return 0;
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

    if ((rc = rg_latched(m, err, cap))) return rc;
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
        if (mask && (rc = rg_pulse(m, mask, t0 + k * tick, tick, err, cap))) {
            for (int j = 0; j < RG_NJOINTS; j++)
                if (mask >> j & 1) done[j]--;      /* not sent */
            for (int j = 0; j < RG_NJOINTS; j++) m->pos[j] += sign[j] * done[j];
            note(m, "stopped (fault)");
            return rc;
        }
        /* rounding may leave an axis a step behind at the end: finish it */
        if (k == K) {
            int behind;
            do {
                behind = 0; mask = 0;
                for (int j = 0; j < RG_NJOINTS; j++)
                    if (done[j] < n[j]) { mask |= 1u << j; done[j]++; behind = 1; }
                if (behind) {
                    K++;
                    if ((rc = rg_pulse(m, mask, t0 + K * tick, tick, err, cap))) {
                        for (int j = 0; j < RG_NJOINTS; j++) {
                            if (mask >> j & 1) done[j]--;
                            m->pos[j] += sign[j] * done[j];
                        }
                        note(m, "stopped (fault)");
                        return rc;
                    }
                }
            } while (behind);
        }
    }
    for (int j = 0; j < RG_NJOINTS; j++) m->pos[j] = target[j];
    if ((rc = rg_settle(m, err, cap))) return rc;
    if ((rc = rg_lost_steps(m, err, cap))) return rc;
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

/* Homing (GRBL's cycle): every axis with a switch at once.  A phase moves the axes in
 * `axes` toward (toward=1) or away from their switches at `speed` (0: home_speed,
 * 1: home_locate_speed) until the switch reads tripped (toward) or released (away),
 * or, with `dist` set, for home_pulloff exactly (then the switch must read released
 * at the end: a pull-off that does not clear it is a fault).  Gives up after
 * home_timeout_s (a broken switch or wire must not drive forever).  The guard
 * (interlock, limits) is read every control step. */
static int home_phase(rg_machine *m, unsigned axes, int toward, int slow, int dist,
                      rg_stop_fn stop, void *ctx, char *err, size_t cap)
{
    const rg_rig *rig = &m->rig;
    const rg_chip_ops *o = m->chip->ops;
    int64_t tick = rg_tick_ns(rig), t0 = o->now(m->chip) + tick, t;
    int64_t limit = (int64_t)llround(rig->home_timeout_s * 1e9);
    double acc[RG_NJOINTS] = {0};
    long togo[RG_NJOINTS] = {0};
    int sign[RG_NJOINTS] = {0}, rc;
    unsigned left = axes;
    for (int j = 0; j < RG_NJOINTS; j++)
        if (axes >> j & 1) {
            sign[j] = toward ? rig->axis[j].home_dir : -rig->axis[j].home_dir;
            togo[j] = lround(rig->axis[j].home_pulloff * rig->axis[j].steps_per);
        }
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
            note(m, "stopped (homing timed out)");
            return rg_latch(m, RG_F_HOMING, RG_ETIMEOUT, err, cap, "axis %s: its home switch "
                            "(line %d) did not %s within %g s", jname[j],
                            rig->axis[j].home.offset, toward ? "trip" : "release",
                            rig->home_timeout_s);
        }
        o->inputs(m->chip, &lv, &ed);
        for (int j = 0; j < RG_NJOINTS; j++) {
            double v;
            if (!(left >> j & 1)) continue;
            if (dist ? togo[j] == 0 : !!(lv >> j & 1) == !!toward) {
                if (dist && (lv >> j & 1)) {
                    note(m, "stopped (homing: pull-off)");
                    return rg_latch(m, RG_F_HOMING, RG_EFAULT, err, cap, "axis %s: the "
                                    "pull-off of %g did not clear its home switch (line %d)",
                                    jname[j], rig->axis[j].home_pulloff,
                                    rig->axis[j].home.offset);
                }
                left &= ~(1u << j);
                continue;
            }
            v = slow ? rig->axis[j].home_locate_speed : rig->axis[j].home_speed;
            acc[j] += v * rig->axis[j].steps_per * (tick / 1e9);
            if (acc[j] >= 1) { acc[j] -= 1; mask |= 1u << j; }
        }
        if (mask) {
            if ((rc = rg_pulse(m, mask, t, tick, err, cap))) { note(m, "stopped (fault)"); return rc; }
            for (int j = 0; j < RG_NJOINTS; j++)
                if (mask >> j & 1) { m->pos[j] += sign[j]; togo[j]--; }
        } else {
            rg_wait(m, t);
            if ((rc = rg_guard(m, 0, err, cap))) { note(m, "stopped (fault)"); return rc; }
        }
    }
    return 0;
}

int rg_home(rg_machine *m, rg_stop_fn stop, void *ctx, char *err, size_t cap)
{
    const rg_rig *rig = &m->rig;
    unsigned axes = 0, lv, ed, on = 0;
    int rc;
    if ((rc = rg_latched(m, err, cap))) return rc;
    if (m->laser_on) rg_laser_off(m);
    for (int j = 0; j < RG_NJOINTS; j++) {
        if (rig->axis[j].home.offset >= 0) axes |= 1u << j;
        if (rig->axis[j].enable.offset >= 0) on |= 1u << j;
    }
    m->homed = 0;
    if ((rc = rg_guard(m, 0, err, cap))) return rc;
    m->chip->ops->set(m->chip, RG_G_ENABLE, on, on);     /* drivers on, and stay on */
    m->drivers_on = 1;
    m->chip->ops->inputs(m->chip, &lv, &ed);
    if ((rc = home_phase(m, axes & lv, 0, 0, 0, stop, ctx, err, cap)) ||   /* off it */
        (rc = home_phase(m, axes, 1, 0, 0, stop, ctx, err, cap)) ||        /* seek */
        (rc = home_phase(m, axes, 0, 0, 1, stop, ctx, err, cap)) ||        /* pull-off */
        (rc = home_phase(m, axes, 1, 1, 0, stop, ctx, err, cap)))          /* locate */
        return rc;
    if (axes) {                                         /* debounce: still tripped? */
        int64_t end = m->chip->ops->now(m->chip) + (int64_t)llround(rig->home_debounce_ms * 1e6);
        rg_wait(m, end);
        if ((rc = rg_guard(m, 0, err, cap))) return rc;
        m->chip->ops->inputs(m->chip, &lv, &ed);
        for (int j = 0; j < RG_NJOINTS; j++)
            if ((axes >> j & 1) && !(lv >> j & 1))
                return rg_latch(m, RG_F_HOMING, RG_EFAULT, err, cap, "axis %s: its home switch "
                                "(line %d) bounced: released %g ms after it tripped", jname[j],
                                rig->axis[j].home.offset, rig->home_debounce_ms);
    }
    if ((rc = home_phase(m, axes, 0, 0, 1, stop, ctx, err, cap))) return rc;  /* pull-off */
    for (int j = 0; j < RG_NJOINTS; j++) {
        const rg_axis *x = &rig->axis[j];
        m->pos[j] = lround(x->home_at * x->steps_per);
        if (x->home.offset >= 0) m->pos[j] -= x->home_dir * lround(x->home_pulloff * x->steps_per);
    }
    note(m, "homed");                /* then settle_ms before anything else */
    if ((rc = rg_settle(m, err, cap))) return rc;
    m->homed = 1;
    return 0;
}
