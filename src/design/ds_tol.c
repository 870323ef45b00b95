/* ds_tol.c -- tolerancing: the criteria of a lens as built (RMS spot after the
 * back-focus compensator, EFL, back focus, the boresight), a tolerance applied alone
 * (sensitivities) and Monte Carlo lenses drawn from every tolerance at once.  Tilts
 * and decentres are offsets of their group (ds_problem.gp) that ds_setup turns into
 * coordinate breaks; first order (EFL, back focus) takes them as zero, as a
 * designer's paraxial data do.
 *
 * The compensator in closed form: rays aimed at the stop do not depend on where the
 * image plane is, and each ray's point on a plane moved by dz is p + dz d (d its
 * direction's slopes), so the field-weighted sum of squared distances from the
 * centroids is a quadratic in dz; its minimum is dz = -sum q a.b / sum q b.b with a
 * the point's offset from its centroid and b the slope's from the mean slope.  One
 * trace per lens, no search.
 *
 * Draws: lens k of seed s takes the SplitMix64 stream started at s ^ k * 0xD1B54A32D192ED03
 * (src/common/lm_rand.h), one number per tolerance in file order (two or more for a
 * rejected Gaussian), so lens k is the same whichever job computes it. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "common/lm_rand.h"
#include "ds_int.h"

#define MAXRAY (2 * DS_MAXRING * DS_MAXARM * LN_WL_MAX)

static int crit(ds_problem *p, const ds_tol_opts *o, ds_crit *c)
{
    static ds_wl w[LN_WL_MAX];
    static double pts[2 * MAXRAY], dir[2 * MAXRAY], wt[MAXRAY];
    const ln_lens *l = &p->lens;
    int nwl = l->nwl ? l->nwl : 1;
    char why[256];
    double zi, zlast, sab = 0, sbb = 0, wsum = 0, bp[2], bs[2];
    memset(c, 0, sizeof *c);
    c->rms = c->efl = c->bfd = c->wave = c->bore[0] = c->bore[1] = NAN;
    if (ds_setup(p, l, w, nwl, why, sizeof why)) return DS_OK;
    zlast = w[0].zl_u;
    zi = ds_image_z(l, &w[0]);
    c->efl = w[0].p.efl;
    c->bfd = w[0].p.z_img - zlast;
    if (!l->nfield || l->ap_kind == LN_AP_NONE || !p->tr) return DS_OK;
    /* two passes over the fields: the compensator's sums, then the spots (the rays
     * are kept per field: pts holds one field at a time, so trace twice only when
     * refocusing) */
    double fa[LN_FIELD_MAX], fb[LN_FIELD_MAX], fc[LN_FIELD_MAX];
    for (int f = 0; f < l->nfield; f++) {
        int n = ds_field_rays(p, w, nwl, f, zi, pts, dir, wt, MAXRAY);
        if (n == -2) return DS_STOPPED;
        if (n < 0) return DS_OK;            /* a failed ray: ok stays 0 */
        double cx = 0, cy = 0, dx = 0, dy = 0, q = 0, aa = 0, ab = 0, bb = 0;
        for (int j = 0; j < n; j++) {
            cx += wt[j] * pts[2 * j]; cy += wt[j] * pts[2 * j + 1];
            dx += wt[j] * dir[2 * j]; dy += wt[j] * dir[2 * j + 1];
            q += wt[j];
        }
        cx /= q; cy /= q; dx /= q; dy /= q;
        for (int j = 0; j < n; j++) {
            double ax = pts[2 * j] - cx, ay = pts[2 * j + 1] - cy;
            double bx = dir[2 * j] - dx, by = dir[2 * j + 1] - dy;
            aa += wt[j] * (ax * ax + ay * ay);
            ab += wt[j] * (ax * bx + ay * by);
            bb += wt[j] * (bx * bx + by * by);
        }
        double fw = l->field[f].weight > 0 ? l->field[f].weight : 0;
        fa[f] = aa / q; fb[f] = ab / q; fc[f] = bb / q;
        sab += fw * fb[f];
        sbb += fw * fc[f];
        wsum += fw;
    }
    double dz = o->compensate && sbb > 0 ? -sab / sbb : 0, r2 = 0;
    for (int f = 0; f < l->nfield; f++) {
        double fw = l->field[f].weight > 0 ? l->field[f].weight : 0;
        double v = fa[f] + 2 * dz * fb[f] + dz * dz * fc[f];
        r2 += fw * (v > 0 ? v : 0);
    }
    c->rms = wsum > 0 ? sqrt(r2 / wsum) : NAN;
    c->focus = dz * w[0].sig;               /* along the light: after odd mirrors it runs -z */
    /* the boresight: field 1's chief ray at the primary wavelength on the refocused
     * plane (linear in tilts and decentres, where the spot is quadratic) */
    if (ds_chief(p, &w[0], 0, zi, bp, bs)) return DS_OK;
    c->bore[0] = bp[0] + dz * bs[0];
    c->bore[1] = bp[1] + dz * bs[1];
    c->ok = 1;
    if (o->wave) {
        double v2 = 0;
        for (int f = 0; f < l->nfield; f++) {
            double fw = l->field[f].weight > 0 ? l->field[f].weight : 0, m = 0, q = 0, s2 = 0;
            int n = ds_field_wave(p, w, nwl, f, zi + dz, pts, wt, MAXRAY);
            if (n == -2) return DS_STOPPED;
            if (n < 0) { c->ok = 0; return DS_OK; }
            for (int j = 0; j < n; j++) { m += wt[j] * pts[j]; q += wt[j]; }
            m /= q;
            for (int j = 0; j < n; j++) s2 += wt[j] * (pts[j] - m) * (pts[j] - m);
            v2 += fw * s2 / q;
        }
        c->wave = wsum > 0 ? sqrt(v2 / wsum) : NAN;
    }
    return DS_OK;
}

