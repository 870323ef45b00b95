/* rg_sim.c -- the simulated chip: the rig's lines, the motors they drive (a STEP
 * rising edge with the driver enabled moves a motor one step the way DIR says), the
 * home switches (tripped on the home side of home_at), the interlock, the laser and
 * the heartbeat charge pump (light only while the laser line is active and the
 * heartbeat toggled within the pump's hold time).  Time is simulated: a wait moves the
 * clock to its deadline, so a replay writes the same event log byte for byte (with
 * sim_realtime the waits also sleep on the real clock; the stamps stay simulated).
 * The log is written with write(2) as events happen (through src/common/lm_out.h: a
 * unique LOG.part.XXXXXX beside a regular file, renamed when the chip closes or stops;
 * a device or FIFO in place), so it survives a kill; its formatter is async-signal-safe for the
 * emergency path.  The chip state may live in a shared file (rg_sim_shared) that a
 * watchdog outside the process reads (tests/rig/rig_watchdog.c).
 * Safety (doc/rig-safety.md): limit switches (tripped beyond travel, or from
 * sim_limit_ms), a key switch (off from sim_key_off_ms), the shutter and emission
 * indicator, an interlock that may close again (sim_interlock_close_ms), a stalled
 * controller (sim_stall_at_ms: the clock jumps as if the process had been
 * preempted), a driver that drops a pulse (sim_lose_step_ms) or any pulse shorter
 * than step_pulse_us; VIOLATION lines for a STEP edge more than 1 ms after the
 * interlock opened or a limit tripped, light with the indicator off or the key off,
 * and emission sooner than emission_delay_ms after the indicator went on.
 * rg_null_open: the same model on the real clock, no log (the timing benchmark). */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>
#include "common/lm_out.h"
#include "rig/rg_hw.h"

static const char *const jname[RG_NJOINTS] = {"m1a", "m1b", "u", "v", "m2a", "m2b"};

typedef struct sim {
    rg_chip base;
    const rg_rig *rig;
    rg_sim_shared *sh;
    int shared;                 /* sh is a mapping of a file */
    size_t shlen;
    int log;                    /* fd of the log (lo.fd), or -1 */
    lm_out lo;                  /* the log's writer */
    int log_errno;              /* the first write error of the log, or 0 */
    int realclock;              /* null chip: real clock, no log */
    int64_t t0_real;            /* real-time pacing base */
    unsigned val[RG_NGROUPS];   /* logical output levels */
    int64_t home_step[RG_NJOINTS];
    int64_t pulses[RG_NJOINTS]; /* STEP edges seen since the last note */
    int64_t il_open_since;      /* interlock open with the laser on, since; -1 */
    int64_t il_opened_at;       /* when the interlock last opened; -1: closed */
    int64_t limit_at[RG_NJOINTS]; /* when each limit switch tripped; -1 */
    int64_t rise_at[RG_NJOINTS];  /* STEP rising edge, for the pulse width */
    int64_t fall_at[RG_NJOINTS];  /* STEP falling edge, for the low time */
    int rise_dir[RG_NJOINTS];     /* the step that rise made (undone if it was too short) */
    int64_t last_step_edge;     /* any STEP edge; -1 none */
    int64_t indicator_on_at;    /* -1: off */
    int lost[RG_NJOINTS];       /* sim_lose_step_ms injected already */
    int stalled;
    int64_t last_read;          /* simulated time of the last input read */
    int violations;
    int closed;
} sim;

/* ---- async-signal-safe log formatting ------------------------------------------- */

typedef struct lbuf { char b[1024]; size_t n; } lbuf;

