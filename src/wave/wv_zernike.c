/* wv_zernike.c -- Zernike polynomials in three orderings (Fringe 1..37, Noll 1..,
 * ANSI Z80.28 0..), their names, and the least-squares fit of a pupil's W (GSL's
 * SVD least squares, gsl_multifit_linear).  Fringe terms are unnormalised (1 at the
 * rim, as OpticStudio's Fringe coefficients); Noll and ANSI terms have unit RMS over
 * the unit disc, so their coefficients are RMS waves. */
#include <gsl/gsl_multifit.h>
#include <math.h>
#include <string.h>
#include "wv_int.h"

/* Fringe (University of Arizona) ordering, terms 1..37: (n, m). */
static const signed char fringe_nm[37][2] = {
    {0, 0}, {1, 1}, {1, -1}, {2, 0}, {2, 2}, {2, -2}, {3, 1}, {3, -1}, {4, 0},
    {3, 3}, {3, -3}, {4, 2}, {4, -2}, {5, 1}, {5, -1}, {6, 0}, {4, 4}, {4, -4},
    {5, 3}, {5, -3}, {6, 2}, {6, -2}, {7, 1}, {7, -1}, {8, 0}, {5, 5}, {5, -5},
    {6, 4}, {6, -4}, {7, 3}, {7, -3}, {8, 2}, {8, -2}, {9, 1}, {9, -1}, {10, 0},
    {12, 0}};

int wv_zernike_nm(int order, int j, int *n, int *m)
{
    if (order == WAVE_Z_FRINGE) {
        if (j < 1 || j > 37) return WAVE_EINVAL;
        *n = fringe_nm[j - 1][0];
        *m = fringe_nm[j - 1][1];
        return WAVE_OK;
    }
    if (order == WAVE_Z_ANSI) {
        if (j < 0 || j > 10000) return WAVE_EINVAL;
        int nn = 0;
        while (nn * (nn + 3) / 2 < j) nn++;         /* j = (n(n+2)+m)/2, |m| <= n */
        *n = nn;
        *m = 2 * j - nn * (nn + 2);
        return WAVE_OK;
    }
    if (order == WAVE_Z_NOLL) {
        if (j < 1 || j > 10000) return WAVE_EINVAL;
        int nn = 0;
        while ((nn + 1) * (nn + 2) / 2 < j) nn++;
        int k = j - nn * (nn + 1) / 2 - 1;          /* 0-based place in the row */
        int am = nn % 2 == 0 ? 2 * ((k + 1) / 2) : 2 * (k / 2) + 1;
        *n = nn;
        *m = am == 0 ? 0 : j % 2 == 0 ? am : -am;   /* Noll: even j cos, odd j sin */
        return WAVE_OK;
    }
    return WAVE_EINVAL;
}

/* R_n^m(rho), m >= 0, n - m even: the explicit sum (n <= 12 here, exact enough). */
static double radial(int n, int m, double rho)
{
    double s = 0;
    for (int k = 0; k <= (n - m) / 2; k++) {
        double c = ((k % 2) ? -1.0 : 1.0) * tgamma(n - k + 1) /
                   (tgamma(k + 1) * tgamma((n + m) / 2 - k + 1) * tgamma((n - m) / 2 - k + 1));
        s += c * pow(rho, n - 2 * k);
    }
    return s;
}

double wv_zernike(int order, int j, double rho, double theta)
{
    int n, m;
    if (wv_zernike_nm(order, j, &n, &m) != WAVE_OK) return NAN;
    int am = m < 0 ? -m : m;
    double v = radial(n, am, rho);
    if (m > 0) v *= cos(am * theta);
    else if (m < 0) v *= sin(am * theta);
    if (order != WAVE_Z_FRINGE) v *= m == 0 ? sqrt(n + 1.0) : sqrt(2.0 * (n + 1));
    return v;
}

const char *wv_zernike_name(int order, int j)
{
    int n, m;
    if (wv_zernike_nm(order, j, &n, &m) != WAVE_OK) return "";
    static const struct { int n, m; const char *name; } names[] = {
        {0, 0, "piston"}, {1, 1, "tilt x"}, {1, -1, "tilt y"}, {2, 0, "defocus"},
        {2, 2, "astigmatism 0/90"}, {2, -2, "astigmatism 45"}, {3, 1, "coma x"},
        {3, -1, "coma y"}, {4, 0, "spherical"}, {3, 3, "trefoil x"}, {3, -3, "trefoil y"},
        {4, 2, "secondary astigmatism 0/90"}, {4, -2, "secondary astigmatism 45"},
        {5, 1, "secondary coma x"}, {5, -1, "secondary coma y"},
        {6, 0, "secondary spherical"}, {4, 4, "tetrafoil 0"}, {4, -4, "tetrafoil 22.5"},
        {8, 0, "tertiary spherical"}};
    for (size_t i = 0; i < sizeof names / sizeof *names; i++)
        if (names[i].n == n && names[i].m == m) return names[i].name;
    return "";
}

