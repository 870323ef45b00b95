/* ds_setup.c -- one evaluation's set-up of the lens per wavelength: first-order pupils
 * by the paraxial engine from the lens unfolded (ln_unfold: mirrors as refracting
 * pairs, coordinate breaks as zero), and the trace engine's rx of the lens as it is,
 * folded (mirrors reflect, breaks turn the frame), with a coordinate break and its
 * inverse around every surface or element a tolerance tilts or decentres.
 *
 * A perturbed group s0..s1 (ds_grp): before s0, a break at s0's vertex (order 0:
 * decentre x, y, then tilt about x, then about the new y: OpticStudio's TSDX/TSTX for
 * a surface, TEDX/TETX for an element, pivoting on its first vertex); after s1 the
 * same break inverted (order 1, every value negated, at the same z: undone exactly,
 * tr_aim.c), so the surfaces after it are where they were.  Groups nest or stand
 * apart (ds_read refuses overlaps): outer ones open first and close last.  A group
 * at zero adds nothing, so the nominal lens traces bit for bit as without. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "ds_int.h"

static int index_at(const ds_problem *p, const ln_lens *l, int i, double lambda, double *n,
                    char *why, size_t cap)
{
    if (ln_index(l, i, lambda, n, NULL, why, cap) != LN_OK) return -1;
    *n += p->dn[i + 1];
    if (!(*n > 0)) {
        snprintf(why, cap, "surface %d: the index is not positive", i + 1);
        return -1;
    }
    return 0;
}

static int active(const ds_problem *p, int g)
{
    const double *v = p->gp[g];
    return v[0] != 0 || v[1] != 0 || v[2] != 0 || v[3] != 0;
}

/* The rx of lens l at x (x->n filled): surfaces with the break pairs. */
static int build_rx(ds_problem *p, const ln_lens *l, ds_wl *x, char *why, size_t cap)
{
    double z = 0, zs[DS_MAXSURF];
    int m = 0, ri_stop = 0, sig = 1;
    for (int i = 0; i < l->nsurf; i++) {
        const ln_surface *s = &l->surf[i];
        zs[i] = z;
        /* groups starting here: the longest (outermost) first */
        for (int e = l->nsurf - 1; e >= i; e--)
            for (int g = 0; g < p->ngrp; g++) {
                if (p->grp[g].s0 != i || p->grp[g].s1 != e || !active(p, g)) continue;
                trace_rx_surface *b = &x->surf[m++];
                memset(b, 0, sizeof *b);
                b->coordbrk = 1;
                b->z = z;
                b->decenter[0] = p->gp[g][0];
                b->decenter[1] = p->gp[g][1];
                b->tilt[0] = p->gp[g][2];
                b->tilt[1] = p->gp[g][3];
                b->n_right = x->n[i];
            }
        trace_rx_surface *t = &x->surf[m];
        memset(t, 0, sizeof *t);
        if (i == l->stop) ri_stop = m;
        m++;
        t->z = z;
        t->radius = isfinite(s->r) ? s->r : 0;
        t->conic = s->conic;
        t->nasph = s->type == LN_EVENASPH ? (s->nasph < TRACE_MAXASPH ? s->nasph
                                                                     : TRACE_MAXASPH) : 0;
        for (int j = 0; j < t->nasph; j++) t->asph[j] = s->asph[j];
        t->n_right = x->n[i + 1];
        t->semi_diameter = 0;       /* no vignetting while designing */
        t->mirror = s->mirror;
        t->coordbrk = s->coordbrk;
        t->order = s->cb_order;
        t->decenter[0] = s->cb_dec[0];
        t->decenter[1] = s->cb_dec[1];
        for (int k = 0; k < 3; k++) t->tilt[k] = s->cb_tilt[k];
        /* groups ending here: the shortest (innermost) first, each at its own s0 */
        for (int b0 = i; b0 >= 0; b0--)
            for (int g = 0; g < p->ngrp; g++) {
                if (p->grp[g].s1 != i || p->grp[g].s0 != b0 || !active(p, g)) continue;
                trace_rx_surface *b = &x->surf[m++];
                memset(b, 0, sizeof *b);
                b->coordbrk = 1;
                b->order = 1;
                b->z = zs[b0];
                b->decenter[0] = -p->gp[g][0];
                b->decenter[1] = -p->gp[g][1];
                b->tilt[0] = -p->gp[g][2];
                b->tilt[1] = -p->gp[g][3];
                b->n_right = x->n[i + 1];
            }
        if (s->mirror) sig = -sig;
        if (i + 1 < l->nsurf) {
            if (!(s->t * sig >= 0)) {
                snprintf(why, cap, "surface %d: thickness %g runs against the light", i + 1,
                         s->t);
                return -1;
            }
            z += s->t;
        }
    }
    x->rx.n_object = x->n[0];
    x->rx.nsurf = m;
    x->rx.surf = x->surf;
    x->rx.stop = ri_stop;
    x->rx.z_image = NAN;
    x->zl = z;
    x->sig = sig;
    return 0;
}

