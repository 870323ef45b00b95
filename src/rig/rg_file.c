/* rg_file.c -- the rig file reader: plain "key value" lines (README "Rig files"),
 * '#' comments, one "axis NAME" block per joint.  Every error names FILE:LINE:
 * unknown keys, a key given twice, bad numbers, a GPIO line used twice, values out of
 * range.  The geometry keys go to the geometry part (rg_geom_file_key). */
#define _DEFAULT_SOURCE
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "rig/rg_hw.h"

#define MAXFILE (1 << 20)
#define MAXWORDS 24

static const char *const axis_names[RG_NJOINTS] = {"m1a", "m1b", "u", "v", "m2a", "m2b"};

typedef struct reader {
    const char *name;
    long line;
    rg_rig *rig;
    int cur;                    /* current axis, -1 before the first */
    char *err;
    size_t cap;
    /* where each key was given (duplicates): globals, then per axis */
    long gseen[64];
    long aseen[RG_NJOINTS][32];
    const rig_api *geo;         /* the geometry half (its keys), or NULL */
} reader;

static int fail(reader *r, const char *fmt, ...)
{
    va_list ap;
    int n = snprintf(r->err, r->cap, "%s:%ld: ", r->name, r->line);
    if (n < 0 || (size_t)n >= r->cap) n = 0;
    va_start(ap, fmt);
    vsnprintf(r->err + n, r->cap - n, fmt, ap);
    va_end(ap);
    return RG_EINVAL;
}

static int number(reader *r, const char *key, const char *w, double *v)
{
    char *end;
    if (!w) return fail(r, "'%s' needs a number", key);
    errno = 0;
    *v = strtod(w, &end);
    if (end == w || *end || errno == ERANGE || !isfinite(*v))
        return fail(r, "'%s' is not a number (for '%s')", w, key);
    return 0;
}

static int positive(reader *r, const char *key, const char *w, double max, double *v)
{
    int rc = number(r, key, w, v);
    if (rc) return rc;
    if (!(*v > 0) || *v > max) return fail(r, "'%s' must be greater than 0 and at most %g",
                                           key, max);
    return 0;
}

static int yesno(reader *r, const char *key, const char *w, const char *yes,
                 const char *no, int *v)
{
    if (w && !strcmp(w, yes)) { *v = 1; return 0; }
    if (w && !strcmp(w, no)) { *v = 0; return 0; }
    return fail(r, "'%s' takes '%s' or '%s'", key, yes, no);
}

/* "OFFSET [active_low]" */
static int line_spec(reader *r, const char *key, char **w, int nw, rg_line *l)
{
    char *end;
    long v;
    if (nw < 2) return fail(r, "'%s' needs a line offset", key);
    errno = 0;
    v = strtol(w[1], &end, 10);
    if (end == w[1] || *end || errno || v < 0 || v > 1023)
        return fail(r, "'%s' is not a line offset (0 to 1023) for '%s'", w[1], key);
    if (nw > 3 || (nw == 3 && strcmp(w[2], "active_low")))
        return fail(r, "after the offset of '%s' only 'active_low' may follow", key);
    l->offset = (int)v;
    l->active_low = nw == 3;
    l->at = (int)r->line;
    return 0;
}

enum { G_CHIP, G_LASER, G_INTERLOCK, G_HEART, G_MAXON, G_TICK, G_HTIMEOUT, G_HOMETO,
       G_SETTLE, G_SIMRT, G_SIMIL, G_SIMILMS, G_CAM, G_CPITCH, G_CPIX, G_CNOISE, G_CSEED,
       G_WAIST, G_EYESAFE, G_POWER, G_WAVE, G_BEAMD, G_KEY, G_INDIC, G_SHUT, G_EDELAY,
       G_SHUTMS, G_PULSE, G_LATE, G_DEBOUNCE, G_SIMILC, G_SIMKEY, G_STALLAT, G_STALL, G_MOVING,
       G_WAISTAT, G_BEAMM2, G_LENS, G_LASERPOL, NG };
