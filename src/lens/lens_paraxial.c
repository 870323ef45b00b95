/* lens_paraxial.c -- the bridge from the lens model to the paraxial engine: the
 * lens as px_csurf surfaces (for px_colour_run, px_seidel_run) and as a px_system
 * at one wavelength, and a folded lens (mirrors) unfolded.  Paraxial optics sees only
 * the vertex curvature (plus an asphere's r^2 term); semi-diameters, conics and
 * higher terms are for the tracer. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "lens.h"
#include "paraxial/paraxial.h"

/* The glass string px_glass_index takes for medium i (-1: object): the lens's own,
 * "AIR" for air, or the file's nd/vd as a model (or constant) glass in buf. */
static const char *glass_name(const ln_lens *l, int i, char *buf)
{
    const char *g = i < 0 ? l->obj_glass : l->surf[i].glass;
    double nd = i < 0 ? l->obj_nd : l->surf[i].nd, vd = i < 0 ? l->obj_vd : l->surf[i].vd;
    double n;
    if (!g[0]) return "AIR";
    if (nd > 1 && px_glass_index(g, PX_LAMBDA_D, &n) == PX_NO_GLASS) {
        char a[32], b[32];
        ln_format(nd, a, sizeof a);
        ln_format(vd, b, sizeof b);
        if (vd == 0 || isinf(vd)) snprintf(buf, LN_NAME_MAX, "%s", a);
        else snprintf(buf, LN_NAME_MAX, "%s/%s", a, b);
        return buf;
    }
    return g;
}

static double paraxial_radius(const ln_surface *s)
{
    double c = ln_paraxial_curvature(s);
    return c == 0 ? INFINITY : 1 / c;
}

int ln_mirrors(const ln_lens *l)
{
    int k = 0;
    for (int i = 0; i < l->nsurf; i++) k += l->surf[i].mirror != 0;
    return k;
}

int ln_breaks(const ln_lens *l)
{
    int k = 0;
    for (int i = 0; i < l->nsurf; i++) k += l->surf[i].coordbrk != 0;
    return k;
}

int ln_unfold(const ln_lens *l, ln_lens *out, int **map, char *err, size_t cap)
{
    int sigma = 1, *m = NULL, k = 0;
    ln_init(out);
    if (map) *map = NULL;
    if (ln_copy(out, l) != LN_OK) { snprintf(err, cap, "out of memory"); return LN_NOMEM; }
    out->nsurf = 0;                            /* rebuilt below (the arrays are out's own) */
    if (map && !(m = malloc(sizeof *m * (size_t)(2 * l->nsurf + 1)))) goto nomem;
    for (int i = 0; i < l->nsurf; i++) {
        ln_surface s = l->surf[i], *d;
        if (s.coordbrk) {               /* the on-axis part: nothing; t joins the gap */
            if (k) out->surf[k - 1].t += s.t * sigma;
            else if (isfinite(out->object)) out->object += s.t;
            if (l->stop == i) out->stop = -1;
            continue;
        }
        if (s.mirror) {
            const char *before = i ? l->surf[i - 1].glass : l->obj_glass;
            double c = ln_paraxial_curvature(&s) * sigma;
            if (before[0] && strcasecmp(before, "AIR")) {
                snprintf(err, cap, "surface %d: a mirror in %s (a Mangin mirror): the "
                         "unfolded equivalent would need a medium of index 2n at every "
                         "wavelength; mirrors in air only", i + 1, before);
                goto bad;
            }
            if (!(d = ln_add_surface(out))) goto nomem;   /* radius -R/2 into index 2 */
            memset(d, 0, sizeof *d);
            d->type = LN_STANDARD;
            ln_set_curvature(d, -2 * c);
            strcpy(d->glass, "2");
            d->semi = s.semi;
            d->line = s.line;
            if (m) m[k] = i;
            k++;
            if (!(d = ln_add_surface(out))) goto nomem;   /* the plane back into air */
            memset(d, 0, sizeof *d);
            d->type = LN_STANDARD;
            ln_set_curvature(d, 0);
            d->line = s.line;
            sigma = -sigma;
            d->t = s.t * sigma;
            if (l->stop == i) out->stop = k - 1;
            if (m) m[k] = i;
            k++;
            continue;
        }
        if (!(d = ln_add_surface(out))) goto nomem;
        *d = s;
        if (sigma < 0) {                            /* z mirrored */
            ln_set_curvature(d, -s.c);
            d->by_curvature = s.by_curvature;
            if (!s.by_curvature) d->r = -s.r;
            for (int j = 0; j < d->nasph; j++) d->asph[j] = -s.asph[j];
            d->t = -s.t;
        }
        if (l->stop == i) out->stop = k;
        if (m) m[k] = i;
        k++;
    }
    if (sigma < 0) out->image_c = -l->image_c;
    if (map) *map = m;
    return LN_OK;
nomem:
    snprintf(err, cap, "out of memory");
    free(m);
    ln_free(out);
    return LN_NOMEM;
bad:
    free(m);
    ln_free(out);
    return LN_BAD;
}

