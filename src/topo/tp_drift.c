/* tp_drift.c -- fixation drift (doc/scan-time.md): the eye moving during a scan.  For
 * simulation, the true eye of each point is displaced by the drift at the point's
 * exposure time (slow: linear over the scan; a saccade: one jump at its middle).  For
 * detection (any scan with exposure times, real eyes too), after the fit: the spots
 * are cut into time segments, and for each segment the eye translation (x, y, z of
 * the apex) that best explains that segment's residuals is solved by linearised
 * least squares (the model's Jacobian by central differences), with its covariance
 * scaled by the fit's chi^2/dof when above 1; the segments' translations are then
 * tested against one common pose (chi^2 with 3 (S - 1) degrees of freedom).  A scan
 * is flagged when that test fails at p < 0.001 and the segments spread by more than
 * 2 um laterally.  Points close in time are close on the eye (the scan visits
 * neighbours in turn), so a segment's translation could also absorb a local misfit of
 * the model: the scaling by chi^2/dof and the 2 um floor keep a cone from reading as
 * drift (measured: doc/scan-time.md). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "tp_int.h"

static double drift_at(const tp_run *r, double t)
{
    const tp_drift *d = &r->drift;
    double T = r->sc.sim_s;
    if (d->kind == TP_DRIFT_NONE || !isfinite(t) || !(T > 0)) return 0;
    if (d->kind == TP_DRIFT_LINEAR) return d->amp * fmin(1, fmax(0, t / T));
    return t >= 0.5 * T ? d->amp : 0;
}

void tp_drift_eye(const tp_run *r, const tp_point *q, rg_geometry *gt, cn_params *tp)
{
    double a = drift_at(r, q->t_s), dx = a * cos(r->drift.dir), dy = a * sin(r->drift.dir);
    if (a == 0) return;
    if (gt) { gt->cornea.trans[0] += dx; gt->cornea.trans[1] += dy; }
    if (tp) { tp->p[CN_DX] += dx; tp->p[CN_DY] += dy; }
}

typedef struct ts { double t; int k; } ts;

static int by_t(const void *a, const void *b)
{
    const ts *x = a, *y = b;
    return x->t < y->t ? -1 : x->t > y->t ? 1 : x->k - y->k;
}

/* 3x3 inverse (symmetric positive definite); 0, or -1 when singular. */
static int inv3(const double a[9], double b[9])
{
    double c0 = a[4] * a[8] - a[5] * a[7], c1 = a[5] * a[6] - a[3] * a[8],
           c2 = a[3] * a[7] - a[4] * a[6], det = a[0] * c0 + a[1] * c1 + a[2] * c2;
    if (!(fabs(det) > 0) || !isfinite(det)) return -1;
    b[0] = c0 / det; b[3] = c1 / det; b[6] = c2 / det;
    b[1] = (a[2] * a[7] - a[1] * a[8]) / det;
    b[4] = (a[0] * a[8] - a[2] * a[6]) / det;
    b[7] = (a[1] * a[6] - a[0] * a[7]) / det;
    b[2] = (a[1] * a[5] - a[2] * a[4]) / det;
    b[5] = (a[2] * a[3] - a[0] * a[5]) / det;
    b[8] = (a[0] * a[4] - a[1] * a[3]) / det;
    return 0;
}

/* Upper tail of chi^2 with k degrees of freedom (Wilson-Hilferty: good to a few per
 * cent of p in the tail for k >= 3, enough for a 0.001 threshold). */
static double chi2_q(double x, int k)
{
    double h = 2.0 / (9 * k), z = (cbrt(x / k) - (1 - h)) / sqrt(h);
    return 0.5 * erfc(z / sqrt(2));
}

