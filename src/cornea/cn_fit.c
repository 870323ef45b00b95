/* cn_fit.c -- the weighted nonlinear least-squares fit of cornea and eye pose to the
 * detector spots (GSL multifit_nlinear, trust region with Levenberg-Marquardt steps,
 * central-difference Jacobian), robust outlier rejection by normalised residuals,
 * and the predicted accuracy of a scan before it is run. */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_multifit_nlinear.h>
#include "cn_int.h"

typedef struct fctx {
    int model, nf, idx[CN_NPARAM], n;
    const int *use;                 /* spots fitted */
    const cn_spot *s;
    const cn_plane *pl;
    const double *apex0;
    cn_params base;
    int threads;                    /* residuals and Jacobian rows over this many */
    int converged;                  /* the last solve met a stopping test (else it ran
                                       into max_iter or GSL failed) */
    int best_converged;             /* of the solution kept */
    int tie_q;                      /* Q steep follows Q flat (its column left out) */
    double sd[CN_NPARAM];           /* after a solve: each free parameter's sd */
    int max_it;                     /* most iterations of one solve */
    int fwd_diff;                   /* the solver's Jacobian: one-sided differences */
} fctx;

static double cn_norm2(const gsl_vector *f)
{
    double s = 0;
    for (size_t i = 0; i < f->size; i++) s += gsl_vector_get(f, i) * gsl_vector_get(f, i);
    return s;
}

static void unpack(const fctx *c, const gsl_vector *x, cn_params *p)
{
    *p = c->base;
    for (int k = 0; k < c->nf; k++) p->p[c->idx[k]] = gsl_vector_get(x, k);
    if (c->tie_q) p->p[CN_QS] = p->p[CN_QF];
}

/* Rows [i0, i1) of the residuals (J NULL) or of the Jacobian (f NULL) at p: every
 * spot's rows depend on that spot alone, so the split over threads changes no bit. */
/* The solver's Jacobian row of spot s: one-sided differences (1 + nfree forward
 * models a spot against central differences' 2 nfree; the forward model is most of
 * a fit's time).  Only the trust region's steps use it: a step's accuracy needs no
 * more, each step is checked against the exact residuals, and the covariance and
 * the analysis take central differences at the solution.  Q steep tied to Q flat:
 * Q flat's column moves both.  0 or -1 (a miss). */
static int jac_fwd(const fctx *c, const cn_params *p, const cn_spot *s, double *ru, double *rv)
{
    double u0, v0;
    if (cn_forward(c->model, p, c->apex0, c->pl, &s->ray, &u0, &v0, NULL, NULL)) return -1;
    for (int k = 0; k < c->nf; k++) {
        int q = c->idx[k];
        cn_params a = *p;
        double h = cn_step[q], ua, va;
        a.p[q] += h;
        if (c->tie_q && q == CN_QF) a.p[CN_QS] += h;
        if (cn_forward(c->model, &a, c->apex0, c->pl, &s->ray, &ua, &va, NULL, NULL)) return -1;
        ru[k] = (ua - u0) / h / s->sigma;
        rv[k] = (va - v0) / h / s->sigma;
    }
    return 0;
}

static void rows(const fctx *c, const cn_params *p, int i0, int i1, gsl_vector *f,
                 gsl_matrix *J)
{
    double ru[CN_NPARAM], rv[CN_NPARAM];
    for (int i = i0; i < i1; i++) {
        const cn_spot *s = &c->s[c->use[i]];
        if (J && c->fwd_diff) {
            if (jac_fwd(c, p, s, ru, rv)) memset(ru, 0, sizeof ru), memset(rv, 0, sizeof rv);
            for (int k = 0; k < c->nf; k++) {
                gsl_matrix_set(J, 2 * i, k, ru[k]);
                gsl_matrix_set(J, 2 * i + 1, k, rv[k]);
            }
            continue;
        }
        if (J) {
            if (c->tie_q) {     /* Q flat's column carries Q steep's, which follows it */
                int id2[CN_NPARAM + 1], qf = -1;
                double u2[CN_NPARAM + 1], v2[CN_NPARAM + 1];
                memcpy(id2, c->idx, sizeof *id2 * (size_t)c->nf);
                id2[c->nf] = CN_QS;
                for (int k = 0; k < c->nf; k++) if (c->idx[k] == CN_QF) qf = k;
                if (cn_jacobian(c->model, p, c->apex0, c->pl, s, id2, c->nf + 1, u2, v2))
                    memset(u2, 0, sizeof u2), memset(v2, 0, sizeof v2);
                memcpy(ru, u2, sizeof *ru * (size_t)c->nf);
                memcpy(rv, v2, sizeof *rv * (size_t)c->nf);
                if (qf >= 0) { ru[qf] += u2[c->nf]; rv[qf] += v2[c->nf]; }
            } else if (cn_jacobian(c->model, p, c->apex0, c->pl, s, c->idx, c->nf, ru, rv))
                memset(ru, 0, sizeof ru), memset(rv, 0, sizeof rv);
            for (int k = 0; k < c->nf; k++) {
                gsl_matrix_set(J, 2 * i, k, ru[k]);
                gsl_matrix_set(J, 2 * i + 1, k, rv[k]);
            }
            continue;
        }
        double u, v;
        if (cn_forward(c->model, p, c->apex0, c->pl, &s->ray, &u, &v, NULL, NULL)) {
            u = s->u + 10; v = s->v + 10;   /* a miss: a large residual turns the
                                               trust region back */
        }
        gsl_vector_set(f, 2 * i, (u - s->u) / s->sigma);
        gsl_vector_set(f, 2 * i + 1, (v - s->v) / s->sigma);
    }
}

