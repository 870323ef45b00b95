/* rg_sweep.c -- exposure on the fly (doc/scan-time.md): one continuous motion through a
 * scan's targets with the laser pulsed as the machine passes each, for a rig whose
 * file says 'expose_moving yes'.  Stop-and-go spends most of a scan accelerating and
 * braking the stage between neighbouring targets; here the joints follow the polyline
 * through the targets (in step space) on one parameter u (target index), and u(t) is
 * planned like a CNC controller's look-ahead: each leg's cruise capped by every
 * joint's speed and by one exposure per leg, each junction's speed by the joints'
 * turn there (the velocity jump u' |d_i - d_(i-1)| at most half the joint's
 * acceleration times the leg's duration 1/u'), ramps within the other half, a
 * backward then forward pass.  The pulse (at most half a control step) sits in a
 * control step's low half, after its STEP edges: no motor steps while the light is
 * on, and the simulator still logs a VIOLATION if one did.  Every safety check of a
 * move and an exposure stays: the travel and the whole sweep's dose before the first
 * pulse, the interlock and the limit switches every control step, the key switch,
 * the heartbeat and its lateness at every pulse, STEP lateness, lost steps at the
 * end. */
#define _DEFAULT_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "rig/rg_hw.h"

typedef struct leg { double v0, v1, vp, a, ta, tc, td, T, t0; } leg;

/* A leg of length 1 in u: from v0 to v1 at most at vc, ramps at a. */
static void leg_plan(leg *l, double v0, double v1, double vc, double a)
{
    double vp = sqrt((2 * a + v0 * v0 + v1 * v1) / 2);
    if (vp > vc) vp = vc;
    if (vp < v0) vp = v0;              /* (rounding: the passes keep v0, v1 <= vc) */
    if (vp < v1) vp = v1;
    l->v0 = v0; l->v1 = v1; l->vp = vp; l->a = a;
    l->ta = (vp - v0) / a;
    l->td = (vp - v1) / a;
    double dr = 1 - (vp * vp - v0 * v0) / (2 * a) - (vp * vp - v1 * v1) / (2 * a);
    l->tc = vp > 0 && dr > 0 ? dr / vp : 0;
    l->T = l->ta + l->tc + l->td;
}

static double leg_u(const leg *l, double t)
{
    if (t <= 0) return 0;
    if (t >= l->T) return 1;
    if (t < l->ta) return l->v0 * t + 0.5 * l->a * t * t;
    double d = l->v0 * l->ta + 0.5 * l->a * l->ta * l->ta;
    if (t < l->ta + l->tc) return d + l->vp * (t - l->ta);
    double x = t - l->ta - l->tc;
    return fmin(1, d + l->vp * l->tc + l->vp * x - 0.5 * l->a * x * x);
}

/* The smooth commanded path at sweep time tau: fractional steps. */
static void path_at(const leg *L, const long *steps, long n, double T, double tau, double x[RG_NJOINTS])
{
    long c = 0;
    if (n < 2 || tau <= 0 || tau >= T) {
        const long *p = steps + (n < 2 || tau <= 0 ? 0 : n - 1) * RG_NJOINTS;
        for (int j = 0; j < RG_NJOINTS; j++) x[j] = (double)p[j];
        return;
    }
    long lo = 0, hi = n - 2;                    /* the leg holding tau */
    while (lo < hi) {
        long mid = (lo + hi + 1) / 2;
        if (L[mid].t0 <= tau) lo = mid; else hi = mid - 1;
    }
    c = lo;
    double f = leg_u(&L[c], tau - L[c].t0);
    const long *a = steps + c * RG_NJOINTS, *b = a + RG_NJOINTS;
    for (int j = 0; j < RG_NJOINTS; j++) x[j] = a[j] + f * (double)(b[j] - a[j]);
}

/* The legs of the sweep through steps[0..n-1] (n - 1 of them, t0 their start in
 * sweep time); st (may be NULL) gets what capped each. */
