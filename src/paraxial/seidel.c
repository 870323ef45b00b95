/* seidel.c -- third-order (Seidel) aberration sums of a prescription by thickness:
 * a paraxial marginal and chief ray traced at the d line (the chief ray aimed at the
 * centre of the aperture stop, which may be any surface), each surface's
 * contribution in Welford's forms (see paraxial.h), and the chromatic sums from the
 * catalogue's nF - nC.  Checked against ray-optics' published table for Sasian's
 * Cooke triplet in tests/unit_published.c. */
#include <math.h>
#include <string.h>
#include "paraxial.h"

/* n at d and dn = nF - nC of a medium; PX_OK or its error. */
static int medium(const char *g, double *n, double *dn)
{
    double nf, nc;
    int r;
    if ((r = px_glass_index(g, PX_LAMBDA_D, n)) != PX_OK) return r;
    if (px_glass_index(g, PX_LAMBDA_F, &nf) != PX_OK ||
        px_glass_index(g, PX_LAMBDA_C, &nc) != PX_OK) nf = nc = 0;   /* no colour data */
    *dn = nf - nc;
    return PX_OK;
}

/* Height at surface `stop` of the paraxial ray that leaves surface 1 at height y
 * with slope u (object space); PX_OK or an error. */
static int height_at(const px_csurf *s, int stop, const char *obj_glass, double y,
                     double u, double *h)
{
    double n, n2, dn;
    int r;
    if ((r = medium(obj_glass, &n, &dn)) != PX_OK) return r;
    for (int k = 0; k < stop; k++) {
        double c = (s[k].r == 0 || isinf(s[k].r)) ? 0 : 1 / s[k].r;
        if ((r = medium(s[k].glass, &n2, &dn)) != PX_OK) return r;
        u = (n * u - y * c * (n2 - n)) / n2;
        n = n2;
        if (!(s[k].t >= 0) || !isfinite(s[k].t)) return PX_BAD;
        y += s[k].t * u;
    }
    *h = y;
    return PX_OK;
}

int px_seidel_run(const px_csurf *s, int nsurf, const char *obj_glass, double y1,
                  double ubar1, px_seidel *out)
{
    return px_seidel_run_stop(s, nsurf, obj_glass, y1, ubar1, 0, out);
}

int px_seidel_run_stop(const px_csurf *s, int nsurf, const char *obj_glass, double y1,
                       double ubar1, int stop, px_seidel *out)
{
    double n, dn, y = y1, u = 0, yb = 0, ub = ubar1;
    int r;
    memset(out, 0, sizeof *out);
    if (nsurf < 1 || nsurf > PX_SEIDEL_MAXSURF || !isfinite(y1) || !isfinite(ubar1) ||
        stop < 0 || stop >= nsurf)
        return PX_BAD;
    if ((r = medium(obj_glass, &n, &dn)) != PX_OK) return r;
    if (stop > 0) {
        /* Paraxial rays are linear in (height, slope) at surface 1: the chief ray is
         * the combination of (0, ubar1) and (1, 0) that meets the stop on the axis. */
        double ha, hb;
        if ((r = height_at(s, stop, obj_glass, 0, ubar1, &ha)) != PX_OK ||
            (r = height_at(s, stop, obj_glass, 1, 0, &hb)) != PX_OK) return r;
        if (hb == 0 || !isfinite(ha / hb)) return PX_BAD;   /* stop imaged at infinity */
        yb = -ha / hb;
    }
    out->nsurf = nsurf;
    out->stop = stop;
    out->ybar1 = yb;
    out->h = n * (ub * y - u * yb);
    for (int k = 0; k < nsurf; k++) {
        double n2, dn2, c = (s[k].r == 0 || isinf(s[k].r)) ? 0 : 1 / s[k].r;
        double a, ab, u2, ub2, d_un, h2 = out->h * out->h;
        px_seidel_sums *q = &out->surf[k];
        if ((r = medium(s[k].glass, &n2, &dn2)) != PX_OK) return r;
        a = n * (u + y * c);
        ab = n * (ub + yb * c);
        u2 = (n * u - y * c * (n2 - n)) / n2;
        ub2 = (n * ub - yb * c * (n2 - n)) / n2;
        d_un = u2 / n2 - u / n;
        q->s1 = -a * a * y * d_un;
        q->s2 = -a * ab * y * d_un;
        q->s3 = -ab * ab * y * d_un;
        q->s4 = -h2 * c * (1 / n2 - 1 / n);
        if (a == 0 && (q->s3 != 0 || q->s4 != 0)) return PX_BAD;
        q->s5 = a == 0 ? 0 : ab / a * (q->s3 + q->s4);
        q->c1 = a * y * (dn2 / n2 - dn / n);
        q->c2 = ab * y * (dn2 / n2 - dn / n);
        out->total.s1 += q->s1; out->total.s2 += q->s2; out->total.s3 += q->s3;
        out->total.s4 += q->s4; out->total.s5 += q->s5;
        out->total.c1 += q->c1; out->total.c2 += q->c2;
        n = n2; dn = dn2; u = u2; ub = ub2;
        if (k + 1 < nsurf) {
            if (!(s[k].t >= 0) || !isfinite(s[k].t)) return PX_BAD;
            y += s[k].t * u;
            yb += s[k].t * ub;
        }
    }
    out->u_last = u;
    out->n_last = n;
    return PX_OK;
}
