/* glass.c -- the glass catalogue (data/glass.txt, compiled in by scripts/gen_glass.sh,
 * and the AGF catalogues of glass_cat.c behind it), indices of catalogue and model
 * glasses at a wavelength (every AGF dispersion formula), wavelength shorthands, Abbe
 * numbers, and absorption from the catalogues' internal-transmittance tables.  No
 * I/O here: glass_cat.c reads the AGF files. */
#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "paraxial.h"
#include "glass_data.h"

#define NGLASS ((int)(sizeof px_glass_table / sizeof px_glass_table[0]))

int px_glass_count(void) { return NGLASS; }

const px_glass_rec *px_glass_at(int i)
{
    return i >= 0 && i < NGLASS ? &px_glass_table[i] : NULL;
}

static const px_glass_rec *builtin(const char *name)
{
    for (int i = 0; i < NGLASS; i++)
        if (!strcasecmp(name, px_glass_table[i].name)) return &px_glass_table[i];
    return NULL;
}

static const px_glass_rec *in_cat(const px_glass_cat *c, const char *name)
{
    for (int i = 0; c && i < c->n; i++)
        if (!strcasecmp(name, c->rec[i].name)) return &c->rec[i];
    return NULL;
}

const px_glass_rec *px_glass_find(const char *name)
{
    const px_glass_rec *g;
    const char *colon = strchr(name, ':');
    if (colon) {                               /* CATALOG:NAME */
        char cat[256];
        if ((size_t)(colon - name) >= sizeof cat) return NULL;
        memcpy(cat, name, (size_t)(colon - name));
        cat[colon - name] = '\0';
        if (!strcasecmp(cat, "LENSMAT")) return builtin(colon + 1);
        return in_cat(px_glass_cat_find(cat), colon + 1);
    }
    if ((g = builtin(name))) return g;
    /* a name that is not a glass's (a number, a model glass, a medium) does not make
     * the catalogues load */
    if (!*name || isdigit((unsigned char)*name) || *name == '.' || strchr(name, '/') ||
        px_medium_index(name) > 0) return NULL;
    for (int i = 0, n = px_glass_cat_count(); i < n; i++)
        if ((g = in_cat(px_glass_cat_at(i), name))) return g;
    return NULL;
}

int px_glass_find_all(const char *name, const px_glass_rec **out, int max)
{
    const px_glass_rec *g;
    int k = 0;
    if ((g = builtin(name)) && k++ < max) out[0] = g;
    for (int i = 0, n = px_glass_cat_count(); i < n; i++)
        if ((g = in_cat(px_glass_cat_at(i), name))) {
            if (k < max) out[k] = g;
            k++;
        }
    return k;
}

/* n at l (um) from the record's formula (static inline: px_glass_index, the hot
 * path of every traced wavelength's index, keeps it inlined). */
static inline double formula(const px_glass_rec *g, double l);
double px_glass_formula(const px_glass_rec *g, double l) { return formula(g, l); }
static inline double formula(const px_glass_rec *g, double l)
{
    const double *c = g->coef;
    double l2 = l * l, n2 = 1, L;
    int f = g->model - PX_GLASS_AGF;
    if (g->model == PX_GLASS_CONST) return c[0];
    if (g->model == PX_GLASS_SELLMEIER || g->model == PX_GLASS_SELLMEIER_L) {
        for (int i = 0; i + 1 < g->ncoef; i += 2) {
            double ci = c[i + 1];
            if (g->model == PX_GLASS_SELLMEIER_L) ci *= ci;
            n2 += c[i] * l2 / (l2 - ci);
        }
        return sqrt(n2);
    }
    switch (f) {
    case 1:                                                       /* Schott */
        n2 = c[0] + c[1] * l2 + c[2] / l2 + c[3] / (l2 * l2) + c[4] / (l2 * l2 * l2) +
             c[5] / (l2 * l2 * l2 * l2);
        break;
    case 2: case 6: case 11:                                      /* Sellmeier 1, 3, 5 */
        for (int i = 0; i < (f == 2 ? 3 : f == 6 ? 4 : 5); i++)
            n2 += c[2 * i] * l2 / (l2 - c[2 * i + 1]);
        break;
    case 3:                                                       /* Herzberger */
        L = 1 / (l2 - 0.028);
        return c[0] + c[1] * L + c[2] * L * L + c[3] * l2 + c[4] * l2 * l2 +
               c[5] * l2 * l2 * l2;
    case 4:                                                       /* Sellmeier 2 */
        n2 = 1 + c[0] + c[1] * l2 / (l2 - c[2] * c[2]) + c[3] * l2 / (l2 - c[4] * c[4]);
        break;
    case 5:                                                       /* Conrady */
        return c[0] + c[1] / l + c[2] / pow(l, 3.5);
    case 7:                                                       /* Handbook 1 */
        n2 = c[0] + c[1] / (l2 - c[2]) - c[3] * l2;
        break;
    case 8:                                                       /* Handbook 2 */
        n2 = c[0] + c[1] * l2 / (l2 - c[2]) - c[3] * l2;
        break;
    case 9:                                                       /* Sellmeier 4 */
        n2 = c[0] + c[1] * l2 / (l2 - c[2]) + c[3] * l2 / (l2 - c[4]);
        break;
    case 10: case 12: case 13: {                                  /* Extended 1-3 */
        /* the negative powers l^-2, l^-4 ...: c2..c7 (10, 12: c2..c5), c3..c8 (13) */
        double m = 1 / l2, p = m;
        int k0 = f == 13 ? 3 : 2, k1 = f == 10 ? 7 : f == 12 ? 5 : 8;
        n2 = c[0] + c[1] * l2 + (f == 13 ? c[2] * l2 * l2 : 0);
        for (int k = k0; k <= k1; k++, p *= m) n2 += c[k] * p;
        if (f == 12) n2 += c[6] * l2 * l2 + c[7] * l2 * l2 * l2;
        break;
    }
    default:
        return NAN;
    }
    return n2 > 0 ? sqrt(n2) : NAN;
}