static const char *const gkeys[NG] = {"chip", "laser", "interlock", "heartbeat",
    "max_on_ms", "tick_us", "heartbeat_timeout_ms", "home_timeout_s", "settle_ms",
    "sim_realtime", "sim_interlock", "sim_interlock_open_ms", "camera", "camera_pitch",
    "camera_pixels", "camera_read_noise", "camera_seed", "beam_waist",
    "eye_safe_without_heartbeat", "laser_power_mw", "wavelength_nm", "beam_diameter_mm",
    "key_switch", "emission_indicator", "shutter", "emission_delay_ms", "shutter_ms",
    "step_pulse_us", "max_late_us", "home_debounce_ms", "sim_interlock_close_ms",
    "sim_key_off_ms", "sim_stall_at_ms", "sim_stall_ms", "expose_moving",
    "beam_waist_at_mm", "beam_m2", "focus_lens_mm", "laser_polarization"};
enum { A_STEP, A_DIR, A_ENABLE, A_HOME, A_STEPS, A_MIN, A_MAX, A_SPEED, A_ACCEL,
       A_HOMEAT, A_HOMEDIR, A_HOMESPEED, A_DIRINV, A_SIMHOME, A_LIMIT, A_PULLOFF,
       A_LOCATE, A_SIMLIMIT, A_SIMLOSE, NA };
static const char *const akeys[NA] = {"step", "dir", "enable", "home", "steps_per", "min",
    "max", "speed", "accel", "home_at", "home_dir", "home_speed", "dir_invert", "sim_home",
    "limit", "home_pulloff", "home_locate_speed", "sim_limit_ms", "sim_lose_step_ms"};

static int find(const char *const *keys, int n, const char *k)
{
    for (int i = 0; i < n; i++) if (!strcmp(keys[i], k)) return i;
    return -1;
}

/* A number from lo to hi (a time, a count). */
static int ranged(reader *r, const char *key, const char *w, double lo, double hi, double *v)
{
    int rc = number(r, key, w, v);
    if (!rc && !(*v >= lo && *v <= hi)) return fail(r, "'%s' must be from %g to %g", key, lo, hi);
    return rc;
}