static int first_term(int order) { return order == WAVE_Z_ANSI ? 0 : 1; }

int wv_pupil_add_zernike(wave_pupil *p, int order, int j, double c)
{
    int n, m;
    if (!p || p->n < 1 || wv_zernike_nm(order, j, &n, &m) != WAVE_OK) return WAVE_EINVAL;
    for (int i = 0; i < p->n; i++)
        for (int k = 0; k < p->n; k++) {
            double x = wv_cell(p->n, k), y = wv_cell(p->n, i);
            p->w[(size_t)i * p->n + k] += c * wv_zernike(order, j, hypot(x, y), atan2(y, x));
        }
    return WAVE_OK;
}

int wv_zernike_fit(const wave_pupil *p, int order, int nterm, wave_zfit *out)
{
    size_t np = 0, r = 0, n2;
    int j0 = first_term(order), rc = WAVE_ENOMEM;
    double wmin = INFINITY, wmax = -INFINITY, s = 0, s2 = 0, chisq;
    if (!p || !out || nterm < 1 || nterm > WAVE_MAXZ) return WAVE_EINVAL;
    if (order == WAVE_Z_FRINGE && nterm > 37) return WAVE_EINVAL;
    if (order != WAVE_Z_FRINGE && order != WAVE_Z_NOLL && order != WAVE_Z_ANSI)
        return WAVE_EINVAL;
    memset(out, 0, sizeof *out);
    out->order = order;
    out->nterm = nterm;
    n2 = (size_t)p->n * p->n;
    for (size_t i = 0; i < n2; i++)
        if (p->amp[i] > 0 && isfinite(p->w[i])) np++;
    if (np < (size_t)nterm + 1) return WAVE_EINVAL;
    gsl_matrix *X = gsl_matrix_alloc(np, nterm), *cov = gsl_matrix_alloc(nterm, nterm);
    gsl_vector *y = gsl_vector_alloc(np), *c = gsl_vector_alloc(nterm);
    gsl_multifit_linear_workspace *ws = gsl_multifit_linear_alloc(np, nterm);
    if (!X || !cov || !y || !c || !ws) goto done;
    for (int i = 0; i < p->n; i++)
        for (int k = 0; k < p->n; k++) {
            size_t at = (size_t)i * p->n + k;
            if (!(p->amp[at] > 0 && isfinite(p->w[at]))) continue;
            double x = wv_cell(p->n, k), yy = wv_cell(p->n, i), rho = hypot(x, yy);
            double th = atan2(yy, x), w = p->w[at];
            for (int t = 0; t < nterm; t++)
                gsl_matrix_set(X, r, t, wv_zernike(order, j0 + t, rho, th));
            gsl_vector_set(y, r, w);
            wmin = fmin(wmin, w);
            wmax = fmax(wmax, w);
            s += w;
            s2 += w * w;
            r++;
        }
    gsl_set_error_handler_off();
    if (gsl_multifit_linear(X, y, c, cov, &chisq, ws) != 0) { rc = WAVE_EINVAL; goto done; }
    double rmin = INFINITY, rmax = -INFINITY, rs2 = 0;
    for (size_t i = 0; i < np; i++) {
        double f = 0;
        for (int t = 0; t < nterm; t++) f += gsl_matrix_get(X, i, t) * gsl_vector_get(c, t);
        double e = gsl_vector_get(y, i) - f;
        rmin = fmin(rmin, e);
        rmax = fmax(rmax, e);
        rs2 += e * e;
    }
    for (int t = 0; t < nterm; t++) {
        out->c[t] = gsl_vector_get(c, t);
        wv_zernike_nm(order, j0 + t, &out->nn[t], &out->mm[t]);
    }
    double mean = s / np, var = s2 / np - mean * mean;
    out->rms = sqrt(var > 0 ? var : 0);
    out->pv = wmax - wmin;
    out->resid_rms = sqrt(rs2 / np);
    out->resid_pv = rmax - rmin;
    out->npoint = (int)np;
    rc = WAVE_OK;
done:
    if (ws) gsl_multifit_linear_free(ws);
    if (X) gsl_matrix_free(X);
    if (cov) gsl_matrix_free(cov);
    if (y) gsl_vector_free(y);
    if (c) gsl_vector_free(c);
    return rc;
}
