/* lens_shape.c -- can the lens be made: every surface reaches its semi-diameter (a
 * sphere of radius 20 has no zone at height 25) and no two neighbouring surfaces
 * cross inside the zone both of them cover (the glass, or the air, between them
 * would have a negative thickness there).  One check, called by every reader of a
 * lens file (ln_check) and by every dialogue that takes semi-diameters from its own
 * question, so the message is the same wherever the lens is entered. */
#include <math.h>
#include <stdio.h>
#include "lens.h"

/* The sag, allowing the rounding of a hemisphere (semi = |r|). */
static double sag(const ln_surface *s, double h)
{
    double z = ln_sag(s, h);
    if (isnan(z) && s->conic == 0 && s->type == LN_STANDARD && s->c != 0 &&
        h <= fabs(1 / s->c) * (1 + 1e-12))
        z = 1 / s->c;            /* the hemisphere's rim: sag = r */
    return z;
}

static double gap(const ln_surface *a, double za, const ln_surface *b, double zb,
                  double h)
{
    return (zb + sag(b, h)) - (za + sag(a, h));
}

int ln_shape_check(const ln_surface *s, const double *z, int n, int *bad, char *why,
                   size_t cap)
{
    double scale = 0;
    for (int i = 0; i < n; i++) {
        scale = fmax(scale, fabs(z[i]));
        scale = fmax(scale, s[i].semi);
    }
    for (int i = 0; i < n; i++) {
        double h = s[i].semi;
        if (!(h > 0)) continue;
        if (isnan(sag(&s[i], h))) {
            char semi[40], r[40];
            ln_format(h, semi, sizeof semi);
            if (s[i].conic == 0 && s[i].type == LN_STANDARD)
                snprintf(why, cap, "surface %d has radius %.10g, so its semi-diameter "
                         "can be at most %.10g (not %s)", i + 1, 1 / s[i].c,
                         fabs(1 / s[i].c), semi);
            else {
                ln_format(s[i].conic, r, sizeof r);
                snprintf(why, cap, "surface %d: the semi-diameter %s: the surface (conic "
                         "%s) has no point that far from the axis", i + 1, semi, r);
            }
            *bad = i;
            return LN_BAD;
        }
    }
    for (int i = 0; i + 1 < n; i++) {
        const ln_surface *a = &s[i], *b = &s[i + 1];
        double hmax = fmin(a->semi, b->semi), tol = 1e-9 * (scale > 0 ? scale : 1);
        double lo = 0, hi = -1;
        enum { STEPS = 2048 };
        if (!(hmax > 0) || !isfinite(z[i]) || !isfinite(z[i + 1])) continue;
        for (int k = 0; k <= STEPS; k++) {
            double h = hmax * k / STEPS, g = gap(a, z[i], b, z[i + 1], h);
            if (g < -tol) { hi = h; break; }
            lo = h;
        }
        if (hi < 0) continue;
        for (int it = 0; it < 60 && hi - lo > 1e-12 * hmax; it++) {
            double m = 0.5 * (lo + hi);
            if (gap(a, z[i], b, z[i + 1], m) < 0) hi = m;
            else lo = m;
        }
        /* the words of the trace dialogue's own check (tr_lens.c), which also says
         * the largest semi-diameter that can be made */
        snprintf(why, cap, "surfaces %d and %d would cross at height %g (edge thickness "
                 "%g at the semi-diameter %g): give at most %g", i + 1, i + 2,
                 0.5 * (lo + hi), gap(a, z[i], b, z[i + 1], hmax), hmax, 0.5 * (lo + hi));
        *bad = i + 1;
        return LN_BAD;
    }
    return LN_OK;
}

int ln_check_shape(const ln_lens *l, const char *src, char *err, size_t cap)
{
    double zs[512], *z = zs, pos = 0;
    char why[LN_ERR_MAX];
    int bad = 0, r;
    if (l->nsurf < 1) return LN_OK;
    if (l->nsurf > (int)(sizeof zs / sizeof *zs)) return LN_OK;   /* beyond any lens */
    for (int i = 0; i < l->nsurf; i++) {
        z[i] = pos;
        pos += l->surf[i].t;
    }
    r = ln_shape_check(l->surf, z, l->nsurf, &bad, why, sizeof why);
    if (r == LN_OK) return LN_OK;
    if (l->surf[bad].line > 0) snprintf(err, cap, "%s:%ld: %s", src, l->surf[bad].line, why);
    else snprintf(err, cap, "%s: %s", src, why);
    return LN_BAD;
}