typedef struct rows_job {
    const fctx *c;
    const cn_params *p;
    int i0, i1;
    gsl_vector *f;
    gsl_matrix *J;
} rows_job;

static void *rows_thread(void *arg)
{
    rows_job *j = arg;
    rows(j->c, j->p, j->i0, j->i1, j->f, j->J);
    return NULL;
}

/* All rows, on c->threads threads when there are enough spots to pay for them (the
 * calling thread takes the first share; a thread that cannot start leaves its share
 * to the caller). */
static void all_rows(const fctx *c, const gsl_vector *x, gsl_vector *f, gsl_matrix *J)
{
    enum { MAXT = 16, MIN_PER_THREAD = 64 };
    cn_params p;
    unpack(c, x, &p);
    int nt = c->threads < 1 ? 1 : c->threads > MAXT ? MAXT : c->threads;
    if (nt > c->n / MIN_PER_THREAD) nt = c->n / MIN_PER_THREAD > 1 ? c->n / MIN_PER_THREAD : 1;
    pthread_t tid[MAXT];
    rows_job job[MAXT];
    int started[MAXT] = {0};
    for (int t = 1; t < nt; t++) {
        job[t] = (rows_job){c, &p, (int)((long)c->n * t / nt), (int)((long)c->n * (t + 1) / nt),
                            f, J};
        started[t] = pthread_create(&tid[t], NULL, rows_thread, &job[t]) == 0;
    }
    rows(c, &p, 0, (int)((long)c->n / nt), f, J);
    for (int t = 1; t < nt; t++) {
        if (started[t]) pthread_join(tid[t], NULL);
        else rows(c, &p, job[t].i0, job[t].i1, f, J);
    }
}

static int f_res(const gsl_vector *x, void *data, gsl_vector *f)
{
    all_rows(data, x, f, NULL);
    return GSL_SUCCESS;
}

static int f_jac(const gsl_vector *x, void *data, gsl_matrix *J)
{
    all_rows(data, x, NULL, J);
    return GSL_SUCCESS;
}

/* The residual map's test: the mean correlation of each spot's normalised residual
 * vector with its nearest neighbour's on the cornea (rx: x, y, ru, rv per spot).
 * Noise gives ~0 (sd about 1/sqrt(n)); a shape the model lacks (a cone) gives
 * neighbours that miss alike, near 1.  O(n^2) (10 000 spots: 1e8 distances), so the
 * stop callback is polled every 256 spots: NaN when it asks to stop. */
static double cn_resid_corr(const double *rx, int n, int (*stop)(void *), void *sctx)
{
    double num = 0, den = 0;
    for (int i = 0; i < n; i++) {
        if ((i & 255) == 0 && stop && stop(sctx)) return NAN;
        const double *a = &rx[4 * i];
        double best = INFINITY;
        int bj = -1;
        for (int j = 0; j < n; j++) {
            if (j == i) continue;
            double d = (rx[4 * j] - a[0]) * (rx[4 * j] - a[0]) +
                       (rx[4 * j + 1] - a[1]) * (rx[4 * j + 1] - a[1]);
            if (d < best) { best = d; bj = j; }
        }
        if (bj < 0) continue;
        num += a[2] * rx[4 * bj + 2] + a[3] * rx[4 * bj + 3];
        den += a[2] * a[2] + a[3] * a[3];
    }
    return den > 0 ? num / den : 0;
}

static int solve(fctx *c, cn_params *p, int max_iter, int (*stop)(void *), void *sctx);

static double chi2_of(const fctx *c, const cn_params *p)
{
    double s = 0;
    for (int i = 0; i < c->n; i++) {
        const cn_spot *sp = &c->s[c->use[i]];
        double u, v;
        if (cn_forward(c->model, p, c->apex0, c->pl, &sp->ray, &u, &v, NULL, NULL))
            return INFINITY;
        s += ((u - sp->u) * (u - sp->u) + (v - sp->v) * (v - sp->v)) / (sp->sigma * sp->sigma);
    }
    return s;
}

