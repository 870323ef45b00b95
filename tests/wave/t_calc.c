/* t_calc.c -- the wave engine's calculators against textbook closed forms: thin-film
 * reflectance (quarter-wave MgF2 on N-BK7; a bare surface; an absentee half-wave
 * layer), Fresnel amplitudes below the critical angle (Hecht's sine and tangent
 * forms) and the TIR phases, Jones calculus (the seed's circular polarization, 67.1:
 * E1 along i, E2 along j a quarter period behind).  Gaussian beams are the paraxial
 * engine's (tests/unit_beam.c). */
#include <stdio.h>
#include "unit.h"
#include "wv_calc.h"

#define PI_ 3.14159265358979323846

int main(void)
{
    const wave_api *wv = wave_get_api(WAVE_ABI);
    double R = 0, e, Rs, Rp;
    if (!wv) return 1;
    e = coating_err(wv, &R);
    CHECK(e <= 1e-9, "quarter-wave MgF2 on N-BK7: R = %.6f%%, closed form within %.2g", 100 * R, e);
    {
        double ns = 1.5168, want = ((1 - ns) / (1 + ns)) * ((1 - ns) / (1 + ns));
        wv->film(1, NULL, NULL, 0, ns, 550e-6, 0, &Rs, &Rp);
        CHECK(fabs(Rs - want) < 1e-15, "no layers: R = ((1 - n)/(1 + n))^2 = %.6f", Rs);
        double n1 = 1.38, d = 550e-6 / (2 * n1);
        wv->film(1, &n1, &d, 1, ns, 550e-6, 0, &Rs, &Rp);
        CHECK(fabs(Rs - want) < 1e-14, "a half-wave layer is absent at its wavelength");
        double t = 45 * PI_ / 180, ts = asin(sin(t) / ns), q1 = -sin(t - ts) / sin(t + ts);
        double q2 = tan(t - ts) / tan(t + ts);
        wv->film(1, NULL, NULL, 0, ns, 550e-6, t, &Rs, &Rp);
        CHECK(fabs(Rs - q1 * q1) < 1e-15 && fabs(Rp - q2 * q2) < 1e-15,
              "bare N-BK7 at 45 degrees: Rs %.6f Rp %.6f (Fresnel's sine and tangent laws)", Rs, Rp);
    }
    {
        double n1 = 1, n2 = 1.5168, worst = 0;
        for (int i = 0; i < 90; i++) {
            double t = i * PI_ / 180, tt = asin(n1 * sin(t) / n2);
            wave_c r[4];
            wv->fresnel(n1, n2, t, r);
            double rs = i ? -sin(t - tt) / sin(t + tt) : (n1 - n2) / (n1 + n2);
            double rp = i ? tan(t - tt) / tan(t + tt) : (n2 - n1) / (n1 + n2);
            double ts = i ? 2 * sin(tt) * cos(t) / sin(t + tt) : 2 * n1 / (n1 + n2);
            double tp = i ? 2 * sin(tt) * cos(t) / (sin(t + tt) * cos(t - tt)) : 2 * n1 / (n1 + n2);
            worst = fmax(worst, fmax(fabs(r[0].re - rs), fabs(r[1].re - rp)));
            worst = fmax(worst, fmax(fabs(r[2].re - ts), fabs(r[3].re - tp)));
            worst = fmax(worst, fmax(fmax(fabs(r[0].im), fabs(r[1].im)), fmax(fabs(r[2].im), fabs(r[3].im))));
        }
        CHECK(worst < 1e-14, "Fresnel rs, rp, ts, tp air to N-BK7, 0..89 degrees: Hecht's forms "
              "within %.2g", worst);
    }
    e = tir_err(wv);
    CHECK(e <= 1e-12, "TIR glass 1.5 to air: phases of rs, rp and their difference, |r| = 1, "
          "within %.2g rad", e);
    {
        wave_c q[4], p[4];
        /* light polarized at 45 degrees through a quarter-wave plate, fast axis along i */
        wv->jones(1, 0, PI_ / 2, q);
        double ex_r = (q[0].re + q[1].re) / sqrt(2), ex_i = (q[0].im + q[1].im) / sqrt(2);
        double ey_r = (q[2].re + q[3].re) / sqrt(2), ey_i = (q[2].im + q[3].im) / sqrt(2);
        /* Ey / Ex = i: the seed's circular polarization */
        double den = ex_r * ex_r + ex_i * ex_i;
        double rr = (ey_r * ex_r + ey_i * ex_i) / den, ri = (ey_i * ex_r - ey_r * ex_i) / den;
        CHECK(fabs(rr) < 1e-15 && fabs(ri - 1) < 1e-15 && fabs(den - 0.5) < 1e-15,
              "45-degree light through a quarter-wave plate: Ey/Ex = %.3g%+.3gi (circular)", rr, ri);
        /* any polarizer passes half of circular light */
        double worst = 0;
        for (int k = 0; k < 12; k++) {
            wv->jones(0, k * PI_ / 12, 0, p);
            double ar = p[0].re * ex_r - p[0].im * ex_i + p[1].re * ey_r - p[1].im * ey_i;
            double ai = p[0].re * ex_i + p[0].im * ex_r + p[1].re * ey_i + p[1].im * ey_r;
            double br = p[2].re * ex_r - p[2].im * ex_i + p[3].re * ey_r - p[3].im * ey_i;
            double bi = p[2].re * ex_i + p[2].im * ex_r + p[3].re * ey_i + p[3].im * ey_r;
            worst = fmax(worst, fabs(ar * ar + ai * ai + br * br + bi * bi - 0.5));
        }
        CHECK(worst < 1e-15, "a polarizer at any angle passes half of it (%.2g)", worst);
        wv->jones(1, PI_ / 8, PI_, q);   /* half wave at 22.5 degrees: i -> 45 degrees */
        double ph = atan2(q[0].im, q[0].re);   /* common phase */
        CHECK(fabs(hypot(q[0].re, q[0].im) - sqrt(0.5)) < 1e-15 &&
              fabs(hypot(q[2].re, q[2].im) - sqrt(0.5)) < 1e-15 &&
              fabs(atan2(q[2].im, q[2].re) - ph) < 1e-15, "a half-wave plate at 22.5 degrees "
              "turns horizontal light to 45 degrees");
        wv->jones(2, PI_ / 6, 0, q);
        CHECK(fabs(q[2].re - 0.5) < 1e-15 && fabs(q[0].re - sqrt(3) / 2) < 1e-15, "a rotator by 30 degrees");
    }
    return unit_failed();
}
