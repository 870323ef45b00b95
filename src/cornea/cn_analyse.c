/* cn_analyse.c -- what a scan determines: the weighted Jacobian of the detector
 * positions with respect to the free parameters (central differences, steps sized
 * for each parameter), its SVD with columns scaled to unit norm (singular values,
 * condition number, the singular directions), the covariance by the truncated
 * pseudo-inverse, which parameters are not determined and why, and the clinical
 * numbers with their propagated uncertainties. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <gsl/gsl_linalg.h>
#include "cn_int.h"

/* Difference steps: small against each parameter's scale, large against rounding
 * of ~65 mm paths (1e-14 mm), so central differences keep ~9 digits. */
const double cn_step[CN_NPARAM] = {1e-5, 1e-7, 1e-7, 1e-4, 1e-4,
                                   1e-5, 1e-5, 1e-5, 1e-6, 1e-6, 1e-7, 1e-8};
/* A parameter whose uncertainty exceeds its limit is "not determined": a number
 * with that error bar is no measurement (R 50 um, cylinder components 0.5 D,
 * Q 0.2, position 0.1 mm, tilt 2 deg; A4 5e-5 mm^-3, the s^4 term of Q 0.2 at R
 * 7.8, and A6 2e-5 mm^-5, the same height as that A4 at s = 1.5 mm). */
static const double limit[CN_NPARAM] = {0.05, 0.5 / 337.5, 0.5 / 337.5, 0.2, 0.2,
                                        0.1, 0.1, 0.1, 0.035, 0.035, 5e-5, 2e-5};

double cn_limit(int k) { return k >= 0 && k < CN_NPARAM ? limit[k] : 0; }

void cn_free_mask_q(int model, int fix_tilt, int free_q, int free[CN_NPARAM])
{
    cn_free_mask(model, fix_tilt, free);
    if (model == CN_ASPHERE) free[CN_QF] = free_q != 0;
}

void cn_free_mask(int model, int fix_tilt, int free[CN_NPARAM])
{
    for (int k = 0; k < CN_NPARAM; k++) free[k] = 0;
    free[CN_R] = free[CN_DX] = free[CN_DY] = free[CN_DZ] = 1;
    if (model == CN_SPHERE) return;    /* a sphere's tilt is its decentration */
    free[CN_QF] = 1;
    if (!fix_tilt) free[CN_TX] = free[CN_TY] = 1;
    if (model == CN_BICONIC) free[CN_C0] = free[CN_C45] = free[CN_QS] = 1;
    if (model == CN_ASPHERE) free[CN_A4] = free[CN_A6] = 1;   /* Q: cn_free_mask_q */
}

int cn_jacobian(int model, const cn_params *p, const double apex0[3], const cn_plane *pl,
                const cn_spot *s, const int *idx, int nfree, double *row_u, double *row_v)
{
    for (int c = 0; c < nfree; c++) {
        int k = idx[c];
        cn_params a = *p, b = *p;
        double h = cn_step[k], ua, va, ub, vb;
        a.p[k] += h;
        b.p[k] -= h;
        if (cn_forward(model, &a, apex0, pl, &s->ray, &ua, &va, NULL, NULL) ||
            cn_forward(model, &b, apex0, pl, &s->ray, &ub, &vb, NULL, NULL))
            return CN_EFIT;
        row_u[c] = (ua - ub) / (2 * h) / s->sigma;
        row_v[c] = (va - vb) / (2 * h) / s->sigma;
    }
    return CN_OK;
}

static void addwhy(char *why, const char *fmt, double a, double b, const char *name)
{
    size_t l = strlen(why);
    if (l + 80 < 512) snprintf(why + l, 512 - l, fmt, name, a, b);
}

