/* rg_gpiod.c -- the real chip through libgpiod 1.6 (v1 API), consumer "lensmat".
 * Each output group is one bulk request (all STEP lines change in one ioctl; DIR,
 * ENABLE, the laser and the heartbeat each have their own, so the laser can be
 * switched off alone from a signal handler); the home switches and the interlock are
 * one input request with both-edge events, so an opening between two reads is still
 * seen.  Active-low is applied here (a bulk request takes one flag for all its lines,
 * a rig may mix).  Lines already held by another consumer are refused by name.
 * Time is the real CLOCK_MONOTONIC, waits are clock_nanosleep(TIMER_ABSTIME). */
#define _GNU_SOURCE
#include <errno.h>
#include <gpiod.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "rig/rg_hw.h"

static const char *const jname[RG_NJOINTS] = {"m1a", "m1b", "u", "v", "m2a", "m2b"};

typedef struct gline {
    const rg_line *l;
    char what[48];
    int bit;                    /* bit in its group's mask */
} gline;

typedef struct ggroup {
    struct gpiod_line_bulk bulk;
    gline lines[RG_NINPUTS];
    int n, requested;
    unsigned val;               /* logical values of the bits */
    int phys[RG_NINPUTS];       /* what was last written, per line in bulk order */
} ggroup;

typedef struct gchip {
    rg_chip base;
    const rg_rig *rig;
    struct gpiod_chip *chip;
    char name[RG_NAMEMAX];
    ggroup out[RG_NGROUPS];
    ggroup in;                  /* home switches (bit = axis), interlock, limits, key
                                   (the RG_IN_* bits) */
    unsigned levels;            /* their last levels read */
    int have_levels;
} gchip;

static void add(ggroup *g, const rg_line *l, int bit, const char *fmt, const char *a)
{
    gline *x;
    if (l->offset < 0) return;
    x = &g->lines[g->n++];
    x->l = l;
    x->bit = bit;
    snprintf(x->what, sizeof x->what, fmt, a);
}

static void describe(const gline *x, char *buf, size_t cap)
{
    snprintf(buf, cap, "line %d (%s, rig file line %d)", x->l->offset, x->what, x->l->at);
}

/* Why a request failed: which line is taken and by whom, else errno. */
static int request_failed(gchip *c, ggroup *g, int e, char *err, size_t cap)
{
    char d[128];
    for (int i = 0; i < g->n; i++) {
        struct gpiod_line *ln = gpiod_line_bulk_get_line(&g->bulk, i);
        gpiod_line_update(ln);
        if (gpiod_line_is_used(ln)) {
            const char *who = gpiod_line_consumer(ln);
            describe(&g->lines[i], d, sizeof d);
            snprintf(err, cap, "%s: %s is already in use by \"%s\": stop that program or "
                     "change the rig file", c->name, d, who && *who ? who : "(unnamed)");
            return RG_EBUSY;
        }
    }
    snprintf(err, cap, "%s: cannot request the lines: %s", c->name, strerror(e));
    return RG_EIO;
}

static int request(gchip *c, ggroup *g, int output, char *err, size_t cap)
{
    int defaults[RG_NINPUTS];
    int n = (int)gpiod_chip_num_lines(c->chip), rc;
    char d[128];
    if (!g->n) return 0;
    gpiod_line_bulk_init(&g->bulk);
    for (int i = 0; i < g->n; i++) {
        struct gpiod_line *ln;
        if (g->lines[i].l->offset >= n) {
            describe(&g->lines[i], d, sizeof d);
            snprintf(err, cap, "%s has %d lines: %s does not exist", c->name, n, d);
            return RG_EINVAL;
        }
        ln = gpiod_chip_get_line(c->chip, (unsigned)g->lines[i].l->offset);
        if (!ln) {
            describe(&g->lines[i], d, sizeof d);
            snprintf(err, cap, "%s: %s: %s", c->name, d, strerror(errno));
            return RG_EIO;
        }
        gpiod_line_bulk_add(&g->bulk, ln);
        defaults[i] = g->phys[i] = g->lines[i].l->active_low;     /* inactive */
    }
    if (output)
        rc = gpiod_line_request_bulk_output(&g->bulk, "lensmat", defaults);
    else
        rc = gpiod_line_request_bulk_both_edges_events(&g->bulk, "lensmat");
    if (rc) return request_failed(c, g, errno, err, cap);
    g->requested = 1;
    return 0;
}

static int g_set(rg_chip *cc, int gi, unsigned mask, unsigned val)
{
    gchip *c = (gchip *)cc;
    ggroup *g = &c->out[gi];
    g->val = (g->val & ~mask) | (val & mask);
    if (!g->requested) return 0;
    for (int i = 0; i < g->n; i++)
        g->phys[i] = (int)(g->val >> g->lines[i].bit & 1) ^ g->lines[i].l->active_low;
    return gpiod_line_set_value_bulk(&g->bulk, g->phys) ? RG_EIO : 0;
}

