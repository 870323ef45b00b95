/* t_machine.c -- the rig engine's machine half through its table (rig.h): the rig
 * file reader and its errors, poses to steps, homing, coordinated trapezoidal moves,
 * travel checks before the first pulse, exposures against the interlock and the
 * maximum on-time, the heartbeat pump, the emergency path, and a replay writing the
 * same simulator log.  Runs on the simulated chip (argv[1]: the example rig file). */
#define _GNU_SOURCE
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>
#include "rig/rig.h"
#include "unit.h"

static const rig_api *rg;
static char example[1 << 16];
static char tmpdir[256];

/* The example with `old` replaced by `new` (first occurrence), in a static buffer. */
static const char *variant(const char *old, const char *new)
{
    static char buf[1 << 16];
    const char *p = strstr(example, old);
    if (!p) { printf("FAIL variant: '%s' not in the example\n", old); return example; }
    snprintf(buf, sizeof buf, "%.*s%s%s", (int)(p - example), example, new, p + strlen(old));
    return buf;
}

static int parse(const char *text, rg_rig *rig, char *err)
{
    return rg->rig_parse(text, strlen(text), "x.rig", rig, err, RG_ERRMAX);
}

static void bad(const char *text, const char *want, const char *what)
{
    rg_rig rig;
    char err[RG_ERRMAX] = "";
    int rc = parse(text, &rig, err);
    CHECK(rc == RG_EINVAL && strstr(err, want), "rig file: %s -> '%s' (got '%s')", what, want,
          err);
}

static void test_reader(void)
{
    rg_rig rig;
    char err[RG_ERRMAX] = "";
    int rc = parse(example, &rig, err);
    CHECK(rc == 0, "the example rig file reads (%s)", err);
    CHECK(!strcmp(rig.chip, "gpiochip0") && rig.laser.offset == 24 &&
          rig.interlock.offset == 25 && rig.interlock.active_low == 1 &&
          rig.heartbeat.offset == 26 && rig.max_on_ms == 200,
          "global keys: chip, laser, interlock active_low, heartbeat, max_on_ms");
    CHECK(rig.axis[RG_J_U].linear && !rig.axis[RG_J_M1A].linear &&
          rig.axis[RG_J_U].steps_per == 400 && rig.axis[RG_J_M2B].step.offset == 5 &&
          rig.axis[RG_J_M1A].enable.active_low && rig.axis[RG_J_M1A].home_dir == -1,
          "axis blocks: units, steps, lines, flags");
    CHECK(fabs(rig.geom.joint[RG_J_M1A].steps_per - 200 * 180 / M_PI) < 1e-9 &&
          fabs(rig.geom.joint[RG_J_U].hi - 20) < 1e-12,
          "the geometry's joints come from the axes (steps per rad, travel in rad/mm)");
    bad(variant("settle_ms 5", "settle_ms 5\nfoo 3"), "x.rig:15: unknown key 'foo'",
        "unknown key");
    bad(variant("max_on_ms 200", "max_on_ms 200\nmax_on_ms 100"),
        "x.rig:13: 'max_on_ms' is given twice (first at line 12)", "key twice");
    bad(variant("speed 10 ", "speed 1O "), "'1O' is not a number (for 'speed')", "bad number");
    bad(variant("accel 100 ", "accel 1e999 "), "'1e999' is not a number", "overflowing number");
    bad(variant("home 19", "home 18"), "x.rig:38: line 18 is already the home line of axis "
        "m1a (line 24)", "a line used twice");
    bad(variant("laser 24", "laser 3"), "x.rig:63: line 3 is already the laser line (line 8)",
        "laser on a STEP line");
    bad(variant("tick_us 250", "tick_us 250\nstep 3"), "'step' belongs to an axis",
        "an axis key before any axis");
    bad(variant("chip gpiochip0\n", ""), "x.rig: no 'chip' line", "no chip");
    bad(variant("speed 10 ", "speed 30 "), "6000 steps/s, more than one step per control step",
        "faster than the control step");
    bad(variant("home_at -15\n", "home_at -16\n"), "'home_at' -16 is outside its travel",
        "home outside travel");
    bad(variant("min -15\n", "min 15\n"), "'min' must be less than 'max'", "min >= max");
    bad(variant("axis m1b", "axis m1a"), "axis m1a is given twice", "an axis twice");
    bad(variant("axis m1b", "axis w"), "'axis' takes one of", "unknown axis");
    bad(variant("laser 24", "laser 24 active_high"), "only 'active_low' may follow",
        "bad flag");
    bad(variant("laser 24", "laser -1"), "is not a line offset", "negative line");
    bad(variant("max_on_ms 200", "max_on_ms 0"), "greater than 0", "zero on-time");
    {
        char nul[64] = "chip a\n";
        CHECK(rg->rig_parse(nul, 10, "n.rig", &rig, err, sizeof err) == RG_EINVAL &&
              strstr(err, "n.rig:2: a NUL byte"), "a NUL byte is refused (%s)", err);
    }
    CHECK(rg->rig_load("/nonexistent.rig", &rig, err, sizeof err) == RG_EINVAL &&
          strstr(err, "/nonexistent.rig: No such file"), "a missing file (%s)", err);
    CHECK(rg->rig_load("/dev/zero", &rig, err, sizeof err) == RG_EINVAL &&
          strstr(err, "not a regular file"), "/dev/zero is not read (%s)", err);
}