int tp_drift_test(tp_run *r)
{
    tp_drift *d = &r->drift;
    const cornea_api *cn = r->cn;
    cn_plane pl;
    int n = 0;
    d->segments = 0;
    d->flagged = 0;
    d->chi2 = d->p = d->range = NAN;
    d->dof = 0;
    if (!r->fitted) return 0;
    ts *o = malloc(sizeof *o * (size_t)(r->npoints ? r->npoints : 1));
    if (!o) return CN_ENOMEM;
    for (int k = 0; k < r->npoints; k++) {
        const tp_point *q = &r->pt[k];
        if (q->planned && q->spot.status == CN_S_OK && isfinite(q->t_s) && q->spot.sigma > 0)
            o[n++] = (ts){q->t_s, k};
    }
    int S = n / 25 < TP_DRIFT_SEGMENTS ? n / 25 : TP_DRIFT_SEGMENTS;
    if (S < 2) { free(o); return 0; }
    qsort(o, (size_t)n, sizeof *o, by_t);
    cn->plane(r->g, &pl);
    const double *apex0 = r->g->cornea.trans, h = 1e-4;
    double scale = r->res.chi2_dof > 1 ? r->res.chi2_dof : 1;
    double Ci[TP_DRIFT_SEGMENTS][9], sumCi[9] = {0}, sumb[3] = {0};
    int seg_ok = 0;
    for (int s = 0; s < S; s++) {
        double A[9] = {0}, b[3] = {0}, C[9];
        int lo = s * n / S, hi = (s + 1) * n / S;
        d->t0[s] = o[lo].t;
        d->t1[s] = o[hi - 1].t;
        for (int i = lo; i < hi; i++) {
            const tp_point *q = &r->pt[o[i].k];
            double mu, mv, J[2][3], w = 1 / (q->spot.sigma * q->spot.sigma);
            if (cn->forward(r->model, &r->res.par, apex0, &pl, &q->spot.ray, &mu, &mv, NULL, NULL))
                continue;
            int bad = 0;
            for (int c = 0; c < 3 && !bad; c++) {
                cn_params p1 = r->res.par, p2 = r->res.par;
                double u1, v1, u2, v2;
                p1.p[CN_DX + c] += h;
                p2.p[CN_DX + c] -= h;
                if (cn->forward(r->model, &p1, apex0, &pl, &q->spot.ray, &u1, &v1, NULL, NULL) ||
                    cn->forward(r->model, &p2, apex0, &pl, &q->spot.ray, &u2, &v2, NULL, NULL))
                    bad = 1;
                J[0][c] = (u1 - u2) / (2 * h);
                J[1][c] = (v1 - v2) / (2 * h);
            }
            if (bad) continue;
            double res[2] = {q->spot.u - mu, q->spot.v - mv};
            for (int a = 0; a < 3; a++) {
                for (int c = 0; c < 3; c++) A[a * 3 + c] += w * (J[0][a] * J[0][c] + J[1][a] * J[1][c]);
                b[a] += w * (J[0][a] * res[0] + J[1][a] * res[1]);
            }
        }
        if (inv3(A, C)) { free(o); return 0; }
        for (int a = 0; a < 3; a++) {
            d->d[s][a] = C[a * 3] * b[0] + C[a * 3 + 1] * b[1] + C[a * 3 + 2] * b[2];
            d->sd[s][a] = sqrt(C[a * 4] * scale);
        }
        for (int a = 0; a < 9; a++) { Ci[s][a] = A[a] / scale; sumCi[a] += Ci[s][a]; }
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++) sumb[a] += Ci[s][a * 3 + c] * d->d[s][c];
        seg_ok++;
    }
    free(o);
    double Cm[9], mean[3];
    if (seg_ok < 2 || inv3(sumCi, Cm)) return 0;
    for (int a = 0; a < 3; a++) mean[a] = Cm[a * 3] * sumb[0] + Cm[a * 3 + 1] * sumb[1] + Cm[a * 3 + 2] * sumb[2];
    double chi2 = 0, range = 0;
    for (int s = 0; s < S; s++) {
        double e[3] = {d->d[s][0] - mean[0], d->d[s][1] - mean[1], d->d[s][2] - mean[2]};
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++) chi2 += e[a] * Ci[s][a * 3 + c] * e[c];
        for (int t = 0; t < s; t++) {
            double l = hypot(d->d[s][0] - d->d[t][0], d->d[s][1] - d->d[t][1]);
            if (l > range) range = l;
        }
    }
    d->segments = S;
    d->chi2 = chi2;
    d->dof = 3 * (S - 1);
    d->p = chi2_q(chi2, d->dof);
    d->range = range;
    d->flagged = d->p < 1e-3 && range > 2e-3;
    return 0;
}
