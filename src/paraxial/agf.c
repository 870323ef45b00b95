/* agf.c -- one Zemax AGF glass catalogue (the format the glass makers distribute
 * their catalogues in) from a text in memory into px_glass_rec records and their
 * internal-transmittance tables.  No file I/O here (glass_cat.c finds the files).
 *
 * The format, one record a line, a glass starting at its NM line:
 *   CC text                         catalogue comment
 *   NM name formula code nd vd [exclude status [melt]]   formula 1-13 (paraxial.h)
 *   GC text                         the glass's comment
 *   ED tce tce100300 density dPgF ignore_thermal          expansion, density
 *   CD c0 c1 ... c9                 dispersion coefficients (the formula's order)
 *   TD d0 d1 d2 e0 e1 ltk temp      thermal dn/dT data
 *   OD cost cr fr sr ar pr          cost and resistance classes
 *   LD lmin lmax                    the formula's validity range, um
 *   IT lambda tau thickness         internal transmittance at lambda (um) of a
 *                                   sample thickness mm thick (one line a point)
 *   MD, BD ...                      (other data, newer files)
 * Status numbers: 0 standard, 1 preferred, 2 obsolete, 3 special, 4 melt.  The
 * files come in UTF-16 (OpticStudio's own), UTF-8 or Latin-1: src/common/lm_text.h. */
#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "paraxial.h"
#include "common/lm_text.h"

#define AGF_TOKS 24

typedef struct agf {
    px_glass_cat *cat;
    const char *src;
    long line;
    char *err;
    size_t cap;
    int capr, capt;
    int cur_tau;                     /* the current glass's table (-1: none yet) */
    int cd_next;                     /* > 0: the CD coefficient a bare-number line
                                        continues with (some files wrap CD lines) */
    int skipping;                    /* the current NM's glass is skipped (its name) */
    size_t nlen, ncap;               /* notes */
} agf;

static int afail(agf *a, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int afail(agf *a, const char *fmt, ...)
{
    char why[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, sizeof why, fmt, ap);
    va_end(ap);
    snprintf(a->err, a->cap, "%s:%ld: %s", a->src, a->line, why);
    return PX_BAD;
}

static void anote(agf *a, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void anote(agf *a, const char *fmt, ...)
{
    char why[512], line[700];
    size_t k;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, sizeof why, fmt, ap);
    va_end(ap);
    if (a->line > 0) snprintf(line, sizeof line, "%s:%ld: %s\n", a->src, a->line, why);
    else snprintf(line, sizeof line, "%s: %s\n", a->src, why);
    k = strlen(line);
    if (a->nlen + k + 1 > a->ncap) {
        size_t c = (a->ncap + k + 1) * 2;
        char *t = realloc(a->cat->notes, c);
        if (!t) return;                    /* a note lost to memory, not the catalogue */
        a->cat->notes = t;
        a->ncap = c;
    }
    memcpy(a->cat->notes + a->nlen, line, k + 1);
    a->nlen += k;
}

/* A number filling the token (AGF writes 1.0E+000, -8.7E-003, 0, .5). */
static int num(const char *t, double *v)
{
    char *end;
    if (!*t || !(isdigit((unsigned char)*t) || *t == '-' || *t == '+' || *t == '.')) return 0;
    *v = strtod(t, &end);
    return *end == '\0' && isfinite(*v);
}

static char *dup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d) memcpy(d, s, n);
    return d;
}

static const char *status_word(double s)
{
    static const char *const w[] = {"standard", "preferred", "obsolete", "special", "melt"};
    return s >= 0 && s <= 4 && s == floor(s) ? w[(int)s] : "";
}

/* How many coefficients each formula uses (the rest of the CD line is ignored). */
static int formula_ncoef(int f)
{
    static const int n[14] = {0, 6, 6, 6, 5, 3, 8, 4, 4, 5, 8, 10, 8, 9};
    return f >= 1 && f <= 13 ? n[f] : 0;
}

