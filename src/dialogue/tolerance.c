/* tolerance.c -- the --tolerance dialogue: a lens file with its tolerances (tol
 * lines, doc/design.md), then (sens) each tolerance alone at -delta and +delta with
 * the criteria of the design module (RMS spot after the back-focus compensator, EFL,
 * back focus, the boresight: field 1's chief ray on the image plane) and the EFL and
 * boresight spreads the linear sensitivities predict; (mc) N lenses
 * drawn from every tolerance, one table row each, percentiles and yield; (table) the
 * same summary of a table that scripts/tolerance-mc.sh merged from many jobs.  The
 * summary is always computed from the table's text, so one process and many jobs
 * print the same.  Texts in prompts/tolerance.txt. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "calcio.h"
#include "designio.h"
#include "dialogues.h"
#include "prompts_tolerance.h"

#define P(k) tolerance_prompts[TOLERANCE_##k]

typedef struct tdlg {
    lm_io *io;
    calc c;
    dz_files f;
    const ds_api *ds;
    ds_tol_opts o;
    double um;                 /* micrometres per lens unit */
} tdlg;

typedef struct lcount { long lo, hi, value; } lcount;
static int check_long(void *ctx, const char *w, char *msg, size_t cap)
{
    lcount *k = ctx;
    char *end;
    errno = 0;
    long v = strtol(w, &end, 10);
    if (end == w || *end || errno || v < k->lo || v > k->hi) {
        snprintf(msg, cap, P(COUNT_BAD), w, k->lo, k->hi);
        return 1;
    }
    k->value = v;
    return 0;
}
static int ask_long(tdlg *d, const char *q, long lo, long hi, long *v)
{
    char buf[64];
    lcount k = {lo, hi, 0};
    int rc = lm_ask_word(d->io, q, q, P(COUNT_WHAT), check_long, &k, buf, sizeof buf);
    *v = k.value;
    return rc;
}
static int check_seed(void *ctx, const char *w, char *msg, size_t cap)
{
    char *end;
    errno = 0;
    unsigned long long v = strtoull(w, &end, 10);
    if (end == w || *end || errno || w[0] == '-') { snprintf(msg, cap, P(SEED_BAD), w); return 1; }
    *(unsigned long long *)ctx = v;
    return 0;
}
static int check_out(void *ctx, const char *w, char *msg, size_t cap)
{
    tdlg *d = ctx;
    if (!strcmp(w, "-")) return 0;
    return dz_check_out(d->io, &d->f, w, msg, cap) ? 1 : 0;
}
static int check_in(void *ctx, const char *w, char *msg, size_t cap)
{
    FILE *f = fopen(w, "rb");
    (void)ctx;
    if (!f) { snprintf(msg, cap, "%s: cannot be read", w); return 1; }
    fclose(f);
    return 0;
}

static double unit_um(const char *u)
{
    return !strcmp(u, "cm") ? 1e4 : !strcmp(u, "m") ? 1e6 : !strcmp(u, "in") ? 25400 : 1000;
}