static int global_key(reader *r, int k, char **w, int nw)
{
    rg_rig *g = r->rig;
    const char *a = nw > 1 ? w[1] : NULL;
    if (nw > (k == G_LASERPOL ? 4 : k == G_LASER || k == G_INTERLOCK || k == G_HEART ||
              k == G_KEY || k == G_INDIC || k == G_SHUT || k == G_LENS ? 3 : 2))
        return fail(r, "'%s' takes one value", w[0]);
    switch (k) {
    case G_CHIP:
        if (!a) return fail(r, "'chip' needs a name");
        if (strlen(a) >= sizeof g->chip) return fail(r, "the chip name is too long");
        strcpy(g->chip, a);
        return 0;
    case G_LASER: return line_spec(r, w[0], w, nw, &g->laser);
    case G_INTERLOCK: return line_spec(r, w[0], w, nw, &g->interlock);
    case G_HEART: return line_spec(r, w[0], w, nw, &g->heartbeat);
    case G_MAXON: return positive(r, w[0], a, 60000, &g->max_on_ms);
    case G_TICK: {
        int rc = number(r, w[0], a, &g->tick_us);
        if (!rc && !(g->tick_us >= 20 && g->tick_us <= 100000))
            return fail(r, "'tick_us' must be from 20 to 100000");
        return rc;
    }
    case G_HTIMEOUT: return positive(r, w[0], a, 10000, &g->heartbeat_timeout_ms);
    case G_HOMETO: return positive(r, w[0], a, 3600, &g->home_timeout_s);
    case G_SETTLE: {
        int rc = number(r, w[0], a, &g->settle_ms);
        if (!rc && !(g->settle_ms >= 0 && g->settle_ms <= 60000))
            return fail(r, "'settle_ms' must be from 0 to 60000");
        return rc;
    }
    case G_SIMRT: return yesno(r, w[0], a, "yes", "no", &g->sim_realtime);
    case G_SIMIL: return yesno(r, w[0], a, "open", "closed", &g->sim_interlock_open);
    case G_SIMILMS: {
        int rc = number(r, w[0], a, &g->sim_interlock_open_ms);
        if (!rc && !(g->sim_interlock_open_ms >= 0))
            return fail(r, "'sim_interlock_open_ms' must be 0 or more");
        return rc;
    }
    case G_CAM: return yesno(r, w[0], a, "frames", "none", &g->cam_frames);
    case G_CPITCH: return positive(r, w[0], a, 1, &g->cam_pitch);
    case G_CPIX: {
        double n;
        int rc = number(r, w[0], a, &n);
        if (!rc && !(n >= 16 && n <= 4096 && n == floor(n)))
            return fail(r, "'camera_pixels' must be a whole number from 16 to 4096");
        if (!rc) g->cam_pixels = (int)n;
        return rc;
    }
    case G_CNOISE: {
        int rc = number(r, w[0], a, &g->cam_read_noise);
        if (!rc && !(g->cam_read_noise >= 0 && g->cam_read_noise <= 1000))
            return fail(r, "'camera_read_noise' must be from 0 to 1000 electrons");
        return rc;
    }
    case G_CSEED: {
        int rc = number(r, w[0], a, &g->cam_seed);
        if (!rc && !(g->cam_seed >= 0 && g->cam_seed <= 4e9 && g->cam_seed == floor(g->cam_seed)))
            return fail(r, "'camera_seed' must be a whole number from 0 to 4000000000");
        return rc;
    }
    case G_WAIST:
        g->beam_waist_line = (int)r->line;
        return positive(r, w[0], a, 10, &g->beam_waist);
    case G_EYESAFE: return yesno(r, w[0], a, "yes", "no", &g->eye_safe_without_heartbeat);
    case G_POWER: return positive(r, w[0], a, 1e4, &g->laser_power_mw);
    case G_WAVE: {
        int rc = number(r, w[0], a, &g->wavelength_nm);
        if (!rc && !(g->wavelength_nm >= 400 && g->wavelength_nm <= 700))
            return fail(r, "'wavelength_nm' %g: the dose check covers visible light, 400 to "
                        "700 nm, only", g->wavelength_nm);
        return rc;
    }
    case G_BEAMD: return positive(r, w[0], a, 100, &g->beam_diameter_mm);
    case G_KEY: return line_spec(r, w[0], w, nw, &g->key_switch);
    case G_INDIC: return line_spec(r, w[0], w, nw, &g->indicator);
    case G_SHUT: return line_spec(r, w[0], w, nw, &g->shutter);
    case G_EDELAY: return ranged(r, w[0], a, 0, 60000, &g->emission_delay_ms);
    case G_SHUTMS: return ranged(r, w[0], a, 0, 10000, &g->shutter_ms);
    case G_PULSE: return ranged(r, w[0], a, 0.1, 50000, &g->step_pulse_us);
    case G_LATE: return ranged(r, w[0], a, 1, 1e9, &g->max_late_us);
    case G_DEBOUNCE: return ranged(r, w[0], a, 0, 10000, &g->home_debounce_ms);
    case G_SIMILC: return ranged(r, w[0], a, 0, 1e12, &g->sim_interlock_close_ms);
    case G_SIMKEY: return ranged(r, w[0], a, 0, 1e12, &g->sim_key_off_ms);
    case G_STALLAT: return ranged(r, w[0], a, 0, 1e12, &g->sim_stall_at_ms);
    case G_STALL: return ranged(r, w[0], a, 0, 1e9, &g->sim_stall_ms);
    case G_MOVING: return yesno(r, w[0], a, "yes", "no", &g->expose_moving);
    case G_WAISTAT: return ranged(r, w[0], a, -1e5, 1e5, &g->beam_waist_at);
    case G_BEAMM2: return ranged(r, w[0], a, 1, 1000, &g->beam_m2);
    case G_LENS: {      /* F AT: a thin lens AT mm before the apex (the leg is checked
                           against the geometry by rig_api.spots, at this line) */
        int rc = number(r, w[0], a, &g->lens_f);
        if (!rc && !(fabs(g->lens_f) >= 0.1 && fabs(g->lens_f) <= 1e5))
            return fail(r, "'focus_lens_mm': the focal length %g mm must be from 0.1 to "
                        "100000 mm, either sign", g->lens_f);
        if (!rc && nw < 3) return fail(r, "'focus_lens_mm' needs F and AT (mm before the "
                                       "cornea apex)");
        if (!rc) rc = number(r, w[0], w[2], &g->lens_at);
        if (!rc && !(g->lens_at > 0 && g->lens_at <= 1e5))
            return fail(r, "'focus_lens_mm': the lens must lie more than 0 and at most 100000 "
                        "mm before the cornea apex (%g)", g->lens_at);
        g->lens_line = (int)r->line;
        return rc;
    }
    case G_LASERPOL:    /* X Y Z (the field leaving the laser) or unpolarized */
        g->laser_pol_line = (int)r->line;
        if (nw == 2 && (!strcmp(a, "unpolarized") || !strcmp(a, "unpolarised"))) {
            g->laser_pol_set = 0;
            return 0;
        }
        if (nw != 4)
            return fail(r, "'laser_polarization' needs X Y Z (the field's direction as the "
                        "beam leaves the laser) or 'unpolarized'");
        for (int i = 0; i < 3; i++) {
            int rc = number(r, w[0], w[1 + i], &g->laser_pol[i]);
            if (rc) return rc;
        }
        if (!(fabs(g->laser_pol[0]) + fabs(g->laser_pol[1]) + fabs(g->laser_pol[2]) > 0))
            return fail(r, "'laser_polarization' 0 0 0: a field needs a direction");
        g->laser_pol_set = 1;
        return 0;
    }
    return 0;
}

