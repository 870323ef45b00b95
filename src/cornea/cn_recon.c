/* cn_recon.c -- the surface from the spots (issue 19), heights and slopes together.
 * Each spot gives its incoming beam and its detector point; where the beam meets the
 * cornea (the length t along it) is unknown, and the normal there follows from t
 * (deflectometry: it halves the turn from the beam to the line to the detector point).
 * So the surface is fitted to the detector positions themselves: z = base sphere +
 * sum c_j Z_j (cn_zern.c), every beam met, reflected and carried to the detector, the
 * coefficients (piston included) by Levenberg-Marquardt with the exact linearisation
 * (the meeting point moves along the beam, the slope with it).  The heights along
 * the beams are what fix the scale: a reference sphere alone, fitted to a coned eye,
 * sat 0.42 mm off and 1.04 mm short in R, and a slope fit on its meeting points read
 * Kmax 6.5 D high; the joint fit does not depend on the reference beyond its frame.
 * The radial order: the lowest BIC of a linear slope fit on the current meeting
 * points (nested orders, one design matrix), re-chosen after each joint solve until
 * it holds.  Leaves the spots' meeting points and slopes for the local curvature fits
 * and maps (cn_kc.c). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_linalg.h>
#include "cn_int.h"

typedef struct rs {             /* one spot in the reference's eye frame */
    double o[3], d[3];          /* its beam (unit d) */
    double D[3];                /* its measured detector point */
    double u, v, sig;           /* measured detector coordinates, their sd */
} rs;

typedef struct rctx {
    int m;
    rs *s;
    double A[3], w[3], e1[3], e2[3];   /* the detector plane in the eye frame */
} rctx;

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The beam (o, d) off a surface point P of slopes (fx, fy), onto the detector. */
static int reflect_to(const rctx *c, const rs *s, const double P[3], double fx, double fy,
                      double *u, double *v)
{
    double nn = sqrt(fx * fx + fy * fy + 1), n[3] = {-fx / nn, -fy / nn, 1 / nn}, r[3], q[3];
    double dn = dot3(s->d, n);
    for (int k = 0; k < 3; k++) r[k] = s->d[k] - 2 * dn * n[k];
    double rw = dot3(r, c->w);
    if (!(fabs(rw) > 1e-12)) return -1;
    for (int k = 0; k < 3; k++) q[k] = c->A[k] - P[k];
    double L = dot3(q, c->w) / rw;
    for (int k = 0; k < 3; k++) q[k] = P[k] + L * r[k] - c->A[k];
    *u = dot3(q, c->e1);
    *v = dot3(q, c->e2);
    return 0;
}

/* Where the beam meets z: Newton on o_z + t d_z - f(o_xy + t d_xy) from *t. */
static int meet(const cn_zfit *z, const rs *s, double *t)
{
    for (int it = 0; it < 30; it++) {
        double x = s->o[0] + *t * s->d[0], y = s->o[1] + *t * s->d[1], f, fx, fy;
        if (cn_zsag(z, x, y, &f, &fx, &fy)) return -1;
        double g = s->o[2] + *t * s->d[2] - f, dg = s->d[2] - fx * s->d[0] - fy * s->d[1];
        if (!(fabs(dg) > 1e-9)) return -1;
        double dt = g / dg;
        *t -= dt;
        if (fabs(dt) < 1e-11) return 0;
    }
    return -1;
}

/* The normal's slopes from the meeting point P and the detector point D: n ~ r - d,
 * r the unit P -> D; L = |P D|. */
static int slopes_at(const double P[3], const rs *s, double *fx, double *fy, double *L)
{
    double r[3], n[3];
    for (int i = 0; i < 3; i++) r[i] = s->D[i] - P[i];
    *L = sqrt(dot3(r, r));
    for (int i = 0; i < 3; i++) { r[i] /= *L; n[i] = r[i] - s->d[i]; }
    if (!(fabs(n[2]) > 1e-9)) return -1;
    *fx = -n[0] / n[2];
    *fy = -n[1] / n[2];
    return 0;
}

