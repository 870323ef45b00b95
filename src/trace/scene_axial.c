/* scene_axial.c -- checks of a parsed scene's axial surfaces along one axis: two
 * consecutive surfaces whose sags cross inside their apertures are refused (naming
 * both FILE:LINEs, the height and the edge thickness), and neighbours whose media
 * disagree are counted and located for the mismatch warning. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "scene_int.h"

/* ---- axial surfaces along one axis: crossing sags, media that disagree ---------
 * Caps, conics and aspheres whose axes lie on one line are taken in order along it
 * (ties in file order).  Two consecutive ones must not cross within the smaller
 * aperture (negative edge thickness: refused), and when both refract, the index one
 * gives the space between them should be the one the other expects: a disagreement
 * is counted, and the first is kept for the message after the trace (scene.h). */

#define AXMAX 4096          /* beyond this many axial surfaces the pairs are not checked */

static double axial_sag(const sc_surface *f, double s)
{
    double c = f->radius != 0 ? 1 / f->radius : 0, s2 = s * s, q;
    q = 1 - (1 + f->conic) * c * c * s2;
    double z = c * s2 / (1 + sqrt(q > 0 ? q : 0)), p = s2;
    for (int i = 0; i < f->ncoef; i++) {
        z += f->coef[i] * p;
        p *= s2;
    }
    return z;
}

typedef struct axm {
    const sc_surface *f;
    double u, sign;         /* vertex position along the line; axis . direction */
} axm;

static int axm_cmp(const void *x, const void *y)
{
    const axm *a = x, *b = y;
    if (a->u != b->u) return a->u < b->u ? -1 : 1;
    return a->f < b->f ? -1 : a->f > b->f;      /* file order */
}

/* Position along the line of member m at height s. */
static double axm_pos(const axm *m, double s) { return m->u + m->sign * axial_sag(m->f, s); }

/* The pair a, b (a first along the line): 0, or -1 with err if their sags cross. */
static int axm_cross(const axm *a, const axm *b, char *err)
{
    enum { N = 64 };
    double smax = fmin(a->f->aperture, b->f->aperture), prev = 0, t = 0;
    double scale = fabs(a->u) + fabs(b->u) + smax;
    if (!(smax > 0)) return 0;
    for (int i = 1; i <= N; i++) {
        double s = smax * i / N;
        t = axm_pos(b, s) - axm_pos(a, s);
        if (t < -1e-12 * scale) {
            double lo = prev, hi = s;       /* t(lo) >= -tol > t(hi) */
            for (int k = 0; k < 100 && lo < hi; k++) {
                double mid = 0.5 * (lo + hi);
                if (!(mid > lo && mid < hi)) break;
                if (axm_pos(b, mid) - axm_pos(a, mid) < 0) hi = mid; else lo = mid;
            }
            double rim = axm_pos(b, smax) - axm_pos(a, smax);
            snprintf(err, SC_ERRMAX, "%s:%ld: and %s:%ld: the surfaces cross at height "
                     "%.6g from their axis (edge thickness %.6g at %.6g): negative edge "
                     "thickness", a->f->src, a->f->line, b->f->src, b->f->line,
                     b->u == a->u ? 0.0 : lo, rim < t ? rim : t, rim < t ? smax : s);
            return -1;
        }
        prev = s;
    }
    return 0;
}

/* The media of the pair a, b: the index a leaves on b's side, b on a's. */
static void axm_media(sc_scene *sc, const axm *a, const axm *b)
{
    if (a->f->kind != SC_REFRACT || b->f->kind != SC_REFRACT) return;
    double na = a->sign > 0 ? a->f->n2 : a->f->n1, nb = b->sign > 0 ? b->f->n1 : b->f->n2;
    if (!(fabs(na - nb) > 1e-9 * na)) return;
    if (!sc->nmismatch++)
        snprintf(sc->mismatch_where, sizeof sc->mismatch_where, "%s:%ld: gives %.10g "
                 "after it, %s:%ld: expects %.10g before it", a->f->src, a->f->line, na,
                 b->f->src, b->f->line, nb);
}

int sc_axial_pairs(sc_scene *sc, char *err)
{
    int n = 0, rc = 0;
    for (int i = 0; i < sc->nsurf; i++)
        n += sc->surf[i].shape >= SC_CAP && sc->surf[i].shape <= SC_ASPHERE;
    if (n < 2 || n > AXMAX) return 0;
    axm *m = malloc((size_t)n * sizeof *m);
    char *used = calloc((size_t)n, 1);
    const sc_surface **ax = malloc((size_t)n * sizeof *ax);
    if (!m || !used || !ax) { free(m); free(used); free(ax); return 0; }
    n = 0;
    for (int i = 0; i < sc->nsurf; i++)
        if (sc->surf[i].shape >= SC_CAP && sc->surf[i].shape <= SC_ASPHERE)
            ax[n++] = &sc->surf[i];
    for (int i = 0; i < n && !rc; i++) {
        const sc_surface *a = ax[i];
        if (used[i]) continue;
        int k = 0;
        for (int j = i; j < n; j++) {               /* the surfaces on a's axis line */
            const sc_surface *b = ax[j];
            if (used[j]) continue;
            double dot = dot3(a->axis, b->axis), w[3], x[3];
            if (!(fabs(dot) > 1 - 1e-12)) continue;
            sub3(b->at, a->at, w);
            cross3(w, a->axis, x);
            double off = sqrt(dot3(x, x)), scale = sqrt(dot3(w, w)) + a->aperture;
            if (!(off <= 1e-12 * scale)) continue;
            used[j] = 1;
            m[k].f = b;
            m[k].u = dot3(w, a->axis);
            m[k].sign = dot > 0 ? 1 : -1;
            k++;
        }
        qsort(m, (size_t)k, sizeof *m, axm_cmp);
        for (int j = 1; j < k && !rc; j++) {
            rc = axm_cross(&m[j - 1], &m[j], err);
            if (!rc) axm_media(sc, &m[j - 1], &m[j]);
        }
    }
    free(m);
    free(used);
    free(ax);
    return rc;
}
