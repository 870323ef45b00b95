/* t_safety.c -- the rig's safety functions on the simulated chip (doc/rig-safety.md),
 * through the engine's table: the latched fault and its reset, with a fault injected
 * at each stage of a scan (before emission, mid-exposure, during a move, during
 * homing); the interlock and a limit switch stopping motion within 1 ms (read from
 * the simulator's own event log); a missed deadline and a lost step; heartbeat loss
 * and the rules for rigs without a heartbeat; the dose against the MPE, checked
 * against the closed forms of IEC 60825-1:2014 Table A.1 written out here; the
 * emission sequence (indicator, delay, shutter, key switch) in time; GRBL homing and
 * settle_ms.  argv[1]: tests/rig/machine.rig. */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "rig/rig.h"
#include "unit.h"

static const rig_api *rg;
static char base[1 << 16], tmpdir[256];

/* The base rig with extra lines appended (later keys are new keys, never repeats). */
static const char *with(const char *extra)
{
    static char buf[1 << 17];
    snprintf(buf, sizeof buf, "%s\n%s\n", base, extra);
    return buf;
}

/* The base with one line replaced. */
static const char *swap(const char *old, const char *new, const char *extra)
{
    static char buf[1 << 17];
    const char *p = strstr(base, old);
    if (!p) { printf("FAIL swap: '%s' not in the rig\n", old); return base; }
    snprintf(buf, sizeof buf, "%.*s%s%s\n%s\n", (int)(p - base), base, new, p + strlen(old),
             extra);
    return buf;
}

static char logp[600];
static rg_rig rig_;

static rg_machine *open_sim(const char *text, const char *name, char *err)
{
    rg_open_opts o = {RG_BACKEND_SIM, NULL, logp, NULL, 0};
    rg_machine *m = NULL;
    snprintf(logp, sizeof logp, "%s/%s.log", tmpdir, name);
    if (rg->rig_parse(text, strlen(text), "s.rig", &rig_, err, RG_ERRMAX)) return NULL;
    if (rg->open(&rig_, &o, &m, err, RG_ERRMAX)) return NULL;
    return m;
}

/* The time stamp of the first log line containing `what` after `from`; -1: none. */
static double stamp(const char *log, const char *what, const char **from)
{
    const char *p = strstr(from && *from ? *from : log, what), *l;
    if (!p) return -1;
    for (l = p; l > log && l[-1] != '\n'; l--) {}
    if (from) *from = p + 1;
    return atof(l);
}

static double field(const char *log, const char *what, const char *key)
{
    const char *p = strstr(log, what);
    p = p ? strstr(p, key) : NULL;
    return p ? atof(p + strlen(key)) : -1;
}

static void to(long t[RG_NJOINTS], rg_machine *m, int j, long d)
{
    rg->position(m, t, NULL);
    t[j] += d;
}

/* Interlock opening during a move: the last STEP edge within 1 ms, latched, laser and
 * drivers off, a reset refused while it is open and accepted once it closed, homing
 * required again. */