/* Shifting the eye across and tilting it about its centre of curvature look alike
 * (the dy / tilt_x valley of a nearly spherical cornea), and a fit can stop in the
 * valley away from the truth.  When the first solution is poor (chi^2 more than 4 sd
 * above its dof), solve again from starts turned about the start's centre of
 * curvature by +-3 deg about x and about y, and keep the lowest chi^2.  Returns the
 * iterations spent or CN_ESTOP. */
static int valley_restarts(fctx *c, const cn_params *start, cn_params *best, int max_iter,
                           int (*stop)(void *), void *sctx)
{
    int dof = 2 * c->n - c->nf, iters = 0;
    double cb = chi2_of(c, best);
    if (dof <= 0 || !((cb - dof) / sqrt(2.0 * dof) > 4)) return 0;
    /* past chi2/dof 100 the model misses the surface itself, not a valley's minimum: a
       cone through the biconic spent 1386 of its 1428 iterations in these restarts
       for a chi2 0.06 % lower, of a model then rejected */
    if (cb > 100.0 * dof) return 0;
    const double a = 3 * M_PI / 180;
    const double turns[4][2] = {{a, 0}, {-a, 0}, {0, a}, {0, -a}};
    double R = start->p[CN_R];
    for (int t = 0; t < 4; t++) {
        cn_params q = *start;
        double tx0 = q.p[CN_TX], ty0 = q.p[CN_TY];
        double tx = tx0 + turns[t][0], ty = ty0 + turns[t][1];
        /* centre of curvature T + R Rot(tx, ty) z: kept where the start has it */
        double c0[3] = {sin(ty0) * cos(tx0), -sin(tx0), cos(ty0) * cos(tx0)};
        double c1[3] = {sin(ty) * cos(tx), -sin(tx), cos(ty) * cos(tx)};
        for (int i = 0; i < 3; i++) q.p[CN_DX + i] += R * (c0[i] - c1[i]);
        q.p[CN_TX] = tx;
        q.p[CN_TY] = ty;
        int rc = solve(c, &q, max_iter, stop, sctx);
        if (rc == CN_ESTOP) return rc;
        if (rc < 0) continue;
        iters += rc;
        double cq = chi2_of(c, &q);
        if (cq < cb) { cb = cq; *best = q; c->best_converged = c->converged; }
    }
    return iters;
}

static int cmpd(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* One trust-region solve over the spots in use; returns iterations or CN_E*. */
static int solve(fctx *c, cn_params *p, int max_iter, int (*stop)(void *), void *sctx)
{
    gsl_multifit_nlinear_fdf fdf;
    gsl_multifit_nlinear_parameters prm = gsl_multifit_nlinear_default_parameters();
    /* Levenberg-Marquardt with geodesic acceleration: plain LM needed 46 iterations on
     * a 0.25 D toric eye from frames with shot noise (the damping shrinks slowly in
     * the valley of nearly alike pose and shape directions), with it 24, the same
     * minimum; dogleg took 13 there but 1000+ on a cone (a misfit model) */
    prm.trs = gsl_multifit_nlinear_trs_lmaccel;
    prm.scale = gsl_multifit_nlinear_scale_more;
    fdf.f = f_res;
    fdf.df = f_jac;
    fdf.fvv = NULL;
    fdf.n = 2 * (size_t)c->n;
    fdf.p = c->nf;
    fdf.params = c;
    c->base = *p;
    gsl_multifit_nlinear_workspace *w =
        gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, &prm, fdf.n, fdf.p);
    gsl_vector *x = gsl_vector_alloc(c->nf);
    if (!w || !x) { if (w) gsl_multifit_nlinear_free(w); gsl_vector_free(x); return CN_ENOMEM; }
    for (int k = 0; k < c->nf; k++) gsl_vector_set(x, k, p->p[c->idx[k]]);
    c->fwd_diff = 1;
    gsl_multifit_nlinear_init(x, &fdf, w);
    int it, rc = 0, small = 0;
    double chi2 = cn_norm2(gsl_multifit_nlinear_residual(w));
    c->converged = 0;
    for (it = 0; it < max_iter; it++) {
        if (stop && stop(sctx)) { rc = CN_ESTOP; break; }
        int st = gsl_multifit_nlinear_iterate(w);
        if (st == GSL_ENOPROG) { c->converged = 1; break; }   /* no step lowers chi^2 */
        if (st) break;
        int info;
        if (gsl_multifit_nlinear_test(1e-12, 1e-12, 0, &info, w) == GSL_SUCCESS) {
            it++;
            c->converged = 1;
            break;
        }
        /* chi^2 no longer falls: two accepted steps in a row each lower it by less
         * than 1e-4 (its own sd is sqrt(2 dof), >= 1: the parameters then sit within
         * ~1e-2 of their sd of the minimum; on a sphere, whose pose the spots cannot
         * tell, 1e-6 let the fit wander 141 iterations along the pose valley).  The step tests above ask for 1e-12 and,
         * with a central-difference Jacobian in a shallow valley (shot noise, zero
         * cylinder), crawl on for hundreds of iterations that change nothing. */
        /* On a model that misfits (a cone through the biconic: chi2/dof 1e3 and more)
         * the same test in the misfit's units: the parameters' sd scale with
         * sqrt(chi2/dof), chi2's steps with chi2/dof, and 1e-4 absolute crawled 5016
         * iterations on a 10 um cone with 0.04 px noise; past chi2/dof 100 (a model
         * that fails its test by far: nothing of it is reported) to 0.1 of the
         * inflated sd, not 0.01: the same cone then takes 175 iterations, not 1428. */
        double c2 = cn_norm2(gsl_multifit_nlinear_residual(w));
        int dof = 2 * c->n - c->nf;
        double tol = (c2 > 100.0 * dof ? 1e-2 : 1e-4) * fmax(1, dof > 0 ? c2 / dof : 1);
        small = chi2 - c2 < tol ? small + 1 : 0;
        chi2 = c2;
        if (small >= 2) {
            it++;
            c->converged = 1;
            break;
        }
    }
    c->fwd_diff = 0;
    unpack(c, w->x, p);
    if (it > c->max_it) c->max_it = it;
    gsl_matrix *cv = gsl_matrix_alloc(c->nf, c->nf);
    for (int k = 0; k < CN_NPARAM; k++) c->sd[k] = INFINITY;
    if (cv && !gsl_multifit_nlinear_covar(gsl_multifit_nlinear_jac(w), 1e-12, cv))
        for (int k = 0; k < c->nf; k++) c->sd[c->idx[k]] = sqrt(gsl_matrix_get(cv, k, k));
    if (cv) gsl_matrix_free(cv);
    gsl_multifit_nlinear_free(w);
    gsl_vector_free(x);
    return rc ? rc : it;
}