/* Solve (M + ridge) x = b for symmetric positive M (k x k, row-major, destroyed),
 * with Jacobi scaling (the terms' scales differ by orders of magnitude); 0 or -1. */
static int spd_solve(double *M, const double *b, double *x, int k, double *inv)
{
    gsl_matrix_view Mv = gsl_matrix_view_array(M, (size_t)k, (size_t)k);
    double *sc = malloc(sizeof *sc * (size_t)k);
    if (!sc) return -1;
    for (int i = 0; i < k; i++) sc[i] = M[i * k + i] > 0 ? 1 / sqrt(M[i * k + i]) : 1;
    for (int i = 0; i < k; i++)
        for (int j = 0; j < k; j++) M[i * k + j] *= sc[i] * sc[j];
    for (int i = 0; i < k; i++) M[i * k + i] += 1e-12;   /* a term the data barely reach */
    gsl_error_handler_t *old = gsl_set_error_handler_off();
    int rc = gsl_linalg_cholesky_decomp1(&Mv.matrix);
    if (!rc && b) {
        gsl_vector_view xv = gsl_vector_view_array(x, (size_t)k);
        for (int i = 0; i < k; i++) x[i] = b[i] * sc[i];
        rc = gsl_linalg_cholesky_svx(&Mv.matrix, &xv.vector);
        for (int i = 0; i < k; i++) x[i] *= sc[i];
    }
    if (!rc && inv) {
        rc = gsl_linalg_cholesky_invert(&Mv.matrix);
        for (int i = 0; !rc && i < k; i++)
            for (int j = 0; j < k; j++) inv[i * k + j] = M[i * k + j] * sc[i] * sc[j];
    }
    gsl_set_error_handler(old);
    free(sc);
    return rc ? -1 : 0;
}

/* The slope fit on the meeting points (px, py), slopes (sx, sy), weights w: the
 * departure from the base sphere by the gradients of terms 1 .. nt-1, the order of
 * lowest BIC (chi^2 + k ln 2m) between lo and hi; coefficients into z (piston
 * untouched).  G: scratch of 2m x (nt_max - 1).  Returns the order or -1. */
static int slope_order(cn_zfit *z, int m, const double *px, const double *py,
                       const double *sx, const double *sy, const double *w, int lo, int hi,
                       double *G)
{
    int ntm = cn_zterms(hi), np = ntm - 1;
    double v[CN_ZTERMS], gx[CN_ZTERMS], gy[CN_ZTERMS];
    double *y = malloc(sizeof *y * 2 * (size_t)m);
    double *M = malloc(sizeof *M * (size_t)np * np), *Mk = malloc(sizeof *Mk * (size_t)np * np);
    double *b = calloc((size_t)np, sizeof *b), *x = malloc(sizeof *x * (size_t)np);
    double *xb = malloc(sizeof *xb * (size_t)np);
    int best = -1;
    if (!y || !M || !Mk || !b || !x || !xb) goto out;
    memset(M, 0, sizeof *M * (size_t)np * np);
    for (int i = 0; i < m; i++) {
        cn_zbasis(ntm, z->rho, px[i], py[i], v, gx, gy);
        double q = sqrt(z->R0 * z->R0 - px[i] * px[i] - py[i] * py[i]), sw = sqrt(w[i]);
        y[2 * i] = sw * (sx[i] - px[i] / q);
        y[2 * i + 1] = sw * (sy[i] - py[i] / q);
        double *gu = &G[2 * (size_t)i * np], *gv = gu + np;
        for (int j = 0; j < np; j++) { gu[j] = sw * gx[j + 1]; gv[j] = sw * gy[j + 1]; }
        for (int a = 0; a < np; a++) {
            b[a] += gu[a] * y[2 * i] + gv[a] * y[2 * i + 1];
            for (int c = a; c < np; c++) M[a * np + c] += gu[a] * gu[c] + gv[a] * gv[c];
        }
    }
    for (int a = 0; a < np; a++) for (int c = 0; c < a; c++) M[a * np + c] = M[c * np + a];
    double bic_best = INFINITY;
    for (int ord = lo; ord <= hi; ord++) {
        int k = cn_zterms(ord) - 1;
        for (int a = 0; a < k; a++) for (int c = 0; c < k; c++) Mk[a * k + c] = M[a * np + c];
        if (spd_solve(Mk, b, x, k, NULL)) break;
        double chi2 = 0;   /* from the residuals themselves, not yWy - b.x (cancels) */
        for (int r = 0; r < 2 * m; r++) {
            double e = y[r];
            const double *g = &G[(size_t)r * np];
            for (int j = 0; j < k; j++) e -= g[j] * x[j];
            chi2 += e * e;
        }
        double bic = chi2 + k * log(2.0 * m);
        z->bic[ord] = bic;
        if (bic < bic_best) { bic_best = bic; best = ord; memcpy(xb, x, sizeof *x * (size_t)k); }
        else if (ord >= best + 3) break;    /* three orders past the best: done */
    }
    if (best > 0) {
        int k = cn_zterms(best);
        memset(z->c + 1, 0, sizeof z->c - sizeof z->c[0]);
        for (int j = 1; j < k; j++) z->c[j] = xb[j - 1];
        z->nterms = k;
        z->order = best;
    }
out:
    free(y); free(M); free(Mk); free(b); free(x); free(xb);
    return best;
}