static void put_s(lbuf *l, const char *s)
{
    while (*s && l->n < sizeof l->b - 2) l->b[l->n++] = *s++;
}
static void put_i(lbuf *l, int64_t v)
{
    char t[24];
    int n = 0;
    uint64_t u = v < 0 ? (uint64_t)0 - (uint64_t)v : (uint64_t)v;
    if (v < 0) put_s(l, "-");
    do { t[n++] = (char)('0' + u % 10); u /= 10; } while (u);
    while (n && l->n < sizeof l->b - 2) l->b[l->n++] = t[--n];
}
static void put_t(lbuf *l, int64_t ns)           /* seconds.nanoseconds */
{
    char t[10];
    int64_t f = ns % 1000000000;
    put_i(l, ns / 1000000000);
    put_s(l, ".");
    for (int i = 8; i >= 0; i--) { t[i] = (char)('0' + f % 10); f /= 10; }
    t[9] = 0;
    put_s(l, t);
}
static void start(sim *s, lbuf *l)
{
    l->n = 0;
    put_t(l, s->sh->now_ns);
    put_s(l, " ");
}
static void emit(sim *s, lbuf *l)
{
    l->b[l->n++] = '\n';
    if (s->log >= 0) {
        const char *p = l->b;
        size_t n = l->n;
        while (n) {
            ssize_t w = write(s->log, p, n);
            if (w < 0 && errno == EINTR) continue;
            if (w <= 0) {
                if (!s->log_errno) s->log_errno = w < 0 ? errno : ENOSPC;
                break;
            }
            p += w; n -= (size_t)w;
        }
    }
}
static void logs(sim *s, const char *a, const char *b)
{
    lbuf l;
    if (s->log < 0) return;
    start(s, &l); put_s(&l, a); if (b) put_s(&l, b);
    emit(s, &l);
}

/* ---- the model ----------------------------------------------------------------- */

static int interlock_closed(const sim *s)
{
    const rg_rig *r = s->rig;
    if (r->sim_interlock_close_ms >= 0 &&
        s->sh->now_ns >= (int64_t)llround(r->sim_interlock_close_ms * 1e6)) return 1;
    if (r->sim_interlock_open) return 0;
    if (r->sim_interlock_open_ms >= 0 &&
        s->sh->now_ns >= (int64_t)llround(r->sim_interlock_open_ms * 1e6)) return 0;
    return 1;
}

static int limit_tripped(const sim *s, int j)
{
    const rg_axis *x = &s->rig->axis[j];
    if (x->limit.offset < 0) return 0;
    if (x->sim_limit_ms >= 0 && s->sh->now_ns >= (int64_t)llround(x->sim_limit_ms * 1e6))
        return 1;
    return s->sh->steps[j] < llround(x->min * x->steps_per) ||
           s->sh->steps[j] > llround(x->max * x->steps_per);
}

static int key_on(const sim *s)
{
    const rg_rig *r = s->rig;
    if (r->key_switch.offset < 0) return 1;
    return !(r->sim_key_off_ms >= 0 && s->sh->now_ns >= (int64_t)llround(r->sim_key_off_ms * 1e6));
}

static int home_tripped(const sim *s, int j)
{
    const rg_axis *x = &s->rig->axis[j];
    if (x->home.offset < 0 || x->sim_home_broken) return 0;
    return (s->sh->steps[j] - s->home_step[j]) * x->home_dir >= 0;
}

/* Light from the laser: line active, and the pump charged (heartbeat recent). */
static int light_now(const sim *s, int64_t t)
{
    if (!s->sh->laser) return 0;
    if (s->rig->shutter.offset >= 0 && !s->sh->shutter) return 0;
    if (s->rig->heartbeat.offset < 0) return 1;
    return t - s->sh->heartbeat_last_ns <= s->sh->timeout_ns;
}

static void update_light(sim *s)
{
    int on = light_now(s, s->sh->now_ns);
    if (on == s->sh->light) return;
    if (!on && s->sh->laser) {      /* the pump ran down: stamp when it did */
        lbuf l;
        int64_t now = s->sh->now_ns;
        s->sh->now_ns = s->sh->heartbeat_last_ns + s->sh->timeout_ns;
        if (s->log >= 0) { start(s, &l); put_s(&l, "light 0 (heartbeat stopped)"); emit(s, &l); }
        s->sh->now_ns = now;
    } else {
        logs(s, on ? "light 1" : "light 0", NULL);
    }
    s->sh->light = on;
    if (on && s->rig->indicator.offset >= 0 && !s->sh->indicator) {
        s->violations++;
        logs(s, "VIOLATION light with the emission indicator off", NULL);
    }
    if (on && !key_on(s)) {
        s->violations++;
        logs(s, "VIOLATION light with the key switch off", NULL);
    }
}

