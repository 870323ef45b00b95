/* tp_drift.c -- fixation drift (doc/scan-time.md): the eye moving during a scan.  For
 * simulation, the true eye of each point is displaced by the drift at the point's
 * exposure time (slow: linear over the scan; a saccade: one jump at its middle).  For
 * detection (any scan with exposure times, real eyes too), after the model's fit: the
 * fitted spots cut into time segments (up to TP_DRIFT_SEGMENTS, 20 spots or more
 * each) and the model refitted with a pose per segment, block by block (each
 * segment's eye translation x, y, z from its residuals by linearised least squares,
 * the model's Jacobian by central differences; every spot corrected by its segment's
 * translation less their weighted mean; the shape refitted, outliers rejected; until
 * the translations settle, at most 8 rounds).  The translations are then tested
 * against one common pose (chi^2 with 3 (S - 1) degrees of freedom, the covariance
 * scaled by the joint fit's chi^2/dof when above 1).  The scan visits neighbours in
 * turn, so points close in time are close on the eye and a segment's translation can
 * also absorb a local misfit of the model (a cone): drift is flagged only when the
 * poses differ (p < 0.001, more than 2 um apart laterally) and a pose per segment
 * explains the misfit (the joint fit's chi^2/dof under TP_DRIFT_CHI2_MAX, or under a
 * twentieth of the one-pose fit's); else the report says the two cannot be told apart. */
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

/* Each segment's eye translation from the residuals of the spots o[lo..hi) against
 * parameters p (linearised: the model's Jacobian by central differences), into d
 * and its inverse covariance Ci (unscaled); the Jacobians kept in J (2 x 3 per spot,
 * for the correction).  0, or -1 when singular. */
static int segment(const tp_run *r, const cn_plane *pl, const cn_params *p, const ts *o,
                   int lo, int hi, const cn_spot *sp, double (*J)[2][3], double d[3],
                   double Ci[9])
{
    const cornea_api *cn = r->cn;
    const double *apex0 = r->g->cornea.trans, h = 1e-4;
    double A[9] = {0}, b[3] = {0}, C[9];
    for (int i = lo; i < hi; i++) {
        const cn_spot *q = &sp[o[i].k];
        double mu, mv, w = 1 / (q->sigma * q->sigma);
        memset(J[i], 0, sizeof J[i]);
        if (q->status != CN_S_OK ||
            cn->forward(r->model, p, apex0, pl, &q->ray, &mu, &mv, NULL, NULL))
            continue;
        int bad = 0;
        for (int c = 0; c < 3 && !bad; c++) {
            cn_params p1 = *p, p2 = *p;
            double u1, v1, u2, v2;
            p1.p[CN_DX + c] += h;
            p2.p[CN_DX + c] -= h;
            if (cn->forward(r->model, &p1, apex0, pl, &q->ray, &u1, &v1, NULL, NULL) ||
                cn->forward(r->model, &p2, apex0, pl, &q->ray, &u2, &v2, NULL, NULL)) {
                bad = 1;
                break;
            }
            J[i][0][c] = (u1 - u2) / (2 * h);
            J[i][1][c] = (v1 - v2) / (2 * h);
        }
        if (bad) { memset(J[i], 0, sizeof J[i]); continue; }
        double res[2] = {q->u - mu, q->v - mv};
        for (int a = 0; a < 3; a++) {
            for (int c = 0; c < 3; c++) A[a * 3 + c] += w * (J[i][0][a] * J[i][0][c] + J[i][1][a] * J[i][1][c]);
            b[a] += w * (J[i][0][a] * res[0] + J[i][1][a] * res[1]);
        }
    }
    if (inv3(A, C)) return -1;
    for (int a = 0; a < 3; a++) d[a] = C[a * 3] * b[0] + C[a * 3 + 1] * b[1] + C[a * 3 + 2] * b[2];
    memcpy(Ci, A, sizeof A);
    return 0;
}

/* The drift test: the model refitted with a pose per time segment (block by block:
 * each segment's translation from its residuals, every spot corrected by its
 * segment's translation less their weighted mean, the shape refitted, until the
 * translations settle), then the segments' translations against one pose. */
