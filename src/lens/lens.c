/* lens.c -- the lens model itself: making and freeing a lens, radius and curvature,
 * the index of a surface's medium (through the paraxial engine's catalogue), sags,
 * the consistency check, and the shortest round-trip number text the writers use. */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "lens.h"
#include "paraxial/paraxial.h"

void ln_init(ln_lens *l)
{
    memset(l, 0, sizeof *l);
    strcpy(l->unit, "mm");
    l->object = INFINITY;
    l->nearpoint = 25;
    l->stop = -1;
    l->field_kind = LN_FIELD_ANGLE;
}

void ln_free(ln_lens *l)
{
    free(l->surf);
    free(l->planes);
    ln_init(l);
}

int ln_copy(ln_lens *dst, const ln_lens *src)
{
    ln_lens t = *src;
    t.surf = NULL;
    t.planes = NULL;
    t.cap = 0;
    if (src->nsurf) {
        if (!(t.surf = malloc((size_t)src->nsurf * sizeof *t.surf))) return LN_NOMEM;
        memcpy(t.surf, src->surf, (size_t)src->nsurf * sizeof *t.surf);
        t.cap = src->nsurf;
    }
    if (src->nplanes) {
        if (!(t.planes = malloc((size_t)src->nplanes * sizeof *t.planes))) {
            free(t.surf);
            return LN_NOMEM;
        }
        memcpy(t.planes, src->planes, (size_t)src->nplanes * sizeof *t.planes);
    }
    *dst = t;
    return LN_OK;
}

ln_surface *ln_add_surface(ln_lens *l)
{
    ln_surface *s;
    if (l->nsurf == l->cap) {
        int cap = l->cap ? 2 * l->cap : 8;
        if (l->cap > (1 << 20)) return NULL;            /* no lens has a million surfaces */
        if (!(s = realloc(l->surf, (size_t)cap * sizeof *s))) return NULL;
        l->surf = s;
        l->cap = cap;
    }
    s = &l->surf[l->nsurf++];
    memset(s, 0, sizeof *s);
    s->type = LN_STANDARD;
    s->r = INFINITY;
    return s;
}

int ln_add_plane(ln_lens *l, double z)
{
    double *p;
    if (!(l->nplanes & (l->nplanes - 1))) {             /* 0, 1, 2, 4...: grow */
        if (l->nplanes > (1 << 20)) return LN_NOMEM;
        if (!(p = realloc(l->planes, (size_t)(l->nplanes ? 2 * l->nplanes : 1) * sizeof *p)))
            return LN_NOMEM;
        l->planes = p;
    }
    l->planes[l->nplanes++] = z;
    return LN_OK;
}

void ln_set_radius(ln_surface *s, double r)
{
    if (r == 0 || isinf(r)) { s->r = INFINITY; s->c = 0; }
    else { s->r = r; s->c = 1 / r; }
    s->by_curvature = 0;
}

void ln_set_curvature(ln_surface *s, double c)
{
    if (c == 0) { s->c = 0; s->r = INFINITY; }
    else { s->c = c; s->r = 1 / c; }
    if (isinf(s->r)) s->r = INFINITY;                   /* a subnormal curvature */
    s->by_curvature = 1;
}

double ln_primary(const ln_lens *l) { return l->nwl ? l->wl[0] : PX_LAMBDA_D; }

double ln_paraxial_curvature(const ln_surface *s)
{
    return s->c + (s->type == LN_EVENASPH && s->nasph > 0 ? 2 * s->asph[0] : 0);
}

