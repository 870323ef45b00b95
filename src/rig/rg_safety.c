/* rg_safety.c -- the laser.  It goes on only inside rg_expose, and only with the
 * interlock closed, every axis at rest (motion and exposure are one thread: a move
 * returns when its last step is done) and for no longer than max_on_ms; while it is
 * on, the interlock is read every control step (and its edge events, so a short
 * opening counts) and the heartbeat output toggles every control step, so the
 * external charge pump keeps the laser's enable only while this loop runs.
 * rg_emergency_off is the async-signal-safe path for signals and stop hooks: laser
 * off first, then every driver disabled, on every open machine. */
#include <math.h>
#include <signal.h>
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
}

static int interlock_open(rg_machine *m)
{
    unsigned lv, ed;
    if (m->chip->ops->inputs(m->chip, &lv, &ed)) return 1;  /* cannot read: unsafe */
    return !(lv & RG_IN_INTERLOCK) || (ed & RG_IN_INTERLOCK);
}

int rg_expose(rg_machine *m, double ms, rg_stop_fn stop, void *ctx, char *err, size_t cap)
{
    const rg_rig *rig = &m->rig;
    const rg_chip_ops *o = m->chip->ops;
    int64_t tick = rg_tick_ns(rig), t0, end, t;
    unsigned heart = 0;
    int have_heart = rig->heartbeat.offset >= 0;

    if (!(ms > 0) || ms > rig->max_on_ms) {
        snprintf(err, cap, "an exposure of %g ms: it must be more than 0 and at most the "
                 "rig's max_on_ms %g", ms, rig->max_on_ms);
        return RG_EINVAL;
    }
    if (!m->homed) {
        snprintf(err, cap, "the machine is not homed: the beam would go who knows where");
        return RG_EINVAL;
    }
    if (interlock_open(m)) {
        snprintf(err, cap, "the interlock is open: the laser stays off");
        return RG_EINTERLOCK;
    }
    t0 = o->now(m->chip);
    end = t0 + (int64_t)llround(ms * 1e6);
    if (have_heart) { heart ^= 1; o->set(m->chip, RG_G_HEART, 1, heart); }
    m->laser_on = 1;
    o->set(m->chip, RG_G_LASER, 1, 1);
    if (o->note) o->note(m->chip, "expose");
    for (t = t0 + tick; ; t += tick) {
        int64_t at = t < end ? t : end;
        rg_wait(m, at);
        if (at == end) break;
        if (interlock_open(m)) {
            rg_laser_off(m);
            snprintf(err, cap, "the interlock opened during the exposure: laser off");
            return RG_EINTERLOCK;
        }
        if (stop && stop(ctx)) {
            rg_laser_off(m);
            snprintf(err, cap, "the exposure was stopped: laser off");
            return RG_ESTOP;
        }
        if (have_heart) { heart ^= 1; o->set(m->chip, RG_G_HEART, 1, heart); }
    }
    rg_laser_off(m);
    return 0;
}
