/* cn_map.c -- what the pictures of a measurement need from the engine: a planned
 * scan re-imaged through a truth with a keratoconus-like bump (the stated model of
 * cornea.h's cn_bump), the maps of a surface (elevation against its best-fit sphere,
 * axial and tangential curvature) on a grid in its eye frame, and where each fitted
 * spot met the fitted surface (for the residual map). */
#include <math.h>
#include <stdint.h>
#include <string.h>
#include "cn_int.h"
#include "common/lm_rand.h"


int cn_reimage(const rg_geometry *g, int model, const cn_params *p, const cn_bump *bump,
               double sigma, unsigned long long seed, cn_spot *spots, int n)
{
    cn_plane pl;
    cn_plane_of(g, &pl);
    uint64_t st = seed;
    int on = 0;
    for (int i = 0; i < n; i++) {
        cn_spot *s = &spots[i];
        double nu = lm_gauss(&st), nv = lm_gauss(&st), u, v;
        s->nres = NAN;
        if (cn_forward_bump(model, p, bump, g->cornea.trans, &pl, &s->ray, &u, &v, NULL,
                            NULL)) {
            s->status = CN_S_NONE;
            s->u = s->v = NAN;
            continue;
        }
        s->sigma = sigma > 0 ? sigma : 1e-4;
        s->u = u + (sigma > 0 ? sigma * nu : 0);
        s->v = v + (sigma > 0 ? sigma * nv : 0);
        s->status = CN_S_OK;
        on++;
    }
    return on;
}

int cn_map(int kind, int model, const cn_params *p, const cn_bump *bump, double hmax,
           int n, double *grid, double *aux)
{
    if (n < 2 || !(hmax > 0) || kind < CN_MAP_ELEVATION || kind > CN_MAP_TANGENTIAL ||
        model < CN_SPHERE || model > CN_ASPHERE)
        return CN_EINVAL;
    cn_surf s;
    cn_surface(model, p, &s);
    if (bump) s.bump = *bump;
    double kn = (CN_KERATO_N - 1) * 1000, cell = 2 * hmax / n;
    /* elevation: the sag first, then the best-fit sphere with its centre on the axis
     * (algebraic least squares: x^2 + y^2 + z^2 = 2 zc z - k, linear in zc, k) */
    double a11 = 0, a12 = 0, a22 = 0, b1 = 0, b2 = 0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            double x = -hmax + (i + 0.5) * cell, y = hmax - (j + 0.5) * cell, z, zx, zy;
            double *g = &grid[(size_t)j * n + i];
            *g = NAN;
            if (hypot(x, y) > hmax) continue;
            if (kind == CN_MAP_ELEVATION) {
                if (cn_sag(&s, x, y, &z, &zx, &zy)) continue;
                double rho = x * x + y * y + z * z;
                a11 += 4 * z * z; a12 += -2 * z; a22 += 1;
                b1 += 2 * z * rho; b2 += -rho;
                *g = z;
            } else {
                double ax, tg;
                if (cn_curvatures(&s, x, y, &ax, &tg)) continue;
                *g = kn * (kind == CN_MAP_AXIAL ? ax : tg);
            }
        }
    if (kind != CN_MAP_ELEVATION) { if (aux) *aux = NAN; return CN_OK; }
    double det = a11 * a22 - a12 * a12;
    if (!(fabs(det) > 0)) return CN_EINVAL;
    double zc = (b1 * a22 - a12 * b2) / det, k = (a11 * b2 - a12 * b1) / det;
    double rb = sqrt(zc * zc - k);
    if (!isfinite(rb)) return CN_EINVAL;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            double *g = &grid[(size_t)j * n + i];
            if (isnan(*g)) continue;
            double x = -hmax + (i + 0.5) * cell, y = hmax - (j + 0.5) * cell;
            double q = rb * rb - x * x - y * y;
            *g = q > 0 ? (zc - sqrt(q) - *g) * 1000 : NAN;   /* um, + toward the eye's
                                                                observer */
        }
    if (aux) *aux = rb;
    return CN_OK;
}

void cn_spot_xy(const rg_geometry *g, const cn_result *r, const cn_spot *spots, int n,
                double *xy)
{
    cn_plane pl;
    cn_plane_of(g, &pl);
    for (int i = 0; i < n; i++) {
        double u, v, at[3], e[3];
        xy[2 * i] = xy[2 * i + 1] = NAN;
        if (spots[i].status != CN_S_OK && spots[i].status != CN_S_OUTLIER) continue;
        if (cn_forward(r->model, &r->par, g->cornea.trans, &pl, &spots[i].ray, &u, &v, at,
                       NULL))
            continue;
        cn_to_eye(&r->par, g->cornea.trans, at, e);
        xy[2 * i] = e[0];
        xy[2 * i + 1] = e[1];
    }
}