static void test_steps(void)
{
    rg_rig rig;
    char err[RG_ERRMAX];
    rg_pose p = {{0}};
    long s[RG_NJOINTS];
    parse(example, &rig, err);
    p.j[RG_J_M1A] = 10 * M_PI / 180;
    p.j[RG_J_U] = -1.25;
    p.j[RG_J_M2B] = -0.0049 * M_PI / 180;     /* just under a step: rounds to -1 */
    CHECK(rg->pose_steps(&rig, &p, s, err, sizeof err) == 0 && s[RG_J_M1A] == 2000 &&
          s[RG_J_U] == -500 && s[RG_J_M2B] == -1 && s[RG_J_M1B] == 0,
          "poses to steps: 10 deg = 2000, -1.25 mm = -500, -0.0049 deg = -1");
    p.j[RG_J_V] = 20.01;
    CHECK(rg->pose_steps(&rig, &p, s, err, sizeof err) == RG_ETRAVEL &&
          strstr(err, "axis v: 20.01 mm is outside its travel [-20, 20]"),
          "a pose outside travel is refused (%s)", err);
}

/* ---- the simulated machine ------------------------------------------------------ */

static rg_sim_shared *map_state(const char *path)
{
    int fd = open(path, O_RDONLY);
    void *p;
    if (fd < 0) return NULL;
    p = mmap(NULL, sizeof(rg_sim_shared), PROT_READ, MAP_SHARED, fd, 0);
    close(fd);
    return p == MAP_FAILED ? NULL : p;
}

typedef struct watch {
    rg_sim_shared *sh;
    long start[RG_NJOINTS], n[RG_NJOINTS];
    double worst;               /* largest spread of progress fractions, in steps */
    long ticks;
    int emergency_at;           /* call emergency_off at this tick (0: never) */
    int stop_at;                /* ask to stop at this tick (0: never) */
    int laser_after;            /* laser line read after the emergency */
} watch;

/* The stop callback runs every control step: it watches the motors through the
 * simulator's shared state (coordination) and can pull the emergency stop. */
static int watcher(void *ctx)
{
    watch *w = ctx;
    int lead = 0;
    double f;
    w->ticks++;
    for (int j = 0; j < RG_NJOINTS; j++) if (w->n[j] > w->n[lead]) lead = j;
    f = w->n[lead] ? (double)labs(w->sh->steps[lead] - w->start[lead]) / w->n[lead] : 0;
    for (int j = 0; j < RG_NJOINTS; j++) {
        double d = fabs(labs(w->sh->steps[j] - w->start[j]) - f * w->n[j]);
        if (d > w->worst) w->worst = d;
    }
    if (w->emergency_at && w->ticks == w->emergency_at) {
        rg->emergency_off();
        w->laser_after = w->sh->laser;
        return 1;
    }
    return w->stop_at && w->ticks >= w->stop_at;
}