static void restore(ds_problem *p)
{
    memcpy(p->lens.surf, p->base.surf, sizeof(ln_surface) * (size_t)p->base.nsurf);
    memset(p->dn, 0, sizeof p->dn);
    memset(p->gp, 0, sizeof p->gp);
}

static void apply(ds_problem *p, int i, double v)
{
    const ds_tol *t = &p->tol[i];
    ln_surface *s = &p->lens.surf[t->surf];
    switch (t->kind) {
    case DT_R: ln_set_radius(s, s->r + v); break;
    case DT_T: s->t += v; break;
    case DT_N: p->dn[t->surf + 1] += v; break;
    case DT_DEC: p->gp[t->grp][t->axis] += v; break;
    case DT_TILT: p->gp[t->grp][2 + t->axis] += v; break;
    default: s->conic += v; break;
    }
}

int ds_tol_nominal(ds_problem *p, const ds_tol_opts *o, ds_crit *c)
{
    restore(p);
    return crit(p, o, c);
}

int ds_tol_one(ds_problem *p, const ds_tol_opts *o, int i, double sign, ds_crit *c)
{
    restore(p);
    apply(p, i, sign * p->tol[i].delta);
    int rc = crit(p, o, c);
    restore(p);
    return rc;
}

static double uniform01(uint64_t *s)
{
    return ((lm_splitmix(s) >> 11) + 0.5) / 9007199254740992.0;
}

int ds_tol_mc(ds_problem *p, const ds_tol_opts *o, uint64_t seed, long k, ds_crit *c)
{
    uint64_t s = seed ^ ((uint64_t)k * 0xD1B54A32D192ED03ull);
    lm_splitmix(&s);
    restore(p);
    for (int i = 0; i < p->ntol; i++) {
        double d = p->tol[i].delta, v;
        if (o->dist == 0) {
            v = d * (2 * uniform01(&s) - 1);
        } else {                               /* sigma d/2, cut at 2 sigma */
            double g = 0;
            for (int tries = 0; tries < 64; tries++) {
                g = lm_gauss(&s);
                if (fabs(g) <= 2) break;
            }
            if (fabs(g) > 2) g = g > 0 ? 2 : -2;
            v = d * g / 2;
        }
        apply(p, i, v);
    }
    int rc = crit(p, o, c);
    restore(p);
    return rc;
}