static int axis_key(reader *r, int k, char **w, int nw)
{
    rg_axis *x = &r->rig->axis[r->cur];
    const char *a = nw > 1 ? w[1] : NULL;
    if (nw > (k <= A_HOME || k == A_LIMIT ? 3 : 2)) return fail(r, "'%s' takes one value", w[0]);
    switch (k) {
    case A_STEP: return line_spec(r, w[0], w, nw, &x->step);
    case A_DIR: return line_spec(r, w[0], w, nw, &x->dir);
    case A_ENABLE: return line_spec(r, w[0], w, nw, &x->enable);
    case A_HOME: return line_spec(r, w[0], w, nw, &x->home);
    case A_STEPS: return positive(r, w[0], a, 1e7, &x->steps_per);
    case A_MIN: return number(r, w[0], a, &x->min);
    case A_MAX: return number(r, w[0], a, &x->max);
    case A_SPEED: return positive(r, w[0], a, 1e6, &x->speed);
    case A_ACCEL: return positive(r, w[0], a, 1e9, &x->accel);
    case A_HOMEAT: return number(r, w[0], a, &x->home_at);
    case A_HOMEDIR:
        if (a && !strcmp(a, "+")) { x->home_dir = 1; return 0; }
        if (a && !strcmp(a, "-")) { x->home_dir = -1; return 0; }
        return fail(r, "'home_dir' takes '+' or '-'");
    case A_HOMESPEED: return positive(r, w[0], a, 1e6, &x->home_speed);
    case A_DIRINV: return yesno(r, w[0], a, "yes", "no", &x->dir_invert);
    case A_SIMHOME: {
        int ok = 1, rc = yesno(r, w[0], a, "ok", "broken", &ok);
        x->sim_home_broken = !ok;
        return rc;
    }
    case A_LIMIT: return line_spec(r, w[0], w, nw, &x->limit);
    case A_PULLOFF: return positive(r, w[0], a, 1e6, &x->home_pulloff);
    case A_LOCATE: return positive(r, w[0], a, 1e6, &x->home_locate_speed);
    case A_SIMLIMIT: return ranged(r, w[0], a, 0, 1e12, &x->sim_limit_ms);
    case A_SIMLOSE: return ranged(r, w[0], a, 0, 1e12, &x->sim_lose_step_ms);
    }
    return 0;
}