static void check_interlock(sim *s)
{
    int closed = interlock_closed(s);
    if (closed != s->sh->interlock) {
        /* stamped when it opened, which may lie between two reads */
        int64_t now = s->sh->now_ns, at = (int64_t)llround(s->rig->sim_interlock_open_ms * 1e6);
        s->sh->interlock = closed;
        if (!closed && s->rig->sim_interlock_open_ms >= 0 && at < now) s->sh->now_ns = at;
        s->il_opened_at = closed ? -1 : s->sh->now_ns;
        logs(s, closed ? "interlock closed" : "interlock open", NULL);
        s->sh->now_ns = now;
    }
    for (int j = 0; j < RG_NJOINTS; j++) {
        int tr = limit_tripped(s, j);
        if (tr && s->limit_at[j] < 0) {
            lbuf l;
            s->limit_at[j] = s->sh->now_ns;
            start(s, &l); put_s(&l, "limit switch of axis "); put_s(&l, jname[j]);
            put_s(&l, " tripped"); emit(s, &l);
        } else if (!tr) {
            s->limit_at[j] = -1;
        }
    }
    if (s->sh->laser && !closed) {
        int64_t tick = rg_tick_ns(s->rig);
        if (s->il_open_since < 0) s->il_open_since = s->sh->now_ns;
        else if (s->sh->now_ns - s->il_open_since > tick) {
            s->violations++;
            logs(s, "VIOLATION laser on with the interlock open for more than one "
                    "control step", NULL);
            s->il_open_since = s->sh->now_ns;
        }
    } else {
        s->il_open_since = -1;
    }
}

/* A STEP edge: none may come more than 1 ms after the interlock opened or a limit
 * switch tripped (the controller reads them every control step). */
static void step_edges(sim *s, int64_t t)
{
    s->last_step_edge = t;
    if (s->realclock) return;
    if (s->il_opened_at >= 0 && t - s->il_opened_at > 1000000) {
        s->violations++;
        logs(s, "VIOLATION a STEP edge more than 1 ms after the interlock opened", NULL);
        s->il_opened_at = t;        /* once per ms, not per edge */
    }
    for (int j = 0; j < RG_NJOINTS; j++)
        if (s->limit_at[j] >= 0 && t - s->limit_at[j] > 1000000) {
            s->violations++;
            logs(s, "VIOLATION a STEP edge more than 1 ms after a limit switch tripped", NULL);
            s->limit_at[j] = t;
        }
}