static int plan(const rg_rig *rig, const long *steps, long n, double ms, leg **out,
                double *total, rg_sweep_stats *st, char *err, size_t cap)
{
    long nl = n - 1;
    double tick = rg_tick_ns(rig) / 1e9, vexp = 1 / (ms / 1e3 + 3 * tick);
    leg *L = malloc(sizeof *L * (size_t)(nl > 0 ? nl : 1));
    double *vc = malloc(sizeof *vc * (size_t)(n + 1) * 3), *va = vc + n + 1, *vj = va + n + 1;
    if (!L || !vc) { free(L); free(vc); snprintf(err, cap, "sweep: out of memory"); return RG_ENOMEM; }
#define D(i, j) ((double)(steps[((i) + 1) * RG_NJOINTS + (j)] - steps[(i) * RG_NJOINTS + (j)]))
    for (long i = 0; i < nl; i++) {             /* each leg's cruise cap and ramp */
        double c = vexp, a = INFINITY;
        int cj = -1, aj = -1;
        for (int j = 0; j < RG_NJOINTS; j++) {
            const rg_axis *x = &rig->axis[j];
            double d = fabs(D(i, j));
            if (d == 0) continue;
            if (x->speed * x->steps_per / d < c) { c = x->speed * x->steps_per / d; cj = j; }
            if (0.5 * x->accel * x->steps_per / d < a) { a = 0.5 * x->accel * x->steps_per / d; aj = j; }
        }
        if (!isfinite(a)) a = 1e12;             /* a repeated target: no motion */
        vc[i] = c;
        va[i] = a;
        if (st) {
            if (cj >= 0) st->lim_speed[cj]++; else st->lim_expose++;
            if (aj >= 0) st->lim_accel[aj]++;
        }
    }
    vj[0] = vj[n - 1] = 0;                      /* at rest at both ends */
    for (long i = 1; i + 1 < n; i++) {          /* junction caps: the turn at target i */
        double v = fmin(vc[i - 1], vc[i]);
        int tj = -1;
        for (int j = 0; j < RG_NJOINTS; j++) {
            const rg_axis *x = &rig->axis[j];
            double dd = fabs(D(i, j) - D(i - 1, j));
            if (dd > 0 && sqrt(0.5 * x->accel * x->steps_per / dd) < v) {
                v = sqrt(0.5 * x->accel * x->steps_per / dd);
                tj = j;
            }
        }
        if (st && tj >= 0) st->lim_turn[tj]++;
        vj[i] = v;
    }
    for (long i = n - 2; i >= 0; i--)           /* backward: able to brake */
        vj[i] = fmin(vj[i], sqrt(vj[i + 1] * vj[i + 1] + 2 * va[i]));
    double t = 0;
    for (long i = 0; i < nl; i++) {             /* forward: able to speed up */
        vj[i + 1] = fmin(vj[i + 1], sqrt(vj[i] * vj[i] + 2 * va[i]));
        leg_plan(&L[i], vj[i], vj[i + 1], vc[i], va[i]);
        L[i].t0 = t;
        t += L[i].T;
        if (st)
            for (int j = 0; j < RG_NJOINTS; j++) {
                double v = L[i].vp * fabs(D(i, j));
                if (v > st->v_max[j]) st->v_max[j] = v;
            }
    }
#undef D
    free(vc);
    *out = L;
    *total = t;
    return 0;
}

int rg_sweep_time(const rg_rig *rig, const long start[RG_NJOINTS], const long *steps, long n,
                  double expose_ms, rg_sweep_stats *st, char *err, size_t cap)
{
    leg *L = NULL;
    double T, tick = rg_tick_ns(rig) / 1e9;
    int rc;
    memset(st, 0, sizeof *st);
    st->n = n;
    if (n <= 0) return 0;
    if ((rc = rg_check_targets(rig, steps, n, err, cap))) return rc;
    if ((rc = plan(rig, steps, n, expose_ms, &L, &T, st, err, cap))) return rc;
    free(L);
    double first = rg_move_time(rig, start, steps, NULL, NULL, NULL, NULL);
    st->t_sweep = T;
    /* as rg_sweep runs it: the first move (DIR tick, whole ticks, settle), the
     * emission delay, half an exposure before the motion, the sweep, the rest of the
     * last exposure, the final settle */
    st->t_total = (first > 0 ? (2 + ceil(first / tick - 1e-9)) * tick + rig->settle_ms / 1e3 : 0) +
                  rig->emission_delay_ms / 1e3 + tick + ceil(T / tick) * tick +
                  ceil(expose_ms / 1e3 / tick - 1e-9) * tick + rig->settle_ms / 1e3;
    return 0;
}

static void laser(rg_machine *m, int on)
{
    const rg_chip_ops *o = m->chip->ops;
    m->laser_on = on;
    o->set(m->chip, RG_G_LASER, 1, on);
    o->set(m->chip, RG_G_SHUTTER, 1, on);
}

