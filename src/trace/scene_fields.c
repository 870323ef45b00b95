/* scene_fields.c -- the fields of one scene-file directive: the keys a line may carry
 * and how many values each takes, read into a `fields` record with every value checked
 * to its FILE:LINE (numbers, wavelengths, indices that name a glass, file names), and
 * the small checks every directive reader uses (a unit vector, a positive value, an
 * integer in range, the keys a directive needs, its `up` vector).  scene_read.c's
 * surfaces and settings and its sources are read through it. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "paraxial/paraxial.h"
#include "scene_int.h"

/* The keys a directive may carry, with their number of values.  ARGS_WORD: one
 * word (a file name); ARGS_VAR: numbers up to the next key; ARGS_WL: wavelengths up
 * to the next key (px_wavelength: nm above 100, else um, or F d C e g hene);
 * ARGS_TOKS: words and numbers up to the next key, read by the key's own reader.  The
 * values of `refract` and `medium` are indices: a number, or a glass (a catalogue
 * name, a model glass ND/VD, a medium of the seed), optionally after the word
 * `glass`. */
enum { ARGS_WORD = -1, ARGS_VAR = -2, ARGS_WL = -3, ARGS_TOKS = -4 };
typedef struct keydef { const char *name; int nargs; } keydef;
static const keydef keys[] = {
    {"refract", 2}, {"mirror", 0}, {"absorb", 0}, {"detect", 0}, {"media", ARGS_WORD},
    {"at", 3}, {"normal", 3}, {"disc", 1}, {"hole", 1}, {"rect", 2}, {"up", 3},
    {"center", 3}, {"radius", 1}, {"vertex", 3}, {"axis", 3}, {"conic", 1},
    {"coef", ARGS_VAR}, {"aperture", 1}, {"tessellate", 1}, {"refine", 0},
    {"file", ARGS_WORD}, {"sphere", 4},
    {"from", 3}, {"dir", 3}, {"to", 6}, {"angle", 1}, {"rays", 1}, {"rings", 1},
    {"toward", 3}, {"grid", 1}, {"waist", 1}, {"wavelength", 1}, {"trunc", 1},
    {"power", 1}, {"medium", 1}, {"pol", ARGS_TOKS}, {"lambda", ARGS_WL},
    {"polarizer", 3}, {"retarder", 4}, {"qwp", 3}, {"hwp", 3}, {"coating", ARGS_WORD},
};
#define NKEYS (int)(sizeof keys / sizeof keys[0])
_Static_assert(sizeof keys / sizeof keys[0] == SC_NKEYS, "SC_NKEYS counts the keys");


int sf_key_index(const tok *t)
{
    for (int i = 0; i < NKEYS; i++)
        if (sl_tok_is(t, keys[i].name)) return i;
    return -1;
}

int sf_has(const fields *f, const char *k)
{
    for (int i = 0; i < NKEYS; i++)
        if (!strcmp(keys[i].name, k)) return f->has[i];
    return 0;
}
const double *sf_val(const fields *f, const char *k)
{
    for (int i = 0; i < NKEYS; i++)
        if (!strcmp(keys[i].name, k)) return f->num[i];
    return NULL;
}