static int sim_set(rg_chip *c, int g, unsigned mask, unsigned val)
{
    sim *s = (sim *)c;
    unsigned old = s->val[g], now = (old & ~mask) | (val & mask);
    lbuf l;
    s->val[g] = now;
    if (g == RG_G_STEP) {
        unsigned rise = now & ~old, fall = old & ~now;
        int64_t t = s->sh->now_ns;
        if (rise | fall) step_edges(s, t);
        for (int j = 0; j < RG_NJOINTS; j++) {
            int en, d;
            if (fall >> j & 1) {
                /* a pulse shorter than the driver's minimum: the driver misses it */
                if (!s->realclock && s->rise_at[j] >= 0 &&
                    t - s->rise_at[j] < (int64_t)llround(s->rig->step_pulse_us * 1e3)) {
                    lbuf l;
                    s->violations++;
                    start(s, &l); put_s(&l, "VIOLATION a STEP pulse of axis ");
                    put_s(&l, jname[j]); put_s(&l, " high "); put_i(&l, t - s->rise_at[j]);
                    put_s(&l, " ns, shorter than the driver's minimum (step missed)");
                    emit(s, &l);
                    s->sh->steps[j] -= s->rise_dir[j];
                }
                s->rise_at[j] = -1;
                s->fall_at[j] = t;
            }
            if (!(rise >> j & 1)) continue;
            en = s->rig->axis[j].enable.offset < 0 || (s->val[RG_G_ENABLE] >> j & 1);
            if (en && !s->realclock && s->fall_at[j] >= 0 &&
                t - s->fall_at[j] < (int64_t)llround(s->rig->step_pulse_us * 1e3)) {
                lbuf l;
                s->violations++;
                start(s, &l); put_s(&l, "VIOLATION a STEP low time of axis ");
                put_s(&l, jname[j]); put_s(&l, " of "); put_i(&l, t - s->fall_at[j]);
                put_s(&l, " ns, shorter than the driver's minimum (step missed)");
                emit(s, &l);
                s->rise_at[j] = -1;
                s->rise_dir[j] = 0;
                continue;
            }
            s->rise_at[j] = en ? t : -1;
            s->rise_dir[j] = 0;
            if (!en) continue;
            if (s->rig->axis[j].sim_lose_step_ms >= 0 && !s->lost[j] &&
                t >= (int64_t)llround(s->rig->axis[j].sim_lose_step_ms * 1e6)) {
                s->lost[j] = 1;
                s->rise_at[j] = -1;
                logs(s, "driver dropped a step (injected) on axis ", jname[j]);
                continue;
            }
            d = ((s->val[RG_G_DIR] >> j & 1) ^ s->rig->axis[j].dir_invert) ? 1 : -1;
            s->sh->steps[j] += d;
            s->rise_dir[j] = d;
            s->pulses[j]++;
            if (s->sh->laser && !s->realclock) {
                s->violations++;
                logs(s, "VIOLATION a step with the laser on", NULL);
            }
        }
        return 0;
    }
    if (g == RG_G_SHUTTER || g == RG_G_INDICATOR) {
        if (old == now) return 0;
        if (g == RG_G_SHUTTER) s->sh->shutter = (int)(now & 1);
        else {
            s->sh->indicator = (int)(now & 1);
            s->indicator_on_at = (now & 1) ? s->sh->now_ns : -1;
        }
        if (!s->realclock && (g == RG_G_SHUTTER ? s->rig->shutter : s->rig->indicator).offset >= 0)
            logs(s, g == RG_G_SHUTTER ? (now & 1 ? "shutter open" : "shutter closed")
                                      : (now & 1 ? "indicator on" : "indicator off"), NULL);
        update_light(s);
        return 0;
    }
    if (g == RG_G_HEART) {
        if ((now ^ old) & 1) {
            /* the pump only charges while it is still charged or being started */
            s->sh->heartbeat_edges++;
            s->sh->heartbeat_last_ns = s->sh->now_ns;
        }
        update_light(s);
        return 0;
    }
    if (old == now || s->realclock) {
        if (g == RG_G_LASER) { s->sh->laser = (int)(now & 1); update_light(s); }
        if (g == RG_G_ENABLE)
            for (int j = 0; j < RG_NJOINTS; j++) s->sh->enable[j] = (int)(now >> j & 1);
        return 0;
    }
    if (g == RG_G_LASER) {
        s->sh->laser = (int)(now & 1);
        if (s->log >= 0) {
            start(s, &l);
            put_s(&l, s->sh->laser ? "laser 1" : "laser 0");
            if (!s->sh->laser && s->rig->heartbeat.offset >= 0) {
                put_s(&l, " (heartbeat toggles "); put_i(&l, s->sh->heartbeat_edges);
                put_s(&l, ")");
            }
            emit(s, &l);
        }
        if (s->sh->laser) s->il_open_since = -1, check_interlock(s);
        if (s->sh->laser && s->rig->emission_delay_ms > 0 &&
            (s->indicator_on_at < 0 || s->sh->now_ns - s->indicator_on_at <
             (int64_t)llround(s->rig->emission_delay_ms * 1e6))) {
            s->violations++;
            logs(s, "VIOLATION laser on sooner than emission_delay_ms after the indicator", NULL);
        }
        update_light(s);
        return 0;
    }
    start(s, &l);
    put_s(&l, g == RG_G_DIR ? "dir" : "enable");
    for (int j = 0; j < RG_NJOINTS; j++) {
        if (!((old ^ now) >> j & 1)) continue;
        put_s(&l, " "); put_s(&l, jname[j]); put_s(&l, now >> j & 1 ? "=1" : "=0");
        if (g == RG_G_ENABLE) s->sh->enable[j] = (int)(now >> j & 1);
    }
    emit(s, &l);
    return 0;
}

