/* rg_safety.c -- the laser and the latched fault.  The laser goes on only inside
 * rg_expose, and only with the interlock closed, the key switch on, no fault latched,
 * every axis at rest (motion and exposure are one thread: a move returns when its
 * last step is done), a heartbeat line (or the rig's word that the beam is eye-safe
 * without one), a dose within the MPE (rg_dose.c) and for no longer than max_on_ms.
 * Order of emission: indicator on, emission delay, laser on, shutter open, the
 * exposure, shutter closed, laser off, indicator off.  While the laser is on, the
 * interlock and key are read every control step (with their edge events, so a short
 * opening counts), the loop's own lateness is measured against the pump's hold, and
 * the heartbeat output toggles every control step, so the external charge pump keeps
 * the laser's enable only while this loop runs.
 * The latch (LinuxCNC's estop_latch): any fault -- interlock open, limit switch,
 * missed deadline, heartbeat loss, lost step, key off during emission -- switches the
 * laser off FIRST (then the shutter closes and the indicator goes off), then every
 * STEP low and every driver disabled; it stays until rg_reset, which is refused while
 * the cause persists; a fault that found the drivers enabled cut their current, so
 * the position is no longer held: homing is required again.
 * rg_emergency_off is the async-signal-safe path for signals and stop hooks: laser
 * off first, then every driver disabled, on every open machine. */
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include "rig/rg_hw.h"

/* The machines emergency_off reaches; a signal may come at any time, so the list is
 * only ever changed with signals blocked. */
#define MAXOPEN 8
static rg_machine *volatile open_list[MAXOPEN];

void rg_safety_register(rg_machine *m, int add)
{
    sigset_t all, old;
    sigfillset(&all);
    sigprocmask(SIG_BLOCK, &all, &old);
    for (int i = 0; i < MAXOPEN; i++) {
        if (add && !open_list[i]) { open_list[i] = m; break; }
        if (!add && open_list[i] == m) { open_list[i] = NULL; break; }
    }
    sigprocmask(SIG_SETMASK, &old, NULL);
}

void rg_emergency_off(void)
{
    for (int i = 0; i < MAXOPEN; i++) {
        rg_machine *m = open_list[i];
        if (!m) continue;
        m->laser_on = 0;
        m->chip->ops->emergency(m->chip);
    }
}

void rg_laser_off(rg_machine *m)
{
    m->chip->ops->set(m->chip, RG_G_LASER, 1, 0);
    m->laser_on = 0;
    m->chip->ops->set(m->chip, RG_G_SHUTTER, 1, 0);
    m->chip->ops->set(m->chip, RG_G_INDICATOR, 1, 0);
}


static const char *const cause_name[] = {"none", "interlock", "limit switch", "deadline",
                                         "heartbeat", "lost step", "key switch", "homing"};

/* Latch a fault: laser off first, then drivers off; the first cause is kept.
 * Returns rc with "why" in err. */
int rg_latch(rg_machine *m, int cause, int rc, char *err, size_t cap, const char *fmt, ...)
{
    const rg_chip_ops *o = m->chip->ops;
    char why[RG_ERRMAX / 2], line[RG_ERRMAX];
    va_list ap;
    rg_laser_off(m);
    o->set(m->chip, RG_G_STEP, (1u << RG_NJOINTS) - 1, 0);
    o->set(m->chip, RG_G_ENABLE, (1u << RG_NJOINTS) - 1, 0);
    va_start(ap, fmt);
    vsnprintf(why, sizeof why, fmt, ap);
    va_end(ap);
    if (m->drivers_on) {
        m->drivers_on = 0;
        m->homed = 0;
    }
    if (!m->fault) {
        m->fault = cause;
        snprintf(m->fault_why, sizeof m->fault_why, "%s", why);
        snprintf(line, sizeof line, "FAULT latched (%s): %s; laser off, drivers off%s",
                 cause_name[cause], why, m->homed ? "" : "; home again after reset");
        if (o->note) o->note(m->chip, line);
    }
    snprintf(err, cap, "%s (fault latched: laser off, drivers off; reset, then home)", why);
    return rc;
}