static int word_in(const char *list, const char *w)
{
    size_t n = strlen(w);
    for (const char *p = list; (p = strstr(p, w)); p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return 1;
    return 0;
}

static int is_index_key(int k)
{
    return !strcmp(keys[k].name, "refract") || !strcmp(keys[k].name, "medium");
}

/* Does the token look like a number (only the characters of one)? */
static int tok_numeric(const tok *t)
{
    for (size_t i = 0; i < t->n; i++)
        if (!strchr("0123456789+-.eE", t->s[i])) return 0;
    return t->n > 0;
}

/* A glass as an index value at r->t[*i] (after an optional word `glass`): its name
 * into name, its index at the d line (or mid-range, for a glass with none at d) into
 * *n; *i is left on its last token.  0 or -1 (error reported). */
static int index_glass(reader *r, const char *what, int *i, char *name, double *n)
{
    const tok *t = &r->t[*i];
    const px_glass_rec *g;
    if (sl_tok_is(t, "glass")) {
        if (*i + 1 == r->nt || sf_key_index(&r->t[*i + 1]) >= 0)
            return sl_fail(r, "%s: 'glass' needs a glass name", what);
        t = &r->t[++*i];
    }
    if (t->n >= SC_GLASSMAX)
        return sl_fail(r, "%s: '%.24s...' is too long for a glass name", what, t->s);
    memcpy(name, t->s, t->n);
    name[t->n] = '\0';
    int rc = px_glass_index(name, PX_LAMBDA_D, n);
    if (rc == PX_GLASS_RANGE && (g = px_glass_find(name)))
        rc = px_glass_index(name, 0.5 * (g->lmin + g->lmax), n);
    if (rc != PX_OK)
        return sl_fail(r, "%s: '%s' is neither a number nor a glass of the catalogue (a name "
                    "such as N-BK7, a model glass ND/VD such as 1.5168/64.17, or a medium "
                    "such as water)", what, name);
    if ((g = px_glass_find(name))) strcpy(name, g->name);   /* the catalogue's spelling */
    return 0;
}

/* Parse the items from t[first] on as key/value groups allowed by `allowed`
 * (space-separated key names). */
int sf_parse_fields(reader *r, int first, const char *dname, const char *allowed,
                        fields *f)
{
    memset(f, 0, sizeof *f);
    for (int i = first; i < r->nt;) {
        int k = sf_key_index(&r->t[i]);
        char w[32], what[64];
        snprintf(w, sizeof w, "%.*s", (int)(r->t[i].n < 24 ? r->t[i].n : 24), r->t[i].s);
        if (k < 0 || !word_in(allowed, keys[k].name))
            return sl_fail(r, "%s: unexpected '%s' (expected one of: %s)", dname, w, allowed);
        if (f->has[k]) return sl_fail(r, "%s: '%s' given twice", dname, w);
        f->has[k] = 1;
        i++;
        if (keys[k].nargs == ARGS_WORD) {
            if (i == r->nt) return sl_fail(r, "%s: '%s' needs a file name", dname, w);
            f->word[k] = r->t[i++];
            continue;
        }
        snprintf(what, sizeof what, "%s: '%s'", dname, w);
        if (keys[k].nargs == ARGS_TOKS) {
            for (f->at[k] = i; i < r->nt && sf_key_index(&r->t[i]) < 0; i++) f->count[k]++;
            continue;
        }
        if (keys[k].nargs == ARGS_WL) {
            while (i < r->nt && sf_key_index(&r->t[i]) < 0) {
                char b[NUMLEN];
                double um;
                snprintf(b, sizeof b, "%.*s", (int)(r->t[i].n < NUMLEN - 1 ? r->t[i].n :
                                                    NUMLEN - 1), r->t[i].s);
                if (f->count[k] == SC_MAXWL)
                    return sl_fail(r, "%s: more than %d wavelengths", dname, SC_MAXWL);
                if (r->t[i].n >= NUMLEN || px_wavelength(b, &um) != PX_OK)
                    return sl_fail(r, "%s: '%s' is not a wavelength (nm above 100, else um, "
                                "or F d C e g hene)", what, b);
                for (int j = 0; j < f->count[k]; j++)   /* (587.5618 is d) */
                    if (fabs(f->num[k][j] - um) <= 1e-12 * um)
                        return sl_fail(r, "%s: wavelength '%s' given twice", what, b);
                f->num[k][f->count[k]++] = um;
                i++;
            }
            if (!f->count[k]) return sl_fail(r, "%s: '%s' needs at least one wavelength", dname, w);
            continue;
        }
        if (keys[k].nargs == ARGS_VAR) {
            while (i < r->nt && sf_key_index(&r->t[i]) < 0) {
                if (f->count[k] == SC_MAXCOEF)
                    return sl_fail(r, "%s: more than %d '%s' values", dname, SC_MAXCOEF, w);
                if (sl_tok_num(r, &r->t[i], what, &f->num[k][f->count[k]++])) return -1;
                i++;
            }
            if (!f->count[k]) return sl_fail(r, "%s: '%s' needs at least one number", dname, w);
            continue;
        }
        for (int j = 0; j < keys[k].nargs; j++, i++) {
            if (i == r->nt || sf_key_index(&r->t[i]) >= 0)
                return sl_fail(r, "%s: '%s' needs %d number%s, found %d", dname, w,
                            keys[k].nargs, keys[k].nargs == 1 ? "" : "s", j);
            if (is_index_key(k) && !tok_numeric(&r->t[i])) {
                if (index_glass(r, what, &i, f->glass[k][j], &f->num[k][j])) return -1;
                continue;
            }
            if (sl_tok_num(r, &r->t[i], what, &f->num[k][j])) return -1;
        }
        f->count[k] = keys[k].nargs;
    }
    return 0;
}

char *sf_tok_dup(const tok *t)
{
    char *s = malloc(t->n + 1);
    if (s) {
        memcpy(s, t->s, t->n);
        s[t->n] = '\0';
    }
    return s;
}

/* A unit vector from key k; fails on a zero vector. */
int sf_unit_vec(reader *r, const fields *f, const char *dname, const char *k,
                    double *u)
{
    const double *v = sf_val(f, k);
    double m = sqrt(dot3(v, v));
    if (!(m > 0) || !isfinite(m))
        return sl_fail(r, "%s: '%s' %g %g %g is a zero-length direction", dname, k, v[0],
                    v[1], v[2]);
    for (int i = 0; i < 3; i++) u[i] = v[i] / m;
    return 0;
}

int sf_need(reader *r, const fields *f, const char *dname, const char *list)
{
    char k[32];
    const char *p = list;
    while (*p) {
        size_t n = strcspn(p, " ");
        snprintf(k, sizeof k, "%.*s", (int)n, p);
        if (!sf_has(f, k)) return sl_fail(r, "%s: '%s' is missing", dname, k);
        p += n;
        while (*p == ' ') p++;
    }
    return 0;
}

int sf_positive(reader *r, const char *dname, const char *what, double v)
{
    if (!(v > 0)) return sl_fail(r, "%s: %s = %g must be positive", dname, what, v);
    return 0;
}

/* An integer value within [lo, hi]. */
int sf_int_val(reader *r, const fields *f, const char *dname, const char *k,
                   long lo, long hi, long *out)
{
    double v = sf_val(f, k)[0];
    if (v != floor(v) || v < (double)lo || v > (double)hi)
        return sl_fail(r, "%s: '%s' %g must be an integer from %ld to %ld", dname, k, v, lo,
                    hi);
    *out = (long)v;
    return 0;
}

/* Some unit vector perpendicular to the unit vector d (or `up` projected). */
static void perpendicular(const double *d, double *u)
{
    double a[3] = {0, 0, 0}, m;
    int k = fabs(d[0]) < fabs(d[1]) ? (fabs(d[0]) < fabs(d[2]) ? 0 : 2)
                                    : (fabs(d[1]) < fabs(d[2]) ? 1 : 2);
    a[k] = 1;
    m = dot3(a, d);
    for (int i = 0; i < 3; i++) a[i] -= m * d[i];
    m = sqrt(dot3(a, a));
    for (int i = 0; i < 3; i++) u[i] = a[i] / m;
}

int sf_up_vector(reader *r, const fields *f, const char *dname, const double *d,
                     double *u)
{
    double m, p;
    if (!sf_has(f, "up")) { perpendicular(d, u); return 0; }
    if (sf_unit_vec(r, f, dname, "up", u)) return -1;
    p = dot3(u, d);
    for (int i = 0; i < 3; i++) u[i] -= p * d[i];
    m = sqrt(dot3(u, u));
    if (m < 1e-9) return sl_fail(r, "%s: 'up' is parallel to the direction", dname);
    for (int i = 0; i < 3; i++) u[i] /= m;
    return 0;
}