static void test_interlock_move(void)
{
    char err[RG_ERRMAX] = "", why[RG_ERRMAX];
    long t[RG_NJOINTS];
    /* homing ends at 26.0178 s; the move starts then and lasts over 1 s */
    rg_machine *m = open_sim(with("sim_interlock_open_ms 26500.0371\n"
                                  "sim_interlock_close_ms 27000"), "ilmove", err);
    CHECK(m != NULL, "open (%s)", err);
    if (!m) return;
    CHECK(rg->home(m, NULL, NULL, err, sizeof err) == 0, "home (%s)", err);
    to(t, m, RG_J_M1A, 2000);
    CHECK(rg->move_steps(m, t, NULL, NULL, err, sizeof err) == RG_EINTERLOCK &&
          strstr(err, "opened during motion"), "the interlock stops the move (%s)", err);
    CHECK(rg->fault(m, why, sizeof why) == RG_F_INTERLOCK && !rg->homed(m),
          "latched (%s), not homed any more", why);
    CHECK(rg->move_steps(m, t, NULL, NULL, err, sizeof err) == RG_EFAULT &&
          rg->expose(m, 5, NULL, NULL, err, sizeof err) == RG_EFAULT &&
          rg->home(m, NULL, NULL, err, sizeof err) == RG_EFAULT,
          "latched: no move, no exposure, no homing (%s)", err);
    CHECK(rg->reset(m, err, sizeof err) == RG_EFAULT && strstr(err, "still open"),
          "a reset is refused while the interlock is open (%s)", err);
    rg->close(m);
    /* closed again (simulated time moves only with the machine): a new machine whose
     * interlock opened and closed before the reset */
    m = open_sim(with("sim_interlock_open_ms 26500.0371\nsim_interlock_close_ms 26600"),
                 "ilreset", err);
    if (!m) return;
    rg->home(m, NULL, NULL, err, sizeof err);
    to(t, m, RG_J_M1A, 2000);
    rg->move_steps(m, t, NULL, NULL, err, sizeof err);
    CHECK(rg->fault(m, NULL, 0) == RG_F_INTERLOCK, "latched again");
    {   /* time passes in homing's refusal? no: it is refused before any wait; reset
         * reads the inputs at 26.5 s: still open -> refused; so let the rig close it at
         * once instead */
    }
    rg->close(m);
    m = open_sim(with("sim_interlock_open_ms 26500.0371\nsim_interlock_close_ms 26500.2"),
                 "ilreset2", err);
    if (!m) return;
    rg->home(m, NULL, NULL, err, sizeof err);
    to(t, m, RG_J_M1A, 2000);
    rg->move_steps(m, t, NULL, NULL, err, sizeof err);
    CHECK(rg->fault(m, NULL, 0) == RG_F_INTERLOCK, "the interlock opened and closed within "
          "one control step: still latched (its edge counts)");
    CHECK(rg->reset(m, err, sizeof err) == 0 && !rg->fault(m, NULL, 0) && !rg->homed(m),
          "reset accepted once it is closed; not homed (%s)", err);
    CHECK(rg->move_steps(m, t, NULL, NULL, err, sizeof err) == RG_EINVAL &&
          strstr(err, "not homed"), "after the reset: home first (%s)", err);
    CHECK(rg->home(m, NULL, NULL, err, sizeof err) == 0 &&
          rg->move_steps(m, t, NULL, NULL, err, sizeof err) == 0,
          "homed again, the move runs (%s)", err);
    rg->close(m);
    {
        char *log = unit_slurp(logp);
        double open = log ? stamp(log, "interlock open", NULL) : -1;
        double last = log ? field(log, "FAULT latched", "last STEP edge ") : -1;
        const char *f = NULL;
        double fault = log ? stamp(log, "FAULT latched", &f) : -1;
        double en = log ? stamp(log, "enable m1a=0", &f) : -1;
        CHECK(open > 26 && last > 0 && last - open <= 1e-3,
              "the last STEP edge %.1f us after the interlock opened (at most 1000)",
              (last - open) * 1e6);
        CHECK(fault >= 0 && en >= fault, "the log: the fault, then the drivers off");
        CHECK(log && !strstr(log, "VIOLATION"), "no violation in the simulator's log");
    }
}