/* chi^2 of the spots on the detector for the surface z, each beam met from t[]
 * (updated); with JtJ (nt x nt) and Jtr: the normal equations of the coefficients
 * (the meeting point's shift along the beam and the slope's with it included). */
static double det_eval(const rctx *c, const cn_zfit *z, double *t, double *JtJ, double *Jtr)
{
    int nt = z->nterms;
    double v[CN_ZTERMS], gx[CN_ZTERMS], gy[CN_ZTERMS], ju[CN_ZTERMS], jv[CN_ZTERMS];
    double chi2 = 0;
    if (JtJ) {
        memset(JtJ, 0, sizeof *JtJ * (size_t)nt * nt);
        memset(Jtr, 0, sizeof *Jtr * (size_t)nt);
    }
    for (int i = 0; i < c->m; i++) {
        const rs *s = &c->s[i];
        double P[3], f, fx, fy, u, vv;
        if (meet(z, s, &t[i])) return INFINITY;
        for (int k = 0; k < 3; k++) P[k] = s->o[k] + t[i] * s->d[k];
        cn_zsag(z, P[0], P[1], &f, &fx, &fy);
        if (reflect_to(c, s, P, fx, fy, &u, &vv)) return INFINITY;
        double ru = (u - s->u) / s->sig, rv = (vv - s->v) / s->sig;
        chi2 += ru * ru + rv * rv;
        if (!JtJ) continue;
        /* (u, v) against (t, fx, fy) at the meeting point: central differences of
           the mirror law (smooth, cheap) */
        double Fu[3], Fv[3], hs[3] = {1e-4, 1e-7, 1e-7};
        for (int q = 0; q < 3; q++) {
            double up, vp, um, vm, Pp[3], Pm[3], a[3] = {0, fx, fy}, bm[3] = {0, fx, fy};
            a[q] += hs[q];
            bm[q] -= hs[q];
            for (int k = 0; k < 3; k++) {
                Pp[k] = s->o[k] + (t[i] + a[0]) * s->d[k];
                Pm[k] = s->o[k] + (t[i] + bm[0]) * s->d[k];
            }
            if (reflect_to(c, s, Pp, a[1], a[2], &up, &vp) ||
                reflect_to(c, s, Pm, bm[1], bm[2], &um, &vm))
                return INFINITY;
            Fu[q] = (up - um) / (2 * hs[q] * s->sig);
            Fv[q] = (vp - vm) / (2 * hs[q] * s->sig);
        }
        /* the surface's Hessian there (the slope seen moves with the meeting point) */
        double h = 1e-4, f1, ax, ay, bx, by, cx, cy, ex, ey;
        cn_zsag(z, P[0] + h, P[1], &f1, &ax, &ay);
        cn_zsag(z, P[0] - h, P[1], &f1, &bx, &by);
        cn_zsag(z, P[0], P[1] + h, &f1, &cx, &cy);
        cn_zsag(z, P[0], P[1] - h, &f1, &ex, &ey);
        double hxx = (ax - bx) / (2 * h), hxy = 0.5 * ((ay - by) + (cx - ex)) / (2 * h),
               hyy = (cy - ey) / (2 * h);
        double gp = s->d[2] - fx * s->d[0] - fy * s->d[1];
        double mx = hxx * s->d[0] + hxy * s->d[1], my = hxy * s->d[0] + hyy * s->d[1];
        cn_zbasis(nt, z->rho, P[0], P[1], v, gx, gy);
        for (int j = 0; j < nt; j++) {
            double dt = v[j] / gp, dfx = gx[j] + mx * dt, dfy = gy[j] + my * dt;
            ju[j] = Fu[0] * dt + Fu[1] * dfx + Fu[2] * dfy;
            jv[j] = Fv[0] * dt + Fv[1] * dfx + Fv[2] * dfy;
        }
        for (int a = 0; a < nt; a++) {
            Jtr[a] += ju[a] * ru + jv[a] * rv;
            double *row = &JtJ[a * nt];
            for (int b = a; b < nt; b++) row[b] += ju[a] * ju[b] + jv[a] * jv[b];
        }
    }
    if (JtJ)
        for (int a = 0; a < nt; a++) for (int b = 0; b < a; b++) JtJ[a * nt + b] = JtJ[b * nt + a];
    return chi2;
}