int cn_analyse(const double *J, int m, int model, const cn_params *p, double rcond,
               cn_svd *a)
{
    (void)model;
    int nf = a->nfree;
    a->undetermined = 0;
    a->why[0] = 0;
    memset(a->cov, 0, sizeof a->cov);
    if (m < nf || nf == 0) return CN_EFIT;
    gsl_matrix *A = gsl_matrix_alloc(m, nf), *V = gsl_matrix_alloc(nf, nf);
    gsl_vector *S = gsl_vector_alloc(nf), *w = gsl_vector_alloc(nf);
    if (!A || !V || !S || !w) {
        gsl_matrix_free(A); gsl_matrix_free(V); gsl_vector_free(S); gsl_vector_free(w);
        return CN_ENOMEM;
    }
    double norm[CN_NPARAM];
    for (int c = 0; c < nf; c++) {
        double s = 0;
        for (int i = 0; i < m; i++) s += J[i * nf + c] * J[i * nf + c];
        norm[c] = s > 0 ? sqrt(s) : 1;
    }
    for (int i = 0; i < m; i++)
        for (int c = 0; c < nf; c++) gsl_matrix_set(A, i, c, J[i * nf + c] / norm[c]);
    gsl_linalg_SV_decomp(A, V, S, w);
    double s0 = gsl_vector_get(S, 0);
    for (int k = 0; k < nf; k++) {
        a->sv[k] = gsl_vector_get(S, k);
        for (int c = 0; c < nf; c++) a->vt[k * nf + c] = gsl_matrix_get(V, c, k);
    }
    a->cond = a->sv[nf - 1] > 0 ? s0 / a->sv[nf - 1] : INFINITY;
    /* covariance: truncated pseudo-inverse, back in parameter units */
    unsigned bad = 0;
    for (int k = 0; k < nf; k++) {
        const double *v = &a->vt[k * nf];
        if (!(a->sv[k] > rcond * s0)) {
            char dir[256] = "";
            for (int c = 0; c < nf; c++)
                if (fabs(v[c]) > 0.1) {
                    bad |= 1u << a->idx[c];
                    size_t l = strlen(dir);
                    snprintf(dir + l, sizeof dir - l, " %+.2f %s", v[c],
                             cn_param_name(a->idx[c]));
                }
            size_t l = strlen(a->why);
            snprintf(a->why + l, sizeof a->why - l,
                     "not determined: singular value %.2g of %.2g along%s\n",
                     a->sv[k], s0, dir);
            continue;
        }
        for (int i = 0; i < nf; i++)
            for (int j = 0; j < nf; j++)
                a->cov[a->idx[i] * CN_NPARAM + a->idx[j]] +=
                    v[i] * v[j] / (a->sv[k] * a->sv[k]) / (norm[i] * norm[j]);
    }
    for (int c = 0; c < nf; c++) {
        int k = a->idx[c];
        double sd = sqrt(a->cov[k * CN_NPARAM + k]);
        if (bad & (1u << k)) continue;
        if (sd > limit[k]) {
            bad |= 1u << k;
            addwhy(a->why, "not determined: %s uncertainty %.3g > limit %.3g\n", sd,
                   limit[k], cn_param_name(k));
        }
    }
    if (bad && a->cond > 1e3) {         /* name the weakest combination too */
        const double *v = &a->vt[(nf - 1) * nf];
        char dir[256] = "";
        for (int c = 0; c < nf; c++)
            if (fabs(v[c]) > 0.1) {
                size_t l = strlen(dir);
                snprintf(dir + l, sizeof dir - l, " %+.2f %s", v[c],
                         cn_param_name(a->idx[c]));
            }
        size_t l = strlen(a->why);
        snprintf(a->why + l, sizeof a->why - l,
                 "weakest direction (condition %.3g):%s\n", a->cond, dir);
    }
    for (int k = 0; k < CN_NPARAM; k++)
        if (bad & (1u << k)) a->cov[k * CN_NPARAM + k] = INFINITY;
    a->undetermined = bad;
    (void)p;
    gsl_matrix_free(A); gsl_matrix_free(V); gsl_vector_free(S); gsl_vector_free(w);
    return CN_OK;
}

/* Clinical values of a parameter vector. */
enum { V_R, V_Q, V_RF, V_RS, V_QF, V_QS, V_K1, V_K2, V_AX, V_KM, V_CYL, V_P,
       V_DX, V_DY, V_DZ, V_TX, V_TY, V_ZK1, V_ZK2, V_ZAX, V_ZKM, V_ZCYL, V_N };
#define ZONE_H 1.5                     /* the 3 mm zone's ring (mm) */
static void values(int model, const cn_params *p, double v[V_N])
{
    cn_surf s;
    cn_surface(model, p, &s);
    double kn = (CN_KERATO_N - 1) * 1000, cn = (CN_CORNEA_N - 1) * 1000;
    v[V_R] = p->p[CN_R];
    v[V_Q] = s.qf;
    v[V_RF] = 1 / s.cf;
    v[V_RS] = 1 / s.cs;
    v[V_QF] = s.qf;
    v[V_QS] = s.qs;
    v[V_K1] = kn * s.cf;
    v[V_K2] = kn * s.cs;
    v[V_AX] = s.alpha * 180 / M_PI;
    v[V_KM] = kn * (s.cf + s.cs) / 2;
    v[V_CYL] = kn * (s.cs - s.cf);
    v[V_P] = cn * (s.cf + s.cs) / 2;
    v[V_DX] = p->p[CN_DX];
    v[V_DY] = p->p[CN_DY];
    v[V_DZ] = p->p[CN_DZ];
    v[V_TX] = p->p[CN_TX] * 180 / M_PI;
    v[V_TY] = p->p[CN_TY] * 180 / M_PI;
    double km, amp, steep;
    if (cn_zone_simk(&s, ZONE_H, &km, &amp, &steep)) km = amp = steep = NAN;
    v[V_ZKM] = kn * km;
    v[V_ZK1] = kn * (km - amp);
    v[V_ZK2] = kn * (km + amp);
    v[V_ZCYL] = kn * 2 * amp;
    v[V_ZAX] = fmod(steep + 90, 180);      /* the flat meridian */
}