static int one_line(reader *r, char *s)
{
    char *w[MAXWORDS + 1], *p = s;
    int nw = 0, k;
    char *hash = strchr(s, '#');
    if (hash) *hash = 0;
    while (*p && isspace((unsigned char)*p)) p++;
    if (!*p) return 0;
    while (*p) {
        while (*p && isspace((unsigned char)*p)) *p++ = 0;
        if (!*p) break;
        if (nw == MAXWORDS) return fail(r, "too many words on this line");
        w[nw++] = p;
        while (*p && !isspace((unsigned char)*p)) p++;
    }
    if (!strcmp(w[0], "axis")) {
        int j = nw == 2 ? find(axis_names, RG_NJOINTS, w[1]) : -1;
        if (j < 0) return fail(r, "'axis' takes one of m1a m1b u v m2a m2b");
        if (r->rig->axis[j].at)
            return fail(r, "axis %s is given twice (first at line %d)", w[1],
                        r->rig->axis[j].at);
        r->rig->axis[j].at = (int)r->line;
        r->cur = j;
        return 0;
    }
    if ((k = find(gkeys, NG, w[0])) >= 0) {
        if (r->gseen[k]) return fail(r, "'%s' is given twice (first at line %ld)", w[0],
                                     r->gseen[k]);
        r->gseen[k] = r->line;
        return global_key(r, k, w, nw);
    }
    if ((k = find(akeys, NA, w[0])) >= 0) {
        if (r->cur < 0)
            return fail(r, "'%s' belongs to an axis: put it after an 'axis NAME' line", w[0]);
        if (r->aseen[r->cur][k])
            return fail(r, "'%s' is given twice for axis %s (first at line %ld)", w[0],
                        axis_names[r->cur], r->aseen[r->cur][k]);
        r->aseen[r->cur][k] = r->line;
        return axis_key(r, k, w, nw);
    }
    if (r->geo && r->geo->geometry_key) {
        char gerr[RG_ERRMAX];
        int g;
        if (!strcmp(w[0], "joint"))
            return fail(r, "'joint' is for geometry-only files: here each axis block gives "
                        "its steps and travel");
        g = r->geo->geometry_key(&r->rig->geom, nw, (const char *const *)w, gerr,
                                 sizeof gerr);
        if (g == 0) { r->rig->geom_keys++; return 0; }
        if (g != 1) return fail(r, "%s", gerr);
    }
    return fail(r, "unknown key '%s'", w[0]);
}

typedef struct named_line { const rg_line *l; char what[32]; } named_line;

