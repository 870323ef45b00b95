/* vm_rig.c -- the libgpiod backend against the kernel's own GPIO character device:
 * run inside the gpio-vm guest (tests/t_85_rig_gpio.sh) with the gpio-sim chip
 * $GPIO_CHIP, whose lines the test reads and drives through $GPIO_SIM/sim_gpioN/
 * (value: what we drive; pull: drives an input).  Checks: a line held by another
 * consumer refused by name, unknown chip and line, homing against a home switch that
 * another process trips, slow moves whose STEP pulses and DIR level are counted
 * through sysfs, the heartbeat toggling and the laser going low when the interlock
 * opens mid-exposure, and SIGTERM mid-scan: laser low, then drivers disabled.
 * argv[1]: the rig file (tests/rig/vm.rig).  Prints PASS/FAIL lines; exit 0 or 1. */
#define _GNU_SOURCE
#include <fcntl.h>
#include <sched.h>
#include <gpiod.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include "rig/rig.h"
#include "unit.h"
#include "vm_sim.h"

static const rig_api *rg;

/* A child that watches one output for ms milliseconds, polling every 0.5 ms:
 * rising edges counted, the level of `other` at the first and last rising edge.
 * Reports through a pipe.  Returns the child's pid. */
typedef struct seen { int rises, other_first, other_last; } seen;
static pid_t watch_line(int line, int other, int ms, int fd[2])
{
    pid_t pid;
    if (pipe(fd)) return -1;
    pid = fork();
    if (pid == 0) {
        seen s = {0, -1, -1};
        struct sched_param sp = {.sched_priority = 90};
        int last;
        /* above the controller: it sees every level the controller leaves for at
         * least one poll (the pulse is 2 ms high: step_pulse_us in vm.rig) */
        sched_setscheduler(0, SCHED_FIFO, &sp);
        last = sysval(line);
        int64_t end = now_ms() + ms;
        close(fd[0]);
        while (now_ms() < end) {
            int v = sysval(line);
            if (v == 1 && last == 0) {
                s.rises++;
                s.other_last = sysval(other);
                if (s.other_first < 0) s.other_first = s.other_last;
            }
            if (v >= 0) last = v;
            usleep(500);
        }
        if (write(fd[1], &s, sizeof s) != sizeof s) _exit(1);
        _exit(0);
    }
    close(fd[1]);
    return pid;
}

/* The home switches as a model of real ones, in a child: tripped trip_ms after the
 * start (the fast seek reaches them), released when DIR of m1a (line 6) turns away
 * from home (the pull-off), tripped again 50 ms after DIR turns back (the slow
 * locate), released at the second pull-off.  With `once` the model ends there. */
static pid_t switch_model(int trip_ms)
{
    pid_t pid = fork();
    if (pid == 0) {
        int64_t end = now_ms() + 20000, t;
        int phase = 0, dir;
        msleep(trip_ms);
        for (int j = 18; j < 24; j++) pull(j, 1);
        while (now_ms() < end && phase < 3) {
            dir = sysval(6);
            if (phase == 0 && dir == 1) { for (int j = 18; j < 24; j++) pull(j, 0); phase = 1; }
            else if (phase == 1 && dir == 0) {
                t = now_ms() + 50;
                while (now_ms() < t) usleep(1000);
                for (int j = 18; j < 24; j++) pull(j, 1);
                phase = 2;
            } else if (phase == 2 && dir == 1) {
                for (int j = 18; j < 24; j++) pull(j, 0);
                phase = 3;
            }
            usleep(1000);
        }
        _exit(phase == 3 ? 0 : 1);
    }
    return pid;
}

static seen watch_result(pid_t pid, int fd[2])
{
    seen s = {-1, -1, -1};
    if (read(fd[0], &s, sizeof s) != sizeof s) s.rises = -1;
    close(fd[0]);
    waitpid(pid, NULL, 0);
    return s;
}