int tp_drift_test(tp_run *r)
{
    tp_drift *d = &r->drift;
    const cornea_api *cn = r->cn;
    cn_plane pl;
    int n = 0, np = r->npoints, rc = 0;
    d->segments = 0;
    d->flagged = 0;
    d->chi2 = d->p = d->range = d->joint_chi2_dof = NAN;
    d->dof = 0;
    d->joint_fitted = 0;
    if (!r->fitted) return 0;
    ts *o = malloc(sizeof *o * (size_t)(np ? np : 1));
    cn_spot *sp0 = malloc(sizeof *sp0 * (size_t)(np ? np : 1));
    cn_spot *sp = malloc(sizeof *sp * (size_t)(np ? np : 1));
    double (*J)[2][3] = malloc(sizeof *J * (size_t)(np ? np : 1));
    cn_result *res = malloc(sizeof *res);
    if (!o || !sp0 || !sp || !J || !res) { rc = CN_ENOMEM; goto out; }
    /* the fitted spots in time order (their statuses after the model's fit) */
    for (int k = 0; k < np; k++) {
        const tp_point *q = &r->pt[k];
        if (q->planned && q->spot.status == CN_S_OK && isfinite(q->t_s) && q->spot.sigma > 0) {
            o[n] = (ts){q->t_s, n};
            sp0[n++] = q->spot;
        }
    }
    int S = n / 20 < TP_DRIFT_SEGMENTS ? n / 20 : TP_DRIFT_SEGMENTS;
    if (S < 2) goto out;
    qsort(o, (size_t)n, sizeof *o, by_t);
    cn->plane(r->g, &pl);
    cn_params p = r->res.par;
    double Ci[TP_DRIFT_SEGMENTS][9], dd[TP_DRIFT_SEGMENTS][3], tot[TP_DRIFT_SEGMENTS][3];
    memset(tot, 0, sizeof tot);
    *res = r->res;
    memcpy(sp, sp0, sizeof *sp * (size_t)n);
    for (int it = 0; it < 8; it++) {
        double sumCi[9] = {0}, sumb[3] = {0}, Cm[9], mean[3], step = 0;
        for (int s = 0; s < S; s++) {
            if (segment(r, &pl, &p, o, s * n / S, (s + 1) * n / S, sp, J, dd[s], Ci[s])) goto out;
            for (int a = 0; a < 9; a++) sumCi[a] += Ci[s][a];
            for (int a = 0; a < 3; a++)
                for (int c = 0; c < 3; c++) sumb[a] += Ci[s][a * 3 + c] * dd[s][c];
        }
        if (inv3(sumCi, Cm)) goto out;
        for (int a = 0; a < 3; a++) mean[a] = Cm[a * 3] * sumb[0] + Cm[a * 3 + 1] * sumb[1] + Cm[a * 3 + 2] * sumb[2];
        /* each spot corrected by its segment's translation relative to the mean (the
           mean is the model's own decentration) */
        for (int s = 0; s < S; s++)
            for (int i = s * n / S; i < (s + 1) * n / S; i++) {
                cn_spot *q = &sp[o[i].k];
                double e[3] = {dd[s][0] - mean[0], dd[s][1] - mean[1], dd[s][2] - mean[2]};
                q->u -= J[i][0][0] * e[0] + J[i][0][1] * e[1] + J[i][0][2] * e[2];
                q->v -= J[i][1][0] * e[0] + J[i][1][1] * e[1] + J[i][1][2] * e[2];
            }
        for (int s = 0; s < S; s++)
            for (int a = 0; a < 3; a++) {
                tot[s][a] += dd[s][a] - mean[a];
                step = fmax(step, fabs(dd[s][a] - mean[a]));
            }
        /* (the spots of a segment that holds a saccade sit at two poses: the fit's
           outlier rejection takes out the ones its segment's pose does not explain) */
        cn_fit_opts fo = {.model = r->model, .stop = r->stop, .stop_ctx = r->stop_ctx,
                          .threads = r->threads, .max_iter = r->max_iter};
        char e[256];
        int frc = cn->fit(r->g, sp, n, &p, &fo, res, e, sizeof e);
        if (frc == CN_ESTOP) { rc = CN_ESTOP; goto out; }
        if (frc || !res->converged) goto out;
        p = res->par;
        if (step < 1e-6) break;
    }
    /* the translations against one pose, with the joint fit's scale */
    double scale = res->chi2_dof > 1 ? res->chi2_dof : 1, chi2 = 0, range = 0;
    double sumCi[9] = {0}, sumb[3] = {0}, Cm[9], mean[3], C[9];
    for (int s = 0; s < S; s++) {
        for (int a = 0; a < 9; a++) { Ci[s][a] /= scale; sumCi[a] += Ci[s][a]; }
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++) sumb[a] += Ci[s][a * 3 + c] * tot[s][c];
    }
    if (inv3(sumCi, Cm)) goto out;
    for (int a = 0; a < 3; a++) mean[a] = Cm[a * 3] * sumb[0] + Cm[a * 3 + 1] * sumb[1] + Cm[a * 3 + 2] * sumb[2];
    for (int s = 0; s < S; s++) {
        double e[3] = {tot[s][0] - mean[0], tot[s][1] - mean[1], tot[s][2] - mean[2]};
        for (int a = 0; a < 3; a++)
            for (int c = 0; c < 3; c++) chi2 += e[a] * Ci[s][a * 3 + c] * e[c];
        if (inv3(Ci[s], C)) goto out;
        for (int a = 0; a < 3; a++) {
            d->d[s][a] = tot[s][a] - mean[a];
            d->sd[s][a] = sqrt(C[a * 4]);
        }
        d->t0[s] = o[s * n / S].t;
        d->t1[s] = o[(s + 1) * n / S - 1].t;
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
    d->joint = *res;
    d->joint_fitted = 1;
    d->joint_chi2_dof = res->chi2_dof;
    d->single_chi2_dof = r->res.chi2_dof;
    /* drift: the poses differ, by more than 2 um, and a pose per segment explains the
       spots (the joint fit within twice the noise: else the model itself misfits) */
    d->flagged = d->p < 1e-3 && range > 2e-3 &&
                 (res->chi2_dof < TP_DRIFT_CHI2_MAX || res->chi2_dof < 0.05 * r->res.chi2_dof);
out:
    free(o); free(sp0); free(sp); free(J); free(res);
    return rc;
}
