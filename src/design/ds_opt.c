/* ds_opt.c -- damped least squares over the problem's variables: GSL's
 * gsl_multifit_nlinear trust-region driver with the Levenberg-Marquardt step (or
 * Levenberg-Marquardt with geodesic acceleration, `design method lmaccel`), More's
 * scaling, the Jacobian by forward differences of the merit's residuals.  We run the
 * iterations ourselves (gsl_multifit_nlinear_iterate) so that every iteration can be
 * reported with its time and a stop request honoured between two evaluations.
 *
 * Why the unknowns are scaled (value / scale, ds_read.c): GSL's finite-difference
 * step is sqrt(eps) |x| (sqrt(eps) at 0); a curvature of 0.04/mm and a thickness of
 * 40 mm then get steps of the same relative size, and an aspheric term that starts
 * at 0 a step that means something in its own units. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_multifit_nlinear.h>
#include "ds_int.h"

double ds_get_var(const ds_problem *p, int i)
{
    const ds_var *v = &p->var[i];
    const ln_surface *s = &p->lens.surf[v->surf];
    double nd = 0, vd = 0;
    switch (v->kind) {
    case DV_C: return isfinite(s->r) ? s->c : 0;
    case DV_T: return s->t;
    case DV_K: return s->conic;
    case DV_A: return s->asph[v->term];
    default:
        sscanf(s->glass, "%lf/%lf", &nd, &vd);
        return v->kind == DV_ND ? nd : vd;
    }
}

/* Keep a model glass on the glass map (the catalogue's convex hull in (Vd/100, nd)):
 * a hard bound, as a designer's model-glass limits are.  axis 1: only nd moves
 * (clamped to the hull's span at this Vd), 0: only Vd, 2: both (nearest point). */
static void on_map(const ds_problem *p, double *nd, double *vd, int axis)
{
    const double *h = p->hull;
    double x = *vd / 100, y = *nd, lo = INFINITY, hi = -INFINITY, bx = x, by = y, best = INFINITY;
    int inside = p->nhull >= 3;
    if (p->nhull < 3) return;
    for (int i = 0; i < p->nhull; i++) {
        const double *a = h + 2 * i, *b = h + 2 * ((i + 1) % p->nhull);
        double ex = b[0] - a[0], ey = b[1] - a[1];
        if (ex * (y - a[1]) - ey * (x - a[0]) < 0) inside = 0;
        /* the edge's crossing of the line nd = y (axis 0) or Vd = x (axis 1) */
        double u0 = axis == 1 ? a[0] : a[1], u1 = axis == 1 ? b[0] : b[1], u = axis == 1 ? x : y;
        if ((u0 <= u && u <= u1) || (u1 <= u && u <= u0)) {
            double t = u1 != u0 ? (u - u0) / (u1 - u0) : 0;
            double v = axis == 1 ? a[1] + t * ey : a[0] + t * ex;
            lo = fmin(lo, v);
            hi = fmax(hi, v);
        }
        double L2 = ex * ex + ey * ey, t = L2 > 0 ? ((x - a[0]) * ex + (y - a[1]) * ey) / L2 : 0;
        t = t < 0 ? 0 : t > 1 ? 1 : t;
        double px = a[0] + t * ex, py = a[1] + t * ey, d = hypot(x - px, y - py);
        if (d < best) { best = d; bx = px; by = py; }
    }
    if (inside) return;
    if (axis == 1 && lo <= hi) *nd = fmin(fmax(y, lo), hi);
    else if (axis == 0 && lo <= hi) *vd = 100 * fmin(fmax(x, lo), hi);
    else { *nd = by; *vd = 100 * bx; }
}

void ds_set_var(ds_problem *p, int i, double x)
{
    const ds_var *v = &p->var[i];
    ln_surface *s = &p->lens.surf[v->surf];
    double nd = 0, vd = 0;
    switch (v->kind) {
    case DV_C: ln_set_curvature(s, x); break;
    case DV_T: s->t = x; break;
    case DV_K: s->conic = x; break;
    case DV_A: s->asph[v->term] = x; break;
    default:
        sscanf(s->glass, "%lf/%lf", &nd, &vd);
        if (v->kind == DV_ND) nd = x; else vd = x;
        {
            int both = 0;
            for (int j = 0; j < p->nvar; j++)
                if (j != i && p->var[j].surf == v->surf &&
                    (p->var[j].kind == DV_ND || p->var[j].kind == DV_VD)) both = 1;
            on_map(p, &nd, &vd, both ? 2 : v->kind == DV_ND ? 1 : 0);
        }
        /* the model glass's formula holds inside these (px_glass_model) */
        nd = fmin(fmax(nd, 1.0001), 2.9999);
        vd = fmin(fmax(vd, 5), 150);
        snprintf(s->glass, sizeof s->glass, "%.17g/%.17g", nd, vd);
    }
}