/* A short pulse between two control steps' STEP edges: from `from` (or now, when the
 * last fall came later) for ms_ns, the heartbeat charged first, the guard read at
 * both ends (the key switch included), no step while the light is on. */
static int pulse_between(rg_machine *m, int64_t from, int64_t ms_ns, unsigned *heart,
                         int64_t *beat, rg_sweep_shot *shot, char *err, size_t cap)
{
    const rg_chip_ops *o = m->chip->ops;
    int64_t hold_ns = (int64_t)llround(m->rig.heartbeat_timeout_ms * 1e6), t_on, now;
    int rc;
    if (o->now(m->chip) < from) rg_wait(m, from);
    if ((rc = rg_guard(m, 1, err, cap))) return rc;
    if (m->rig.heartbeat.offset >= 0) {
        *heart ^= 1;
        o->set(m->chip, RG_G_HEART, 1, *heart);
        *beat = o->now(m->chip);
    }
    laser(m, 1);
    t_on = o->now(m->chip);
    if (shot) {
        shot->t_on = t_on / 1e9;
        shot->nat = 1;
        for (int j = 0; j < RG_NJOINTS; j++) {
            shot->at[0][j] = m->pos[j];
            shot->mean[j] = (double)m->pos[j];
        }
    }
    rg_wait(m, t_on + ms_ns);
    now = o->now(m->chip);
    if (m->rig.heartbeat.offset >= 0 && now - *beat > hold_ns)
        return rg_latch(m, RG_F_HEARTBEAT, RG_EFAULT, err, cap, "a pulse of the sweep ran "
                        "%.3f ms: the heartbeat pump (hold %g ms) has cut the beam",
                        (now - *beat) / 1e6, m->rig.heartbeat_timeout_ms);
    if ((rc = rg_guard(m, 1, err, cap))) return rc;
    laser(m, 0);
    m->dose_n++;
    m->dose_t += (o->now(m->chip) - t_on) / 1e9;
    return 0;
}