static void test_refusals(const rg_rig *rig0, const char *chip)
{
    rg_rig rig = *rig0;
    rg_open_opts o = {RG_BACKEND_GPIOD, chip, NULL, NULL, 0};
    rg_machine *m = NULL;
    char err[RG_ERRMAX] = "";
    struct gpiod_chip *c = gpiod_chip_open_lookup(chip);
    struct gpiod_line *l = c ? gpiod_chip_get_line(c, 24) : NULL;
    int rc;
    CHECK(l && gpiod_line_request_output(l, "other", 0) == 0, "another consumer holds line 24");
    rc = rg->open(&rig, &o, &m, err, sizeof err);
    CHECK(rc == RG_EBUSY && !m && strstr(err, "line 24 (the laser, rig file line 6) is already "
          "in use by \"other\""), "a line held by another consumer is refused (%s)", err);
    if (l) gpiod_line_release(l);
    if (c) gpiod_chip_close(c);
    o.chip = "nochip";
    CHECK(rg->open(&rig, &o, &m, err, sizeof err) == RG_EINVAL && strstr(err, "no GPIO chip "
          "'nochip'"), "an unknown chip (%s)", err);
    o.chip = chip;
    rig.axis[RG_J_V].home.offset = 40;
    CHECK(rg->open(&rig, &o, &m, err, sizeof err) == RG_EINVAL && strstr(err, "has 32 lines: "
          "line 40 (home switch of axis v"), "an unknown line (%s)", err);
}

static void test_machine(const rg_rig *rig, const char *chip)
{
    rg_open_opts o = {RG_BACKEND_GPIOD, chip, NULL, NULL, 0};
    rg_machine *m = NULL;
    char err[RG_ERRMAX] = "";
    long pos[RG_NJOINTS], t[RG_NJOINTS];
    int fd[2], rc;
    pid_t pid;
    seen s;

    CHECK(rg->open(rig, &o, &m, err, sizeof err) == 0, "open the gpio-sim chip (%s)", err);
    if (!m) return;
    CHECK(sysval(24) == 0 && sysval(12) == 1 && sysval(17) == 1,
          "at open: laser low, the active-low ENABLE lines high (drivers disabled)");
    /* homing: another process models the home switches (tripped after 0.3 s) */
    pid = switch_model(300);
    {
        int64_t t0 = now_ms();
        int st = 1;
        rc = rg->home(m, NULL, NULL, err, sizeof err);
        waitpid(pid, &st, 0);
        rg->position(m, pos, NULL);
        /* GRBL cycle: seek, pull-off, locate, debounce, pull-off (0.02 deg = 4 steps,
         * 0.02 mm = 8 steps off home_at) */
        CHECK(rc == 0 && rg->homed(m) && pos[0] == -2996 && pos[2] == -7992 &&
              now_ms() - t0 >= 250 && WIFEXITED(st) && WEXITSTATUS(st) == 0,
              "homing: seek, pull-off, locate, pull-off against the switches (%s, %lld ms, "
              "at %ld %ld)", err, (long long)(now_ms() - t0), pos[0], pos[2]);
        CHECK(sysval(12) == 0, "drivers enabled (ENABLE active-low: low)");
    }
    /* a slow move: +20 steps on m1a, counted through sysfs, DIR high */
    memcpy(t, pos, sizeof t);
    t[0] += 20;
    pid = watch_line(0, 6, 2000, fd);
    rc = rg->move_steps(m, t, NULL, NULL, err, sizeof err);
    s = watch_result(pid, fd);
    /* on a loaded host the controller may come too late for a step: then it stops
     * the move (a latched deadline fault) and says how far it got -- never a pulse
     * too short to see */
    if (rc == RG_EFAULT && strstr(err, "late")) {
        long now[RG_NJOINTS];
        rg->position(m, now, NULL);
        CHECK(s.rises == now[0] - pos[0], "a move of +20 steps stopped late (%s): %d STEP "
              "pulses seen, %ld sent", err, s.rises, now[0] - pos[0]);
        rg->close(m);
        for (int j = 18; j < 24; j++) pull(j, 0);
        return;
    }
    CHECK(rc == 0 && s.rises == 20 && s.other_first == 1 && s.other_last == 1,
          "a move of +20 steps: %d STEP pulses seen, DIR %d..%d (%s)", s.rises, s.other_first,
          s.other_last, err);
    t[0] -= 13;
    pid = watch_line(0, 6, 2000, fd);
    rc = rg->move_steps(m, t, NULL, NULL, err, sizeof err);
    s = watch_result(pid, fd);
    CHECK(rc == 0 && s.rises == 13 && s.other_first == 0 && s.other_last == 0,
          "a move of -13 steps: %d STEP pulses seen, DIR %d..%d", s.rises, s.other_first,
          s.other_last);
    /* exposure: the heartbeat toggles; the interlock opens at 0.4 s; laser low */
    pid = fork();
    if (pid == 0) {
        int ok = 1, changes = 0, last = sysval(26);
        int64_t end = now_ms() + 300;
        msleep(20);
        ok &= sysval(24) == 1;
        while (now_ms() < end) {
            int v = sysval(26);
            if (v != last) changes++;
            last = v;
            usleep(1000);
        }
        ok &= changes >= 5;
        ok &= sysval(24) == 1;
        pull(25, 1);           /* active-low interlock: high = open */
        msleep(100);
        ok &= sysval(24) == 0;
        _exit(ok ? 0 : 1);
    }
    rc = rg->expose(m, 1500, NULL, NULL, err, sizeof err);
    {
        int st;
        waitpid(pid, &st, 0);
        CHECK(WIFEXITED(st) && WEXITSTATUS(st) == 0, "during the exposure: laser high, the "
              "heartbeat toggling, and laser low within 100 ms of the interlock opening");
    }
    CHECK(rc == RG_EINTERLOCK && sysval(24) == 0 && sysval(12) == 1,
          "expose returns the interlock, fault latched: laser low, drivers disabled (%s)", err);
    CHECK(rg->expose(m, 10, NULL, NULL, err, sizeof err) == RG_EFAULT && sysval(24) == 0,
          "no exposure while the fault is latched");
    pull(25, 0);
    rg->close(m);
    CHECK(sysval(24) == 0, "closed: laser low");
    for (int j = 18; j < 24; j++) pull(j, 0);
}