typedef struct octx {
    ds_problem *p;
    double *f;                 /* room for one evaluation's residuals */
    long n;
    double penalty;
    int bad;
} octx;

static void unpack(octx *c, const gsl_vector *x)
{
    for (int i = 0; i < c->p->nvar; i++)
        ds_set_var(c->p, i, gsl_vector_get(x, (size_t)i) * c->p->var[i].scale);
}

/* A lens the merit cannot evaluate (a thickness gone negative, a ray-aiming failure
 * of the whole pupil) gets a large residual vector: the trust region then shrinks
 * and the step is refused, as OpticStudio refuses steps into impossible lenses. */
static int f_res(const gsl_vector *x, void *data, gsl_vector *f)
{
    octx *c = data;
    char why[256];
    unpack(c, x);
    if (c->p->stop && c->p->stop(c->p->stop_ctx)) { c->p->stopped = 1; return GSL_EBADFUNC; }
    /* GSL hands in Jacobian columns as f: a strided view, never f->data directly */
    int rc = ds_eval(c->p, c->f, why, sizeof why);
    if (rc == 0)
        for (long i = 0; i < c->n; i++) gsl_vector_set(f, (size_t)i, c->f[i]);
    if (rc == 1) return GSL_EBADFUNC;
    if (rc < 0) {
        for (long i = 0; i < c->n; i++) gsl_vector_set(f, (size_t)i, c->penalty);
        c->bad++;
    }
    return GSL_SUCCESS;
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

int ds_optimise(ds_problem *p, int max_iter, int (*progress)(void *, const ds_step *),
                int (*stop)(void *), void *ctx, ds_opt_result *res, char *err, size_t cap)
{
    long n = ds_nres(p);
    size_t nv = (size_t)p->nvar;
    octx c = {p, NULL, n, 0, 0};
    double t0 = now(), best = INFINITY;
    char why[512];
    int rc = DS_OK, info = 0;
    memset(res, 0, sizeof *res);
    p->stop = stop;
    p->stop_ctx = ctx;
    p->stopped = 0;
    p->evals = 0;
    if (nv == 0) { snprintf(err, cap, "%s: nothing to vary (no vary line)", p->src); return DS_BAD; }
    if ((long)nv > n) {
        snprintf(err, cap, "%s: %zu variables but only %ld residuals: add operands", p->src,
                 nv, n);
        return DS_BAD;
    }
    gsl_vector *x = gsl_vector_alloc(nv), *f0 = gsl_vector_alloc((size_t)n);
    gsl_vector *xbest = gsl_vector_alloc(nv);
    if (!x || !f0 || !xbest) {
        gsl_vector_free(x); gsl_vector_free(f0); gsl_vector_free(xbest);
        snprintf(err, cap, "out of memory");
        return DS_NOMEM;
    }
    for (size_t i = 0; i < nv; i++) gsl_vector_set(x, i, ds_get_var(p, (int)i) / p->var[i].scale);
    /* warm starts of the ray aiming, from nothing at every optimisation (so a replay,
     * which runs the same evaluations, aims every ray the same) */
    {
        size_t ng = (size_t)p->lens.nfield * (size_t)(p->lens.nwl ? p->lens.nwl : 1) *
                    (size_t)(p->rings * p->arms + 1);
        free(p->guess);
        free(p->gok);
        p->guess = malloc(sizeof(double) * 2 * (ng ? ng : 1));
        p->gok = calloc(ng ? ng : 1, 1);
        p->nguess = p->guess && p->gok ? ng : 0;
        p->warm = p->nguess > 0;
    }
    int e = ds_eval(p, f0->data, why, sizeof why);
    if (e) {
        gsl_vector_free(x); gsl_vector_free(f0); gsl_vector_free(xbest);
        if (e == 1) return DS_STOPPED;
        snprintf(err, cap, "%s: the starting lens cannot be evaluated: %s", p->src, why);
        return DS_BAD;
    }
    res->merit0 = res->merit = best = ds_merit_of(p, f0->data);
    /* the penalty: every residual as large as the start's merit, times 10 */
    c.penalty = 10 * fmax(best, 1e-6) / sqrt((double)n) * 10;
    gsl_vector_memcpy(xbest, x);

    gsl_multifit_nlinear_parameters prm = gsl_multifit_nlinear_default_parameters();
    prm.trs = p->method ? gsl_multifit_nlinear_trs_lmaccel : gsl_multifit_nlinear_trs_lm;
    prm.scale = gsl_multifit_nlinear_scale_more;
    prm.solver = gsl_multifit_nlinear_solver_qr;
    prm.fdtype = GSL_MULTIFIT_NLINEAR_FWDIFF;
    /* 1e-6 of each scaled unknown: well above the ray aiming's 1e-14 noise on spots
     * of a micrometre, well below any curvature of the merit */
    prm.h_df = 1e-6;
    snprintf(res->method, sizeof res->method, "GSL multifit_nlinear: %s, %s scaling, %s "
             "solver, forward-difference Jacobian",
             p->method ? "Levenberg-Marquardt with geodesic acceleration" :
                         "Levenberg-Marquardt", prm.scale->name, prm.solver->name);
    c.f = f0->data;
    gsl_multifit_nlinear_workspace *ws =
        gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, &prm, (size_t)n, nv);
    gsl_multifit_nlinear_fdf fdf;
    memset(&fdf, 0, sizeof fdf);
    fdf.f = f_res;
    fdf.n = (size_t)n;
    fdf.p = nv;
    fdf.params = &c;
    gsl_error_handler_t *old = gsl_set_error_handler_off();
    if (!ws || gsl_multifit_nlinear_init(x, &fdf, ws) != GSL_SUCCESS) {
        rc = p->stopped ? DS_STOPPED : DS_BAD;
        if (rc == DS_BAD) snprintf(err, cap, "%s: the least-squares solver cannot start", p->src);
        goto done;
    }
    ds_step st = {0, best, now() - t0, p->evals};
    if (progress && progress(ctx, &st)) { rc = DS_STOPPED; goto done; }
    res->reason = 3;
    double last = best;
    int flat = 0;
    for (int it = 1; it <= max_iter; it++) {
        int s = gsl_multifit_nlinear_iterate(ws);
        if (p->stopped) { rc = DS_STOPPED; res->reason = 0; break; }
        if (s != GSL_SUCCESS && s != GSL_ENOPROG) { res->reason = 4; break; }
        double m = gsl_blas_dnrm2(gsl_multifit_nlinear_residual(ws));
        if (m < best) { best = m; gsl_vector_memcpy(xbest, gsl_multifit_nlinear_position(ws)); }
        res->iterations = it;
        st.iter = it;
        st.merit = best;
        st.seconds = now() - t0;
        st.evaluations = p->evals;
        if (progress && progress(ctx, &st)) { rc = DS_STOPPED; res->reason = 0; break; }
        if (s == GSL_ENOPROG) { res->reason = 4; break; }
        if (gsl_multifit_nlinear_test(1e-15, 1e-30, 0, &info, ws) == GSL_SUCCESS) {
            res->reason = info == 1 ? 1 : 2;
            break;
        }
        /* ten iterations without a relative gain of 1e-9: done */
        if (best > last * (1 - 1e-9)) { if (++flat >= 10) { res->reason = 4; break; } }
        else flat = 0;
        last = best;
    }
done:
    gsl_set_error_handler(old);
    /* leave the lens at the best point reached (GSL's position may be a refused trial) */
    for (size_t i = 0; i < nv; i++)
        ds_set_var(p, (int)i, gsl_vector_get(xbest, i) * p->var[i].scale);
    p->stop = NULL;
    p->warm = 0;
    if (rc == DS_OK || rc == DS_STOPPED) {
        int e2 = ds_eval(p, NULL, why, sizeof why);
        (void)e2;
    }
    res->merit = best;
    res->seconds = now() - t0;
    res->evaluations = p->evals;
    if (ws) gsl_multifit_nlinear_free(ws);
    gsl_vector_free(x);
    gsl_vector_free(f0);
    gsl_vector_free(xbest);
    return rc;
}