/* Whole-file checks: required keys, ranges, every GPIO line used once. */
static int dose_bounds(reader *r);
static int finish(reader *r)
{
    rg_rig *g = r->rig;
    int rc;
    named_line all[RG_NJOINTS * 5 + 6];
    int n = 0;
    static const char *const lname[5] = {"STEP", "DIR", "ENABLE", "home", "limit"};
    r->line = 0;
#define WHOLE(...) (snprintf(r->err, r->cap, __VA_ARGS__), RG_EINVAL)
    if (!g->chip[0]) return WHOLE("%s: no 'chip' line", r->name);
    if (g->laser.offset < 0) return WHOLE("%s: no 'laser' line", r->name);
    if (g->interlock.offset < 0) return WHOLE("%s: no 'interlock' line", r->name);
    if (!(g->max_on_ms > 0)) return WHOLE("%s: no 'max_on_ms' line", r->name);
    for (int j = 0; j < RG_NJOINTS; j++) {
        rg_axis *x = &g->axis[j];
        const char *an = axis_names[j];
        double rate;
        if (!x->at) return WHOLE("%s: no 'axis %s' block", r->name, an);
        r->line = x->at;
        if (x->step.offset < 0) return fail(r, "axis %s has no 'step' line", an);
        if (x->dir.offset < 0) return fail(r, "axis %s has no 'dir' line", an);
        if (!(x->steps_per > 0)) return fail(r, "axis %s has no 'steps_per' line", an);
        if (!r->aseen[j][A_MIN] || !r->aseen[j][A_MAX])
            return fail(r, "axis %s needs 'min' and 'max'", an);
        if (!(x->min < x->max)) return fail(r, "axis %s: 'min' must be less than 'max'", an);
        if (!(x->speed > 0) || !(x->accel > 0))
            return fail(r, "axis %s needs 'speed' and 'accel'", an);
        if (fabs(x->min) * x->steps_per > 1e12 || fabs(x->max) * x->steps_per > 1e12)
            return fail(r, "axis %s: the travel is more than 1e12 steps", an);
        rate = x->speed * x->steps_per;
        if (rate > 1e6 / g->tick_us)
            return fail(r, "axis %s: speed %g is %g steps/s, more than one step per control "
                        "step (tick_us %g: %g steps/s)", an, x->speed, rate, g->tick_us,
                        1e6 / g->tick_us);
        if (x->home.offset >= 0) {
            if (!x->home_dir) return fail(r, "axis %s: its home switch needs 'home_dir'", an);
            if (!r->aseen[j][A_HOMEAT])
                return fail(r, "axis %s: its home switch needs 'home_at'", an);
            if (!(x->home_at >= x->min && x->home_at <= x->max))
                return fail(r, "axis %s: 'home_at' %g is outside its travel [%g, %g]", an,
                            x->home_at, x->min, x->max);
            if (!(x->home_speed > 0)) x->home_speed = x->speed / 4;
            if (x->home_speed > x->speed)
                return fail(r, "axis %s: 'home_speed' is more than 'speed'", an);
            if (!(x->home_pulloff > 0)) x->home_pulloff = 0.5;
            if (!(x->home_locate_speed > 0)) x->home_locate_speed = x->home_speed / 10;
            if (x->home_locate_speed > x->home_speed)
                return fail(r, "axis %s: 'home_locate_speed' is more than 'home_speed'", an);
            {
                double off = x->home_at - x->home_dir * x->home_pulloff;
                if (!(off >= x->min && off <= x->max))
                    return fail(r, "axis %s: the pull-off from home_at %g by %g leaves its "
                                "travel [%g, %g]", an, x->home_at, x->home_pulloff, x->min,
                                x->max);
            }
        } else if (!r->aseen[j][A_HOMEAT]) {
            return fail(r, "axis %s has neither a 'home' switch nor 'home_at' (where it "
                        "stands at power-on)", an);
        }
        for (int k = 0; k < 5; k++) {
            const rg_line *l = k == 0 ? &x->step : k == 1 ? &x->dir : k == 2 ? &x->enable
                             : k == 3 ? &x->home : &x->limit;
            if (l->offset < 0) continue;
            all[n].l = l;
            snprintf(all[n].what, sizeof all[n].what, "the %s line of axis %s", lname[k], an);
            n++;
        }
    }
    all[n].l = &g->laser; strcpy(all[n++].what, "the laser line");
    all[n].l = &g->interlock; strcpy(all[n++].what, "the interlock line");
    if (g->heartbeat.offset >= 0) { all[n].l = &g->heartbeat; strcpy(all[n++].what, "the heartbeat line"); }
    if (g->key_switch.offset >= 0) { all[n].l = &g->key_switch; strcpy(all[n++].what, "the key switch line"); }
    if (g->indicator.offset >= 0) { all[n].l = &g->indicator; strcpy(all[n++].what, "the emission indicator line"); }
    if (g->shutter.offset >= 0) { all[n].l = &g->shutter; strcpy(all[n++].what, "the shutter line"); }
    for (int a = 0; a < n; a++)
        for (int b = 0; b < n; b++)
            if (a != b && all[a].l->offset == all[b].l->offset &&
                (all[a].l->at < all[b].l->at || (all[a].l->at == all[b].l->at && a < b))) {
                r->line = all[b].l->at;
                return fail(r, "line %d is already %s (line %d)", all[b].l->offset,
                            all[a].what, all[a].l->at);
            }
    if (g->heartbeat.offset >= 0 && !(g->heartbeat_timeout_ms > 0))
        g->heartbeat_timeout_ms = 5;
    if (!r->gseen[G_PULSE]) g->step_pulse_us = 5;
    if (g->step_pulse_us > g->tick_us / 2) {
        r->line = r->gseen[G_PULSE];
        return fail(r, "'step_pulse_us' %g does not fit in half a control step (tick_us %g)",
                    g->step_pulse_us, g->tick_us);
    }
    if (!r->gseen[G_LATE]) g->max_late_us = g->tick_us / 2;
    if (!r->gseen[G_DEBOUNCE]) g->home_debounce_ms = 10;
    {
        int nd = !!r->gseen[G_POWER] + !!r->gseen[G_WAVE] + !!r->gseen[G_BEAMD];
        if (nd && nd < 3)
            return WHOLE("%s: the dose needs all three of 'laser_power_mw', 'wavelength_nm' "
                         "and 'beam_diameter_mm'", r->name);
        if (nd == 3 && (rc = dose_bounds(r))) return rc;
    }
    /* the geometry's joints are the axes (per rad for angles) */
    for (int j = 0; j < RG_NJOINTS; j++) {
        const rg_axis *x = &g->axis[j];
        double u = x->linear ? 1 : M_PI / 180;
        g->geom.joint[j].steps_per = x->steps_per / u;
        g->geom.joint[j].lo = x->min * u;
        g->geom.joint[j].hi = x->max * u;
    }
    if (r->geo && r->geo->geometry_check) {
        char gerr[RG_ERRMAX];
        if (r->geo->geometry_check(&g->geom, gerr, sizeof gerr))
            return WHOLE("%s: the geometry: %s", r->name, gerr);
    }
#undef WHOLE
    return 0;
}