/* Model glass: n = A + B/l^2 through nd at d, nF - nC = (nd - 1)/vd. */
#define MODEL_LMIN 0.36
#define MODEL_LMAX 1.0
int px_glass_model(double nd, double vd, double l, double *n)
{
    double b, a;
    if (!(nd > 1 && nd < 3) || !(vd >= 5 && vd <= 150)) return PX_NO_GLASS;
    if (!(l > 0) || !isfinite(l)) return PX_BAD;
    if (l < MODEL_LMIN || l > MODEL_LMAX) return PX_GLASS_RANGE;
    b = (nd - 1) / vd / (1 / (PX_LAMBDA_F * PX_LAMBDA_F) - 1 / (PX_LAMBDA_C * PX_LAMBDA_C));
    a = nd - b / (PX_LAMBDA_D * PX_LAMBDA_D);
    *n = a + b / (l * l);
    return PX_OK;
}

/* "ND/VD" with both numbers complete: 1 and the two values, else 0. */
static int parse_model(const char *s, double *nd, double *vd)
{
    char *end;
    if (!isdigit((unsigned char)*s)) return 0;
    *nd = strtod(s, &end);
    if (end == s || *end != '/') return 0;
    s = end + 1;
    if (!isdigit((unsigned char)*s)) return 0;
    *vd = strtod(s, &end);
    return end != s && *end == '\0';
}

int px_glass_index(const char *name, double l, double *n)
{
    const px_glass_rec *g = px_glass_find(name);
    double nd, vd, m;
    if (!(l > 0) || !isfinite(l)) return PX_BAD;
    if (g) {
        if (l < g->lmin || l > g->lmax) return PX_GLASS_RANGE;
        *n = formula(g, l);
        return isfinite(*n) && *n > 0 ? PX_OK : PX_GLASS_RANGE;
    }
    if (strchr(name, ':')) return PX_NO_GLASS;      /* CATALOG:NAME not in that catalogue */
    if (parse_model(name, &nd, &vd)) return px_glass_model(nd, vd, l, n);
    if (isdigit((unsigned char)name[0])) {   /* a plain number: a constant index */
        char *end;
        m = strtod(name, &end);
        if (*end || !(m > 0) || !isfinite(m) || m > 100) return PX_NO_GLASS;
        *n = m;
        return PX_OK;
    }
    if ((m = px_medium_index(name)) > 0) {    /* the seed's constants (cornea, ...) */
        *n = m;
        return PX_OK;
    }
    return PX_NO_GLASS;
}

const char *px_glass_former(const char *name, const char **why)
{
    for (int i = 0; i < PX_NFORMER; i++)
        if (!strcasecmp(name, px_former_table[i].old)) {
            if (why) *why = px_former_table[i].why;
            return px_former_table[i].now;
        }
    return NULL;
}