/* Levenberg-Marquardt on the coefficients of z against the detector; t[] the
 * meeting lengths (warm starts, left at the solution).  Returns chi^2 (INFINITY:
 * a beam missed the start surface); cov (nt x nt) the inverse of J^T J there. */
static double joint_solve(const rctx *c, cn_zfit *z, double *t, double *cov, int *iters,
                          int max_it)
{
    int nt = z->nterms;
    double *JtJ = malloc(sizeof *JtJ * (size_t)nt * nt), *M = malloc(sizeof *M * (size_t)nt * nt);
    double *Jtr = malloc(sizeof *Jtr * (size_t)nt), *dx = malloc(sizeof *dx * (size_t)nt);
    double *tt = malloc(sizeof *tt * (size_t)c->m), c0[CN_ZTERMS];
    double chi2 = INFINITY, lambda = 1e-3;
    if (!JtJ || !M || !Jtr || !dx || !tt) goto out;
    chi2 = det_eval(c, z, t, JtJ, Jtr);
    for (int it = 0; isfinite(chi2) && it < max_it; it++) {
        memcpy(M, JtJ, sizeof *M * (size_t)nt * nt);
        for (int a = 0; a < nt; a++) M[a * nt + a] *= 1 + lambda;
        if (spd_solve(M, Jtr, dx, nt, NULL)) { lambda *= 10; if (lambda > 1e12) break; continue; }
        memcpy(c0, z->c, sizeof *c0 * (size_t)nt);
        for (int a = 0; a < nt; a++) z->c[a] -= dx[a];
        memcpy(tt, t, sizeof *tt * (size_t)c->m);
        double c2 = det_eval(c, z, tt, NULL, NULL);
        (*iters)++;
        if (c2 < chi2) {
            double drop = chi2 - c2;
            memcpy(t, tt, sizeof *t * (size_t)c->m);
            chi2 = det_eval(c, z, t, JtJ, Jtr);
            lambda = fmax(lambda / 3, 1e-9);
            /* chi^2's own sd is sqrt(2 dof) >> 1e-3: nothing left to gain */
            if (drop < 1e-3 + 1e-9 * chi2) break;
        } else {
            memcpy(z->c, c0, sizeof *c0 * (size_t)nt);
            lambda *= 4;
            if (lambda > 1e12) break;
        }
    }
    if (cov && isfinite(chi2)) {
        memcpy(M, JtJ, sizeof *M * (size_t)nt * nt);
        if (spd_solve(M, NULL, NULL, nt, cov))
            for (int a = 0; a < nt * nt; a++) cov[a] = a % (nt + 1) ? 0 : INFINITY;
    }
out:
    free(JtJ); free(M); free(Jtr); free(dx); free(tt);
    return chi2;
}