/* The hold times the dose allows (README-less rule, doc/rig-safety.md): a controller
 * that dies at the end of a max_on_ms exposure leaves the beam on for the pump's hold
 * more, so max_on_ms + heartbeat_timeout_ms must stay within the MPE; a rig that says
 * it is eye-safe without a heartbeat must be, for 100 s (IEC 60825-1's longest
 * accidental exposure to visible light). */
static int dose_bounds(reader *r)
{
    rg_rig *g = r->rig;
    rg_dose d;
    char e[RG_ERRMAX];
    int rc;
    if (g->heartbeat.offset >= 0) {
        double lo = 0, hi = g->heartbeat_timeout_ms;
        rc = rg_dose_rig(g, g->max_on_ms + g->heartbeat_timeout_ms, 1, &d, e, sizeof e);
        if (rc == RG_EDOSE) {
            for (int i = 0; i < 60; i++) {       /* the largest hold within the limit */
                double mid = 0.5 * (lo + hi);
                if (rg_dose_rig(g, g->max_on_ms + mid, 1, &d, e, sizeof e) == 0) lo = mid;
                else hi = mid;
            }
            rg_dose_rig(g, g->max_on_ms + g->heartbeat_timeout_ms, 1, &d, e, sizeof e);
            r->line = r->gseen[G_HTIMEOUT] ? r->gseen[G_HTIMEOUT] : r->gseen[G_MAXON];
            return fail(r, "a controller that dies at the end of a %g ms exposure leaves the "
                        "beam on %g ms more (heartbeat_timeout_ms): %.3g times the MPE; the "
                        "dose allows at most %.3g ms of hold (or a shorter max_on_ms)",
                        g->max_on_ms, g->heartbeat_timeout_ms, d.fraction, lo);
        }
    } else if (g->eye_safe_without_heartbeat) {
        rc = rg_dose_rig(g, 100e3, 1, &d, e, sizeof e);
        if (rc == RG_EDOSE) {
            r->line = r->gseen[G_EYESAFE];
            return fail(r, "'eye_safe_without_heartbeat yes', but a beam left on for 100 s "
                        "(IEC 60825-1's longest accidental exposure to visible light) is "
                        "%.3g times the MPE: add a heartbeat line", d.fraction);
        }
    }
    return 0;
}

