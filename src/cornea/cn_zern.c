/* cn_zern.c -- the surface from the data as a function (issue 19): the Zernike basis
 * (unnormalised, R_n^|m|(rho) cos/sin |m| theta over the data's disc) with its
 * analytic gradients, the reconstructed sag z = R0 - sqrt(R0^2 - r^2) + sum c_j Z_j
 * and its slopes, where a beam meets it, and which points the data cover.  The fit
 * that finds the coefficients from the spots is cn_recon.c; what a topographer reads
 * off the surface (maps, keratoconus indices) is cn_kc.c. */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cn_int.h"

int cn_zterms(int order) { return (order + 1) * (order + 2) / 2; }

/* The radial polynomials' coefficients, once: term j (n = 0.., m = -n, -n+2 .. n)
 * has a[j][s] on rho^(n - 2s). */
static struct { double a[CN_ZTERMS][CN_ZORDER / 2 + 1]; int n[CN_ZTERMS], m[CN_ZTERMS]; } zb;
static pthread_once_t zb_once = PTHREAD_ONCE_INIT;

static void zb_init(void)
{
    double fact[CN_ZORDER + 1];
    fact[0] = 1;
    for (int k = 1; k <= CN_ZORDER; k++) fact[k] = fact[k - 1] * k;
    int j = 0;
    for (int n = 0; n <= CN_ZORDER; n++)
        for (int m = -n; m <= n; m += 2, j++) {
            int am = m < 0 ? -m : m;
            zb.n[j] = n;
            zb.m[j] = m;
            for (int s = 0; s <= (n - am) / 2; s++)
                zb.a[j][s] = ((s & 1) ? -1.0 : 1.0) * fact[n - s] /
                             (fact[s] * fact[(n + am) / 2 - s] * fact[(n - am) / 2 - s]);
        }
}

/* The first nt terms at (x, y) mm over the disc rho: values v[j] and, when gx is
 * not NULL, gradients (1/mm, analytic: dR/drho and R/rho are polynomials too, so
 * the origin needs no special case beyond theta = 0 there). */
void cn_zbasis(int nt, double rho, double x, double y, double *v, double *gx, double *gy)
{
    pthread_once(&zb_once, zb_init);
    double xn = x / rho, yn = y / rho, r = hypot(xn, yn), c1 = 1, s1 = 0;
    if (r > 0) { c1 = xn / r; s1 = yn / r; }
    double pw[CN_ZORDER + 1], cm[CN_ZORDER + 1], sm[CN_ZORDER + 1];
    pw[0] = 1;
    cm[0] = 1;
    sm[0] = 0;
    for (int k = 1; k <= CN_ZORDER; k++) {
        pw[k] = pw[k - 1] * r;
        cm[k] = cm[k - 1] * c1 - sm[k - 1] * s1;
        sm[k] = sm[k - 1] * c1 + cm[k - 1] * s1;
    }
    for (int j = 0; j < nt; j++) {
        int n = zb.n[j], m = zb.m[j], am = m < 0 ? -m : m;
        double R = 0, dR = 0, Rr = 0;
        for (int s = 0; s <= (n - am) / 2; s++) {
            int p = n - 2 * s;
            double a = zb.a[j][s];
            R += a * pw[p];
            if (p > 0) { dR += a * p * pw[p - 1]; Rr += a * pw[p - 1]; }
        }
        double C = m >= 0 ? cm[am] : sm[am], Cp = m >= 0 ? -am * sm[am] : am * cm[am];
        v[j] = R * C;
        if (gx) {
            gx[j] = (dR * C * c1 - Rr * Cp * s1) / rho;
            gy[j] = (dR * C * s1 + Rr * Cp * c1) / rho;
        }
    }
}

int cn_zsag(const cn_zfit *z, double x, double y, double *f, double *fx, double *fy)
{
    double v[CN_ZTERMS], gx[CN_ZTERMS], gy[CN_ZTERMS], r2 = x * x + y * y;
    double s = 0, sx = 0, sy = 0;
    if (z->R0 > 0 && r2 < z->R0 * z->R0) {
        double q = sqrt(z->R0 * z->R0 - r2);
        s = z->R0 - q;
        sx = x / q;
        sy = y / q;
    }
    cn_zbasis(z->nterms, z->rho, x, y, v, gx, gy);
    for (int j = 0; j < z->nterms; j++) {
        s += z->c[j] * v[j];
        sx += z->c[j] * gx[j];
        sy += z->c[j] * gy[j];
    }
    *f = s;
    if (fx) *fx = sx;
    if (fy) *fy = sy;
    return isfinite(s) ? 0 : -1;
}

/* The Zernike surface's slope at the frame's origin (its vertex tilt). */
void cn_zvertex(cn_zfit *z)
{
    double f;
    z->g0x = z->g0y = 0;
    cn_zsag(z, 0, 0, &f, &z->g0x, &z->g0y);
}

int cn_zcovered(const cn_zfit *z, double x, double y)
{
    if (hypot(x, y) > z->rho) return 0;
    double lim = z->gap * z->gap;
    for (int i = 0; i < z->npts; i++) {
        double dx = z->xy[2 * i] - x, dy = z->xy[2 * i + 1] - y;
        if (dx * dx + dy * dy <= lim) return 1;
    }
    return 0;
}

