/* wv_direct.c -- diffraction integrals evaluated point by point, to check the FFT:
 * section 43's Kirchhoff formula over the reference sphere (exact distances, the
 * obliquity factor (cos(n, r) + cos(n, r')) / 2, 1/r; the wave converges along the
 * sphere's normal so cos(n, r') = 1), and the Fraunhofer integral of a circular pupil
 * in polar coordinates by Gauss-Legendre quadrature (GSL's nodes) in rho and the
 * trapezoid rule in theta (spectrally accurate for a periodic integrand), with its
 * encircled energy by a second quadrature over the image plane. */
#include <gsl/gsl_integration.h>
#include <math.h>
#include <stdlib.h>
#include "wv_int.h"

int wv_kirchhoff(const wave_pupil *p, double a, double R, double lambda, const double *x,
                 const double *y, int npt, double *out)
{
    int n;
    double k, dA, u0 = 0;
    if (!p || p->n < 2 || !(a > 0) || !(R > a) || !(lambda > 0) || npt < 0) return WAVE_EINVAL;
    n = p->n;
    k = 2 * WV_PI / lambda;
    dA = (2 * a / n) * (2 * a / n);
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double am = p->amp[(size_t)i * n + j], sx = a * wv_cell(n, j), sy = a * wv_cell(n, i);
            if (am > 0) u0 += am * dA * R / sqrt(R * R - sx * sx - sy * sy) / R;
        }
    if (!(u0 > 0)) return WAVE_EINVAL;
    for (int t = 0; t < npt; t++) {
        double re = 0, im = 0, u = x[t], v = y[t];
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) {
                size_t at = (size_t)i * n + j;
                double am = p->amp[at];
                if (!(am > 0)) continue;
                double sx = a * wv_cell(n, j), sy = a * wv_cell(n, i);
                double zs = sqrt(R * R - sx * sx - sy * sy);
                double ps = sx * u + sy * v, d2 = u * u + v * v - 2 * ps;  /* r^2 - R^2 */
                double r = sqrt(R * R + d2), dr = d2 / (r + R);
                double obl = 0.5 * ((R * R - ps) / (R * r) + 1);
                double amp = am * dA * (R / zs) * obl / r;
                double ph = k * dr - 2 * WV_PI * p->w[at];
                re += amp * cos(ph);
                im += amp * sin(ph);
            }
        out[t] = (re * re + im * im) / (u0 * u0);
    }
    return WAVE_OK;
}

static double w_at(int order, const double *zc, int nz, double rho, double th)
{
    double w = 0;
    int j0 = order == WAVE_Z_ANSI ? 0 : 1;
    for (int j = 0; j < nz; j++)
        if (zc[j] != 0) w += zc[j] * wv_zernike(order, j0 + j, rho, th);
    return w;
}

int wv_fraunhofer(int order, const double *zc, int nz, int nr, int nt, const double *u,
                  const double *v, int npt, double *out)
{
    gsl_integration_glfixed_table *g;
    if (nr < 2 || nt < 4 || npt < 0 || nz < 0 || (nz && !zc)) return WAVE_EINVAL;
    g = gsl_integration_glfixed_table_alloc((size_t)nr);
    if (!g) return WAVE_ENOMEM;
    double *rw = malloc(sizeof(double) * 2 * (size_t)nr), *wv = NULL, *ct = NULL;
    wv = malloc(sizeof(double) * (size_t)nr * nt);
    ct = malloc(sizeof(double) * 2 * (size_t)nt);
    if (!rw || !wv || !ct) {
        free(rw); free(wv); free(ct);
        gsl_integration_glfixed_table_free(g);
        return WAVE_ENOMEM;
    }
    for (int i = 0; i < nr; i++)
        gsl_integration_glfixed_point(0, 1, (size_t)i, &rw[2 * i], &rw[2 * i + 1], g);
    for (int j = 0; j < nt; j++) {
        double th = 2 * WV_PI * j / nt;
        ct[2 * j] = cos(th);
        ct[2 * j + 1] = sin(th);
        for (int i = 0; i < nr; i++) wv[(size_t)i * nt + j] = w_at(order, zc, nz, rw[2 * i], th);
    }
    for (int t = 0; t < npt; t++) {
        double re = 0, im = 0;
        for (int i = 0; i < nr; i++) {
            double rho = rw[2 * i], wt = rw[2 * i + 1] * rho * (2 * WV_PI / nt);
            for (int j = 0; j < nt; j++) {
                double ph = -2 * WV_PI * wv[(size_t)i * nt + j] -
                            WV_PI * rho * (u[t] * ct[2 * j] + v[t] * ct[2 * j + 1]);
                re += wt * cos(ph);
                im += wt * sin(ph);
            }
        }
        re /= WV_PI;
        im /= WV_PI;
        out[t] = re * re + im * im;
    }
    free(rw); free(wv); free(ct);
    gsl_integration_glfixed_table_free(g);
    return WAVE_OK;
}

/* EE(r0) = (pi/4) int_0^r0 int_0^2pi PSF r dr dphi: the PSF above integrates to 4/pi
 * over the plane (Parseval: U is 4/pi times the transform of the disc of radius 1/2 in
 * the conjugate variable).  Panels of width <= 1/2 lambda F, 20 nodes each, 4 angles. */
int wv_fraunhofer_ee(int nr, int nt, const double *r_ee, int nee, double *ee)
{
    gsl_integration_glfixed_table *g = gsl_integration_glfixed_table_alloc(20);
    if (!g) return WAVE_ENOMEM;
    int rc = WAVE_OK;
    for (int e = 0; e < nee && rc == WAVE_OK; e++) {
        double r0 = r_ee[e], sum = 0;
        int np = (int)ceil(r0 / 0.5);
        if (!(r0 >= 0)) { rc = WAVE_EINVAL; break; }
        for (int pnl = 0; pnl < np && rc == WAVE_OK; pnl++) {
            double a = r0 * pnl / np, b = r0 * (pnl + 1) / np;
            for (size_t i = 0; i < 20 && rc == WAVE_OK; i++) {
                double r, w, u[4], v[4], psf[4];
                gsl_integration_glfixed_point(a, b, i, &r, &w, g);
                for (int q = 0; q < 4; q++) {
                    u[q] = r * cos(WV_PI / 2 * q + 0.3);
                    v[q] = r * sin(WV_PI / 2 * q + 0.3);
                }
                rc = wv_fraunhofer(WAVE_Z_NOLL, NULL, 0, nr, nt, u, v, 4, psf);
                for (int q = 0; q < 4; q++) sum += w * r * psf[q] * (2 * WV_PI / 4);
            }
        }
        ee[e] = WV_PI / 4 * sum;
    }
    gsl_integration_glfixed_table_free(g);
    return rc;
}