int rg_latched(rg_machine *m, char *err, size_t cap)
{
    if (!m->fault) return 0;
    snprintf(err, cap, "a fault is latched (%s: %s): the laser stays off and nothing moves "
             "until it is reset", cause_name[m->fault], m->fault_why);
    return RG_EFAULT;
}

int rg_fault_get(const rg_machine *m, char *why, size_t cap)
{
    if (why && cap) {
        if (m->fault) snprintf(why, cap, "%s: %s", cause_name[m->fault], m->fault_why);
        else why[0] = 0;
    }
    return m->fault;
}

static int read_inputs(rg_machine *m, unsigned *lv, unsigned *ed)
{
    if (m->chip->ops->inputs(m->chip, lv, ed)) { *lv = 0; *ed = RG_IN_INTERLOCK; return 1; }
    return 0;
}

static int first_limit(unsigned bits)
{
    for (int j = 0; j < RG_NJOINTS; j++) if (bits & RG_IN_LIMIT(j)) return j;
    return -1;
}

static const char *const jn[RG_NJOINTS] = {"m1a", "m1b", "u", "v", "m2a", "m2b"};

/* Every control step of a move, a homing or an exposure: the interlock (level and
 * edges) and the limit switches; emitting 1 (the laser on): the key switch too;
 * 2: just before an exposure; 0: motion or rest. */
int rg_guard(rg_machine *m, int emitting, char *err, size_t cap)
{
    unsigned lv, ed;
    int bad = read_inputs(m, &lv, &ed), j;
    if (bad || !(lv & RG_IN_INTERLOCK) || (ed & RG_IN_INTERLOCK))
        return rg_latch(m, RG_F_INTERLOCK, RG_EINTERLOCK, err, cap, bad ?
                        "the inputs cannot be read (the interlock counts as open)" :
                        emitting == 1 ? "the interlock opened during the exposure" :
                        emitting == 2 ? "the interlock is open: the laser stays off" :
                        "the interlock opened during motion");
    if ((j = first_limit(lv | ed)) >= 0)
        return rg_latch(m, RG_F_LIMIT, RG_EFAULT, err, cap, "axis %s: its limit switch "
                        "(line %d) tripped", jn[j], m->rig.axis[j].limit.offset);
    if (emitting == 1 && m->rig.key_switch.offset >= 0 &&
        (!(lv & RG_IN_KEY) || (ed & RG_IN_KEY)))
        return rg_latch(m, RG_F_KEY, RG_EINTERLOCK, err, cap,
                        "the key switch turned off during the exposure");
    return 0;
}

int rg_reset(rg_machine *m, char *err, size_t cap)
{
    unsigned lv, ed;
    int j;
    if (!m->fault) return 0;
    if (read_inputs(m, &lv, &ed) || !(lv & RG_IN_INTERLOCK)) {
        snprintf(err, cap, "reset refused: the interlock is still open (close it first)");
        return RG_EFAULT;
    }
    if ((j = first_limit(lv)) >= 0) {
        snprintf(err, cap, "reset refused: the limit switch of axis %s (line %d) is still "
                 "tripped (free the axis by hand, drivers off)", jn[j],
                 m->rig.axis[j].limit.offset);
        return RG_EFAULT;
    }
    if (m->rig.key_switch.offset >= 0 && !(lv & RG_IN_KEY)) {
        snprintf(err, cap, "reset refused: the key switch is off");
        return RG_EFAULT;
    }
    m->fault = 0;
    m->fault_why[0] = 0;
    if (m->chip->ops->note)
        m->chip->ops->note(m->chip, m->homed ? "reset" : "reset (not homed: home again)");
    return 0;
}