/* A fault injected at each stage of a scan. */
static void test_stages(void)
{
    char err[RG_ERRMAX] = "", why[RG_ERRMAX];
    long t[RG_NJOINTS];
    rg_machine *m;
    char *log;
    /* during homing (homing starts at 0 and takes 26 s) */
    m = open_sim(with("sim_interlock_open_ms 5000"), "ilhome", err);
    if (!m) { CHECK(0, "open (%s)", err); return; }
    CHECK(rg->home(m, NULL, NULL, err, sizeof err) == RG_EINTERLOCK && !rg->homed(m) &&
          rg->fault(m, why, sizeof why) == RG_F_INTERLOCK,
          "interlock open during homing: latched, not homed (%s)", why);
    rg->close(m);
    log = unit_slurp(logp);
    CHECK(log && field(log, "FAULT latched", "last STEP edge ") - 5.0 <= 1e-3 &&
          !strstr(log, "VIOLATION") && !strstr(log, "laser 1"),
          "... its last STEP edge within 1 ms of 5 s, laser never on");
    /* before emission: open at rest, then expose */
    m = open_sim(with("sim_interlock_open_ms 26100"), "ilbefore", err);
    if (!m) return;
    rg->home(m, NULL, NULL, err, sizeof err);
    to(t, m, RG_J_M1A, 10);
    rg->move_steps(m, t, NULL, NULL, err, sizeof err);
    {   /* wait past 26.1 s in short exposures' absence: a slow move of 200 steps */
        to(t, m, RG_J_M1B, 100);
        int rc = rg->move_steps(m, t, NULL, NULL, err, sizeof err);
        if (rc == 0) rc = rg->expose(m, 10, NULL, NULL, err, sizeof err);
        CHECK(rc == RG_EINTERLOCK && rg->fault(m, NULL, 0) == RG_F_INTERLOCK,
              "interlock open before the exposure: refused and latched (%s)", err);
    }
    rg->close(m);
    log = unit_slurp(logp);
    CHECK(log && !strstr(log, "laser 1") && !strstr(log, "VIOLATION"),
          "... the laser never went on");
    /* mid-exposure */
    m = open_sim(with("sim_interlock_open_ms 26100.1"), "ilmid", err);
    if (!m) return;
    rg->home(m, NULL, NULL, err, sizeof err);
    {
        int rc = 0, n = 0;
        while (n < 20 && !(rc = rg->expose(m, 50, NULL, NULL, err, sizeof err))) n++;
        CHECK(rc == RG_EINTERLOCK && strstr(err, "during the exposure") &&
              rg->fault(m, NULL, 0) == RG_F_INTERLOCK && !rg->homed(m),
              "interlock open mid-exposure: laser off, latched, home again (%s)", err);
    }
    rg->close(m);
    log = unit_slurp(logp);
    {
        double open = log ? stamp(log, "interlock open", NULL) : -1;
        const char *f = log ? strstr(log, "interlock open") : NULL;
        double off = f ? stamp(log, "laser 0", &f) : -1;
        double drv = f ? stamp(log, "enable m1a=0", &f) : -1;
        CHECK(open > 0 && off >= open && off - open <= 250e-6 + 1e-9 && drv >= off,
              "... laser off %.0f us after the opening (one control step), then the drivers",
              (off - open) * 1e6);
    }
}

static void test_limit_deadline_lost(void)
{
    char err[RG_ERRMAX] = "", why[RG_ERRMAX];
    long t[RG_NJOINTS], real[RG_NJOINTS];
    rg_machine *m;
    char *log;
    /* a limit switch on m1a (line 27) trips mid-move */
    m = open_sim(swap("home_speed 2\n", "home_speed 2\nlimit 27\nsim_limit_ms 26500.05\n", ""),
                 "limit", err);
    CHECK(m != NULL, "a rig with a limit switch (%s)", err);
    if (!m) return;
    rg->home(m, NULL, NULL, err, sizeof err);
    to(t, m, RG_J_M1A, 2000);
    CHECK(rg->move_steps(m, t, NULL, NULL, err, sizeof err) == RG_EFAULT &&
          rg->fault(m, why, sizeof why) == RG_F_LIMIT && strstr(why, "limit switch (line 27)"),
          "a limit switch stops the move and latches (%s)", why);
    CHECK(rg->reset(m, err, sizeof err) == RG_EFAULT && strstr(err, "still tripped"),
          "reset refused while it is tripped (%s)", err);
    rg->close(m);
    log = unit_slurp(logp);
    CHECK(log && field(log, "FAULT latched", "last STEP edge ") - 26.50005 <= 1e-3 &&
          !strstr(log, "VIOLATION"), "... the last STEP edge within 1 ms of the trip");
    /* soft limits stay separate: refused before the first pulse, nothing latched */
    m = open_sim(base, "soft", err);
    if (!m) return;
    rg->home(m, NULL, NULL, err, sizeof err);
    to(t, m, RG_J_U, 1000000);
    CHECK(rg->move_steps(m, t, NULL, NULL, err, sizeof err) == RG_ETRAVEL &&
          !rg->fault(m, NULL, 0), "a soft limit refuses the move before a pulse, no latch");
    rg->close(m);
    /* a missed deadline: the controller preempted 3 ms mid-move (max_late_us 125) */
    m = open_sim(with("sim_stall_at_ms 26300\nsim_stall_ms 3"), "late", err);
    if (!m) return;
    rg->home(m, NULL, NULL, err, sizeof err);
    to(t, m, RG_J_M1A, 2000);
    CHECK(rg->move_steps(m, t, NULL, NULL, err, sizeof err) == RG_EFAULT &&
          rg->fault(m, why, sizeof why) == RG_F_DEADLINE && strstr(why, "ms late"),
          "a STEP edge 3 ms late stops the move, latched (%s)", why);
    rg->position(m, t, NULL);
    rg->motors(m, real);
    CHECK(t[RG_J_M1A] == real[RG_J_M1A], "... no step lost: the controller knows where it "
          "stopped (%ld = motor %ld)", t[RG_J_M1A], real[RG_J_M1A]);
    rg->close(m);
    log = unit_slurp(logp);
    CHECK(log && !strstr(log, "VIOLATION"), "... and no pulse shorter than the driver's minimum");
    /* the same stall with a tolerance above it: late pulses keep their width, no loss */
    m = open_sim(with("sim_stall_at_ms 26300\nsim_stall_ms 3\nmax_late_us 5000"), "late2", err);
    if (!m) return;
    rg->home(m, NULL, NULL, err, sizeof err);
    to(t, m, RG_J_M1A, 2000);
    CHECK(rg->move_steps(m, t, NULL, NULL, err, sizeof err) == 0, "within max_late_us the "
          "move goes on (%s)", err);
    rg->motors(m, real);
    CHECK(real[RG_J_M1A] == t[RG_J_M1A], "... and arrives: every pulse at least step_pulse_us "
          "high after a preemption (motor %ld, want %ld)", real[RG_J_M1A], t[RG_J_M1A]);
    rg->close(m);
    log = unit_slurp(logp);
    CHECK(log && strstr(log, "controller preempted") && !strstr(log, "VIOLATION"),
          "... no VIOLATION (the simulator drops pulses shorter than the minimum)");
    /* a lost step: the driver drops one pulse */
    m = open_sim(swap("home_speed 2\n", "home_speed 2\nsim_lose_step_ms 26400\n", ""), "lost", err);
    if (!m) return;
    rg->home(m, NULL, NULL, err, sizeof err);
    to(t, m, RG_J_M1A, 2000);
    CHECK(rg->move_steps(m, t, NULL, NULL, err, sizeof err) == RG_EFAULT &&
          rg->fault(m, why, sizeof why) == RG_F_LOSTSTEP && strstr(why, "1 steps off"),
          "a lost step latches (%s)", why);
    rg->close(m);
}