static int sens(tdlg *d)
{
    const ds_api *ds = d->ds;
    ds_problem *p = d->f.p;
    ds_crit n, a, b;
    double ve = 0, vb = 0, vx = 0, vy = 0, k = d->o.dist ? 0.25 * 0.7737413 : 1.0 / 3;
    d->o.wave = 1;
    if (ds->tol_nominal(p, &d->o, &n) == DS_STOPPED) return LM_FAIL;
    calc_say(&d->c, P(NOMINAL), n.rms * d->um, n.wave, n.efl, n.bfd, lm_clean(d->io, n.focus));
    calc_say(&d->c, "%s", P(SENS_HEAD));
    for (int i = 0; i < ds->ntol(p); i++) {
        ds_tol_info t;
        ds->tol_info(p, i, &t);
        if (lm_stop_requested()) return LM_FAIL;
        if (ds->tol_one(p, &d->o, i, -1, &a) == DS_STOPPED ||
            ds->tol_one(p, &d->o, i, 1, &b) == DS_STOPPED)
            return LM_FAIL;
        if (!a.ok || !b.ok) { calc_say(&d->c, P(SENS_FAIL), t.name, t.delta, t.line); continue; }
        double bx = (b.bore[0] - a.bore[0]) / 2 * d->um, by = (b.bore[1] - a.bore[1]) / 2 * d->um;
        /* a shift that is rounding (1e-18 um across a fold) prints as 0 on every build */
        if (fabs(bx) < 1e-9) bx = 0;
        if (fabs(by) < 1e-9) by = 0;
        calc_say(&d->c, P(SENS_ROW), t.name, t.delta, a.rms * d->um, b.rms * d->um, a.wave,
                 b.wave, a.efl, b.efl, a.bfd, b.bfd, lm_clean(d->io, bx), lm_clean(d->io, by),
                 t.line);
        /* the half-difference is the linear change at +delta; its variance factor
         * that of the distribution over [-delta, delta] in delta^2 */
        ve += k * pow((b.efl - a.efl) / 2, 2);
        vb += k * pow((b.bfd - a.bfd) / 2, 2);
        vx += k * bx * bx;
        vy += k * by * by;
    }
    calc_say(&d->c, P(PREDICT), sqrt(ve), sqrt(vb));
    calc_say(&d->c, P(PREDICT_BORE), n.bore[0] * d->um, n.bore[1] * d->um, sqrt(vx), sqrt(vy));
    return LM_GO;
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* Nearest-rank percentile of sorted v[0..n-1]. */
static double pct(const double *v, long n, double q)
{
    long r = (long)ceil(q / 100 * (double)n);
    if (r < 1) r = 1;
    if (r > n) r = n;
    return v[r - 1];
}

/* The summary of a table's text (rows "lens rms_um efl bfd focus [bx_um by_um]", '#'
 * comments; the boresight columns summarised when every good row has them). */
static int summary(tdlg *d, const char *src, const char *text, double limit_um)
{
    long n = 0, cap = 1024, fails = 0, good = 0, line = 0;
    double *rms = malloc(sizeof(double) * (size_t)cap), se = 0, se2 = 0, sb = 0, sb2 = 0;
    double sx = 0, sx2 = 0, sy = 0, sy2 = 0;
    int nf = 0, nbore = 0;
    const char *s = text;
    if (!rms) return LM_FAIL;
    while (*s) {
        const char *e = strchr(s, '\n');
        size_t len = e ? (size_t)(e - s) : strlen(s);
        char buf[256], r[64];
        long k;
        double efl, bfd, foc, bx, by;
        int got;
        line++;
        if (len && s[0] != '#') {
            if (len >= sizeof buf) len = sizeof buf - 1;
            memcpy(buf, s, len);
            buf[len] = '\0';
            got = sscanf(buf, "%ld %63s %lf %lf %lf %lf %lf", &k, r, &efl, &bfd, &foc, &bx, &by);
            if (got != 5 && got != 7) {
                char m[512];
                snprintf(m, sizeof m, P(BAD_TABLE), src, line);
                calc_say(&d->c, P(REFUSED), m);
                fprintf(stderr, P(ERR), m);
                free(rms);
                return LM_FAIL;
            }
            if (n == cap) {
                double *t = realloc(rms, sizeof(double) * (size_t)(cap *= 2));
                if (!t) { free(rms); return LM_FAIL; }
                rms = t;
            }
            if (!strcmp(r, "fail")) { fails++; rms[n++] = INFINITY; }
            else {
                double v = strtod(r, NULL);
                rms[n++] = v;
                if (limit_um > 0 && v <= limit_um) good++;
                se += efl; se2 += efl * efl; sb += bfd; sb2 += bfd * bfd; nf++;
                if (got == 7) { sx += bx; sx2 += bx * bx; sy += by; sy2 += by * by; nbore++; }
            }
        }
        s = e ? e + 1 : s + len;
    }
    calc_say(&d->c, P(ROWS), n, fails);
    if (n) {
        qsort(rms, (size_t)n, sizeof *rms, cmp_d);
        calc_say(&d->c, P(PCT), pct(rms, n, 10), pct(rms, n, 50), pct(rms, n, 90),
                 pct(rms, n, 95), pct(rms, n, 99), rms[n - 1]);
    }
    if (nf > 1) {
        double me = se / nf, mb = sb / nf;
        double ve = (se2 - nf * me * me) / (nf - 1), vb = (sb2 - nf * mb * mb) / (nf - 1);
        calc_say(&d->c, P(EFL), me, sqrt(ve > 0 ? ve : 0), mb, sqrt(vb > 0 ? vb : 0));
    }
    if (nf > 1 && nbore == nf) {
        double mx = sx / nf, my = sy / nf;
        double vx = (sx2 - nf * mx * mx) / (nf - 1), vy = (sy2 - nf * my * my) / (nf - 1);
        calc_say(&d->c, P(BORE), lm_clean(d->io, mx), sqrt(vx > 0 ? vx : 0),
                 lm_clean(d->io, my), sqrt(vy > 0 ? vy : 0));
    }
    if (limit_um > 0 && n) calc_say(&d->c, P(YIELD), limit_um, good, n, 100.0 * good / n);
    free(rms);
    return LM_GO;
}

static int mc(tdlg *d)
{
    const ds_api *ds = d->ds;
    ds_problem *p = d->f.p;
    static const char *const dists[] = {"uniform", "gauss", NULL};
    static const char *const comps[] = {"bfd", "none", NULL};
    long count, first;
    unsigned long long seed = 0;
    int di = 0, ci = 0, rc;
    double limit;
    char buf[64], out[4096], sd[32];
    if ((rc = ask_long(d, P(COUNT), 1, 1000000, &count)) ||
        (rc = ask_long(d, P(FIRST), 1, 1000000000, &first)) ||
        (rc = lm_ask_word(d->io, P(SEED), P(SEED), P(SEED_WHAT), check_seed, &seed, buf,
                          sizeof buf)) ||
        (rc = calc_choice(&d->c, P(DIST), P(DIST_WHAT), dists, &di)) ||
        (rc = calc_choice(&d->c, P(COMP), P(COMP_WHAT), comps, &ci)) ||
        (rc = calc_num(&d->c, P(LIMIT), P(LIMIT_WHAT), LM_NONNEG, &limit)) ||
        (rc = lm_ask_word(d->io, P(TABLE), P(TABLE), P(TABLE_WHAT), check_out, d, out,
                          sizeof out)))
        return rc;
    d->o.dist = di;
    d->o.compensate = ci == 0;
    snprintf(sd, sizeof sd, "%llu", seed);
    calc_say(&d->c, P(MC_HEAD), first, first + count - 1, sd, di ? "Gaussian, sigma delta/2 cut "
             "at 2 sigma" : "uniform in [-delta, delta]");
    size_t cap = (size_t)count * 160 + 128, len = 0;
    char *tab = malloc(cap);
    if (!tab) return LM_FAIL;
    if (first == 1) len += (size_t)snprintf(tab, cap, "# lens rms_um efl bfd focus bx_um by_um\n");
    for (long k = first; k < first + count; k++) {
        ds_crit c;
        if (lm_stop_requested() || ds->tol_mc(p, &d->o, seed, k, &c) == DS_STOPPED) {
            free(tab);
            calc_say(&d->c, "%s", P(STOPPED));
            fprintf(stderr, "%s", P(STOPPED_ERR));
            return LM_FAIL;
        }
        char r[32];
        if (c.ok) snprintf(r, sizeof r, "%.6f", c.rms * d->um);
        else snprintf(r, sizeof r, "fail");
        len += (size_t)snprintf(tab + len, cap - len, "%ld %s %.9f %.9f %.6e %.6f %.6f\n", k,
                                r, isfinite(c.efl) ? c.efl : 0.0, isfinite(c.bfd) ? c.bfd : 0.0,
                                c.ok ? c.focus : 0.0, c.ok ? lm_clean(d->io, c.bore[0] * d->um) : 0.0,
                                c.ok ? lm_clean(d->io, c.bore[1] * d->um) : 0.0);
    }
    rc = summary(d, "-", tab, limit);
    if (rc == LM_GO && strcmp(out, "-")) {
        char err[512];
        if (dz_write(out, tab, len, err, sizeof err)) {
            calc_say(&d->c, P(REFUSED), err);
            fprintf(stderr, P(ERR), err);
            rc = LM_FAIL;
        } else {
            calc_say(&d->c, P(WROTE), out);
        }
    }
    free(tab);
    return rc;
}

static int table(tdlg *d)
{
    char name[4096], msg[4700];
    double limit;
    size_t len;
    int rc;
    if ((rc = lm_ask_word(d->io, P(TABLE_IN), P(TABLE_IN), P(TABLE_WHAT), check_in, d, name,
                          sizeof name)) ||
        (rc = calc_num(&d->c, P(LIMIT), P(LIMIT_WHAT), LM_NONNEG, &limit)))
        return rc;
    char *text = dz_slurp(name, &len, msg, sizeof msg);
    if (!text) { calc_say(&d->c, P(REFUSED), msg); fprintf(stderr, P(ERR), msg); return LM_FAIL; }
    if (memchr(text, '\0', len)) {
        snprintf(msg, sizeof msg, P(NUL), name);
        free(text);
        calc_say(&d->c, P(REFUSED), msg);
        fprintf(stderr, P(ERR), msg);
        return LM_FAIL;
    }
    rc = summary(d, name, text, limit);
    free(text);
    return rc;
}

int lm_tolerance(lm_io *io)
{
    static const char *const kinds[] = {"sens", "mc", "table", NULL};
    tdlg dd, *d = &dd;
    int rc, kind = 0;
    char desc[512];
    memset(d, 0, sizeof *d);
    d->io = io;
    d->c.io = io;
    d->c.unit = PX_MM;
    d->c.uname = "mm";
    if (!(d->ds = dz_api())) return LM_FAIL;
    rc = dz_ask_files(io, P(FILE), P(FILE_WHAT), P(MERIT), P(MERIT_WHAT), &d->f);
    if (rc == LM_GO) rc = calc_choice(&d->c, P(KIND), P(KIND_WHAT), kinds, &kind);
    if (rc == LM_GO) {
        d->ds->tol_defaults(d->f.p, &d->o);
        d->um = unit_um(d->ds->unit(d->f.p));
        int nt = d->ds->ntol(d->f.p);
        calc_say(&d->c, P(HEAD), d->f.lens, nt, nt == 1 ? "" : "s",
                 d->o.compensate ? "back focus" : "none");
        d->ds->describe(d->f.p, desc, sizeof desc);
        calc_say(&d->c, P(SAMPLING), desc);
        rc = kind == 0 ? sens(d) : kind == 1 ? mc(d) : table(d);
    }
    if (rc == LM_GO) rc = calc_done(&d->c);
    if (d->f.p) d->ds->free(d->f.p);
    return rc;
}
const char *lm_tolerance_example(void) { return P(EXAMPLE); }