static int recon_once(const rg_geometry *g, const cn_spot *spots, int n, const cn_params *ref,
                      int ref_model, int max_order, int max_lm, cn_zfit *z, char *err,
                      size_t errcap)
{
    cn_plane pl;
    cn_plane_of(g, &pl);
    const double *apex0 = g->cornea.trans;
    memset(z, 0, sizeof *z);
    z->ref = *ref;
    z->R0 = ref->p[CN_R];
    if (max_order <= 0 || max_order > CN_ZORDER) max_order = CN_ZORDER;
    int cap = n < CN_ZPTS ? (n > 0 ? n : 1) : CN_ZPTS;
    rctx c = {0};
    c.s = malloc(sizeof *c.s * (size_t)cap);
    double *buf = malloc(sizeof *buf * 6 * (size_t)cap);
    double *G = malloc(sizeof *G * 2 * (size_t)cap * (CN_ZTERMS - 1));
    double *cov = malloc(sizeof *cov * CN_ZTERMS * CN_ZTERMS);
    int rc = CN_OK;
    if (!c.s || !buf || !G || !cov) { snprintf(err, errcap, "out of memory"); rc = CN_ENOMEM; goto out; }
    double *px = buf, *py = buf + cap, *sx = buf + 2 * cap, *sy = buf + 3 * cap,
           *w = buf + 4 * cap, *t = buf + 5 * cap;
    {   /* the detector plane in the eye frame */
        double tmp[3], at[3];
        cn_to_eye(ref, apex0, pl.at, c.A);
        const double *dirs[3] = {pl.w, pl.e1, pl.e2};
        double *outs[3] = {c.w, c.e1, c.e2};
        for (int k = 0; k < 3; k++) {
            for (int i = 0; i < 3; i++) tmp[i] = pl.at[i] + dirs[k][i];
            cn_to_eye(ref, apex0, tmp, at);
            for (int i = 0; i < 3; i++) outs[k][i] = at[i] - c.A[i];
        }
    }
    /* every usable spot: its beam and detector point in the eye frame, and where the
       beam meets the reference (the first meeting points, the data's disc) */
    int m = 0;
    for (int i = 0; i < n && m < cap; i++) {
        const cn_spot *s = &spots[i];
        if ((s->status != CN_S_OK && s->status != CN_S_OUTLIER) || !(s->sigma > 0) ||
            !isfinite(s->u) || !isfinite(s->v))
            continue;
        double u, v, at[3], e[3], p1[3], e1[3], Dr[3], nn = 0;
        if (cn_forward(ref_model, ref, apex0, &pl, &s->ray, &u, &v, at, NULL)) continue;
        rs *q = &c.s[m];
        cn_to_eye(ref, apex0, at, e);
        cn_to_eye(ref, apex0, s->ray.o, q->o);
        for (int k = 0; k < 3; k++) p1[k] = s->ray.o[k] + s->ray.d[k];
        cn_to_eye(ref, apex0, p1, e1);
        for (int k = 0; k < 3; k++) { q->d[k] = e1[k] - q->o[k]; nn += q->d[k] * q->d[k]; }
        nn = sqrt(nn);
        for (int k = 0; k < 3; k++) q->d[k] /= nn;
        for (int k = 0; k < 3; k++) Dr[k] = pl.at[k] + s->u * pl.e1[k] + s->v * pl.e2[k];
        cn_to_eye(ref, apex0, Dr, q->D);
        q->u = s->u;
        q->v = s->v;
        q->sig = s->sigma;
        t[m] = dot3((double[3]){e[0] - q->o[0], e[1] - q->o[1], e[2] - q->o[2]}, q->d);
        px[m] = e[0];
        py[m] = e[1];
        m++;
    }
    c.m = m;
    if (m < 10) {
        snprintf(err, errcap, "%d spots meet the reference sphere: too few for a surface", m);
        rc = CN_EFIT;
        goto out;
    }
    double rmax = 0;
    for (int i = 0; i < m; i++) rmax = fmax(rmax, hypot(px[i], py[i]));
    z->rho = rmax * 1.0001;
    z->npts = m;
    z->gap = 2.5 * rmax * sqrt(M_PI / m);   /* 2.5 spacings of a uniform scan */
    while (max_order > 1 && 2 * m < 3 * (cn_zterms(max_order) - 1)) max_order--;   /* 1.5 rows a term */
    int order = -1, iters = 0;
    double chi2 = INFINITY;
    for (int pass = 0; pass < 4; pass++) {
        /* the meeting points and the slopes the spots give there */
        for (int i = 0; i < m; i++) {
            const rs *s = &c.s[i];
            double P[3], L;
            for (int k = 0; k < 3; k++) P[k] = s->o[k] + t[i] * s->d[k];
            px[i] = P[0];
            py[i] = P[1];
            if (slopes_at(P, s, &sx[i], &sy[i], &L)) { w[i] = 0; sx[i] = sy[i] = 0; continue; }
            /* a normal turned by a turns the reflected beam by 2a: the detector moves
               2 a L; a slope f' changes by (1 + f'^2) per radian */
            double sl = s->sig / (2 * L) * (1 + sx[i] * sx[i] + sy[i] * sy[i]);
            w[i] = 1 / (sl * sl);
        }
        int lo = 1, hi = max_order;
        if (order > 0) { lo = order > 2 ? order - 2 : 1; hi = order + 2 < max_order ? order + 2 : max_order; }
        double cprev[CN_ZTERMS];
        int ntprev = z->nterms;
        memcpy(cprev, z->c, sizeof cprev);
        int best = slope_order(z, m, px, py, sx, sy, w, lo, hi, G);
        if (best < 0) { snprintf(err, errcap, "the slope fit failed (%d spots)", m); rc = CN_EFIT; goto out; }
        if (pass > 0 && best == order) {   /* the order holds: keep the joint solution */
            memcpy(z->c, cprev, sizeof cprev);
            z->nterms = ntprev;
            z->order = order;
            break;
        }
        order = best;
        /* piston: the new surface through the current meeting points on average */
        double dz = 0, f;
        z->c[0] = 0;
        for (int i = 0; i < m; i++) {
            cn_zsag(z, px[i], py[i], &f, NULL, NULL);
            dz += c.s[i].o[2] + t[i] * c.s[i].d[2] - f;
        }
        z->c[0] = dz / m;
        chi2 = joint_solve(&c, z, t, cov, &iters, max_lm);
        if (!isfinite(chi2)) {
            snprintf(err, errcap, "a beam misses the reconstructed surface (%d spots, order %d)", m, order);
            rc = CN_EFIT;
            goto out;
        }
    }
    /* the final meeting points, slopes and weights: the local curvature fits' data */
    for (int i = 0; i < m; i++) {
        const rs *s = &c.s[i];
        double P[3], L, fx, fy;
        for (int k = 0; k < 3; k++) P[k] = s->o[k] + t[i] * s->d[k];
        z->xy[2 * i] = P[0];
        z->xy[2 * i + 1] = P[1];
        if (slopes_at(P, s, &fx, &fy, &L)) { z->wt[i] = 0; z->sl[2 * i] = z->sl[2 * i + 1] = 0; continue; }
        double sl = s->sig / (2 * L) * (1 + fx * fx + fy * fy);
        z->sl[2 * i] = fx;
        z->sl[2 * i + 1] = fy;
        z->wt[i] = 1 / (sl * sl);
    }
    {
        int nt = z->nterms;
        for (int a = 0; a < nt; a++)
            for (int b = 0; b < nt; b++) z->cov[a * CN_ZTERMS + b] = cov[a * nt + b];
    }
    z->kr = 2.5 * rmax * sqrt(M_PI / m);     /* 2.5 spacings: about 20 spots a fit */
    int dof = 2 * m - z->nterms;
    z->det_chi2 = chi2;
    z->chi2_dof = dof > 0 ? chi2 / dof : NAN;   /* against the spots' own noise */
    z->nused = m;
    z->iterations = iters;
    cn_zvertex(z);
    cn_zlocal_vertex(z);
out:
    free(c.s);
    free(buf);
    free(G);
    free(cov);
    return rc;
}

