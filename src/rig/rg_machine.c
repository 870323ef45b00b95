/* rg_machine.c -- a machine's life: open the chip of the chosen backend (laser off,
 * drivers disabled, the interlock read), real-time scheduling when permitted, the
 * step-timing figures, close (laser off, then drivers disabled, then the lines
 * released), and the machine block of the engine's table. */
#define _GNU_SOURCE
#include <errno.h>
#include <math.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include "rig/rg_hw.h"

void rg_safety_register(rg_machine *m, int add);

const rig_api *rg_geom_api(void) { return rig_get_api(RIG_ABI); }

static void realtime(rg_machine *m)
{
    struct sched_param sp = {.sched_priority = 50};
    char a[64], b[64];
    if (sched_setscheduler(0, SCHED_FIFO, &sp) == 0) snprintf(a, sizeof a, "SCHED_FIFO 50");
    else snprintf(a, sizeof a, "SCHED_FIFO not permitted (%s)", strerror(errno));
    if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) snprintf(b, sizeof b, "memory locked");
    else snprintf(b, sizeof b, "mlockall not permitted (%s)", strerror(errno));
    snprintf(m->sched, sizeof m->sched, "%s, %s", a, b);
}

int rg_open(const rg_rig *rig, const rg_open_opts *o, rg_machine **mp, char *err, size_t cap)
{
    rg_machine *m = calloc(1, sizeof *m);
    unsigned lv, ed;
    int rc, backend = o ? o->backend : RG_BACKEND_SIM;
    *mp = NULL;
    if (!m) { snprintf(err, cap, "out of memory"); return RG_ENOMEM; }
    m->rig = *rig;
    snprintf(m->sched, sizeof m->sched, "simulated time (no real-time scheduling needed)");
    if (backend == RG_BACKEND_GPIOD)
        rc = rg_gpiod_open(&m->rig, o && o->chip ? o->chip : rig->chip, &m->chip, err, cap);
    else if (backend == RG_BACKEND_NULL)
        rc = rg_null_open(&m->rig, &m->chip, err, cap);
    else
        rc = rg_sim_open(&m->rig, o, &m->chip, err, cap);
    if (rc) { free(m); return rc; }
    rg_safety_register(m, 1);
    if (backend != RG_BACKEND_SIM) {
        m->measure = 1;
        m->late = calloc(RG_TIMING_MAX, sizeof *m->late);
        if (o && o->realtime) realtime(m);
        else snprintf(m->sched, sizeof m->sched, "normal scheduling (real time not asked)");
    }
    /* safe state first, whatever the lines were */
    rg_laser_off(m);
    m->chip->ops->set(m->chip, RG_G_ENABLE, (1u << RG_NJOINTS) - 1, 0);
    for (int j = 0; j < RG_NJOINTS; j++)
        if (rig->axis[j].home.offset < 0)
            m->pos[j] = lround(rig->axis[j].home_at * rig->axis[j].steps_per);
    if (m->chip->ops->inputs(m->chip, &lv, &ed) || !(lv & RG_IN_INTERLOCK)) {
        snprintf(err, cap, "the interlock (line %d) is open: close it (door, key switch) "
                 "before the rig starts", rig->interlock.offset);
        rg_close(m);
        return RG_EINTERLOCK;
    }
    *mp = m;
    return 0;
}

int rg_close(rg_machine *m)
{
    if (!m) return 0;
    rg_laser_off(m);
    m->chip->ops->set(m->chip, RG_G_ENABLE, (1u << RG_NJOINTS) - 1, 0);
    rg_safety_register(m, 0);
    int rc = m->chip->ops->close(m->chip);
    free(m->late);
    free(m);
    return rc;
}

static int cmpf(const void *a, const void *b)
{
    float x = *(const float *)a, y = *(const float *)b;
    return (x > y) - (x < y);
}

void rg_get_timing(const rg_machine *m, rg_timing *t)
{
    long n = m->late_n < RG_TIMING_MAX ? m->late_n : RG_TIMING_MAX;
    float *s;
    memset(t, 0, sizeof *t);
    t->edges = m->late_n;
    if (!n || !(s = malloc(n * sizeof *s))) return;
    memcpy(s, m->late, n * sizeof *s);
    qsort(s, n, sizeof *s, cmpf);
    t->p50_us = s[n / 2];
    t->p99_us = s[(long)(n * 0.99) < n ? (long)(n * 0.99) : n - 1];
    t->max_us = s[n - 1];
    free(s);
}

const char *rg_sched_note(const rg_machine *m) { return m->sched; }
static int homed(const rg_machine *m) { return m->homed; }
static int motors(const rg_machine *m, long steps[RG_NJOINTS])
{
    if (m->chip->ops->motors && m->chip->ops->motors(m->chip, steps)) return 1;
    rg_position(m, steps, NULL);
    return 0;
}

static double clock_s(const rg_machine *m) { return m->chip->ops->now(m->chip) / 1e9; }

void rg_machine_fill(rig_api *a)
{
    a->rig_load = rg_rig_load;
    a->rig_parse = rg_rig_parse;
    a->pose_steps = rg_pose_steps;
    a->open = rg_open;
    a->sched_note = rg_sched_note;
    a->home = rg_home;
    a->move = rg_move;
    a->move_steps = rg_move_steps;
    a->plan_move = rg_plan_move;
    a->expose = rg_expose;
    a->position = rg_position;
    a->homed = homed;
    a->motors = motors;
    a->timing = rg_get_timing;
    a->close = rg_close;
    a->emergency_off = rg_emergency_off;
    a->fault = rg_fault_get;
    a->reset = rg_reset;
    a->dose_plan = rg_dose_plan;
    a->dose_rig = rg_dose_rig;
    a->mpe = rg_mpe;
    a->scan_order = rg_scan_order;
    a->scan_time = rg_scan_time;
    a->scan_limit_text = rg_scan_limit_text;
    a->clock_s = clock_s;
    a->sweep = rg_sweep;
    a->sweep_time = rg_sweep_time;
    a->spots = rg_spots_run;
    a->spot_chain = rg_spot_chain;
    a->spot_pose = rg_spot_pose_run;
}