int cn_fit(const rg_geometry *g, cn_spot *spots, int n, const cn_params *start,
           const cn_fit_opts *o, cn_result *res, char *err, size_t errcap)
{
    cn_fit_opts d = {0};
    if (!o) o = &d;
    memset(res, 0, sizeof *res);
    if (o->model < CN_SPHERE || o->model > CN_ASPHERE || n < 0) {
        snprintf(err, errcap, "bad fit options (model %d, %d spots)", o->model, n);
        return CN_EINVAL;
    }
    cn_plane pl;
    cn_plane_of(g, &pl);
    const double *apex0 = g->cornea.trans;
    cn_params p;
    if (start) p = *start;
    else {
        cn_params_from_cornea(&g->cornea, apex0, 0, 0, &p);
        if (o->model == CN_BICONIC && p.p[CN_C0] == 0 && p.p[CN_C45] == 0)
            p.p[CN_C0] = -1e-4;   /* off the axis singularity of zero cylinder */
    }
    if (o->model == CN_SPHERE) p.p[CN_TX] = p.p[CN_TY] = 0;
    fctx c = {.model = o->model, .s = spots, .pl = &pl, .apex0 = apex0,
              .threads = o->threads};
    cn_free_mask_q(o->model, o->fix_tilt, o->free_q, res->free);
    for (int k = 0; k < CN_NPARAM; k++) if (res->free[k]) c.idx[c.nf++] = k;
    int *use = malloc(sizeof *use * (n > 0 ? n : 1));
    double *tmp = malloc(sizeof *tmp * (n > 0 ? n : 1));
    if (!use || !tmp) { free(use); free(tmp); snprintf(err, errcap, "out of memory"); return CN_ENOMEM; }
    for (int i = 0; i < n; i++) {
        spots[i].nres = NAN;
        if (spots[i].status == CN_S_OK &&
            !(spots[i].sigma > 0 && isfinite(spots[i].u) && isfinite(spots[i].v)))
            spots[i].status = CN_S_NONE;
    }
    double k_rej = o->reject_k > 0 ? o->reject_k : 5;
    /* rejection rounds until none is new (at most 12): a local shape the model lacks
     * is carved out step by step, each refit lowering the robust scale */
    int rounds = o->reject_rounds == 0 ? 12 : o->reject_rounds < 0 ? 0 : o->reject_rounds;
    int max_iter = o->max_iter > 0 ? o->max_iter : 1000;
    int rc = 0, iters = 0, q_tied = 0;
    for (int round = 0;; round++) {
        c.n = 0;
        for (int i = 0; i < n; i++) if (spots[i].status == CN_S_OK) use[c.n++] = i;
        c.use = use;
        if (2 * c.n < c.nf + 1) {
            snprintf(err, errcap, "%d usable spots: too few for %d parameters", c.n, c.nf);
            rc = CN_EFIT;
            goto out;
        }
        cn_params p0 = p;
        if (round == 0 && o->model == CN_BICONIC && res->free[CN_QS]) {
            /* first one Q for both meridians: which meridian is flat is not defined
             * at zero cylinder, so there Q flat and Q steep trade places as the
             * axis swings and the trust region crawled (544 iterations on a
             * 1000-spot sphere-like eye, 1759 in issue 19); from that solution, the
             * two Q free (16 iterations more on it) */
            fctx c1 = c;
            c1.nf = 0;
            for (int k = 0; k < c.nf; k++) if (c.idx[k] != CN_QS) c1.idx[c1.nf++] = c.idx[k];
            c1.tie_q = 1;
            rc = solve(&c1, &p, max_iter, o->stop, o->stop_ctx);
            if (rc == CN_ESTOP) { snprintf(err, errcap, "stopped"); goto out; }
            if (rc > 0) iters += rc;
            if (c1.max_it > c.max_it) c.max_it = c1.max_it;
            p0 = p;
            /* a cylinder within 4 of its sd of zero: no meridian is flat, the two Q
             * cannot be told apart and the full fit only crawls about the axis
             * (1000 iterations unconverged on a sphere): one Q is the answer */
            double cyl = hypot(p.p[CN_C0], p.p[CN_C45]);
            double sdc = hypot(c1.sd[CN_C0], c1.sd[CN_C45]);
            if (c1.converged && !(cyl > 4 * sdc)) {
                q_tied = 1;
                c.nf = c1.nf;
                memcpy(c.idx, c1.idx, sizeof c.idx);
                c.tie_q = 1;
                res->free[CN_QS] = 0;
                c.converged = 1;
                rc = 0;
                goto solved;
            }
        }
        rc = solve(&c, &p, max_iter, o->stop, o->stop_ctx);
    solved:
        if (rc < 0) { snprintf(err, errcap, rc == CN_ESTOP ? "stopped" : "fit failed"); goto out; }
        iters += rc;
        rc = 0;
        c.best_converged = c.converged;
        if (round == 0 && res->free[CN_TX] && res->free[CN_TY]) {
            int more = valley_restarts(&c, &p0, &p, max_iter, o->stop, o->stop_ctx);
            if (more < 0) { snprintf(err, errcap, "stopped"); rc = more; goto out; }
            iters += more;
            }
        /* normalised residuals; robust scale from their median (Rayleigh: 1.1774) */
        int m = 0;
        for (int i = 0; i < c.n; i++) {
            cn_spot *s = &spots[use[i]];
            double u, v;
            if (cn_forward(o->model, &p, apex0, &pl, &s->ray, &u, &v, NULL, NULL)) {
                s->status = CN_S_MISS;
                continue;
            }
            s->nres = hypot(u - s->u, v - s->v) / s->sigma;
            tmp[m++] = s->nres;
        }
        if (round >= rounds || m == 0) break;
        qsort(tmp, m, sizeof *tmp, cmpd);
        double scale = tmp[m / 2] / 1.1774;
        double thr = k_rej * fmax(scale, 0.5);
        int nrej = 0;
        for (int i = 0; i < c.n; i++) {
            cn_spot *s = &spots[use[i]];
            if (s->status == CN_S_OK && s->nres > thr) { s->status = CN_S_OUTLIER; nrej++; }
        }
        if (!nrej) break;
    }
    /* the analysis at the solution */
    c.n = 0;
    for (int i = 0; i < n; i++) if (spots[i].status == CN_S_OK) use[c.n++] = i;
    int M = 2 * c.n;
    double *J = malloc(sizeof *J * (size_t)M * c.nf);
    if (!J) { snprintf(err, errcap, "out of memory"); rc = CN_ENOMEM; goto out; }
    double chi2 = 0, ss = 0, hmax = 0;
    double *rx = malloc(sizeof *rx * 4 * (size_t)(c.n > 0 ? c.n : 1));   /* x y ru rv */
    if (!rx) { free(J); snprintf(err, errcap, "out of memory"); rc = CN_ENOMEM; goto out; }
    for (int i = 0; i < c.n; i++) {
        const cn_spot *s = &spots[use[i]];
        double u, v, at[3], e[3];
        cn_forward(o->model, &p, apex0, &pl, &s->ray, &u, &v, at, NULL);
        cn_to_eye(&p, apex0, at, e);
        hmax = fmax(hmax, hypot(e[0], e[1]));
        rx[4 * i] = e[0];
        rx[4 * i + 1] = e[1];
        rx[4 * i + 2] = (u - s->u) / s->sigma;
        rx[4 * i + 3] = (v - s->v) / s->sigma;
        ss += (u - s->u) * (u - s->u) + (v - s->v) * (v - s->v);
        chi2 += s->nres * s->nres;
    }
    {   /* the Jacobian rows as the solver saw them (Q steep tied: in Q flat's) */
        gsl_vector_view xv;
        double xs[CN_NPARAM];
        for (int k = 0; k < c.nf; k++) xs[k] = p.p[c.idx[k]];
        xv = gsl_vector_view_array(xs, (size_t)c.nf);
        gsl_matrix_view Jv = gsl_matrix_view_array(J, (size_t)M, (size_t)c.nf);
        c.base = p;
        c.use = use;
        all_rows(&c, &xv.vector, NULL, &Jv.matrix);
    }
    cn_svd a = {.nfree = c.nf};
    memcpy(a.idx, c.idx, sizeof a.idx);
    rc = cn_analyse(J, M, o->model, &p, o->rcond > 0 ? o->rcond : 1e-9, &a);
    free(J);
    if (rc) { snprintf(err, errcap, "too few spots to analyse the fit"); goto out; }
    res->model = o->model;
    res->nused = c.n;
    res->nrejected = n - c.n;
    res->iterations = iters;
    res->converged = c.best_converged;
    if (q_tied) {           /* Q steep is Q flat: the same number, the same sd */
        for (int k = 0; k < CN_NPARAM; k++) {
            res->cov[CN_QS * CN_NPARAM + k] = res->cov[CN_QF * CN_NPARAM + k];
            res->cov[k * CN_NPARAM + CN_QS] = res->cov[k * CN_NPARAM + CN_QF];
        }
        res->cov[CN_QS * (CN_NPARAM + 1)] = res->cov[CN_QF * (CN_NPARAM + 1)];
        size_t l = strlen(res->why);
        if (l + 160 < sizeof res->why)
            snprintf(res->why + l, sizeof res->why - l, "one Q for both meridians: the "
                     "cylinder is within 4 sd of zero, no meridian is the flat one\n");
    }
    res->max_solve_iter = c.max_it;
    res->inflation = 1;
    res->rms = c.n ? sqrt(ss / c.n) : NAN;
    res->chi2_dof = M > c.nf ? chi2 / (M - c.nf) : NAN;
    res->par = p;
    res->hmax = hmax;
    res->resid_corr = cn_resid_corr(rx, c.n, o->stop, o->stop_ctx);
    free(rx);
    if (isnan(res->resid_corr)) { snprintf(err, errcap, "stopped"); rc = CN_ESTOP; goto out; }
    res->nfree = c.nf;
    memcpy(res->idx, c.idx, sizeof res->idx);
    memcpy(res->sv, a.sv, sizeof a.sv);
    memcpy(res->vt, a.vt, sizeof a.vt);
    memcpy(res->cov, a.cov, sizeof a.cov);
    res->cond = a.cond;
    res->undetermined = a.undetermined;
    memcpy(res->why, a.why, sizeof a.why);
    /* many outliers: the robust test carved a region out of the scan (a cone, a
     * scar), or the scan is bad; the numbers describe the surface without it */
    int nout = 0, nin = 0;
    for (int i = 0; i < n; i++) {
        nout += spots[i].status == CN_S_OUTLIER;
        nin += spots[i].status == CN_S_OK || spots[i].status == CN_S_OUTLIER;
    }
    if (nin > 0 && nout > 0.1 * nin) {
        size_t l = strlen(res->why);
        if (l + 230 < sizeof res->why)
            snprintf(res->why + l, sizeof res->why - l, "MANY OUTLIERS: %d of %d spots "
                     "(%.0f %%) rejected by the robust test: a local shape the model lacks "
                     "(a cone?) or a bad scan; the numbers describe the surface without "
                     "them (see the residual map)\n", nout, nin, 100.0 * nout / nin);
    }
    /* chi^2 test: a fit far above its noise is a local minimum, the wrong model or
     * a sigma too small; what its weakest direction mixes is then not trustworthy */
    int dof = M - c.nf;
    res->chi2_z = dof > 0 ? (chi2 - dof) / sqrt(2.0 * dof) : 0;
    if (!res->converged) {   /* no minimum: nothing below describes it */
        size_t l = strlen(res->why);
        if (l + 120 > sizeof res->why) l = sizeof res->why - 120;
        snprintf(res->why + l, sizeof res->why - l, "NOT CONVERGED: the fit stopped at its "
                 "cap of %d iterations, not at a minimum: no number of it is a result\n",
                 max_iter);
        for (int q = 0; q < c.nf; q++) {
            res->undetermined |= 1u << c.idx[q];
            res->cov[c.idx[q] * (CN_NPARAM + 1)] = INFINITY;
        }
    } else if (res->chi2_z > 4) {
        res->poor = 1;
        size_t l = strlen(res->why);
        if (l + 480 > sizeof res->why) l = sizeof res->why - 480;   /* room for this */
        l += snprintf(res->why + l, sizeof res->why - l,
                      "POOR FIT: chi2/dof %.3g, %.1f sd above 1: the model does not fit "
                      "the spots within their noise\n", res->chi2_dof, res->chi2_z);
        if (res->resid_corr > 0.3) {
            /* the wrong model (a cone, a shape it lacks): no uncertainty of its
             * parameters means anything, scaled or not (a cone's Q came out -3.56
             * +- 0.03 against a truth of -0.26); none is given */
            res->rejected_model = 1;
            for (int q = 0; q < c.nf; q++) {
                res->undetermined |= 1u << c.idx[q];
                res->cov[c.idx[q] * (CN_NPARAM + 1)] = INFINITY;
            }
            snprintf(res->why + l, sizeof res->why - l, "SYSTEMATIC RESIDUALS: neighbour "
                     "correlation %.2f: the model misses a shape of the surface (a local "
                     "steepening?): see the residual map; MODEL REJECTED: its numbers are "
                     "not reported\n", res->resid_corr);
        } else {
            /* residuals like noise, only larger: the spots' sigma is too small (or a
             * few bad spots); the honest uncertainty is the covariance scaled by
             * chi^2/dof, sd by its root */
            res->inflation = sqrt(res->chi2_dof);
            for (int i = 0; i < CN_NPARAM * CN_NPARAM; i++)
                if (isfinite(res->cov[i])) res->cov[i] *= res->chi2_dof;
            l += snprintf(res->why + l, sizeof res->why - l, "residuals not correlated "
                          "between neighbours (%.2f): the spots' sigma is too small or "
                          "there are outliers; UNCERTAINTIES INFLATED by sqrt(chi2/dof) = "
                          "%.3g", res->resid_corr, res->inflation);
            int over = 0;
            for (int q = 0; q < c.nf; q++) {
                int k = c.idx[q];
                if (!(sqrt(res->cov[k * (CN_NPARAM + 1)]) > cn_limit(k))) continue;
                if (l + 40 < sizeof res->why)
                    l += snprintf(res->why + l, sizeof res->why - l, "%s %s",
                                  over++ ? "" : "; then over their limits:",
                                  cn_param_name(k));
                res->undetermined |= 1u << k;
                res->cov[k * (CN_NPARAM + 1)] = INFINITY;
            }
            if (l + 1 < sizeof res->why) strcat(res->why, "\n");
        }
    }
    cn_clinical_of(o->model, &p, res->cov, res->undetermined, &res->k);
out:
    free(use);
    free(tmp);
    return rc;
}