/* The sphere through the reconstructed surface's meeting points (eye frame): centre
 * (a, b, c) and radius, by the algebraic fit then Gauss-Newton on the distances. */
static int sphere_of(const cn_zfit *z, double *a, double *b, double *c, double *R)
{
    double M[16] = {0}, rhs[4] = {0}, x[4];
    int m = 0;
    for (int i = 0; i < z->npts; i++) {
        double X = z->xy[2 * i], Y = z->xy[2 * i + 1], Z;
        if (!(z->wt[i] > 0) || cn_zsag(z, X, Y, &Z, NULL, NULL)) continue;
        double row[4] = {X, Y, Z, 1}, y = -(X * X + Y * Y + Z * Z);
        for (int p = 0; p < 4; p++) {
            rhs[p] += row[p] * y;
            for (int q = 0; q < 4; q++) M[p * 4 + q] += row[p] * row[q];
        }
        m++;
    }
    if (m < 10 || spd_solve(M, rhs, x, 4, NULL)) return -1;
    *a = -x[0] / 2;
    *b = -x[1] / 2;
    *c = -x[2] / 2;
    *R = sqrt(*a * *a + *b * *b + *c * *c - x[3]);
    for (int it = 0; it < 10; it++) {   /* distances: |P - C| - R */
        double N[16] = {0}, g[4] = {0}, d[4];
        for (int i = 0; i < z->npts; i++) {
            double X = z->xy[2 * i], Y = z->xy[2 * i + 1], Z;
            if (!(z->wt[i] > 0) || cn_zsag(z, X, Y, &Z, NULL, NULL)) continue;
            double ux = X - *a, uy = Y - *b, uz = Z - *c, L = sqrt(ux * ux + uy * uy + uz * uz);
            double r = L - *R, j[4] = {-ux / L, -uy / L, -uz / L, -1};
            for (int p = 0; p < 4; p++) {
                g[p] -= j[p] * r;
                for (int q = 0; q < 4; q++) N[p * 4 + q] += j[p] * j[q];
            }
        }
        if (spd_solve(N, g, d, 4, NULL)) return -1;
        *a += d[0]; *b += d[1]; *c += d[2]; *R += d[3];
        if (fabs(d[0]) + fabs(d[1]) + fabs(d[2]) + fabs(d[3]) < 1e-9) break;
    }
    return isfinite(*R) ? 0 : -1;
}