/* Closed forms of IEC 60825-1:2014 Table A.1 (small source, C6 = 1), written out again. */
static double mpe_ref(double wl, double t)
{
    if (t <= 10) return 18 * pow(t, 0.75);
    double th = 18 * pow(10, -0.25) * t, c3 = wl < 450 ? 1 : pow(10, 0.02 * (wl - 450));
    double ph = wl >= 600 ? INFINITY : t <= 100 ? 100 * c3 : c3 * t;
    return fmin(th, ph);
}

static void test_dose(void)
{
    char err[RG_ERRMAX] = "";
    rg_rig rig;
    rg_dose d;
    const char *lim;
    const double E1 = 1e-3 / (M_PI * 3.5e-3 * 3.5e-3);     /* 1 mW into 7 mm: W/m^2 */
    double wl[] = {400, 450, 532, 599, 632.8, 700}, ts[] = {1.8e-5, 1e-3, 0.25, 10, 11, 50,
                                                            100, 500, 3e4};
    int ok = 1;
    for (int i = 0; i < 6; i++)
        for (int k = 0; k < 9; k++) {
            double a = rg->mpe(wl[i], ts[k], &lim), b = mpe_ref(wl[i], ts[k]);
            if (!(fabs(a - b) <= 1e-12 * b)) { ok = 0; printf("  mpe(%g, %g) %g vs %g\n", wl[i], ts[k], a, b); }
        }
    CHECK(ok, "the MPE follows Table A.1's closed forms (6 wavelengths x 9 durations)");
    CHECK(isnan(rg->mpe(800, 1, NULL)) && isnan(rg->mpe(632.8, 1e-6, NULL)),
          "no MPE outside 400-700 nm or below 18 us");
    CHECK(fabs(rg->mpe(632.8, 0.25, NULL) - 6.3640) < 1e-4, "MPE(0.25 s) = 18 x 0.25^0.75 = "
          "6.3640 J/m^2 (%.4f)", rg->mpe(632.8, 0.25, NULL));
    /* the worked number: 1 mW, 632.8 nm, 1 mm beam */
    {
        const char *t = swap("laser_power_mw 0.1", "laser_power_mw 1", "");
        char *p;
        static char buf[1 << 17];
        snprintf(buf, sizeof buf, "%s", t);
        p = strstr(buf, "beam_diameter_mm 0.4");
        if (p) memcpy(p, "beam_diameter_mm 1  ", 20);
        CHECK(rg->rig_parse(buf, strlen(buf), "x.rig", &rig, err, sizeof err) == 0,
              "a 1 mW rig (%s)", err);
    }
    CHECK(rg->dose_rig(&rig, 10, 20, &d, err, sizeof err) == 0 &&
          fabs(d.E_aperture - E1) < 1e-9 * E1 && fabs(E1 - 25.984) < 1e-3 &&
          fabs(d.H_total - E1 * 0.2) < 1e-9 &&
          fabs(d.fraction - E1 * 0.2 / (18 * pow(0.2, 0.75))) < 1e-12,
          "1 mW, 632.8 nm: E = %.3f W/m^2 over 7 mm; 20 x 10 ms = %.4f J/m^2, %.4f of the MPE",
          d.E_aperture, d.H_total, d.fraction);
    /* E t = 18 t^0.75 at t = (18 / E)^4 = 0.2304 s: 23 exposures of 10 ms pass, 24 not */
    CHECK(rg->dose_rig(&rig, 10, 23, &d, err, sizeof err) == 0 &&
          rg->dose_rig(&rig, 10, 24, &d, err, sizeof err) == RG_EDOSE &&
          fabs(d.fraction - E1 * 0.24 / (18 * pow(0.24, 0.75))) < 1e-12 && strstr(err, "1.01"),
          "23 x 10 ms pass, 24 x 10 ms exceed (%s)", err);
    /* the heartbeat's hold is bounded by the dose: 1 mW, max_on 200 ms: the largest
     * hold is (18 / E)^4 - 0.2 s (where E t = 18 t^0.75) */
    {
        static char buf[1 << 17];
        double tmax = pow(18 / E1, 4), hold = (tmax - 0.2) * 1e3;
        char want[64];
        snprintf(buf, sizeof buf, "%s", swap("heartbeat_timeout_ms 5", "heartbeat_timeout_ms 40",
                                             "laser_power_mw 1\n"));
        {
            char *p = strstr(buf, "laser_power_mw 0.1");
            if (p) memcpy(p, "#", 1);
        }
        snprintf(want, sizeof want, "at most %.3g ms of hold", hold);
        CHECK(rg->rig_parse(buf, strlen(buf), "x.rig", &rig, err, sizeof err) == RG_EINVAL &&
              strstr(err, want), "heartbeat_timeout_ms 40 at 1 mW refused: '%s' (%s)", want, err);
    }
    /* dose keys: all three or none; none: no emission */
    {
        rg_machine *m;
        static char buf[1 << 17];
        snprintf(buf, sizeof buf, "%s", base);
        char *p = strstr(buf, "wavelength_nm");
        if (p) *p = '#';
        CHECK(rg->rig_parse(buf, strlen(buf), "x.rig", &rig, err, sizeof err) == RG_EINVAL &&
              strstr(err, "needs all three"), "two of the three dose keys: refused (%s)", err);
        snprintf(buf, sizeof buf, "%s", base);
        for (const char *k = "laser_power_mw"; k; k = !strcmp(k, "laser_power_mw") ?
             "wavelength_nm" : !strcmp(k, "wavelength_nm") ? "beam_diameter_mm" : NULL)
            if ((p = strstr(buf, k))) *p = '#';
        m = open_sim(buf, "nodose", err);
        if (m) {
            rg->home(m, NULL, NULL, err, sizeof err);
            CHECK(rg->expose(m, 5, NULL, NULL, err, sizeof err) == RG_EINVAL &&
                  strstr(err, "cannot be checked"), "no dose keys: no emission (%s)", err);
            rg->close(m);
        }
    }
    /* the machine keeps the session's dose and refuses the exposure that would pass it */
    {
        rg_machine *m;
        static char buf[1 << 17];
        snprintf(buf, sizeof buf, "%s", swap("laser_power_mw 0.1", "laser_power_mw 1", ""));
        m = open_sim(buf, "session", err);
        if (m) {
            int rc = 0, n = 0;
            rg->home(m, NULL, NULL, err, sizeof err);
            while (n < 100 && !(rc = rg->expose(m, 10, NULL, NULL, err, sizeof err))) n++;
            rg->dose_plan(m, 10, 0, &d, err, sizeof err);
            CHECK(rc == RG_EDOSE && d.n == n && d.fraction <= 1 &&
                  n == (int)floor(pow(18 / E1, 4) / 0.01),
                  "the session's exposures stop before the MPE: %d of 10 ms, %.4f of it", n,
                  d.fraction);
            rg->close(m);
        }
    }
}