int cn_predict_scan(const rg_geometry *g, const cn_spot *spots, int n, int model,
                    int fix_tilt, const cn_params *p, double sigma, cn_predict *pr,
                    char *err, size_t errcap)
{
    cn_plane pl;
    int free_[CN_NPARAM];
    memset(pr, 0, sizeof *pr);
    cn_plane_of(g, &pl);
    cn_free_mask_q(model, fix_tilt, 0, free_);
    cn_svd a = {0};
    for (int k = 0; k < CN_NPARAM; k++) if (free_[k]) a.idx[a.nfree++] = k;
    double *J = malloc(sizeof *J * 2 * (size_t)(n > 0 ? n : 1) * a.nfree);
    if (!J) { snprintf(err, errcap, "out of memory"); return CN_ENOMEM; }
    int m = 0;
    for (int i = 0; i < n; i++) {
        cn_spot s = spots[i];
        if (s.status != CN_S_OK && s.status != CN_S_OUTLIER) continue;
        if (sigma > 0) s.sigma = sigma;
        if (!(s.sigma > 0)) continue;
        if (cn_jacobian(model, p, g->cornea.trans, &pl, &s, a.idx, a.nfree,
                        &J[m * a.nfree], &J[(m + 1) * a.nfree]) == CN_OK)
            m += 2;
    }
    int rc = cn_analyse(J, m, model, p, 1e-9, &a);
    free(J);
    if (rc) { snprintf(err, errcap, "%d usable spots: too few to predict", m / 2); return rc; }
    pr->nfree = a.nfree;
    memcpy(pr->idx, a.idx, sizeof a.idx);
    memcpy(pr->sv, a.sv, sizeof a.sv);
    memcpy(pr->vt, a.vt, sizeof a.vt);
    pr->cond = a.cond;
    for (int k = 0; k < CN_NPARAM; k++) pr->sd[k] = sqrt(a.cov[k * CN_NPARAM + k]);
    pr->undetermined = a.undetermined;
    memcpy(pr->why, a.why, sizeof pr->why);
    cn_clinical_of(model, p, a.cov, a.undetermined, &pr->k);
    return CN_OK;
}