/* The reconstruction, its frame re-centred.  The caller's reference fitted to a
 * coned eye is off (the bump pulls a global fit: 0.42 mm along the axis and R 1.04
 * mm short on the bench's cone), which leaves the joint fit a large, nonlinear
 * departure to cover (40 steps crawled from chi2/dof 1900 to 470); so the sphere
 * through the reconstructed surface becomes the frame and base sphere and the
 * surface is fitted again in it (15 steps a pass; order 8 at most until the frame
 * moves less than 10 um, then the full order), until the frame moves less than 1 um.  The last pass, converged, is in the frame of the instrument's axis
 * (the rig's nominal axis, laterally at the nominal apex, the apex height and R0 of
 * that sphere): axial power is taken about that axis, as a Placido topographer
 * takes it about its videokeratoscope axis, whatever the reference's pose. */
int cn_zfit_run(const rg_geometry *g, const cn_spot *spots, int n, const cn_params *ref,
                int ref_model, int max_order, cn_zfit *z, char *err, size_t errcap)
{
    if (ref_model < CN_SPHERE || ref_model > CN_ASPHERE) {
        snprintf(err, errcap, "bad reference model %d", ref_model);
        return CN_EINVAL;
    }
    int mo = max_order > 0 && max_order <= CN_ZORDER ? max_order : CN_ZORDER;
    cn_params p = *ref;
    int model = ref_model, iters = 0, rc = CN_OK;
    const double *apex0 = g->cornea.trans;
    {   /* a reference that fits its spots (chi^2 within 4 sd of its dof, the fit's own
           test) is the eye's frame: one converged pass in it, curvatures about its
           apex (a tilted toric eye's maps and I-S read about the instrument's axis
           came out -37..75 um and -0.45 D against 0) */
        cn_plane pl;
        cn_plane_of(g, &pl);
        double chi2 = 0;
        int m = 0;
        for (int i = 0; i < n; i++) {
            const cn_spot *s = &spots[i];
            double u, v;
            if (s->status != CN_S_OK || !(s->sigma > 0)) continue;
            if (cn_forward(ref_model, ref, apex0, &pl, &s->ray, &u, &v, NULL, NULL)) { chi2 = INFINITY; break; }
            chi2 += ((u - s->u) * (u - s->u) + (v - s->v) * (v - s->v)) / (s->sigma * s->sigma);
            m++;
        }
        int dof = 2 * m - 10;
        if (dof > 0 && (chi2 - dof) / sqrt(2.0 * dof) <= 4)
            return recon_once(g, spots, n, ref, ref_model, mo, 40, z, err, errcap);
    }
    double C[3] = {0, 0, 0}, R = ref->p[CN_R];   /* the sphere's centre, rig frame */
    int cap = mo < 8 ? mo : 8;
    for (int pass = 0; pass < 10; pass++) {
        /* the frame needs the sphere through the surface, not its fine shape: order
           8 at most at first (45 terms: the normal equations 26 times cheaper than
           order 20's) until the frame moves less than 10 um, then the full order
           (the sphere through an order-8 cone sat 0.25 mm short in R) */
        rc = recon_once(g, spots, n, &p, model, cap, 15, z, err, errcap);
        if (rc) return rc;
        iters += z->iterations;
        if (cap < mo && z->order >= cap) {
            /* the cap binds: the data ask for more than order 8 can carry, and the
               sphere through a surface that misses them is no frame (a cone on a
               9.5 mm zone: chi2/dof 5e5 at order 8, the frame walked 1.9 mm down
               in R with the apex 0.77 mm in, to chi2/dof 4e3 and the ISO
               comparison -75 um off); the full order from this frame */
            cap = mo;
            pass--;
            continue;
        }
        double a, b, c;
        if (sphere_of(z, &a, &b, &c, &R)) { snprintf(err, errcap, "no sphere through the surface"); return CN_EFIT; }
        /* the centre back in the rig: T + M (a, b, c), M's rows from cn_to_eye */
        double e[3] = {a, b, c}, T[3], o[3], moved = 0;
        for (int i = 0; i < 3; i++) T[i] = apex0[i] + p.p[CN_DX + i];
        cn_to_eye(&p, apex0, T, o);
        for (int i = 0; i < 3; i++) {
            double x[3] = {T[0], T[1], T[2]}, row[3];
            x[i] += 1;
            cn_to_eye(&p, apex0, x, row);
            C[i] = T[i] + (row[0] - o[0]) * e[0] + (row[1] - o[1]) * e[1] + (row[2] - o[2]) * e[2];
        }
        /* the next frame: the sphere's own (apex = centre - R z), no tilt */
        double old[4] = {p.p[CN_DX], p.p[CN_DY], p.p[CN_DZ], p.p[CN_R]};
        memset(&p, 0, sizeof p);
        for (int i = 0; i < 3; i++) p.p[CN_DX + i] = C[i] - apex0[i] - (i == 2 ? R : 0);
        p.p[CN_R] = R;
        model = CN_SPHERE;
        for (int i = 0; i < 3; i++) moved += fabs(p.p[CN_DX + i] - old[i]);
        moved += fabs(R - old[3]);
        if (cap < mo && moved < 1e-2) cap = mo;
        else if (cap == mo && moved < 1e-3) break;
    }
    /* the instrument's axis through the sphere: x = y = 0 (about the nominal apex) */
    double ux = C[0] - apex0[0], uy = C[1] - apex0[1], q = R * R - ux * ux - uy * uy;
    if (!(q > 0)) { snprintf(err, errcap, "the surface's sphere misses the instrument's axis"); return CN_EFIT; }
    memset(&p, 0, sizeof p);
    p.p[CN_R] = R;
    p.p[CN_DZ] = C[2] - apex0[2] - sqrt(q);
    rc = recon_once(g, spots, n, &p, CN_SPHERE, max_order, 40, z, err, errcap);
    if (rc) return rc;
    z->iterations += iters;
    return rc;
}