void cn_clinical_of(int model, const cn_params *p, const double *cov,
                    unsigned undetermined, cn_clinical *k)
{
    double v[V_N], g[CN_NPARAM][V_N], sd[V_N];
    values(model, p, v);
    for (int j = 0; j < CN_NPARAM; j++) {
        double a[V_N], b[V_N];
        cn_params pa = *p, pb = *p;
        pa.p[j] += cn_step[j];
        pb.p[j] -= cn_step[j];
        values(model, &pa, a);
        values(model, &pb, b);
        for (int i = 0; i < V_N; i++) {
            double d = a[i] - b[i];
            if (i == V_AX || i == V_ZAX) d = remainder(d, 180.0);   /* axes wrap */
            g[j][i] = d / (2 * cn_step[j]);
        }
    }
    for (int i = 0; i < V_N; i++) {
        double s = 0;
        int inf = 0;
        for (int a = 0; a < CN_NPARAM; a++) {
            if (g[a][i] == 0) continue;
            if (undetermined & (1u << a)) { inf = 1; break; }
            for (int b = 0; b < CN_NPARAM; b++)
                if (g[b][i] != 0 && !(undetermined & (1u << b)))
                    s += g[a][i] * cov[a * CN_NPARAM + b] * g[b][i];
        }
        sd[i] = inf ? INFINITY : sqrt(fmax(s, 0));
    }
    k->R = v[V_R]; k->sd_R = sd[V_R];
    k->Q = v[V_Q]; k->sd_Q = sd[V_Q];
    k->R_flat = v[V_RF]; k->sd_R_flat = sd[V_RF];
    k->R_steep = v[V_RS]; k->sd_R_steep = sd[V_RS];
    k->Q_flat = v[V_QF]; k->sd_Q_flat = sd[V_QF];
    k->Q_steep = v[V_QS]; k->sd_Q_steep = sd[V_QS];
    k->K1 = v[V_K1]; k->sd_K1 = sd[V_K1];
    k->K2 = v[V_K2]; k->sd_K2 = sd[V_K2];
    if (model == CN_BICONIC) {
        k->K1_axis = v[V_AX];
        k->K2_axis = fmod(v[V_AX] + 90, 180);
        k->sd_axis = sd[V_AX];
    } else
        k->K1_axis = k->K2_axis = k->sd_axis = NAN;
    k->Km = v[V_KM]; k->sd_Km = sd[V_KM];
    k->cyl = v[V_CYL]; k->sd_cyl = sd[V_CYL];
    k->P = v[V_P]; k->sd_P = sd[V_P];
    k->dx = v[V_DX]; k->sd_dx = sd[V_DX];
    k->dy = v[V_DY]; k->sd_dy = sd[V_DY];
    k->dz = v[V_DZ]; k->sd_dz = sd[V_DZ];
    k->tx = v[V_TX]; k->sd_tx = sd[V_TX];
    k->ty = v[V_TY]; k->sd_ty = sd[V_TY];
    k->zone_h = ZONE_H;
    k->zK1 = v[V_ZK1]; k->sd_zK1 = sd[V_ZK1];
    k->zK2 = v[V_ZK2]; k->sd_zK2 = sd[V_ZK2];
    k->zKm = v[V_ZKM]; k->sd_zKm = sd[V_ZKM];
    k->zcyl = v[V_ZCYL]; k->sd_zcyl = sd[V_ZCYL];
    if (model == CN_BICONIC) {
        k->zK1_axis = v[V_ZAX];
        k->zK2_axis = fmod(v[V_ZAX] + 90, 180);
        k->sd_zaxis = sd[V_ZAX];
    } else
        k->zK1_axis = k->zK2_axis = k->sd_zaxis = NAN;
}