static int nm_line(agf *a, char **tok, int n)
{
    px_glass_cat *c = a->cat;
    px_glass_rec *g;
    double f, nd = 0, vd = 0, st = -1;
    if (n < 3) return afail(a, "NM: expected NM NAME FORMULA CODE ND VD ...");
    if (!num(tok[2], &f) || f != floor(f) || f < 1 || f > 13)
        return afail(a, "NM %s: formula %s is not one of the AGF formulas 1-13 (Schott, "
                     "Sellmeier 1-5, Herzberger, Conrady, Handbook of Optics 1-2, "
                     "Extended 1-3)", tok[1], tok[2]);
    if (n > 4 && !num(tok[4], &nd)) return afail(a, "NM %s: nd '%s' is not a number", tok[1], tok[4]);
    if (n > 5 && !num(tok[5], &vd)) return afail(a, "NM %s: Vd '%s' is not a number", tok[1], tok[5]);
    if (n > 7 && !num(tok[7], &st)) st = -1;
    if (strlen(tok[1]) >= 64) return afail(a, "NM: a glass name of more than 63 bytes");
    a->cd_next = 0;
    a->skipping = 0;
    for (const char *p = tok[1]; *p; p++)
        if (*p == '@' || *p == '/' || *p == ':' || *p == '"' || *p == '#' || *p == ',') {
            /* lensmat's names hold none of these (NAME@W, ND/VD, CATALOG:NAME, the
             * prescription's columns): this glass is left out, the file still reads */
            anote(a, "NM %s: a glass name with @ / : \" # or , is skipped (lensmat's glass "
                  "names hold none of them)", tok[1]);
            a->skipping = 1;
            return PX_OK;
        }
    if (c->n == a->capr) {
        int cap = a->capr ? 2 * a->capr : 64;
        px_glass_rec *r = realloc(c->rec, (size_t)cap * sizeof *r);
        if (!r) return PX_NOMEM;
        c->rec = r;
        a->capr = cap;
    }
    g = &c->rec[c->n];
    memset(g, 0, sizeof *g);
    g->model = PX_GLASS_AGF + (int)f;
    g->ncoef = formula_ncoef((int)f);
    g->lmin = 0;                     /* no LD line: any wavelength (noted at the end) */
    g->lmax = INFINITY;
    g->catalog = c->name;
    g->status = status_word(st);
    if (!(g->name = dup(tok[1]))) return PX_NOMEM;
    /* nd and Vd as the catalogue prints them (a test knows the digits printed) */
    if (!(g->nd = dup(nd > 0 ? tok[4] : "-"))) { free((char *)g->name); return PX_NOMEM; }
    if (!(g->vd = dup(vd > 0 ? tok[5] : "-"))) {
        free((char *)g->name); free((char *)g->nd);
        return PX_NOMEM;
    }
    c->n++;
    a->cur_tau = -1;
    return PX_OK;
}

static int it_line(agf *a, char **tok, int n)
{
    px_glass_cat *c = a->cat;
    px_glass_rec *g = &c->rec[c->n - 1];
    px_tau_rec *t;
    double l, tau, th;
    if (n < 4 || !num(tok[1], &l) || !num(tok[2], &tau) || !num(tok[3], &th)) {
        anote(a, "%s: an IT line needs wavelength, transmittance, thickness: skipped", g->name);
        return PX_OK;
    }
    if (!(l > 0) || tau < 0 || tau > 1 || !(th > 0)) {
        anote(a, "%s: IT %s %s %s is outside 0 < lambda, 0 <= tau <= 1, 0 < thickness: "
              "skipped", g->name, tok[1], tok[2], tok[3]);
        return PX_OK;
    }
    if (a->cur_tau >= 0 && c->tau[a->cur_tau].thickness != th) {
        anote(a, "%s: IT at %g mm after points at %g mm: only the first thickness is "
              "kept", g->name, th, c->tau[a->cur_tau].thickness);
        return PX_OK;
    }
    if (a->cur_tau < 0) {
        if (c->ntau == a->capt) {
            int cap = a->capt ? 2 * a->capt : 64;
            px_tau_rec *r = realloc(c->tau, (size_t)cap * sizeof *r);
            if (!r) return PX_NOMEM;
            c->tau = r;
            a->capt = cap;
        }
        t = &c->tau[c->ntau];
        memset(t, 0, sizeof *t);
        t->name = g->name;
        t->thickness = th;
        a->cur_tau = c->ntau++;
    }
    t = &c->tau[a->cur_tau];
    if (t->n == PX_TAU_MAX) {
        anote(a, "%s: more than %d IT points: the rest are skipped", g->name, PX_TAU_MAX);
        return PX_OK;
    }
    if (t->n && !(l > t->l[t->n - 1])) {
        anote(a, "%s: IT wavelengths must ascend (%g after %g): skipped", g->name, l,
              t->l[t->n - 1]);
        return PX_OK;
    }
    t->l[t->n] = l;
    t->t[t->n++] = tau;
    return PX_OK;
}