static int open_sim(const char *text, rg_rig *rig, rg_machine **m, const char *log,
                    const char *state, char *err)
{
    rg_open_opts o = {RG_BACKEND_SIM, NULL, log, state, 0};
    int rc = parse(text, rig, err);
    if (rc) return rc;
    return rg->open(rig, &o, m, err, RG_ERRMAX);
}

static void path(char *buf, const char *name)
{
    snprintf(buf, 512, "%s/%s", tmpdir, name);
}

static void test_motion(void)
{
    rg_rig rig;
    rg_machine *m = NULL;
    char err[RG_ERRMAX] = "", logp[512], statep[512];
    long s[RG_NJOINTS], t[RG_NJOINTS] = {0};
    rg_sim_shared *sh;
    int64_t t0;
    watch w;
    path(logp, "motion.log");
    path(statep, "motion.state");
    CHECK(open_sim(example, &rig, &m, logp, statep, err) == 0, "open the simulator (%s)", err);
    if (!m) return;
    sh = map_state(statep);
    CHECK(sh && !memcmp(sh->magic, "lmrigsim", 8), "the simulator's state is in a shared file");
    if (!sh) return;
    CHECK(rg->move_steps(m, t, NULL, NULL, err, sizeof err) == RG_EINVAL &&
          strstr(err, "not homed"), "no move before homing (%s)", err);
    CHECK(rg->home(m, NULL, NULL, err, sizeof err) == 0 && rg->homed(m), "homing (%s)", err);
    rg->position(m, s, NULL);
    /* GRBL homing ends a pull-off (0.5 deg = 100 steps, 0.5 mm = 200) off home_at */
    CHECK(s[RG_J_M1A] == -2900 && s[RG_J_U] == -7800 && sh->steps[RG_J_M1A] == -2900 &&
          sh->steps[RG_J_V] == -7800,
          "homed: the controller and the motors agree at home_at + pull-off (%ld, motor %lld)",
          s[RG_J_M1A], (long long)sh->steps[RG_J_M1A]);
    CHECK(sh->enable[0] == 1 && sh->laser == 0, "drivers enabled for the moves, laser off");

    /* one axis: 2000 steps at 2000 steps/s, 20000 steps/s^2: 0.1 s up, 0.9 s cruise,
     * 0.1 s down */
    t[RG_J_M1A] = s[RG_J_M1A] + 2000;
    for (int j = 1; j < RG_NJOINTS; j++) t[j] = s[j];
    t0 = sh->now_ns;
    CHECK(rg->move_steps(m, t, NULL, NULL, err, sizeof err) == 0 &&
          sh->steps[RG_J_M1A] == t[RG_J_M1A], "a move of 2000 steps arrives (%s)", err);
    {
        double dt = (sh->now_ns - t0) / 1e9 - 0.005 - 0.00025;   /* settle, DIR setup */
        CHECK(fabs(dt - 1.1) < 0.001, "the trapezoid takes 1.1 s (%.6f s)", dt);
    }
    /* six axes together: they arrive together, each step on its own profile */
    memset(&w, 0, sizeof w);
    w.sh = sh;
    {
        long want[RG_NJOINTS] = {2000, -2000, 3000, -7000, 100, 1};
        for (int j = 0; j < RG_NJOINTS; j++) {
            w.start[j] = sh->steps[j];
            w.n[j] = labs(want[j] - sh->steps[j]);
        }
        CHECK(rg->move_steps(m, want, watcher, &w, err, sizeof err) == 0, "a six-axis move");
        for (int j = 0; j < RG_NJOINTS; j++) if (sh->steps[j] != want[j]) {
            CHECK(0, "axis %d at %lld, want %ld", j, (long long)sh->steps[j], want[j]);
        }
        CHECK(w.worst <= 2.0, "coordinated: every axis within 2 of its steps of where the "
              "longest axis's progress puts it, worst %.3f", w.worst);
        /* travel checked before the first pulse */
        long before = sh->steps[RG_J_U];
        want[RG_J_U] = 8001;
        CHECK(rg->move_steps(m, want, NULL, NULL, err, sizeof err) == RG_ETRAVEL &&
              sh->steps[RG_J_U] == before && strstr(err, "axis u: 20.0025 mm"),
              "a move past travel is refused before any pulse (%s)", err);
    }
    /* a move stopped half way (a signal): the position is no longer trusted */
    {
        long back[RG_NJOINTS], now[RG_NJOINTS];
        memset(&w, 0, sizeof w);
        w.sh = sh;
        w.stop_at = 300;
        rg->position(m, back, NULL);
        back[RG_J_M1A] -= 2000;
        CHECK(rg->move_steps(m, back, watcher, &w, err, sizeof err) == RG_ESTOP &&
              !rg->homed(m) && strstr(err, "stopped"), "a stopped move un-homes the machine");
        rg->position(m, now, NULL);
        CHECK(now[RG_J_M1A] == sh->steps[RG_J_M1A] && now[RG_J_M1A] > back[RG_J_M1A],
              "... after counting the steps it made (%ld)", now[RG_J_M1A]);
        CHECK(rg->move_steps(m, back, NULL, NULL, err, sizeof err) == RG_EINVAL &&
              rg->expose(m, 5, NULL, NULL, err, sizeof err) == RG_EINVAL,
              "no move and no exposure until it is homed again");
        CHECK(rg->home(m, NULL, NULL, err, sizeof err) == 0, "homed again (%s)", err);
        memcpy(back, s, sizeof back);
        back[RG_J_M1A] = 2000;
        back[RG_J_M1B] = -2000; back[RG_J_U] = 3000; back[RG_J_V] = -7000;
        back[RG_J_M2A] = 100; back[RG_J_M2B] = 1;
        CHECK(rg->move_steps(m, back, NULL, NULL, err, sizeof err) == 0, "and back (%s)", err);
    }
    /* exposures */
    CHECK(rg->expose(m, 201, NULL, NULL, err, sizeof err) == RG_EINVAL &&
          strstr(err, "max_on_ms 200"), "an exposure longer than max_on_ms is refused (%s)", err);
    t0 = sh->now_ns;
    CHECK(rg->expose(m, 50, NULL, NULL, err, sizeof err) == 0 && sh->laser == 0 &&
          sh->light == 0 && fabs((sh->now_ns - t0) / 1e6 - 50) < 1e-6,
          "a 50 ms exposure: laser on for 50 ms exactly, off after (%s)", err);
    CHECK(sh->heartbeat_edges == 200, "the heartbeat toggled every control step (%lld)",
          (long long)sh->heartbeat_edges);
    /* the emergency path from within a computation */
    memset(&w, 0, sizeof w);
    w.sh = sh;
    w.emergency_at = 10;
    CHECK(rg->expose(m, 100, watcher, &w, err, sizeof err) == RG_ESTOP && w.laser_after == 0 &&
          sh->enable[0] == 0 && sh->enable[5] == 0,
          "emergency_off mid-exposure: laser off, then every driver disabled");
    rg->close(m);
    {
        char *log = unit_slurp(logp);
        const char *a = log ? strstr(log, "stop: laser 0") : NULL;
        const char *b = a ? strstr(a, "stop: enable 0") : NULL;
        CHECK(a && b && strstr(b, "final (stopped) laser=0 light=0 enable=000000"),
              "the log: laser off first, then drivers, then the final states");
        CHECK(log && !strstr(log, "VIOLATION"), "no safety violation in the log");
        CHECK(log && strstr(log, "moved: pulses m1a=2000 m1b=0"), "the log counts pulses");
    }
    munmap(sh, sizeof *sh);
}