static void on_term(int sig)
{
    (void)sig;
    rg->emergency_off();    /* what the dialogue's stop hook does */
    for (;;) pause();       /* keep the lines: the parent reads them, then SIGKILLs */
}

/* SIGTERM while a scan runs: the laser goes low, then the drivers are disabled. */
static void test_kill(const rg_rig *rig0, const char *chip)
{
    rg_rig rig = *rig0;
    pid_t pid;
    int before, laser, en0, en5, st;
    for (int j = 0; j < RG_NJOINTS; j++) rig.axis[j].home.offset = -1;   /* homed at once */
    pid = fork();
    if (pid == 0) {
        rg_open_opts o = {RG_BACKEND_GPIOD, chip, NULL, NULL, 0};
        rg_machine *m;
        char err[RG_ERRMAX];
        long t[RG_NJOINTS];
        signal(SIGTERM, on_term);
        if (rg->open(&rig, &o, &m, err, sizeof err) || rg->home(m, NULL, NULL, err, sizeof err))
            _exit(1);
        rg->position(m, t, NULL);
        for (int k = 0; k < 100; k++) {            /* the scan: step, expose */
            t[k % RG_NJOINTS] += 1;
            if (rg->move_steps(m, t, NULL, NULL, err, sizeof err) ||
                rg->expose(m, 1500, NULL, NULL, err, sizeof err)) _exit(1);
        }
        _exit(0);
    }
    msleep(700);
    before = sysval(24);
    kill(pid, SIGTERM);
    msleep(300);
    laser = sysval(24); en0 = sysval(12); en5 = sysval(17);
    kill(pid, SIGKILL);
    waitpid(pid, &st, 0);
    CHECK(before == 1, "the scan was mid-exposure when SIGTERM came (laser %d)", before);
    CHECK(laser == 0 && en0 == 1 && en5 == 1, "after SIGTERM mid-scan: laser low (%d), drivers "
          "disabled (ENABLE %d %d)", laser, en0, en5);
}

int main(int argc, char **argv)
{
    rg_rig rig;
    char err[RG_ERRMAX];
    const char *chip = getenv("GPIO_CHIP");
    sim_dir = getenv("GPIO_SIM");
    setvbuf(stdout, NULL, _IOLBF, 0);
    rg = rig_get_api(RIG_ABI);
    if (!chip || !sim_dir || argc < 2) { printf("FAIL not in the gpio-vm guest\n"); return 1; }
    if (rg->rig_load(argv[1], &rig, err, sizeof err)) { printf("FAIL %s\n", err); return 1; }
    test_refusals(&rig, chip);
    test_machine(&rig, chip);
    test_kill(&rig, chip);
    return unit_failed();
}