const char *cn_report(const cn_result *r, char *buf, size_t cap)
{
    static const char *const mn[] = {"sphere", "conic", "biconic", "asphere"};
    const cn_clinical *k = &r->k;
    size_t l = 0;
#define OUT(...) do { if (l < cap) l += snprintf(buf + l, cap - l, __VA_ARGS__); } while (0)
    if (cap) buf[0] = 0;
    OUT("model %s: %d spots fitted, %d left out, %d iterations, residual RMS %.3g um, "
        "chi2/dof %.3g\n", mn[r->model], r->nused, r->nrejected, r->iterations,
        r->rms * 1000, r->chi2_dof);
    if (r->rejected_model || !r->converged) {
        /* numbers without meaning are not printed, with or without a +- */
        OUT("%s: R, Q, K, cylinder, power and the eye's pose not reported\n",
            r->converged ? "the model is rejected" : "the fit did not converge");
        if (r->why[0]) OUT("%s", r->why);
        return buf;
    }
    if (r->free[CN_QF] || r->model == CN_SPHERE)
        OUT("apex radius R %.5f +- %.5f mm   Q %.4f +- %.4f\n", k->R, k->sd_R, k->Q, k->sd_Q);
    else
        OUT("apex radius R %.5f +- %.5f mm   Q %.4f (held)\n", k->R, k->sd_R, k->Q);
    if (r->model == CN_ASPHERE)
        OUT("asphere A4 %.5g +- %.2g mm^-3   A6 %.5g +- %.2g mm^-5%s\n", r->par.p[CN_A4],
            sqrt(r->cov[CN_A4 * (CN_NPARAM + 1)]), r->par.p[CN_A6],
            sqrt(r->cov[CN_A6 * (CN_NPARAM + 1)]), r->free[CN_QF] ? "" : "   (Q held)");
    if (r->model == CN_BICONIC)
        OUT("R flat %.5f +- %.5f mm (Q %.4f +- %.4f)   R steep %.5f +- %.5f mm "
            "(Q %.4f +- %.4f)\n", k->R_flat, k->sd_R_flat, k->Q_flat, k->sd_Q_flat,
            k->R_steep, k->sd_R_steep, k->Q_steep, k->sd_Q_steep);
    if (r->model == CN_BICONIC) {
        OUT("Sim K (n 1.3375): K1 %.3f +- %.3f D @ %.1f   K2 %.3f +- %.3f D @ %.1f   "
            "axis +- %.2f deg\n", k->K1, k->sd_K1, k->K1_axis, k->K2, k->sd_K2,
            k->K2_axis, k->sd_axis);
        OUT("mean K %.3f +- %.3f D   cylinder %.3f +- %.3f D @ %.1f   corneal power "
            "(n 1.376) %.3f +- %.3f D\n", k->Km, k->sd_Km, k->cyl, k->sd_cyl, k->K2_axis,
            k->P, k->sd_P);
    } else
        OUT("K (n 1.3375) %.3f +- %.3f D (no cylinder in this model)   corneal power "
            "(n 1.376) %.3f +- %.3f D\n", k->Km, k->sd_Km, k->P, k->sd_P);
    if (r->model == CN_BICONIC)
        OUT("Sim K 3 mm zone: K1 %.3f +- %.3f D @ %.1f   K2 %.3f +- %.3f D @ %.1f   mean "
            "%.3f +- %.3f D   cylinder %.3f +- %.3f D", k->zK1, k->sd_zK1, k->zK1_axis,
            k->zK2, k->sd_zK2, k->zK2_axis, k->zKm, k->sd_zKm, k->zcyl, k->sd_zcyl);
    else
        OUT("Sim K 3 mm zone: mean %.3f +- %.3f D", k->zKm, k->sd_zKm);
    if (r->hmax < k->zone_h) OUT("   (extrapolated: data to %.2f mm)", r->hmax);
    OUT("\n");
    OUT("eye: apex shift %.4f %.4f %.4f mm (+- %.4f %.4f %.4f), tilt %.3f %.3f deg "
        "(+- %.3f %.3f)\n", k->dx, k->dy, k->dz, k->sd_dx, k->sd_dy, k->sd_dz, k->tx,
        k->ty, k->sd_tx, k->sd_ty);
    OUT("singular values (scaled columns):");
    for (int i = 0; i < r->nfree; i++) OUT(" %.3g", r->sv[i]);
    OUT("   condition %.3g\n", r->cond);
    if (r->why[0]) OUT("%s", r->why);
#undef OUT
    return buf;
}