/* Wait to `end` a control step at a time, emitting (heartbeat, lateness) or not. */
static int hold(rg_machine *m, int64_t end, int emitting, unsigned *heart, int64_t *last_beat,
                rg_stop_fn stop, void *ctx, char *err, size_t cap)
{
    const rg_chip_ops *o = m->chip->ops;
    int64_t tick = rg_tick_ns(&m->rig), hold_ns = (int64_t)llround(m->rig.heartbeat_timeout_ms * 1e6);
    int have_heart = m->rig.heartbeat.offset >= 0, rc;
    for (int64_t t = o->now(m->chip) + tick; ; t += tick) {
        int64_t at = t < end ? t : end, now;
        rg_wait(m, at);
        now = o->now(m->chip);
        if (emitting && have_heart && now - *last_beat > hold_ns)
            return rg_latch(m, RG_F_HEARTBEAT, RG_EFAULT, err, cap, "the exposure loop ran "
                            "%.3f ms late: the heartbeat pump (hold %g ms) has cut the beam",
                            (now - *last_beat) / 1e6, m->rig.heartbeat_timeout_ms);
        if ((rc = rg_guard(m, emitting ? 1 : 2, err, cap))) return rc;
        if (stop && stop(ctx)) {
            rg_laser_off(m);
            snprintf(err, cap, "the exposure was stopped: laser off");
            return RG_ESTOP;
        }
        if (at == end) return 0;
        if (emitting && have_heart) {
            *heart ^= 1;
            o->set(m->chip, RG_G_HEART, 1, *heart);
            *last_beat = o->now(m->chip);
        }
    }
}

int rg_expose(rg_machine *m, double ms, rg_stop_fn stop, void *ctx, char *err, size_t cap)
{
    const rg_rig *rig = &m->rig;
    const rg_chip_ops *o = m->chip->ops;
    int64_t t0, t1, beat;
    unsigned heart = 0, lv, ed;
    int rc;
    rg_dose d;

    if (!(ms > 0) || ms > rig->max_on_ms) {
        snprintf(err, cap, "an exposure of %g ms: it must be more than 0 and at most the "
                 "rig's max_on_ms %g", ms, rig->max_on_ms);
        return RG_EINVAL;
    }
    if ((rc = rg_latched(m, err, cap))) return rc;
    if (!m->homed) {
        snprintf(err, cap, "the machine is not homed: the beam would go who knows where");
        return RG_EINVAL;
    }
    if (rig->heartbeat.offset < 0 && !rig->eye_safe_without_heartbeat) {
        snprintf(err, cap, "the rig file has no 'heartbeat' line: nothing would cut the beam "
                 "if this program died mid-exposure, so the laser stays off (wire a charge "
                 "pump and add 'heartbeat LINE', or, only for a beam that is eye-safe left "
                 "on, say 'eye_safe_without_heartbeat yes')");
        return RG_EINVAL;
    }
    if ((rc = rg_dose_plan(m, ms, 1, &d, err, cap))) return rc;
    if ((rc = rg_guard(m, 2, err, cap))) return rc;
    if (read_inputs(m, &lv, &ed), rig->key_switch.offset >= 0 && !(lv & RG_IN_KEY)) {
        snprintf(err, cap, "the key switch is off: the laser stays off");
        return RG_EINTERLOCK;
    }
    /* indicator first, then the emission delay (no light yet) */
    if (o->note) o->note(m->chip, "expose");
    o->set(m->chip, RG_G_INDICATOR, 1, 1);
    beat = o->now(m->chip);
    if (rig->emission_delay_ms > 0 &&
        (rc = hold(m, beat + (int64_t)llround(rig->emission_delay_ms * 1e6), 0, &heart, &beat,
                   stop, ctx, err, cap))) { rg_laser_off(m); return rc; }
    if (rig->heartbeat.offset >= 0) { heart ^= 1; o->set(m->chip, RG_G_HEART, 1, heart); }
    m->laser_on = 1;
    o->set(m->chip, RG_G_LASER, 1, 1);
    t0 = beat = o->now(m->chip);
    o->set(m->chip, RG_G_SHUTTER, 1, 1);
    rc = hold(m, t0 + (int64_t)llround((ms + rig->shutter_ms) * 1e6), 1, &heart, &beat, stop,
              ctx, err, cap);
    if (!rc) {
        o->set(m->chip, RG_G_SHUTTER, 1, 0);
        if (rig->shutter_ms > 0)
            rc = hold(m, o->now(m->chip) + (int64_t)llround(rig->shutter_ms * 1e6), 1, &heart,
                      &beat, stop, ctx, err, cap);
    }
    rg_laser_off(m);
    t1 = o->now(m->chip);
    m->dose_n++;
    m->dose_t += (t1 - t0) / 1e9;
    return rc;
}