static void test_heartbeat(void)
{
    char err[RG_ERRMAX] = "", why[RG_ERRMAX];
    rg_machine *m;
    rg_rig rig;
    static char buf[1 << 17];
    char *p;
    /* no heartbeat line: motion yes, emission no */
    snprintf(buf, sizeof buf, "%s", base);
    if ((p = strstr(buf, "heartbeat 26"))) *p = '#';
    m = open_sim(buf, "nohb", err);
    CHECK(m != NULL, "a rig without a heartbeat opens (%s)", err);
    if (m) {
        rg->home(m, NULL, NULL, err, sizeof err);
        CHECK(rg->expose(m, 5, NULL, NULL, err, sizeof err) == RG_EINVAL &&
              strstr(err, "no 'heartbeat' line"), "... but refuses to emit (%s)", err);
        rg->close(m);
        CHECK(strstr(unit_slurp(logp), "no heartbeat: emission refused") != NULL,
              "the simulator's log says so at open");
    }
    strcat(buf, "\neye_safe_without_heartbeat yes\n");
    m = open_sim(buf, "eyesafe", err);
    if (m) {
        rg->home(m, NULL, NULL, err, sizeof err);
        CHECK(rg->expose(m, 5, NULL, NULL, err, sizeof err) == 0,
              "'eye_safe_without_heartbeat yes' at 0.1 mW: emission allowed (%s)", err);
        rg->close(m);
    }
    if ((p = strstr(buf, "laser_power_mw 0.1"))) memcpy(p, "laser_power_mw 9  ", 18);
    CHECK(rg->rig_parse(buf, strlen(buf), "x.rig", &rig, err, sizeof err) == RG_EINVAL &&
          strstr(err, "100 s"), "... but not at 9 mW (%s)", err);
    /* heartbeat loss: the loop preempted 8 ms mid-exposure (hold 5 ms) */
    m = open_sim(with("sim_stall_at_ms 26100\nsim_stall_ms 8"), "hbloss", err);
    if (m) {
        int rc = 0, n = 0;
        rg->home(m, NULL, NULL, err, sizeof err);
        while (n < 20 && !(rc = rg->expose(m, 50, NULL, NULL, err, sizeof err))) n++;
        CHECK(rc == RG_EFAULT && rg->fault(m, why, sizeof why) == RG_F_HEARTBEAT,
              "a stalled exposure loop: heartbeat fault latched (%s)", why);
        rg->close(m);
        {
            char *log = unit_slurp(logp);
            const char *f = log ? strstr(log, "controller preempted") : NULL;
            double st = f ? stamp(log, "controller preempted", NULL) : -1;
            double off = f ? stamp(log, "light 0 (heartbeat stopped)", &f) : -1;
            CHECK(st > 0 && off > st && off - st <= 5.25e-3 && !strstr(log, "VIOLATION"),
                  "... the pump cut the light %.3f ms into the stall (hold 5 ms)",
                  (off - st) * 1e3);
        }
    }
}

