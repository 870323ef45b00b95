/* ds_read.c -- the design lines (vary, target, min, max, tol, tolopt, design) of a
 * prescription or merit file into a problem, and the lens they act on.  The lens
 * file's own design lines are blanked into comments before src/lens reads it, so the
 * lens reader sees a plain prescription and its FILE:LINE messages stay right. */
#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <gsl/gsl_integration.h>
#include "ds_int.h"

#define TOKS 24

static int fail(char *err, size_t cap, const char *src, long line, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
static int fail(char *err, size_t cap, const char *src, long line, const char *fmt, ...)
{
    va_list ap;
    int n = line > 0 ? snprintf(err, cap, "%s:%ld: ", src, line) : snprintf(err, cap, "%s: ", src);
    if (n < 0) n = 0;
    if ((size_t)n < cap) {
        va_start(ap, fmt);
        vsnprintf(err + n, cap - (size_t)n, fmt, ap);
        va_end(ap);
    }
    return DS_BAD;
}

static int is_design_word(const char *w, size_t n)
{
    static const char *const k[] = {"vary", "target", "min", "max", "tol", "tolopt",
                                    "design", NULL};
    for (int i = 0; k[i]; i++)
        if (strlen(k[i]) == n && !memcmp(k[i], w, n)) return 1;
    return 0;
}

static int num(const char *t, double *v)
{
    char *e;
    if (!*t) return 0;
    *v = strtod(t, &e);
    return *e == '\0' && isfinite(*v);
}

static int whole(const char *t, int lo, int hi, int *v)
{
    char *e;
    long x = strtol(t, &e, 10);
    if (e == t || *e || x < lo || x > hi) return 0;
    *v = (int)x;
    return 1;
}

typedef struct rdr {
    ds_problem *p;
    const char *src;
    long line;
    char *err;
    size_t cap;
} rdr;

#define BAD(...) fail(r->err, r->cap, r->src, r->line, __VA_ARGS__)

static int surface_no(rdr *r, const char *t, int *s)
{
    if (!whole(t, 1, r->p->lens.nsurf, s))
        return BAD("'%s': give a surface number from 1 to %d", t, r->p->lens.nsurf);
    (*s)--;
    return DS_OK;
}

static double glen(const ln_lens *l)
{
    double L = 0;
    for (int i = 0; i < l->nsurf; i++) L += fabs(l->surf[i].t);
    return L > 1 ? L : 1;
}

static int add_var(rdr *r, int kind, int s, int term)
{
    ds_problem *p = r->p;
    double L = glen(&p->lens);
    if (p->nvar >= DS_MAXVAR) return BAD("more than %d variables", DS_MAXVAR);
    for (int i = 0; i < p->nvar; i++)
        if (p->var[i].kind == kind && p->var[i].surf == s && p->var[i].term == term)
            return BAD("this variable is already varied (line %ld)", p->var[i].line);
    ds_var *v = &p->var[p->nvar++];
    v->kind = kind;
    v->surf = s;
    v->term = term;
    v->line = r->line;
    switch (kind) {
    case DV_C: v->scale = 1 / L; break;
    case DV_T: v->scale = L / 10; break;
    case DV_K: v->scale = 1; break;
    case DV_A: v->scale = pow(L, -(2.0 * term + 1)); break;
    case DV_ND: v->scale = 0.1; break;
    default: v->scale = 10; break;
    }
    return DS_OK;
}

/* The medium right of surface s as a model glass ND/VD (a catalogue glass becomes its
 * own nd, Vd: what a designer's "model glass" starts from). */
static int to_model(rdr *r, int s)
{
    ln_surface *g = &r->p->lens.surf[s];
    double nd, vd;
    const px_glass_rec *rec;
    char *slash = strchr(g->glass, '/');
    if (slash && num(slash + 1, &vd)) {
        *slash = '\0';
        int ok = num(g->glass, &nd);
        *slash = '/';
        if (ok) return DS_OK;
    }
    rec = g->glass[0] ? px_glass_find(g->glass) : NULL;
    if (!rec || !num(rec->nd, &nd) || !num(rec->vd, &vd))
        return BAD("surface %d: the medium to vary must be a catalogue glass with nd and "
                   "Vd, or a model glass ND/VD (it is '%s')", s + 1,
                   g->glass[0] ? g->glass : "air");
    snprintf(g->glass, sizeof g->glass, "%.17g/%.17g", nd, vd);
    g->nd = g->vd = 0;
    return DS_OK;
}

static int line_vary(rdr *r, char **t, int n)
{
    int s, a;
    if (n != 3) return BAD("vary KIND SURFACE (KIND: c r t k a4..a16 glass)");
    if (surface_no(r, t[2], &s)) return DS_BAD;
    const char *k = t[1];
    const ln_surface *gs = &r->p->lens.surf[s];
    if ((gs->coordbrk && strcmp(k, "t") && strcmp(k, "thic")) ||
        (gs->mirror && (!strcmp(k, "glass") || !strcmp(k, "nd") || !strcmp(k, "vd"))))
        return BAD("surface %d is a %s: '%s' cannot vary there", s + 1,
                   gs->coordbrk ? "coordinate break" : "mirror", k);
    if (!strcmp(k, "c") || !strcmp(k, "r") || !strcmp(k, "curv")) return add_var(r, DV_C, s, 0);
    if (!strcmp(k, "t") || !strcmp(k, "thic")) return add_var(r, DV_T, s, 0);
    if (!strcmp(k, "k") || !strcmp(k, "conic")) return add_var(r, DV_K, s, 0);
    if (k[0] == 'a' && whole(k + 1, 2, 16, &a) && a % 2 == 0) {
        ln_surface *g = &r->p->lens.surf[s];
        if (g->type != LN_EVENASPH) {
            g->type = LN_EVENASPH;
            g->nasph = 0;
        }
        while (g->nasph < a / 2) g->asph[g->nasph++] = 0;
        return add_var(r, DV_A, s, a / 2 - 1);
    }
    if (!strcmp(k, "glass") || !strcmp(k, "nd") || !strcmp(k, "vd")) {
        if (to_model(r, s)) return DS_BAD;
        if (strcmp(k, "vd") && add_var(r, DV_ND, s, 0)) return DS_BAD;
        if (strcmp(k, "nd") && add_var(r, DV_VD, s, 0)) return DS_BAD;
        for (int i = 0; i < r->p->nop; i++)
            if (r->p->op[i].kind == DO_GMAP && r->p->op[i].surf == s) return DS_OK;
        if (r->p->nop >= DS_MAXOP) return BAD("more than %d operands", DS_MAXOP);
        ds_op *o = &r->p->op[r->p->nop++];
        memset(o, 0, sizeof *o);
        o->kind = DO_GMAP;
        o->bound = -1;
        o->weight = 0;                 /* a hard bound (ds_opt.c): shown, never weighed */
        o->surf = s;
        o->line = r->line;
        return DS_OK;
    }
    return BAD("'%s' is not a variable (c r t k a4..a16 glass nd vd)", k);
}

static int op_kind(const char *k)
{
    static const struct { const char *n; int k; } names[] = {
        {"efl", DO_EFL}, {"effl", DO_EFL}, {"bfd", DO_BFD}, {"bfl", DO_BFD},
        {"totr", DO_TOTR}, {"rms", DO_RMS}, {"rsce", DO_RMS}, {"dist", DO_DIST},
        {"axcl", DO_AXCL}, {"spha", DO_SPHA}, {"ct", DO_CT}, {"ctva", DO_CT},
        {"et", DO_ET}, {"etva", DO_ET}, {"coma", DO_COMA}, {"asti", DO_ASTI},
        {"fcur", DO_FCUR}, {"sdis", DO_SDIS}, {"lacl", DO_LACL}, {"rmsw", DO_RMSW},
        {"rwre", DO_RMSW}, {NULL, 0}};
    for (int i = 0; names[i].n; i++)
        if (!strcasecmp(k, names[i].n)) return names[i].k;
    return -1;
}

static int line_op(rdr *r, char **t, int n, int bound)
{
    ds_problem *p = r->p;
    ds_op o;
    int all_fields = 0, have_surf = 0, have_field = 0;
    memset(&o, 0, sizeof o);
    o.bound = bound;
    o.weight = 1;
    o.wave = -1;
    o.line = r->line;
    if (n < 3) return BAD("%s OPERAND VALUE [field F|all] [wave W|all] [surface S] "
                          "[weight W]", t[0]);
    if ((o.kind = op_kind(t[1])) < 0)
        return BAD("'%s' is not an operand (efl bfd totr rms rmsw dist axcl spha coma asti "
                   "fcur sdis lacl ct et)", t[1]);
    if (!num(t[2], &o.target)) return BAD("'%s' is not a number", t[2]);
    for (int i = 3; i < n; i += 2) {
        if (i + 1 >= n) return BAD("'%s' wants a value after it", t[i]);
        const char *k = t[i], *v = t[i + 1];
        if (!strcmp(k, "weight")) {
            if (!num(v, &o.weight) || o.weight < 0) return BAD("weight '%s': a number >= 0", v);
        } else if (!strcmp(k, "field")) {
            have_field = 1;
            if (!strcmp(v, "all")) all_fields = 1;
            else if (!whole(v, 1, p->lens.nfield, &o.field))
                return BAD("field '%s': give all or 1 to %d", v, p->lens.nfield);
            else o.field--;
        } else if (!strcmp(k, "wave")) {
            int nwl = p->lens.nwl ? p->lens.nwl : 1;
            if (!strcmp(v, "all") || !strcmp(v, "0")) o.wave = -1;
            else if (!whole(v, 1, nwl, &o.wave))
                return BAD("wave '%s': give all (0) or 1 to %d", v, nwl);
            else o.wave--;
        } else if (!strcmp(k, "surface")) {
            if (surface_no(r, v, &o.surf)) return DS_BAD;
            have_surf = 1;
        } else {
            return BAD("'%s': field, wave, surface or weight", k);
        }
    }
    if ((o.kind == DO_CT || o.kind == DO_ET) && !have_surf)
        return BAD("%s needs a surface (surface S)", t[1]);
    if (o.kind == DO_CT && o.surf >= p->lens.nsurf - 1 && p->lens.surf[o.surf].t == 0)
        return BAD("surface %d has no thickness after it", o.surf + 1);
    if (o.kind == DO_ET) {
        if (o.surf + 1 >= p->lens.nsurf) return BAD("et: surface %d is the last", o.surf + 1);
        if (!(p->lens.surf[o.surf].semi > 0) && !(p->lens.surf[o.surf + 1].semi > 0))
            return BAD("et: surfaces %d and %d have no semi-diameter", o.surf + 1, o.surf + 2);
    }
    if (o.kind == DO_RMS || o.kind == DO_DIST || o.kind == DO_RMSW) {
        if (!p->lens.nfield) return BAD("%s needs the lens's fields (a field line)", t[1]);
        if (p->lens.ap_kind == LN_AP_NONE)
            return BAD("%s needs the lens's aperture (epd, fnum or na)", t[1]);
        if (p->lens.stop < 0) return BAD("%s needs the lens's stop", t[1]);
        if (!have_field) all_fields = 1;   /* every field, as a default merit */
    } else if (all_fields) {
        return BAD("%s takes no field", t[1]);
    }
    if (o.kind == DO_AXCL && (p->lens.nwl < 2))
        return BAD("axcl needs at least two wavelengths");
    int f1 = all_fields ? p->lens.nfield : o.field + 1;
    for (int f = all_fields ? 0 : o.field; f < f1; f++) {
        if (p->nop >= DS_MAXOP) return BAD("more than %d operands", DS_MAXOP);
        o.field = f;
        p->op[p->nop++] = o;
    }
    return DS_OK;
}

/* The group of surfaces s0..s1 (a surface, or an element) tilts and decentres use:
 * found or made; groups must nest or stand apart (each is a break pair in the rx). */
static int group_of(rdr *r, int s0, int s1, int *g)
{
    ds_problem *p = r->p;
    for (int i = 0; i < p->ngrp; i++) {
        const ds_grp *q = &p->grp[i];
        if (q->s0 == s0 && q->s1 == s1) { *g = i; return DS_OK; }
        int apart = s1 < q->s0 || q->s1 < s0;
        int nested = (q->s0 <= s0 && s1 <= q->s1) || (s0 <= q->s0 && q->s1 <= s1);
        if (!apart && !nested)
            return BAD("surfaces %d-%d overlap the element %d-%d of an earlier tol line: "
                       "elements that tilt or decentre must nest or stand apart",
                       s0 + 1, s1 + 1, q->s0 + 1, q->s1 + 1);
    }
    if (p->ngrp >= DS_MAXGRP) return BAD("more than %d surfaces and elements tilt or decentre",
                                         DS_MAXGRP);
    p->grp[p->ngrp].s0 = s0;
    p->grp[p->ngrp].s1 = s1;
    *g = p->ngrp++;
    return DS_OK;
}

/* Tilts and decentres: tx ty (degrees, about the x and y axes through the first
 * vertex) and dx dy (lens units) of a surface S, an element S-E, or all (every
 * surface that has an effect); OpticStudio's TSTX TSTY TSDX TSDY (a surface) and TETX
 * TETY TEDX TEDY (an element) too. */
static int tol_tilt(rdr *r, char **t, int kind, int axis, int element, double d)
{
    ds_problem *p = r->p;
    const ln_lens *l = &p->lens;
    int s0, s1, all = !strcmp(t[2], "all");
    char *dash = all ? NULL : strchr(t[2], '-');
    if (all) {
        if (element) return BAD("an element tolerance takes surfaces S-E, not all");
        s0 = 0;
        s1 = l->nsurf - 1;
    } else if (dash) {
        *dash = '\0';
        int bad = surface_no(r, t[2], &s0) || surface_no(r, dash + 1, &s1);
        *dash = '-';
        if (bad) return DS_BAD;
        if (s1 <= s0) return BAD("'%s': an element is surfaces S-E with E after S", t[2]);
    } else {
        if (element) return BAD("'%s' tilts or decentres an element: give its surfaces S-E",
                                t[1]);
        if (surface_no(r, t[2], &s0)) return DS_BAD;
        s1 = s0;
    }
    for (int s = dash ? s0 : s1 + 1; s <= s1; s++)
        if (l->surf[s].coordbrk)              /* its inverse would not commute with it */
            return BAD("surface %d is a coordinate break: an element that tilts or "
                       "decentres as one holds surfaces only", s + 1);
    for (int s = s0; s <= s1; s++) {
        const ln_surface *g = &l->surf[s];
        int e = dash ? s1 : s, gi = 0;
        if (!dash && g->coordbrk) {
            if (all) continue;
            return BAD("surface %d is a coordinate break: tilt or decentre the surface "
                       "after it", s + 1);
        }
        if (all) {                            /* all: the surfaces it moves */
            const char *before = s ? l->surf[s - 1].glass : l->obj_glass;
            int plane = !isfinite(g->r) && !(g->type == LN_EVENASPH && g->nasph);
            int air0 = !before[0] || !strcasecmp(before, "air");
            int air1 = !g->glass[0] || !strcasecmp(g->glass, "air");
            int same = (air0 && air1) || !strcasecmp(before, g->glass);
            if (plane && (kind == DT_DEC || (!g->mirror && same))) continue;
        }
        if (group_of(r, s, e, &gi)) return DS_BAD;
        if (p->ntol >= DS_MAXTOL) return BAD("more than %d tolerances", DS_MAXTOL);
        ds_tol *o = &p->tol[p->ntol++];
        o->kind = kind;
        o->axis = axis;
        o->surf = s;
        o->grp = gi;
        o->delta = d;
        o->line = r->line;
        if (dash) break;
    }
    return DS_OK;
}

static int line_tol(rdr *r, char **t, int n)
{
    ds_problem *p = r->p;
    int kind, s0, s1, rel = 0, axis = 0, element = 0;
    double d;
    char v[64];
    static const char *const tilts[] = {"tx", "ty", "dx", "dy", "tstx", "tsty", "tsdx",
                                        "tsdy", "tetx", "tety", "tedx", "tedy", NULL};
    if (n != 4) return BAD("tol KIND SURFACE|S-E|all DELTA[%%] (KIND: r t n k tx ty dx dy)");
    if (!strcmp(t[1], "r")) kind = DT_R;
    else if (!strcmp(t[1], "t")) kind = DT_T;
    else if (!strcmp(t[1], "n")) kind = DT_N;
    else if (!strcmp(t[1], "k")) kind = DT_K;
    else {
        int i = 0;
        while (tilts[i] && strcasecmp(tilts[i], t[1])) i++;
        if (!tilts[i])
            return BAD("'%s' is not a tolerance (r t n k; tx ty dx dy, or OpticStudio's "
                       "TSTX TSTY TSDX TSDY TETX TETY TEDX TEDY)", t[1]);
        kind = (i % 4) < 2 ? DT_TILT : DT_DEC;
        axis = i % 2;
        element = i >= 8;
    }
    snprintf(v, sizeof v, "%s", t[3]);
    size_t lv = strlen(v);
    if (lv && v[lv - 1] == '%') { v[lv - 1] = '\0'; rel = 1; }
    if (!num(v, &d) || !(d > 0)) return BAD("'%s': a tolerance is a number > 0", t[3]);
    if (rel && kind != DT_R) return BAD("only radius tolerances may be relative (%%)");
    if (kind == DT_TILT && d >= 45) return BAD("'%s': a tilt tolerance is in degrees, < 45", t[3]);
    if (kind == DT_TILT || kind == DT_DEC) return tol_tilt(r, t, kind, axis, element, d);
    if (!strcmp(t[2], "all")) { s0 = 0; s1 = p->lens.nsurf; }
    else { if (surface_no(r, t[2], &s0)) return DS_BAD; s1 = s0 + 1; }
    for (int s = s0; s < s1; s++) {
        const ln_surface *g = &p->lens.surf[s];
        if (g->coordbrk && kind != DT_T) {
            if (s1 - s0 > 1) continue;
            return BAD("surface %d is a coordinate break: it has no %s", s + 1,
                       kind == DT_R ? "radius" : kind == DT_N ? "glass" : "conic");
        }
        if (!strcmp(t[2], "all")) {            /* all: the ones that have it */
            if (kind == DT_R && !isfinite(g->r)) continue;
            if (kind == DT_T && (s == p->lens.nsurf - 1 || g->t == 0)) continue;
            if (kind == DT_N && (!g->glass[0] || !strcasecmp(g->glass, "air"))) continue;
        } else if (kind == DT_R && !isfinite(g->r)) {
            return BAD("surface %d is a plane: give its tolerance as a power (not here)", s + 1);
        }
        if (kind == DT_N && g->mirror)
            return BAD("surface %d is a mirror: its medium is the one before it", s + 1);
        if (p->ntol >= DS_MAXTOL) return BAD("more than %d tolerances", DS_MAXTOL);
        ds_tol *o = &p->tol[p->ntol++];
        o->kind = kind;
        o->surf = s;
        o->delta = rel ? fabs(g->r) * d / 100 : d;
        o->line = r->line;
    }
    return DS_OK;
}

static int line_opt(rdr *r, char **t, int n)
{
    ds_problem *p = r->p;
    for (int i = 1; i < n; i += 2) {
        if (i + 1 >= n) return BAD("'%s' wants a value after it", t[i]);
        const char *k = t[i], *v = t[i + 1];
        double x;
        if (!strcmp(t[0], "design") && !strcmp(k, "rings")) {
            if (!whole(v, 1, DS_MAXRING, &p->rings)) return BAD("rings: 1 to %d", DS_MAXRING);
        } else if (!strcmp(t[0], "design") && !strcmp(k, "arms")) {
            if (!whole(v, 2, DS_MAXARM, &p->arms) || p->arms % 2)
                return BAD("arms: an even number from 2 to %d", DS_MAXARM);
        } else if (!strcmp(t[0], "design") && !strcmp(k, "method")) {
            if (!strcmp(v, "lm")) p->method = 0;
            else if (!strcmp(v, "lmaccel")) p->method = 1;
            else return BAD("method: lm or lmaccel");
        } else if (!strcmp(t[0], "design") && !strcmp(k, "aim")) {
            if (!strcmp(v, "stop")) p->aim_paraxial = 0;
            else if (!strcmp(v, "paraxial")) p->aim_paraxial = 1;
            else return BAD("aim: stop (real rays aimed at the stop) or paraxial");
        } else if (!strcmp(t[0], "tolopt") && !strcmp(k, "dist")) {
            if (!strcmp(v, "uniform")) p->topt.dist = 0;
            else if (!strcmp(v, "gauss")) p->topt.dist = 1;
            else return BAD("dist: uniform or gauss");
        } else if (!strcmp(t[0], "tolopt") && !strcmp(k, "compensator")) {
            if (!strcmp(v, "bfd")) p->topt.compensate = 1;
            else if (!strcmp(v, "none")) p->topt.compensate = 0;
            else return BAD("compensator: bfd or none");
        } else if (!strcmp(t[0], "tolopt") && !strcmp(k, "limit")) {
            if (!num(v, &x) || !(x > 0)) return BAD("limit: a number > 0 (lens units)");
            p->topt.limit = x;
        } else {
            return BAD("'%s' is not a setting of %s", k, t[0]);
        }
    }
    return DS_OK;
}

static int split(char *s, char **t)
{
    int n = 0;
    char *h = strchr(s, '#');
    if (h) *h = '\0';
    for (;;) {
        while (*s == ' ' || *s == '\t' || *s == '\r') s++;
        if (!*s) return n;
        if (n == TOKS) return -1;
        t[n++] = s;
        while (*s && *s != ' ' && *s != '\t' && *s != '\r') s++;
        if (*s) *s++ = '\0';
    }
}

/* Read the design lines of text; keep: also copy them into p->merit_lines. */
static int read_lines(ds_problem *p, const char *text, size_t len, const char *src, int keep,
                      char *err, size_t cap)
{
    rdr rr = {p, src, 0, err, cap}, *r = &rr;
    const char *q = text, *end = text + len;
    while (q < end) {
        const char *nl = memchr(q, '\n', (size_t)(end - q)), *e = nl ? nl : end;
        char buf[1024], *t[TOKS];
        int n;
        r->line++;
        if ((size_t)(e - q) >= sizeof buf) {
            const char *w = q;
            while (w < e && (*w == ' ' || *w == '\t')) w++;
            size_t k = 0;
            while (w + k < e && isalpha((unsigned char)w[k])) k++;
            if (is_design_word(w, k)) return BAD("line longer than %zu bytes", sizeof buf - 1);
            q = nl ? nl + 1 : end;
            continue;
        }
        memcpy(buf, q, (size_t)(e - q));
        buf[e - q] = '\0';
        n = split(buf, t);
        if (n < 0) return BAD("more than %d words", TOKS);
        if (n > 0 && is_design_word(t[0], strlen(t[0]))) {
            int rc;
            if (!strcmp(t[0], "vary")) rc = line_vary(r, t, n);
            else if (!strcmp(t[0], "target")) rc = line_op(r, t, n, 0);
            else if (!strcmp(t[0], "min")) rc = line_op(r, t, n, 1);
            else if (!strcmp(t[0], "max")) rc = line_op(r, t, n, -1);
            else if (!strcmp(t[0], "tol")) rc = line_tol(r, t, n);
            else rc = line_opt(r, t, n);
            if (rc) return rc;
            if (keep) {
                size_t l = (size_t)(e - q);
                char *m = realloc(p->merit_lines, p->merit_len + l + 2);
                if (!m) return BAD("out of memory");
                p->merit_lines = m;
                memcpy(m + p->merit_len, q, l);
                p->merit_len += l;
                if (p->merit_len && m[p->merit_len - 1] == '\r') p->merit_len--;
                m[p->merit_len++] = '\n';
                m[p->merit_len] = '\0';
            }
        } else if (!keep && n > 0) {
            return BAD("'%s' is not a line of a merit file (vary target min max tol "
                       "tolopt design)", t[0]);
        }
        q = nl ? nl + 1 : end;
    }
    return DS_OK;
}

/* The design lines of a prescription made comments: '#' over their first letter. */
static char *blank_design(const char *text, size_t len)
{
    char *s = malloc(len + 1);
    if (!s) return NULL;
    memcpy(s, text, len);
    s[len] = '\0';
    for (size_t i = 0; i < len;) {
        size_t j = i, k = 0;
        while (j < len && (s[j] == ' ' || s[j] == '\t')) j++;
        while (j + k < len && isalpha((unsigned char)s[j + k])) k++;
        if (is_design_word(s + j, k) && (j + k == len || strchr(" \t\r\n#", s[j + k])))
            s[j] = '#';
        while (i < len && s[i] != '\n') i++;
        i++;
    }
    return s;
}

static double cross(const double *o, const double *a, const double *b)
{
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}
static int cmp_pt(const void *a, const void *b)
{
    const double *x = a, *y = b;
    return x[0] < y[0] ? -1 : x[0] > y[0] ? 1 : x[1] < y[1] ? -1 : x[1] > y[1];
}

/* The glass map: the convex hull of the catalogue's (Vd/100, nd) points (Andrew's
 * monotone chain), counter-clockwise. */
static void glass_hull(ds_problem *p)
{
    int n = 0, m = px_glass_count(), k = 0;
    double *pt = malloc(sizeof(double) * 2 * (size_t)(m + 1));
    if (!pt) return;
    for (int i = 0; i < m; i++) {
        const px_glass_rec *g = px_glass_at(i);
        double nd, vd;
        if (!g || !num(g->nd, &nd) || !num(g->vd, &vd)) continue;
        pt[2 * n] = vd / 100;
        pt[2 * n + 1] = nd;
        n++;
    }
    qsort(pt, (size_t)n, 2 * sizeof(double), cmp_pt);
    double *h = p->hull;
    int cap = (int)(sizeof p->hull / sizeof p->hull[0]) / 2 - 1;
    if (2 * n > cap) n = cap / 2;
    for (int i = 0; i < n; i++) {
        while (k >= 2 && cross(h + 2 * (k - 2), h + 2 * (k - 1), pt + 2 * i) <= 0) k--;
        memcpy(h + 2 * k++, pt + 2 * i, 2 * sizeof(double));
    }
    for (int i = n - 2, t = k + 1; i >= 0; i--) {
        while (k >= t && cross(h + 2 * (k - 2), h + 2 * (k - 1), pt + 2 * i) <= 0) k--;
        memcpy(h + 2 * k++, pt + 2 * i, 2 * sizeof(double));
    }
    p->nhull = k > 1 ? k - 1 : k;
    free(pt);
}

int ds_read(const char *lens_text, size_t lens_len, const char *lens_src,
            const char *merit_text, size_t merit_len, const char *merit_src,
            const trace_api *tr, ds_problem **out, char *err, size_t cap)
{
    ds_problem *p = calloc(1, sizeof *p);
    ln_notes notes = {0};
    char *clean;
    int rc;
    *out = NULL;
    if (!p) return fail(err, cap, lens_src, 0, "out of memory");
    ln_init(&p->lens);
    ln_init(&p->base);
    p->tr = tr;
    p->rings = 3;
    p->arms = 6;
    p->topt.compensate = 1;
    snprintf(p->src, sizeof p->src, "%s", lens_src);
    if (ln_is_zmx(lens_text, lens_len)) {
        rc = ln_read_zmx(lens_text, lens_len, lens_src, &p->lens, &notes, err, cap);
        clean = NULL;
    } else {
        if (!(clean = blank_design(lens_text, lens_len))) {
            free(p);
            return fail(err, cap, lens_src, 0, "out of memory");
        }
        rc = ln_read_rx(clean, lens_len, lens_src, &p->lens, &notes, err, cap);
    }
    ln_notes_free(&notes);
    if (rc == LN_OK && !ln_is_rx_thickness(lens_text, lens_len) && !ln_is_zmx(lens_text, lens_len))
        rc = fail(err, cap, lens_src, 0, "a lens to design is a prescription by thickness "
                  "(a 'thickness' line) or a .zmx");
    if (rc == LN_OK) rc = ln_check(&p->lens, lens_src, err, cap) == LN_OK ? DS_OK : DS_BAD;
    if (rc == DS_OK && p->lens.nsurf > DS_MAXSURF)
        rc = fail(err, cap, lens_src, 0, "%d surfaces: at most %d", p->lens.nsurf, DS_MAXSURF);
    if (rc == DS_OK && (ln_mirrors(&p->lens) || ln_breaks(&p->lens))) {
        /* folded or tilted: first order from the lens unfolded (ds_setup.c) */
        ln_lens u;
        char why[LN_ERR_MAX];
        if (ln_unfold(&p->lens, &u, NULL, why, sizeof why) != LN_OK) {
            rc = fail(err, cap, lens_src, 0, "%s", why);
        } else {
            if (u.nsurf > DS_MAXSURF)
                rc = fail(err, cap, lens_src, 0, "%d surfaces unfolded: at most %d", u.nsurf,
                          DS_MAXSURF);
            ln_free(&u);
        }
        if (rc == DS_OK && p->lens.stop >= 0 && p->lens.surf[p->lens.stop].coordbrk)
            rc = fail(err, cap, lens_src, p->lens.surf[p->lens.stop].line,
                      "surface %d: a coordinate break cannot be the stop", p->lens.stop + 1);
    }
    if (rc == DS_OK && clean) rc = read_lines(p, lens_text, lens_len, lens_src, 1, err, cap);
    free(clean);
    if (rc == DS_OK && merit_text)
        rc = read_lines(p, merit_text, merit_len, merit_src, 0, err, cap);
    if (rc == DS_OK && ln_check(&p->lens, lens_src, err, cap) != LN_OK) rc = DS_BAD;
    if (rc == DS_OK && p->rings * p->arms * (p->lens.nwl ? p->lens.nwl : 1) >
                           2 * DS_MAXRING * DS_MAXARM)
        rc = fail(err, cap, merit_src ? merit_src : lens_src, 0, "%d rings x %d arms x %d "
                  "wavelengths: at most %d rays a field", p->rings, p->arms,
                  p->lens.nwl ? p->lens.nwl : 1, 2 * DS_MAXRING * DS_MAXARM);
    if (rc == DS_OK && ln_copy(&p->base, &p->lens) != LN_OK)
        rc = fail(err, cap, lens_src, 0, "out of memory");
    if (rc != DS_OK) {
        ds_free(p);
        return rc == LN_NOMEM ? DS_NOMEM : DS_BAD;
    }
    /* Gauss-Legendre in rho^2 over (0, 1): rings at sqrt(u_i), weights w_i (sum 1) */
    gsl_integration_glfixed_table *gl = gsl_integration_glfixed_table_alloc((size_t)p->rings);
    for (int i = 0; gl && i < p->rings; i++)
        gsl_integration_glfixed_point(0, 1, (size_t)i, &p->ru[i], &p->rw[i], gl);
    if (gl) gsl_integration_glfixed_table_free(gl);
    glass_hull(p);
    *out = p;
    return DS_OK;
}

void ds_free(ds_problem *p)
{
    if (!p) return;
    ln_free(&p->lens);
    ln_free(&p->base);
    free(p->merit_lines);
    free(p->guess);
    free(p->gok);
    free(p);
}