static int g_inputs(rg_chip *cc, unsigned *level, unsigned *edges)
{
    gchip *c = (gchip *)cc;
    ggroup *g = &c->in;
    int v[RG_NINPUTS];
    struct timespec zero = {0, 0};
    struct gpiod_line_bulk evb;
    *level = *edges = 0;
    if (!g->requested) return 0;
    /* one poll over every input's event fd (this runs every control step) */
    while (gpiod_line_event_wait_bulk(&g->bulk, &zero, &evb) == 1) {
        int more = 0;
        for (unsigned k = 0; k < gpiod_line_bulk_num_lines(&evb); k++) {
            struct gpiod_line *ln = gpiod_line_bulk_get_line(&evb, k);
            struct gpiod_line_event ev[16];
            for (int i = 0; i < g->n; i++)
                if (gpiod_line_offset(ln) == (unsigned)g->lines[i].l->offset)
                    *edges |= 1u << g->lines[i].bit;
            if (gpiod_line_event_read_multiple(ln, ev, 16) == 16) more = 1;
        }
        if (!more) break;
    }
    /* the levels change only with an event: read them again only then (one poll a
     * control step instead of a poll and an ioctl) */
    if (c->have_levels && !*edges) { *level = c->levels; return 0; }
    if (gpiod_line_get_value_bulk(&g->bulk, v)) return RG_EIO;
    for (int i = 0; i < g->n; i++)
        if (v[i] ^ g->lines[i].l->active_low) *level |= 1u << g->lines[i].bit;
    c->levels = *level;
    c->have_levels = 1;
    return 0;
}

static int64_t g_now(rg_chip *c)
{
    struct timespec t;
    (void)c;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000000000 + t.tv_nsec;
}

static void g_sleep_until(rg_chip *c, int64_t t)
{
    struct timespec d = {(time_t)(t / 1000000000), (long)(t % 1000000000)};
    (void)c;
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &d, NULL) == EINTR) {}
}

/* Async-signal-safe: gpiod_line_set_value_bulk fills a struct on the stack and makes
 * one ioctl (no allocation, no locks). */
static void g_emergency(rg_chip *cc)
{
    gchip *c = (gchip *)cc;
    static const int order[] = {RG_G_LASER, RG_G_SHUTTER, RG_G_INDICATOR, RG_G_ENABLE};
    for (int k = 0; k < 4; k++) {      /* laser first, drivers last */
        ggroup *g = &c->out[order[k]];
        if (g->requested) {
            for (int i = 0; i < g->n; i++) g->phys[i] = g->lines[i].l->active_low;
            g->val = 0;
            gpiod_line_set_value_bulk(&g->bulk, g->phys);
        }
    }
}

static int g_close(rg_chip *cc)
{
    gchip *c = (gchip *)cc;
    for (int gi = 0; gi < RG_NGROUPS; gi++)
        if (c->out[gi].requested) gpiod_line_release_bulk(&c->out[gi].bulk);
    if (c->in.requested) gpiod_line_release_bulk(&c->in.bulk);
    if (c->chip) gpiod_chip_close(c->chip);
    free(c);
    return 0;
}

static const rg_chip_ops gpiod_ops = {g_set, g_inputs, g_now, g_sleep_until, g_emergency,
                                      g_close, NULL, NULL};

int rg_gpiod_open(const rg_rig *rig, const char *name, rg_chip **out, char *err, size_t cap)
{
    gchip *c = calloc(1, sizeof *c);
    int rc = 0;
    if (!c) { snprintf(err, cap, "out of memory"); return RG_ENOMEM; }
    c->base.ops = &gpiod_ops;
    c->rig = rig;
    snprintf(c->name, sizeof c->name, "%s", name);
    c->chip = gpiod_chip_open_lookup(name);
    if (!c->chip) {
        snprintf(err, cap, "no GPIO chip '%s' (%s): see ls /dev/gpiochip* or gpiodetect",
                 name, strerror(errno));
        free(c);
        return RG_EINVAL;
    }
    /* the outputs first go to their inactive levels in the request itself */
    for (int j = 0; j < RG_NJOINTS; j++) {
        add(&c->out[RG_G_STEP], &rig->axis[j].step, j, "STEP of axis %s", jname[j]);
        add(&c->out[RG_G_DIR], &rig->axis[j].dir, j, "DIR of axis %s", jname[j]);
        add(&c->out[RG_G_ENABLE], &rig->axis[j].enable, j, "ENABLE of axis %s", jname[j]);
        add(&c->in, &rig->axis[j].home, j, "home switch of axis %s", jname[j]);
    }
    add(&c->out[RG_G_LASER], &rig->laser, 0, "%s", "the laser");
    add(&c->out[RG_G_HEART], &rig->heartbeat, 0, "%s", "the heartbeat");
    add(&c->out[RG_G_SHUTTER], &rig->shutter, 0, "%s", "the shutter");
    add(&c->out[RG_G_INDICATOR], &rig->indicator, 0, "%s", "the emission indicator");
    add(&c->in, &rig->interlock, RG_NJOINTS, "%s", "the interlock");
    for (int j = 0; j < RG_NJOINTS; j++)
        add(&c->in, &rig->axis[j].limit, RG_NJOINTS + 1 + j, "limit switch of axis %s", jname[j]);
    add(&c->in, &rig->key_switch, 2 * RG_NJOINTS + 1, "%s", "the key switch");
    /* laser first: if anything else fails, it was never on */
    if ((rc = request(c, &c->out[RG_G_LASER], 1, err, cap)) ||
        (rc = request(c, &c->out[RG_G_SHUTTER], 1, err, cap)) ||
        (rc = request(c, &c->out[RG_G_INDICATOR], 1, err, cap)) ||
        (rc = request(c, &c->out[RG_G_HEART], 1, err, cap)) ||
        (rc = request(c, &c->out[RG_G_ENABLE], 1, err, cap)) ||
        (rc = request(c, &c->out[RG_G_STEP], 1, err, cap)) ||
        (rc = request(c, &c->out[RG_G_DIR], 1, err, cap)) ||
        (rc = request(c, &c->in, 0, err, cap))) {
        g_close(&c->base);
        return rc;
    }
    *out = &c->base;
    return 0;
}