static void test_emission(void)
{
    char err[RG_ERRMAX] = "", why[RG_ERRMAX];
    rg_machine *m = open_sim(with("key_switch 27\nemission_indicator 28\nshutter 29\n"
                                  "emission_delay_ms 50\nshutter_ms 2"), "emit", err);
    CHECK(m != NULL, "a rig with key switch, indicator, shutter (%s)", err);
    if (!m) return;
    rg->home(m, NULL, NULL, err, sizeof err);
    CHECK(rg->expose(m, 20, NULL, NULL, err, sizeof err) == 0, "an exposure (%s)", err);
    rg->close(m);
    {
        char *log = unit_slurp(logp);
        const char *f = NULL;
        double ind = stamp(log, "indicator on", &f), las = stamp(log, "laser 1", &f),
               sho = stamp(log, "shutter open", &f), li = stamp(log, "light 1", &f),
               shc = stamp(log, "shutter closed", &f), lo = stamp(log, "laser 0", &f),
               ino = stamp(log, "indicator off", &f);
        CHECK(ind >= 0 && las - ind >= 0.050 - 1e-9 && sho >= las && li >= sho &&
              shc - sho >= 0.022 - 1e-9 && lo - shc >= 0.002 - 1e-9 && ino >= lo,
              "in time: indicator on, 50 ms, laser on, shutter open, light, shutter closed "
              "after 20 + 2 ms, laser off 2 ms later, indicator off (%.6f %.6f %.6f %.6f %.6f "
              "%.6f)", ind, las, sho, shc, lo, ino);
        CHECK(!strstr(log, "VIOLATION"), "no violation");
    }
    /* the key switch: off before: refused, nothing latched; off during: latched */
    m = open_sim(with("key_switch 27\nsim_key_off_ms 1"), "keyoff", err);
    if (m) {
        rg->home(m, NULL, NULL, err, sizeof err);
        CHECK(rg->expose(m, 20, NULL, NULL, err, sizeof err) == RG_EINTERLOCK &&
              strstr(err, "key switch is off") && !rg->fault(m, NULL, 0),
              "key off: no emission, nothing latched (%s)", err);
        rg->close(m);
    }
    m = open_sim(with("key_switch 27\nsim_key_off_ms 26100.1"), "keymid", err);
    if (m) {
        int rc = 0, n = 0;
        rg->home(m, NULL, NULL, err, sizeof err);
        while (n < 20 && !(rc = rg->expose(m, 50, NULL, NULL, err, sizeof err))) n++;
        CHECK(rc == RG_EINTERLOCK && rg->fault(m, why, sizeof why) == RG_F_KEY,
              "key turned off mid-exposure: latched (%s)", why);
        CHECK(rg->reset(m, err, sizeof err) == RG_EFAULT && strstr(err, "key switch is off"),
              "reset refused while the key is off (%s)", err);
        rg->close(m);
        CHECK(!strstr(unit_slurp(logp), "VIOLATION"), "no violation");
    }
}