int ln_index(const ln_lens *l, int i, double lambda, double *n, int *fallback,
             char *why, size_t cap)
{
    const char *g = i < 0 ? l->obj_glass : l->surf[i].glass;
    double nd = i < 0 ? l->obj_nd : l->surf[i].nd, vd = i < 0 ? l->obj_vd : l->surf[i].vd;
    int r;
    if (fallback) *fallback = 0;
    if (!g[0]) { *n = 1; return LN_OK; }                 /* air */
    r = px_glass_index(g, lambda, n);
    if (r == PX_OK) return LN_OK;
    if (r == PX_NO_GLASS && nd > 1) {
        if (fallback) *fallback = 1;
        if (vd == 0 || isinf(vd)) { *n = nd; return LN_OK; }
        r = px_glass_model(nd, vd, lambda, n);
        if (r == PX_OK) return LN_OK;
        if (r == PX_GLASS_RANGE)
            snprintf(why, cap, "glass %s (model %.6g/%.4g) has no index at %.6g um "
                     "(a model glass holds from 0.36 to 1 um)", g, nd, vd, lambda);
        else snprintf(why, cap, "glass %s: nd %.6g, Vd %.4g is not a model glass "
                      "(1 < nd < 3, 5 <= Vd <= 150)", g, nd, vd);
        return LN_BAD;
    }
    if (r == PX_GLASS_RANGE) {
        const px_glass_rec *rec = px_glass_find(g);
        if (rec) snprintf(why, cap, "%s's formula holds from %g to %g um, not at %.6g um",
                          rec->name, rec->lmin, rec->lmax, lambda);
        else snprintf(why, cap, "glass %s has no index at %.6g um (a model glass holds "
                      "from 0.36 to 1 um)", g, lambda);
    } else if (r == PX_NO_GLASS) {
        snprintf(why, cap, "glass %s is neither in the catalogue (data/glass.txt) nor a "
                 "model glass ND/VD nor a number", g);
    } else snprintf(why, cap, "wavelength %.6g um is not a wavelength", lambda);
    return LN_BAD;
}

double ln_sag(const ln_surface *s, double h)
{
    double c = s->c, h2 = h * h, q = 1 - (1 + s->conic) * c * c * h2, z, p;
    if (q < 0) return NAN;
    z = c * h2 / (1 + sqrt(q));
    if (s->type == LN_EVENASPH) {
        p = h2;
        for (int i = 0; i < s->nasph && i < LN_ASPH_MAX; i++, p *= h2) z += s->asph[i] * p;
    }
    return z;
}

static int fail(char *err, size_t cap, const char *src, long line, const char *fmt,
                const char *a, double v)
{
    char why[LN_ERR_MAX];
    snprintf(why, sizeof why, fmt, a, v);
    if (line > 0) snprintf(err, cap, "%s:%ld: %s", src, line, why);
    else snprintf(err, cap, "%s: %s", src, why);
    return LN_BAD;
}