/* Is the rx symmetric under x -> -x (a field in the y-z plane may then be traced on
 * one half of the pupil)?  Not when a break decentres in x or turns about y or z. */
static int x_symmetric(const ds_problem *p, const ln_lens *l)
{
    for (int i = 0; i < l->nsurf; i++) {
        const ln_surface *s = &l->surf[i];
        if (s->coordbrk && (s->cb_dec[0] != 0 || s->cb_tilt[1] != 0 || s->cb_tilt[2] != 0))
            return 0;
    }
    for (int g = 0; g < p->ngrp; g++)
        if (p->gp[g][0] != 0 || p->gp[g][3] != 0) return 0;
    return 1;
}

static int setup(ds_problem *p, const ln_lens *l, const ln_lens *u, const int *map, ds_wl *w,
                 int nwl, char *why, size_t cap)
{
    double z_prim_stop = 0;
    for (int k = 0; k < nwl; k++) {
        ds_wl *x = &w[k];
        x->lambda = l->nwl ? l->wl[k] : ln_primary(l);
        x->index = k;
        if (index_at(p, l, -1, x->lambda, &x->n[0], why, cap)) return -1;
        for (int i = 0; i < l->nsurf; i++)
            if (index_at(p, l, i, x->lambda, &x->n[i + 1], why, cap)) return -1;
        /* first order: the unfolded lens; a mirror's first half is the medium of index
         * 2 (no tolerance), the rest each carry their folded surface's offset */
        snprintf(x->names[0], sizeof x->names[0], "%.17g", x->n[0]);
        x->zl_u = 0;
        for (int i = 0; i < u->nsurf; i++) {
            const ln_surface *s = &u->surf[i];
            double c = ln_paraxial_curvature(s), n;
            if (map) {
                int f = map[i], half = l->surf[f].mirror && (i == 0 || map[i - 1] != f);
                if (ln_index(u, i, x->lambda, &n, NULL, why, cap) != LN_OK) return -1;
                if (!half) n += p->dn[f + 1];
            } else {
                n = x->n[i + 1];
            }
            snprintf(x->names[i + 1], sizeof x->names[i + 1], "%.17g", n);
            x->cs[i].r = c == 0 ? INFINITY : 1 / c;
            x->cs[i].t = s->t;
            x->cs[i].glass = x->names[i + 1];
            if (i + 1 < u->nsurf) {
                if (!(s->t >= 0)) {
                    snprintf(why, cap, "surface %d: negative thickness %g",
                             (map ? map[i] : i) + 1, s->t);
                    return -1;
                }
                x->zl_u += s->t;
            }
        }
        x->nu = u->nsurf;
        x->stop_u = u->stop < 0 ? 0 : u->stop;
        px_pupil_in in = {x->cs, u->nsurf, x->stop_u, x->names[0], x->lambda, PX_AP_EPD,
                          l->ap_value, isinf(l->object) ? INFINITY : l->object,
                          isinf(l->object) ? 45 : 1};
        in.aperture = l->ap_kind == LN_AP_FNUM ? PX_AP_FNUM :
                      l->ap_kind == LN_AP_NA ? PX_AP_NA : PX_AP_EPD;
        if (l->ap_kind == LN_AP_NONE) { in.aperture = PX_AP_EPD; in.ap_value = 1; }
        if (px_pupil_run(&in, &x->p) != PX_OK) {
            snprintf(why, cap, "%s", x->p.why);
            return -1;
        }
        if (k == 0) z_prim_stop = x->p.r_stop;
        x->s = z_prim_stop / x->p.r_stop;
        if (build_rx(p, l, x, why, cap)) return -1;
        x->rx.stop_radius = z_prim_stop;
    }
    return 0;
}

int ds_setup(ds_problem *p, const ln_lens *l, ds_wl *w, int nwl, char *why, size_t cap)
{
    int rc;
    if (l->stop >= 0 && l->surf[l->stop].coordbrk) {
        snprintf(why, cap, "surface %d: a coordinate break cannot be the stop", l->stop + 1);
        return -1;
    }
    p->xsym = x_symmetric(p, l);
    if (!ln_mirrors(l) && !ln_breaks(l)) return setup(p, l, l, NULL, w, nwl, why, cap);
    ln_lens u;
    int *map = NULL;
    if (ln_unfold(l, &u, &map, why, cap) != LN_OK) return -1;
    if (u.nsurf > DS_MAXSURF) {
        snprintf(why, cap, "%d surfaces unfolded: at most %d", u.nsurf, DS_MAXSURF);
        rc = -1;
    } else {
        rc = setup(p, l, &u, map, w, nwl, why, cap);
    }
    ln_free(&u);
    free(map);
    return rc;
}

double ds_image_z(const ln_lens *l, const ds_wl *prim)
{
    double t = l->surf[l->nsurf - 1].t;
    if (t * prim->sig > 0) return prim->zl + t;
    return prim->zl + prim->sig * (prim->p.z_img - prim->zl_u);
}