static void test_interlock(void)
{
    rg_rig rig;
    rg_machine *m = NULL;
    char err[RG_ERRMAX] = "", logp[512];
    path(logp, "il.log");
    CHECK(open_sim(variant("settle_ms 5", "settle_ms 5\nsim_interlock open"), &rig, &m, NULL,
                   NULL, err) == RG_EINTERLOCK && !m && strstr(err, "interlock (line 25) is open"),
          "an interlock open at start refuses to start (%s)", err);
    /* opens at 30 s: homing takes 26 s of simulated time, then expose until it opens */
    CHECK(open_sim(variant("settle_ms 5", "settle_ms 5\nsim_interlock_open_ms 30000.1"), &rig, &m,
                   logp, NULL, err) == 0, "open (%s)", err);
    if (!m) return;
    rg->home(m, NULL, NULL, err, sizeof err);
    {
        int rc = 0, n = 0;
        while (n < 200 && (rc = rg->expose(m, 150, NULL, NULL, err, sizeof err)) == 0) n++;
        CHECK(rc == RG_EINTERLOCK && strstr(err, "opened during the exposure"),
              "the interlock opening mid-exposure stops it (%s, after %d)", err, n);
        CHECK(rg->expose(m, 10, NULL, NULL, err, sizeof err) == RG_EFAULT &&
              strstr(err, "fault is latched"), "no exposure while the fault is latched");
    }
    rg->close(m);
    {
        char *log = unit_slurp(logp);
        const char *a = log ? strstr(log, "interlock open") : NULL;
        const char *b = a ? strstr(a, "laser 0") : NULL;
        double ta = 0, tb = 0;
        if (a) { const char *l = a; while (l > log && l[-1] != '\n') l--; ta = atof(l); }
        if (b) { const char *l = b; while (l > log && l[-1] != '\n') l--; tb = atof(l); }
        CHECK(a && b && tb - ta <= 250e-6 + 1e-9 && tb >= ta,
              "laser off within one control step of the opening (%.0f us)", (tb - ta) * 1e6);
        CHECK(log && !strstr(log, "VIOLATION"), "no violation");
    }
}