int px_wavelength(const char *tok, double *um)
{
    static const struct { const char *name; double l; } lines[] = {
        {"F", PX_LAMBDA_F}, {"d", PX_LAMBDA_D}, {"C", PX_LAMBDA_C},
        {"e", PX_LAMBDA_E}, {"g", PX_LAMBDA_G}, {"hene", PX_LAMBDA_HENE},
    };
    char *end;
    double v;
    for (size_t i = 0; i < sizeof lines / sizeof *lines; i++)
        if (!strcasecmp(tok, lines[i].name)) { *um = lines[i].l; return PX_OK; }
    if (!isdigit((unsigned char)tok[0]) && tok[0] != '.') return PX_BAD;
    v = strtod(tok, &end);
    if (end == tok || *end || !(v > 0) || !isfinite(v)) return PX_BAD;
    if (v > 100) v /= 1000;                  /* nanometres */
    if (v < 0.1 || v > 100) return PX_BAD;   /* 100 nm .. 100 um */
    *um = v;
    return PX_OK;
}

int px_glass_abbe(const char *name, double *vd)
{
    double nd, nf, nc;
    int r;
    if ((r = px_glass_index(name, PX_LAMBDA_D, &nd)) != PX_OK ||
        (r = px_glass_index(name, PX_LAMBDA_F, &nf)) != PX_OK ||
        (r = px_glass_index(name, PX_LAMBDA_C, &nc)) != PX_OK) return r;
    if (nf == nc) return PX_BAD;             /* no dispersion: Vd infinite */
    *vd = (nd - 1) / (nf - nc);
    return PX_OK;
}

const px_tau_rec *px_glass_tau(const char *name, int k)
{
    const px_glass_rec *g = px_glass_find(name);
    if (!g || !g->catalog || !strcmp(g->catalog, "LENSMAT")) {
        for (int i = 0; i < PX_NTAU; i++)
            if (!strcasecmp(g ? g->name : name, px_tau_table[i].name) && k-- == 0)
                return &px_tau_table[i];
        return NULL;
    }
    const px_glass_cat *c = px_glass_cat_find(g->catalog);      /* an AGF glass's IT */
    for (int i = 0; c && i < c->ntau; i++)
        if (c->tau[i].name == g->name && k-- == 0) return &c->tau[i];
    return NULL;
}

/* The thickest table of a glass (a k table only when it has no other); NULL with *rc
 * set when there is none. */
static const px_tau_rec *thickest(const char *name, int *rc)
{
    const px_tau_rec *best = NULL, *t;
    for (int k = 0; (t = px_glass_tau(name, k)); k++)
        if (!best || t->thickness > best->thickness) best = t;
    if (!best) *rc = px_glass_find(name) || px_glass_index(name, PX_LAMBDA_D, &(double){0})
                     == PX_OK ? PX_NO_TAU : PX_NO_GLASS;
    return best;
}

/* The first and last points with t > 0 (the table's usable span), or -1.  (A k table
 * is usable throughout.) */
static int span(const px_tau_rec *t, int *last)
{
    int i0 = 0, i1 = t->n - 1;
    if (t->thickness > 0) {
        while (i0 < t->n && !(t->t[i0] > 0)) i0++;
        while (i1 > i0 && !(t->t[i1] > 0)) i1--;
    }
    *last = i1;
    return i0 < t->n ? i0 : -1;
}

/* alpha (1/mm) at point i of a table. */
static double alpha_at(const px_tau_rec *t, int i)
{
    if (t->thickness > 0) return -log(t->t[i]) / t->thickness;
    return 4 * 3.14159265358979323846 * t->t[i] / (t->l[i] * 1e-3);
}

int px_glass_absorption_range(const char *name, double *lmin, double *lmax)
{
    int rc = PX_OK, i0, i1;
    const px_tau_rec *t = thickest(name, &rc);
    if (!t) return rc;
    if ((i0 = span(t, &i1)) < 0) return PX_GLASS_RANGE;
    *lmin = t->l[i0];
    *lmax = t->l[i1];
    return PX_OK;
}

/* alpha (so ln t) is linear in lambda between neighbouring points (a zero inside the
 * span, an opaque point between transparent ones, makes alpha infinite there). */
int px_glass_absorption(const char *name, double l, double *alpha)
{
    int rc = PX_OK, i0, i1, i;
    const px_tau_rec *t = thickest(name, &rc);
    if (!(l > 0) || !isfinite(l)) return PX_BAD;
    if (!t) return rc;
    if ((i0 = span(t, &i1)) < 0 || l < t->l[i0] || l > t->l[i1]) return PX_GLASS_RANGE;
    for (i = i0; i < i1 && l > t->l[i + 1]; i++) {}
    if (i == i1 || l == t->l[i]) {
        *alpha = alpha_at(t, i);
    } else {
        double a = alpha_at(t, i), b = alpha_at(t, i + 1);
        double u = (l - t->l[i]) / (t->l[i + 1] - t->l[i]);
        *alpha = a + u * (b - a);
    }
    if (*alpha < 0) *alpha = 0;       /* t = 1 printed: -log(1) = -0 */
    return PX_OK;
}