int ln_check(const ln_lens *l, const char *src, char *err, size_t cap)
{
    char why[LN_ERR_MAX], which[64];
    double n;
    if (l->nsurf < 1) return fail(err, cap, src, 0, "%sno surface", "", 0);
    if (l->stop >= l->nsurf) return fail(err, cap, src, 0, "%sthe stop is surface %g, "
                                         "past the last", "", l->stop + 1);
    if (isnan(l->object)) return fail(err, cap, src, 0, "%sthe object distance is not "
                                      "a number", "", 0);
    for (int w = -1; w < l->nwl; w++) {
        double lambda = w < 0 ? ln_primary(l) : l->wl[w];
        if (w >= 0 && !(lambda > 0 && isfinite(lambda)))
            return fail(err, cap, src, 0, "%swavelength %g is not a wavelength", "", lambda);
        for (int i = -1; i < l->nsurf; i++)
            if (ln_index(l, i, lambda, &n, NULL, why, sizeof why) != LN_OK) {
                long line = i < 0 ? 0 : l->surf[i].line;
                if (i < 0) snprintf(which, sizeof which, "the object medium");
                else snprintf(which, sizeof which, "surface %d", i + 1);
                if (line > 0) snprintf(err, cap, "%s:%ld: %s: %s", src, line, which, why);
                else snprintf(err, cap, "%s: %s: %s", src, which, why);
                return LN_BAD;
            }
    }
    for (int i = 0, sigma = 1; i < l->nsurf; i++) {
        const ln_surface *s = &l->surf[i];
        if (s->coordbrk && (s->mirror || i == l->stop || (s->cb_order != 0 && s->cb_order != 1) ||
                            !isfinite(s->cb_dec[0]) || !isfinite(s->cb_dec[1]) ||
                            !isfinite(s->cb_tilt[0]) || !isfinite(s->cb_tilt[1]) ||
                            !isfinite(s->cb_tilt[2])))
            return fail(err, cap, src, s->line, "%sa coordinate break (surface %g) needs "
                        "finite decentres and tilts, order 0 or 1, and is neither a mirror "
                        "nor the stop", "", i + 1);
        if (s->mirror) {
            const char *before = i ? l->surf[i - 1].glass : l->obj_glass;
            sigma = -sigma;
            if (before[0] && strcasecmp(before, "AIR")) {
                snprintf(why, sizeof why, "a mirror in %s (a Mangin mirror) is not supported: "
                         "mirrors in air only", before);
                return fail(err, cap, src, s->line, "%s", why, 0);
            }
            if (s->glass[0] && strcasecmp(s->glass, "AIR")) {
                snprintf(why, sizeof why, "%s: a mirror sends the light back into the medium "
                         "it came from (air), not into a glass", s->glass);
                return fail(err, cap, src, s->line, "%s", why, 0);
            }
        }
        if (!isfinite(s->t) || (sigma > 0 ? !(s->t >= 0) : !(s->t <= 0)))
            return fail(err, cap, src, s->line, sigma > 0 ? "%sthe thickness %g is negative "
                        "or not finite (light travels toward +z here)" : "%sthe thickness %g "
                        "is positive or not finite (after an odd number of mirrors light "
                        "travels toward -z: thicknesses are negative)", "", s->t);
        if (isnan(s->r) || isnan(s->c) || isnan(s->conic) || !(s->semi >= 0) ||
            !isfinite(s->semi) || !isfinite(s->conic))
            return fail(err, cap, src, s->line, "%sa value of surface %g is not a number",
                        "", i + 1);
        for (int k = 0; k < s->nasph; k++)
            if (!isfinite(s->asph[k]))
                return fail(err, cap, src, s->line, "%san aspheric term of surface %g is "
                            "not finite", "", i + 1);
    }
    if (l->ap_kind != LN_AP_NONE && !(l->ap_value > 0 && isfinite(l->ap_value)))
        return fail(err, cap, src, 0, "%sthe aperture %g must be a positive number", "",
                    l->ap_value);
    if (l->ap_kind == LN_AP_NA && ln_index(l, -1, ln_primary(l), &n, NULL, why, sizeof why) ==
        LN_OK && !(l->ap_value < n))
        return fail(err, cap, src, 0, "%sthe numerical aperture %g is not below the object "
                    "medium's index", "", l->ap_value);
    for (int w = 0; w < l->nwl; w++)
        if (!(l->wl_weight[w] >= 0) || !isfinite(l->wl_weight[w]))
            return fail(err, cap, src, 0, "%sthe weight of wavelength %g must be a number "
                        ">= 0", "", w + 1);
    for (int f = 0; f < l->nfield; f++)
        if (!(l->field[f].weight >= 0) || !isfinite(l->field[f].weight))
            return fail(err, cap, src, 0, "%sthe weight of field %g must be a number >= 0",
                        "", f + 1);
    for (int f = 0; f < l->nfield; f++)
        if (!isfinite(l->field[f].x) || !isfinite(l->field[f].y) ||
            (l->field_kind == LN_FIELD_ANGLE &&
             (fabs(l->field[f].x) >= 90 || fabs(l->field[f].y) >= 90)))
            return fail(err, cap, src, 0, "%sfield %g is not finite (angles: under 90 "
                        "degrees)", "", f + 1);
    return LN_OK;
}

void ln_format(double v, char *buf, size_t cap)
{
    int p, e;
    char fixed[64];
    if (isnan(v)) { snprintf(buf, cap, "nan"); return; }
    if (isinf(v)) { snprintf(buf, cap, v > 0 ? "inf" : "-inf"); return; }
    for (p = 1; p < 17; p++) {
        snprintf(buf, cap, "%.*g", p, v);
        if (strtod(buf, NULL) == v) break;
    }
    if (p == 17) snprintf(buf, cap, "%.17g", v);
    /* 1e+01 reads back, but a designer writes 10: plain decimals for exponents a
     * table would print without one */
    if (!strchr(buf, 'e') || v == 0) return;
    e = (int)floor(log10(fabs(v)));
    if (e < -5 || e >= 16) return;
    snprintf(fixed, sizeof fixed, "%.*f", p - 1 - e > 0 ? p - 1 - e : 0, v);
    if (strtod(fixed, NULL) == v && strlen(fixed) <= strlen(buf)) strcpy(buf, fixed);
}

void ln_format_radius(const ln_surface *s, char *buf, size_t cap)
{
    double r = s->r, c = s->c, tol = 1e-14 * fabs(c);
    if (isinf(r) || r == 0) { snprintf(buf, cap, "plane"); return; }
    for (int p = 1; p <= 17; p++) {
        char t[40];
        double v;
        snprintf(t, sizeof t, "%.*g", p, r);
        v = strtod(t, NULL);
        if (v == r || (s->by_curvature && fabs(1 / v - c) <= tol)) {
            ln_format(v, buf, cap);
            return;
        }
    }
    ln_format(r, buf, cap);
}

void ln_notes_free(ln_notes *n)
{
    free(n->s);
    memset(n, 0, sizeof *n);
}