int ln_to_csurf(const ln_lens *l, struct px_csurf *out, char (*names)[LN_NAME_MAX],
                const char **obj_glass, char *err, size_t cap)
{
    if (l->nsurf < 1) { snprintf(err, cap, "no surface"); return LN_BAD; }
    for (int i = 0; i < l->nsurf; i++)
        if (l->surf[i].coordbrk) {
            snprintf(err, cap, "surface %d is a coordinate break: pupils, colour and "
                     "Seidel sums take the lens without it (ln_unfold)", i + 1);
            return LN_BAD;
        }
    for (int i = 0; i < l->nsurf; i++)
        if (l->surf[i].mirror) {
            snprintf(err, cap, "surface %d is a mirror: pupils, colour and Seidel sums "
                     "here take refracting surfaces only (the lens's first-order data, "
                     "unfolded: --prescription)", i + 1);
            return LN_BAD;
        }
    for (int i = 0; i < l->nsurf; i++) {
        out[i].r = paraxial_radius(&l->surf[i]);
        out[i].t = l->surf[i].t;
        out[i].glass = glass_name(l, i, names[i]);
    }
    *obj_glass = glass_name(l, -1, names[l->nsurf]);
    return LN_OK;
}

int ln_paraxial(const ln_lens *l, double lambda, struct px_system *s, char *err,
                size_t cap)
{
    double n;
    char why[LN_ERR_MAX];
    int r;
    if (l->nsurf < 1) { snprintf(err, cap, "no surface"); return LN_BAD; }
    if (ln_mirrors(l) || ln_breaks(l)) {
        ln_lens u;
        if ((r = ln_unfold(l, &u, NULL, err, cap)) != LN_OK) return r;
        r = ln_paraxial(&u, lambda, s, err, cap);
        ln_free(&u);
        return r;
    }
    if (ln_index(l, -1, lambda, &n, NULL, why, sizeof why)) {
        snprintf(err, cap, "the object medium: %s", why);
        return LN_BAD;
    }
    px_system_init(s, n);
    for (int i = 0; i < l->nsurf; i++) {
        if (ln_index(l, i, lambda, &n, NULL, why, sizeof why)) {
            snprintf(err, cap, "surface %d: %s", i + 1, why);
            return LN_BAD;
        }
        if (i > 0 && (r = px_system_gap(s, l->surf[i - 1].t)) != PX_OK) {
            snprintf(err, cap, "surface %d: thickness %g %s", i, l->surf[i - 1].t,
                     r == PX_NOMEM ? "(out of memory)" : "is negative or not finite");
            return r == PX_NOMEM ? LN_NOMEM : LN_BAD;
        }
        if ((r = px_system_surface(s, paraxial_radius(&l->surf[i]), n)) != PX_OK) {
            snprintf(err, cap, "surface %d: %s", i + 1,
                     r == PX_NOMEM ? "out of memory" : "not a surface");
            return r == PX_NOMEM ? LN_NOMEM : LN_BAD;
        }
    }
    return LN_OK;
}