static int sim_inputs(rg_chip *c, unsigned *level, unsigned *edges)
{
    sim *s = (sim *)c;
    unsigned v = 0;
    for (int j = 0; j < RG_NJOINTS; j++) if (home_tripped(s, j)) v |= 1u << j;
    check_interlock(s);
    if (s->sh->interlock) v |= RG_IN_INTERLOCK;
    for (int j = 0; j < RG_NJOINTS; j++) if (limit_tripped(s, j)) v |= RG_IN_LIMIT(j);
    if (key_on(s)) v |= RG_IN_KEY;
    *level = v;
    /* an interlock that opened and closed again since the last read: its edge */
    *edges = 0;
    if (s->rig->sim_interlock_open_ms >= 0) {
        int64_t at = (int64_t)llround(s->rig->sim_interlock_open_ms * 1e6);
        if (at > s->last_read && at <= s->sh->now_ns) *edges |= RG_IN_INTERLOCK;
    }
    s->last_read = s->sh->now_ns;
    return 0;
}

static int64_t real_ns(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000000000 + t.tv_nsec;
}

static void real_sleep(int64_t t)
{
    struct timespec d = {(time_t)(t / 1000000000), (long)(t % 1000000000)};
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &d, NULL) == EINTR) {}
}

static int64_t sim_now(rg_chip *c)
{
    sim *s = (sim *)c;
    return s->realclock ? real_ns() : s->sh->now_ns;
}

static void sim_sleep_until(rg_chip *c, int64_t t)
{
    sim *s = (sim *)c;
    if (s->realclock) { real_sleep(t); return; }
    if (t > s->sh->now_ns) {
        if (s->rig->sim_realtime) real_sleep(s->t0_real + t);
        s->sh->now_ns = t;
    }
    /* injected: the controller is preempted here (its clock jumps on) */
    if (!s->stalled && s->rig->sim_stall_at_ms >= 0 &&
        s->sh->now_ns >= (int64_t)llround(s->rig->sim_stall_at_ms * 1e6)) {
        lbuf l;
        s->stalled = 1;
        start(s, &l); put_s(&l, "controller preempted (injected) for ");
        put_i(&l, (int64_t)llround(s->rig->sim_stall_ms * 1e3)); put_s(&l, " us"); emit(s, &l);
        if (s->rig->sim_realtime) real_sleep(s->t0_real + s->sh->now_ns +
                                             (int64_t)llround(s->rig->sim_stall_ms * 1e6));
        s->sh->now_ns += (int64_t)llround(s->rig->sim_stall_ms * 1e6);
    }
    check_interlock(s);
    update_light(s);
}

static void final_states(sim *s, const char *why)
{
    lbuf l;
    if (s->log < 0) return;
    start(s, &l);
    put_s(&l, why);
    put_s(&l, " laser="); put_i(&l, s->sh->laser);
    put_s(&l, " light="); put_i(&l, s->sh->light);
    put_s(&l, " enable=");
    for (int j = 0; j < RG_NJOINTS; j++) put_i(&l, s->sh->enable[j]);
    put_s(&l, " steps");
    for (int j = 0; j < RG_NJOINTS; j++) {
        put_s(&l, " "); put_s(&l, jname[j]); put_s(&l, "="); put_i(&l, s->sh->steps[j]);
    }
    put_s(&l, " violations="); put_i(&l, s->violations);
    emit(s, &l);
}

static void finish_log(sim *s)
{
    /* async-signal-safe (the emergency path): close and rename, nothing freed; a log
     * that lost lines stays LOG.part, never under its name */
    if (s->log < 0) return;
    s->log = -1;
    if (s->log_errno) lm_out_abort_fd_now(&s->lo);
    else if (lm_out_commit_fd_now(&s->lo)) s->log_errno = errno ? errno : EIO;
}