static void defaults(rg_rig *g, const rig_api *geo)
{
    memset(g, 0, sizeof *g);
    if (geo && geo->geometry_default) geo->geometry_default(&g->geom);
    g->laser.offset = g->interlock.offset = g->heartbeat.offset = -1;
    g->key_switch.offset = g->indicator.offset = g->shutter.offset = -1;
    g->sim_interlock_close_ms = g->sim_key_off_ms = g->sim_stall_at_ms = -1;
    for (int j = 0; j < RG_NJOINTS; j++) {
        rg_axis *x = &g->axis[j];
        x->step.offset = x->dir.offset = x->enable.offset = x->home.offset = -1;
        x->limit.offset = -1;
        x->sim_limit_ms = x->sim_lose_step_ms = -1;
        x->linear = j == RG_J_U || j == RG_J_V;
    }
    g->tick_us = 250;
    g->home_timeout_s = 30;
    g->sim_interlock_open_ms = -1;
    g->cam_pitch = 0.02;
    g->cam_pixels = 128;
    g->cam_read_noise = 5;
    g->cam_seed = 1;
    g->beam_waist = 0.2;
    g->beam_waist_at = NAN;
    g->beam_m2 = 1;
}

int rg_rig_parse(const char *text, size_t len, const char *name, rg_rig *rig, char *err,
                 size_t cap)
{
    reader r;
    char buf[4096];
    size_t i = 0;
    memset(&r, 0, sizeof r);
    r.name = name; r.rig = rig; r.cur = -1; r.err = err; r.cap = cap;
    r.geo = rg_geom_api();
    defaults(rig, r.geo);
    snprintf(rig->path, sizeof rig->path, "%s", name);
    while (i < len) {
        size_t e = i, n;
        int rc;
        r.line++;
        while (e < len && text[e] != '\n') e++;
        n = e - i;
        if (memchr(text + i, 0, n)) return fail(&r, "a NUL byte: this is not a text file");
        if (n >= sizeof buf) return fail(&r, "the line is longer than %zu characters",
                                         sizeof buf - 1);
        memcpy(buf, text + i, n);
        buf[n] = 0;
        if ((rc = one_line(&r, buf))) return rc;
        i = e + 1;
    }
    return finish(&r);
}

int rg_rig_load(const char *path, rg_rig *rig, char *err, size_t cap)
{
    FILE *f = fopen(path, "r");
    char *text;
    size_t n;
    int rc;
    struct stat st;
    if (!f) { snprintf(err, cap, "%s: %s", path, strerror(errno)); return RG_EINVAL; }
    if (fstat(fileno(f), &st) || !S_ISREG(st.st_mode)) {
        fclose(f);
        snprintf(err, cap, "%s: not a regular file", path);
        return RG_EINVAL;
    }
    text = malloc(MAXFILE + 1);
    if (!text) { fclose(f); snprintf(err, cap, "%s: out of memory", path); return RG_ENOMEM; }
    n = fread(text, 1, MAXFILE + 1, f);
    if (ferror(f)) {
        snprintf(err, cap, "%s: %s", path, strerror(errno));
        rc = RG_EINVAL;
    } else if (n > MAXFILE) {
        snprintf(err, cap, "%s: larger than %d bytes: not a rig file", path, MAXFILE);
        rc = RG_EINVAL;
    } else {
        rc = rg_rig_parse(text, n, path, rig, err, cap);
    }
    free(text);
    fclose(f);
    return rc;
}
