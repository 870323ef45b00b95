/* cn_sim.c -- a simulated scan: a sunflower (or one-meridian) pattern of targets on
 * the rig's nominal cornea, each solved and quantised by the rig engine, traced by
 * rig_api.forward through the true (unknown) cornea, its detector hit plus Gaussian
 * centroid noise from a fixed-seed generator (bit-reproducible). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include "cn_int.h"
#include "common/lm_rand.h"


int cn_simulate(const rig_api *rg, const rg_geometry *g, const rg_cornea *truth,
                const cn_scan_opts *o, cn_spot *spots, int cap, char *err, size_t errcap)
{
    if (!rg || !g || !truth || !o || o->npoints <= 0 || !(o->theta_max > 0)) {
        snprintf(err, errcap, "bad scan options");
        return CN_EINVAL;
    }
    cn_plane pl;
    cn_plane_of(g, &pl);
    rg_geometry gt = *g;
    gt.cornea = *truth;
    uint64_t seed = o->seed;
    int n = 0;
    char e[256];
    for (int k = 0; k < o->npoints && n < cap; k++) {
        rg_target t = {RG_T_ANGLES, 0, 0};
        if (o->one_meridian) {
            t.a = o->theta_max * (k / 2 + 1.0) / ((o->npoints + 1) / 2);
            t.b = o->meridian + (k & 1) * M_PI;
        } else {
            t.a = o->theta_max * sqrt((k + 0.5) / o->npoints);
            t.b = fmod(k * 2.399963229728653, 2 * M_PI);
        }
        rg_solution s;
        rg_quantised q;
        if (rg->solve(g, &t, NULL, &s, e, sizeof e)) continue;   /* unreachable */
        rg_pose pose = s.pose;
        if (o->quantise) {
            if (rg->quantise(g, &t, &s, &q, e, sizeof e)) continue;
            pose = q.pose;
        }
        cn_spot *sp = &spots[n];
        memset(sp, 0, sizeof *sp);
        if (cn_ray_of_pose(rg, g, &pose, &sp->ray, e, sizeof e)) continue;
        rg_beam b;
        rg->forward(&gt, &pose, &b, e, sizeof e);
        sp->sigma = o->sigma > 0 ? o->sigma : 1e-4;
        double nu = lm_gauss(&seed), nv = lm_gauss(&seed);   /* drawn for every target:
                                                          the noise of point k does
                                                          not depend on the others */
        double dn = b.d3[0] * pl.w[0] + b.d3[1] * pl.w[1] + b.d3[2] * pl.w[2];
        if ((b.diag & RG_D_MISS_CORNEA) || !isfinite(b.spot[0]) || !(dn > 0)) {
            sp->status = CN_S_NONE;
            sp->u = sp->v = NAN;
            n++;
            continue;
        }
        double rel[3], hit[3], kk = 0;
        for (int i = 0; i < 3; i++) rel[i] = pl.at[i] - b.spot[i];
        kk = (rel[0] * pl.w[0] + rel[1] * pl.w[1] + rel[2] * pl.w[2]) / dn;
        for (int i = 0; i < 3; i++) hit[i] = b.spot[i] + kk * b.d3[i] - pl.at[i];
        sp->u = hit[0] * pl.e1[0] + hit[1] * pl.e1[1] + hit[2] * pl.e1[2];
        sp->v = hit[0] * pl.e2[0] + hit[1] * pl.e2[1] + hit[2] * pl.e2[2];
        if (o->sigma > 0) { sp->u += o->sigma * nu; sp->v += o->sigma * nv; }
        sp->status = CN_S_OK;
        n++;
    }
    return n;
}