static void sim_emergency(rg_chip *c)
{
    sim *s = (sim *)c;
    if (s->closed) return;
    s->val[RG_G_LASER] = 0;
    s->sh->laser = 0;
    s->sh->light = 0;
    logs(s, "stop: laser 0", NULL);
    s->val[RG_G_SHUTTER] = s->val[RG_G_INDICATOR] = 0;
    s->sh->shutter = s->sh->indicator = 0;
    s->val[RG_G_ENABLE] = 0;
    for (int j = 0; j < RG_NJOINTS; j++) s->sh->enable[j] = 0;
    logs(s, "stop: enable 0 (every driver)", NULL);
    final_states(s, "final (stopped)");
    finish_log(s);
}

static void sim_note(rg_chip *c, const char *what)
{
    sim *s = (sim *)c;
    lbuf l;
    if (s->log < 0) return;
    start(s, &l);
    put_s(&l, what);
    if (!strncmp(what, "FAULT", 5) || !strncmp(what, "stopped", 7)) {
        put_s(&l, "; last STEP edge ");
        if (s->last_step_edge >= 0) put_t(&l, s->last_step_edge); else put_s(&l, "none");
        if (s->il_opened_at >= 0) { put_s(&l, ", interlock opened "); put_t(&l, s->il_opened_at); }
    }
    if (!strncmp(what, "moved", 5) || !strncmp(what, "homed", 5) ||
        !strncmp(what, "stopped", 7)) {
        put_s(&l, ": pulses");
        for (int j = 0; j < RG_NJOINTS; j++) {
            put_s(&l, " "); put_s(&l, jname[j]); put_s(&l, "="); put_i(&l, s->pulses[j]);
        }
        put_s(&l, ", motors at");
        for (int j = 0; j < RG_NJOINTS; j++) {
            put_s(&l, " "); put_i(&l, s->sh->steps[j]);
        }
    }
    memset(s->pulses, 0, sizeof s->pulses);
    emit(s, &l);
}

static int sim_close(rg_chip *c)
{
    sim *s = (sim *)c;
    int rc;
    if (!s->closed) {
        final_states(s, "final");
        finish_log(s);
    }
    s->closed = 1;
    lm_out_free(&s->lo);
    if (s->shared) munmap(s->sh, s->shlen);
    else free(s->sh);
    rc = s->log_errno ? RG_EIO : 0;
    free(s);
    return rc;
}

static int sim_motors(rg_chip *c, long steps[RG_NJOINTS])
{
    sim *s = (sim *)c;
    for (int j = 0; j < RG_NJOINTS; j++) steps[j] = (long)s->sh->steps[j];
    return 1;
}

static const rg_chip_ops sim_ops = {sim_set, sim_inputs, sim_now, sim_sleep_until,
                                    sim_emergency, sim_close, sim_note, sim_motors};

/* The state file appears under its name only once it has its full size (a watchdog
 * mapping it earlier would fault): made as PATH.part, renamed when it is mapped. */
static int open_shared(sim *s, const char *path, const rg_rig *rig, char *err, size_t cap)
{
    lm_out o;
    /* a mapped file: a regular one (a unique temporary, renamed when mapped) */
    if (lm_out_open(&o, path, LM_OUT_FD | LM_OUT_REGULAR, err, cap)) return RG_EIO;
    s->shlen = sizeof(rg_sim_shared);
    if (ftruncate(o.fd, (off_t)s->shlen)) {
        snprintf(err, cap, "%s: %s", path, strerror(errno));
        lm_out_abort(&o, 0);
        return RG_EIO;
    }
    s->sh = mmap(NULL, s->shlen, PROT_READ | PROT_WRITE, MAP_SHARED, o.fd, 0);
    if (s->sh == MAP_FAILED) {
        snprintf(err, cap, "%s: %s", path, strerror(errno));
        lm_out_abort(&o, 0);
        s->sh = NULL;
        return RG_EIO;
    }
    memcpy(s->sh->magic, "lmrigsim", 8);
    s->sh->pid = (int32_t)getpid();
    /* the pump's hold and presence before the file appears: a watchdog must never see
     * a hold of 0 */
    s->sh->timeout_ns = (int64_t)llround(rig->heartbeat_timeout_ms * 1e6);
    s->sh->pump = rig->heartbeat.offset >= 0;
    if (lm_out_commit(&o, err, cap)) {
        munmap(s->sh, s->shlen);
        s->sh = NULL;
        return RG_EIO;
    }
    s->shared = 1;
    return 0;
}