static int line(agf *a, char *s)
{
    char *tok[AGF_TOKS];
    int n = 0;
    px_glass_cat *c = a->cat;
    char *save = NULL;
    for (char *p = strtok_r(s, " \t\r\f\v", &save); p && n < AGF_TOKS;
         p = strtok_r(NULL, " \t\r\f\v", &save))
        tok[n++] = p;
    if (n == 0) return PX_OK;
    if (!strcmp(tok[0], "NM")) return nm_line(a, tok, n);
    if (!strcmp(tok[0], "CC") || tok[0][0] == '!') return PX_OK;     /* comments */
    if (c->n == 0 && !a->skipping) {
        if (strlen(tok[0]) == 2 && isupper((unsigned char)tok[0][0]))
            return afail(a, "%s before the first NM line (not an AGF catalogue?)", tok[0]);
        /* a text line above the catalogue (a redistributor's header): said, skipped */
        anote(a, "'%.20s...' before the first NM line is not an AGF line: skipped", tok[0]);
        return PX_OK;
    }
    if (a->skipping) return PX_OK;
    px_glass_rec *g = &c->rec[c->n - 1];
    {   /* a line of bare numbers right after CD: its coefficients go on */
        double v;
        if (a->cd_next > 0 && num(tok[0], &v)) {
            for (int i = 0; i < n && a->cd_next <= PX_GLASS_MAXCOEF; i++, a->cd_next++)
                if (!num(tok[i], &g->coef[a->cd_next - 1]))
                    return afail(a, "%s: CD coefficient %d '%s' is not a number", g->name,
                                 a->cd_next, tok[i]);
            return PX_OK;
        }
        a->cd_next = 0;
    }
    if (!strcmp(tok[0], "CD")) {
        int i;
        for (i = 1; i < n && i <= PX_GLASS_MAXCOEF; i++)
            if (!num(tok[i], &g->coef[i - 1]))
                return afail(a, "%s: CD coefficient %d '%s' is not a number", g->name, i, tok[i]);
        a->cd_next = i;
        return PX_OK;
    }
    if (!strcmp(tok[0], "LD")) {
        double lo, hi;
        if (n < 3 || !num(tok[1], &lo) || !num(tok[2], &hi) || !(lo > 0) || !(hi > lo))
            return afail(a, "%s: LD needs two wavelengths LMIN < LMAX (um)", g->name);
        g->lmin = lo;
        g->lmax = hi;
        return PX_OK;
    }
    if (!strcmp(tok[0], "IT")) return it_line(a, tok, n);
    /* ED, TD, OD, GC, MD, BD and others: thermal, environmental, cost, comments */
    return PX_OK;
}

void px_agf_free(px_glass_cat *c)
{
    for (int i = 0; i < c->n; i++) {
        free((char *)c->rec[i].name);
        free((char *)c->rec[i].nd);
        free((char *)c->rec[i].vd);
    }
    free(c->rec);
    free(c->tau);
    free(c->name);
    free(c->path);
    free(c->notes);
    memset(c, 0, sizeof *c);
}

int px_agf_read(const char *text, size_t len, const char *name, const char *src,
                px_glass_cat *cat, char *err, size_t cap)
{
    agf a;
    size_t n;
    char *s = lm_text_utf8(text, len, &n), *p;
    int rc = PX_OK;
    memset(cat, 0, sizeof *cat);
    if (!s || !(cat->name = dup(name)) || !(cat->path = dup(""))) {
        free(s);
        px_agf_free(cat);
        snprintf(err, cap, "%s: out of memory", src);
        return PX_NOMEM;
    }
    for (char *q = cat->name; *q; q++) *q = (char)toupper((unsigned char)*q);
    memset(&a, 0, sizeof a);
    a.cat = cat; a.src = src; a.err = err; a.cap = cap; a.cur_tau = -1;
    for (p = s; rc == PX_OK && *p; ) {
        char *nl = strchr(p, '\n');
        if (nl) *nl = '\0';
        a.line++;
        rc = line(&a, p);
        p = nl ? nl + 1 : p + strlen(p);
    }
    free(s);
    if (rc == PX_NOMEM) snprintf(err, cap, "%s: out of memory", src);
    if (rc == PX_OK && cat->n == 0) {
        snprintf(err, cap, "%s: no NM line: not an AGF glass catalogue", src);
        rc = PX_BAD;
    }
    /* the records' catalogue pointer: the name, now that it will not move */
    for (int i = 0; rc == PX_OK && i < cat->n; i++) {
        cat->rec[i].catalog = cat->name;
        if (isinf(cat->rec[i].lmax)) {
            a.line = 0;
            anote(&a, "%s: no LD line: its formula is used at every wavelength",
                  cat->rec[i].name);
        }
    }
    if (rc != PX_OK) px_agf_free(cat);
    return rc;
}