int rg_sweep(rg_machine *m, const long *steps, long n, double ms, rg_stop_fn stop, void *ctx,
             rg_sweep_shot *shot, char *err, size_t cap)
{
    const rg_rig *rig = &m->rig;
    const rg_chip_ops *o = m->chip->ops;
    int64_t tick = rg_tick_ns(rig), ms_ns = (int64_t)llround(ms * 1e6);
    unsigned heart = 0, lv = 0, ed = 0;
    long cur = 0, K, exp_i = 0;
    int dir[RG_NJOINTS] = {0}, rc;
    leg *L = NULL;
    double T;
    int64_t beat = 0;
    rg_dose d;

    if ((rc = rg_latched(m, err, cap))) return rc;
    if (!m->homed) { snprintf(err, cap, "the machine is not homed: home it first"); return RG_EINVAL; }
    if (!rig->expose_moving) {
        snprintf(err, cap, "the rig file does not allow exposure on the fly ('expose_moving "
                 "yes', doc/scan-time.md): expose at rest");
        return RG_EINVAL;
    }
    if (rig->shutter_ms > 0) {
        snprintf(err, cap, "exposure on the fly needs shutter_ms 0: a shutter taking %g ms "
                 "would smear the exposure", rig->shutter_ms);
        return RG_EINVAL;
    }
    if (!(ms > 0) || ms > rig->max_on_ms || ms_ns > tick / 2) {
        snprintf(err, cap, "an exposure of %g ms on the fly: it must be more than 0, at most "
                 "the rig's max_on_ms %g and fit in half a control step (%g ms at tick_us %g: "
                 "a longer one would see the motors step during it)", ms, rig->max_on_ms,
                 rig->tick_us / 2e3, rig->tick_us);
        return RG_EINVAL;
    }
    if (rig->heartbeat.offset < 0 && !rig->eye_safe_without_heartbeat) {
        snprintf(err, cap, "the rig file has no 'heartbeat' line: the laser stays off");
        return RG_EINVAL;
    }
    if (n <= 0) return 0;
    if ((rc = rg_check_targets(rig, steps, n, err, cap))) return rc;
    /* the whole sweep's dose, before anything moves or emits */
    if ((rc = rg_dose_plan(m, ms, n, &d, err, cap))) return rc;
    if ((rc = plan(rig, steps, n, ms, &L, &T, NULL, err, cap))) return rc;
    if ((rc = rg_move_steps(m, steps, stop, ctx, err, cap))) goto out;
    if ((rc = rg_guard(m, 2, err, cap))) goto out;
    o->inputs(m->chip, &lv, &ed);
    if (rig->key_switch.offset >= 0 && !(lv & RG_IN_KEY)) {
        snprintf(err, cap, "the key switch is off: the laser stays off");
        rc = RG_EINTERLOCK;
        goto out;
    }
    if (o->note) o->note(m->chip, "sweep (exposure on the fly)");
    /* the indicator stays on for the whole sweep, the emission delay once, at rest */
    o->set(m->chip, RG_G_INDICATOR, 1, 1);
    int64_t t0 = o->now(m->chip) + (int64_t)llround(rig->emission_delay_ms * 1e6);
    for (int64_t t = o->now(m->chip) + tick; t < t0 + tick; t += tick) {
        rg_wait(m, t < t0 ? t : t0);
        if ((rc = rg_guard(m, 2, err, cap))) goto out;
    }
    /* control step k: the joints to the smooth path at sweep time k tick (each at most
       a step), then, at target i's tick (t_i / tick), the pulse in the step's low half */
    K = (long)ceil(T * 1e9 / tick) + 2;
    for (long k = 1; k <= K; k++) {
        int64_t at = t0 + k * tick;
        double tau = k * tick / 1e9;
        unsigned mask = 0, dmask = 0, dval = 0;
        if (stop && stop(ctx)) {
            rg_laser_off(m);
            m->homed = 0;           /* a stepper stopped at speed may lose steps */
            if (o->note) o->note(m->chip, "stopped (position no longer known: home again)");
            snprintf(err, cap, "the sweep was stopped: laser off");
            rc = RG_ESTOP;
            goto out;
        }
        while (cur < n - 2 && tau >= L[cur].t0 + L[cur].T) cur++;
        double f = n > 1 ? leg_u(&L[cur], tau - L[cur].t0) : 0;
        for (int j = 0; j < RG_NJOINTS; j++) {
            const long *a = steps + (n > 1 ? cur : 0) * RG_NJOINTS, *b = a + (n > 1 ? RG_NJOINTS : 0);
            long want = tau >= T ? steps[(n - 1) * RG_NJOINTS + j] : lround(a[j] + f * (b[j] - a[j]));
            int sg = want > m->pos[j] ? 1 : want < m->pos[j] ? -1 : 0;
            if (!sg) continue;
            if (sg != dir[j]) {     /* DIR first, the step a control step later */
                dmask |= 1u << j;
                if ((sg > 0) ^ rig->axis[j].dir_invert) dval |= 1u << j;
                dir[j] = sg;
            } else mask |= 1u << j;
        }
        if (dmask) o->set(m->chip, RG_G_DIR, dmask, dval);
        if (mask) {
            if ((rc = rg_pulse(m, mask, at, tick, err, cap))) goto out;
            for (int j = 0; j < RG_NJOINTS; j++)
                if (mask >> j & 1) m->pos[j] += dir[j];
        } else {
            rg_wait(m, at);
            if ((rc = rg_guard(m, 0, err, cap))) goto out;
        }
        long kon = -1;
        if (exp_i < n) {
            kon = (long)llround((exp_i ? L[exp_i - 1].t0 + L[exp_i - 1].T : 0) * 1e9 / tick);
            if (kon < 1) kon = 1;
        }
        if (kon >= 1 && k >= kon) {
            if ((rc = pulse_between(m, at + tick / 2, ms_ns, &heart, &beat,
                                    shot ? &shot[exp_i] : NULL, err, cap)))
                goto out;
            if (shot) {
                double ton = (shot[exp_i].t_on * 1e9 - t0) / 1e9;
                path_at(L, steps, n, T, ton, shot[exp_i].c_on);
                path_at(L, steps, n, T, ton + ms / 1e3, shot[exp_i].c_off);
            }
            exp_i++;
        }
        if (k == K && (exp_i < n || memcmp(m->pos, steps + (n - 1) * RG_NJOINTS, sizeof m->pos)))
            K++;                    /* a step or a pulse still due: one more tick */
        if (K > k + 1000000) {
            snprintf(err, cap, "sweep: the motion did not reach its last target");
            rc = RG_EINVAL;
            goto out;
        }
    }
    rg_laser_off(m);
    if ((rc = rg_settle(m, err, cap))) goto out;
    if ((rc = rg_lost_steps(m, err, cap))) goto out;
    if (o->note) o->note(m->chip, "swept");
out:
    if (m->laser_on) rg_laser_off(m);
    else m->chip->ops->set(m->chip, RG_G_INDICATOR, 1, 0);
    free(L);
    return rc;
}