static int sim_make(const rg_rig *rig, const rg_open_opts *o, int realclock, rg_chip **c,
                    char *err, size_t cap)
{
    sim *s = calloc(1, sizeof *s);
    int rc = 0;
    if (!s) { snprintf(err, cap, "out of memory"); return RG_ENOMEM; }
    s->base.ops = &sim_ops;
    s->rig = rig;
    s->log = -1;
    s->realclock = realclock;
    s->il_open_since = -1;
    s->il_opened_at = -1;
    s->last_step_edge = -1;
    s->indicator_on_at = -1;
    for (int j = 0; j < RG_NJOINTS; j++) s->limit_at[j] = s->rise_at[j] = s->fall_at[j] = -1;
    if (o && o->sim_state) rc = open_shared(s, o->sim_state, rig, err, cap);
    else if (!(s->sh = calloc(1, sizeof *s->sh))) { snprintf(err, cap, "out of memory"); rc = RG_ENOMEM; }
    if (rc) { free(s); return rc; }
    memcpy(s->sh->magic, "lmrigsim", 8);
    s->sh->pid = (int32_t)getpid();
    s->sh->timeout_ns = (int64_t)llround(rig->heartbeat_timeout_ms * 1e6);
    s->sh->pump = rig->heartbeat.offset >= 0;
    s->sh->heartbeat_last_ns = -s->sh->timeout_ns - 1;
    for (int j = 0; j < RG_NJOINTS; j++) {
        const rg_axis *x = &rig->axis[j];
        s->home_step[j] = llround(x->home_at * x->steps_per);
        /* power-on: a motor with a home switch stands mid-travel (not known to the
         * controller until homed); one without stands where home_at says */
        s->sh->steps[j] = x->home.offset >= 0 ? llround((x->min + x->max) / 2 * x->steps_per)
                                              : s->home_step[j];
    }
    s->sh->interlock = interlock_closed(s);
    if (o && o->sim_log && !realclock) {
        if (lm_out_open(&s->lo, o->sim_log, LM_OUT_FD, err, cap)) {
            sim_close(&s->base);
            return RG_EIO;
        }
        s->log = s->lo.fd;
    }
    if (rig->sim_realtime || realclock) s->t0_real = real_ns();
    if (s->log >= 0) {
        lbuf l;
        start(s, &l);
        put_s(&l, "open simulated chip (rig file ");
        put_s(&l, rig->path);
        put_s(&l, "), interlock ");
        put_s(&l, s->sh->interlock ? "closed" : "open");
        if (rig->heartbeat.offset >= 0) {
            put_s(&l, ", heartbeat pump hold ");
            put_i(&l, s->sh->timeout_ns / 1000);
            put_s(&l, " us");
        } else if (rig->eye_safe_without_heartbeat) {
            put_s(&l, ", no heartbeat (the rig file says the beam is eye-safe without one)");
        } else {
            put_s(&l, ", no heartbeat: emission refused");
        }
        emit(s, &l);
    }
    *c = &s->base;
    return 0;
}

int rg_sim_open(const rg_rig *rig, const rg_open_opts *o, rg_chip **c, char *err,
                size_t cap)
{
    return sim_make(rig, o, 0, c, err, cap);
}

int rg_null_open(const rg_rig *rig, rg_chip **c, char *err, size_t cap)
{
    return sim_make(rig, NULL, 1, c, err, cap);
}
