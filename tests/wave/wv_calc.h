/* wv_calc.h -- the calculators' errors against textbook closed forms written here,
 * shared by t_calc.c and bench_wave.c: a quarter-wave MgF2 layer on N-BK7 (R =
 * ((n0 ns - n1^2)/(n0 ns + n1^2))^2, Hecht 9.10) and the phases of total internal
 * reflection (tan(delta_s/2) = sqrt(sin^2 t - n^2)/cos t, tan(delta_p/2) =
 * sqrt(sin^2 t - n^2)/(n^2 cos t), n = n2/n1; Born and Wolf 1.5.4). */
#ifndef WV_CALC_H
#define WV_CALC_H
#include <math.h>
#include "wave/wave.h"

/* MgF2 1.38 on N-BK7 1.5168 (Schott, d line), quarter wave at 550 nm, normal
 * incidence: relative error of R. */
static double coating_err(const wave_api *wv, double *R)
{
    double n0 = 1, n1 = 1.38, ns = 1.5168, lam = 550e-6, d = lam / (4 * n1), Rs, Rp;
    double q = (n0 * ns - n1 * n1) / (n0 * ns + n1 * n1), want = q * q;
    if (wv->film(n0, &n1, &d, 1, ns, lam, 0, &Rs, &Rp) != WAVE_OK) return 1;
    if (R) *R = Rs;
    return fmax(fabs(Rs - want), fabs(Rp - want)) / want;
}

/* Glass 1.5 to air from the critical angle + 0.01 degree to 89.99 degrees: the
 * largest |phase - formula| of rs, rp and of their difference, radians. */
static double tir_err(const wave_api *wv)
{
    double n1 = 1.5, n2 = 1.0, n = n2 / n1, tc = asin(n), e = 0;
    for (int i = 0; i <= 400; i++) {
        double t = tc + 1e-4 + (1.5706 - tc - 1e-4) * i / 400, s = sin(t), c = cos(t);
        wave_c r[4];
        if (wv->fresnel(n1, n2, t, r) != WAVE_OK) return 1;
        double root = sqrt(s * s - n * n);
        double ds = 2 * atan(root / c), dp = 2 * atan(root / (n * n * c));
        double d = 2 * atan(c * root / (s * s));           /* dp - ds */
        double as = -atan2(r[0].im, r[0].re), ap = -atan2(r[1].im, r[1].re);
        e = fmax(e, fmax(fabs(as - ds), fabs(ap - dp)));
        e = fmax(e, fabs((ap - as) - d));
        e = fmax(e, fmax(fabs(hypot(r[0].re, r[0].im) - 1), fabs(hypot(r[1].re, r[1].im) - 1)));
    }
    return e;
}

#endif