static void test_home_timeout(void)
{
    rg_rig rig;
    rg_machine *m = NULL;
    char err[RG_ERRMAX] = "";
    const char *v = variant("axis m2a\n", "axis m2a\nsim_home broken\n");
    CHECK(open_sim(v, &rig, &m, NULL, NULL, err) == 0, "open (%s)", err);
    if (!m) return;
    CHECK(rg->home(m, NULL, NULL, err, sizeof err) == RG_ETIMEOUT && !rg->homed(m) &&
          strstr(err, "axis m2a: its home switch (line 22) did not trip within 30 s"),
          "a home switch that never trips times out (%s)", err);
    rg->close(m);
}

/* The same session twice writes the same log, byte for byte (simulated time). */
static void session(const char *log)
{
    rg_rig rig;
    rg_machine *m = NULL;
    char err[RG_ERRMAX];
    long a[RG_NJOINTS] = {100, 200, -300, 400, -500, 600};
    if (open_sim(example, &rig, &m, log, NULL, err)) return;
    rg->home(m, NULL, NULL, err, sizeof err);
    rg->move_steps(m, a, NULL, NULL, err, sizeof err);
    rg->expose(m, 20, NULL, NULL, err, sizeof err);
    rg->close(m);
}

static void test_replay(void)
{
    char a[512], b[512], *ta;
    path(a, "r1.log");
    path(b, "r2.log");
    session(a);
    session(b);
    ta = strdup(unit_slurp(a) ? unit_slurp(a) : "");
    CHECK(ta[0] && !strcmp(ta, unit_slurp(b) ? unit_slurp(b) : "x"), "a replay writes an identical log");
    CHECK(access(a, F_OK) == 0 && access(strcat(strcpy((char[600]){0}, a), ".part"), F_OK) != 0,
          "the log is renamed from LOG.part when the machine closes");
    free(ta);
}

int main(int argc, char **argv)
{
    char *ex;
    rg = rig_get_api(RIG_ABI);
    if (!rg || !rg->rig_parse) { printf("FAIL no machine table\n"); return 1; }
    ex = unit_slurp(argc > 1 ? argv[1] : "tests/rig/machine.rig");
    if (!ex) { printf("FAIL cannot read the example rig file\n"); return 1; }
    snprintf(example, sizeof example, "%s", ex);
    if (unit_tmpdir(tmpdir, sizeof tmpdir, "t_machine")) return 1;
    test_reader();
    test_steps();
    test_motion();
    test_interlock();
    test_home_timeout();
    test_replay();
    unit_rmtree(tmpdir);
    return unit_failed();
}