static void test_homing(void)
{
    char err[RG_ERRMAX] = "";
    rg_machine *m = open_sim(base, "home", err);
    long s[RG_NJOINTS];
    if (!m) { CHECK(0, "open (%s)", err); return; }
    CHECK(rg->home(m, NULL, NULL, err, sizeof err) == 0, "home (%s)", err);
    rg->position(m, s, NULL);
    CHECK(s[RG_J_M1A] == -3000 + 100 && s[RG_J_U] == -8000 + 200,
          "homed a pull-off (0.5) off home_at (%ld %ld)", s[RG_J_M1A], s[RG_J_U]);
    CHECK(rg->expose(m, 5, NULL, NULL, err, sizeof err) == 0, "expose (%s)", err);
    rg->close(m);
    {
        char *log = unit_slurp(logp);
        const char *f = NULL;
        double h = stamp(log, "homed", &f), e = stamp(log, "laser 1", &f);
        CHECK(h > 0 && fabs(e - h - 0.005) < 1e-9, "settle_ms after homing: laser on %.6f s "
              "after 'homed' (settle 5 ms)", e - h);
        CHECK(!strstr(log, "VIOLATION"), "no violation");
    }
    /* a switch that bounces is caught by the debounce; a pull-off that does not clear */
    m = open_sim(swap("home_speed 2\n", "home_speed 2\nhome_pulloff 200\n", ""), "pull", err);
    CHECK(!m && strstr(err, "leaves its travel"), "a pull-off that leaves travel is refused "
          "(%s)", err);
}

int main(int argc, char **argv)
{
    char *b;
    rg = rig_get_api(RIG_ABI);
    if (!rg || !rg->reset) { printf("FAIL no safety table\n"); return 1; }
    b = unit_slurp(argc > 1 ? argv[1] : "tests/rig/machine.rig");
    if (!b) { printf("FAIL no rig file\n"); return 1; }
    snprintf(base, sizeof base, "%s", b);
    if (unit_tmpdir(tmpdir, sizeof tmpdir, "t_safety")) return 1;
    test_interlock_move();
    test_stages();
    test_limit_deadline_lost();
    test_dose();
    test_heartbeat();
    test_emission();
    test_homing();
    unit_rmtree(tmpdir);
    return unit_failed();
}
