/* wv_calc.c -- the closed-form calculators (Gaussian beams are the paraxial
 * engine's, src/paraxial/beam.c): Jones matrices (sections 67-69), Fresnel amplitude
 * coefficients with the phase of total internal reflection, and thin-film stacks by
 * characteristic matrices (section 40's interference; Born and Wolf section 1.6).
 * Fields go as exp(i(kz - wt)): an evanescent wave has Im(cos theta_t) > 0; rp takes
 * Hecht's sign (rp = rs at normal incidence would be Born and Wolf's opposite). */
#include <complex.h>
#include <math.h>
#include "wv_int.h"

static wave_c wc(double complex z) { wave_c r = {creal(z), cimag(z)}; return r; }

int wv_jones(int kind, double angle, double ret, wave_c m[4])
{
    double c = cos(angle), s = sin(angle);
    if (!m) return WAVE_EINVAL;
    if (kind == 0) {
        m[0] = wc(c * c); m[1] = wc(c * s); m[2] = wc(c * s); m[3] = wc(s * s);
    } else if (kind == 1) {
        /* R(-a) diag(exp(-i ret/2), exp(i ret/2)) R(a): fast axis at a */
        double complex f = cexp(-I * ret / 2), sl = cexp(I * ret / 2);
        m[0] = wc(c * c * f + s * s * sl);
        m[1] = wc(c * s * (f - sl));
        m[2] = wc(c * s * (f - sl));
        m[3] = wc(s * s * f + c * c * sl);
    } else if (kind == 2) {
        m[0] = wc(c); m[1] = wc(-s); m[2] = wc(s); m[3] = wc(c);
    } else {
        return WAVE_EINVAL;
    }
    return WAVE_OK;
}

static double complex cos_t(double n1, double n2, double th)
{
    double s = n1 / n2 * sin(th), q = 1 - s * s;
    return q >= 0 ? sqrt(q) : I * sqrt(-q);
}

int wv_fresnel(double n1, double n2, double th, wave_c out[4])
{
    if (!(n1 > 0) || !(n2 > 0) || !(fabs(th) <= WV_PI / 2) || !out) return WAVE_EINVAL;
    double ci = cos(th);
    double complex ct = cos_t(n1, n2, th);
    out[0] = wc((n1 * ci - n2 * ct) / (n1 * ci + n2 * ct));
    out[1] = wc((n2 * ci - n1 * ct) / (n2 * ci + n1 * ct));
    out[2] = wc(2 * n1 * ci / (n1 * ci + n2 * ct));
    out[3] = wc(2 * n1 * ci / (n2 * ci + n1 * ct));
    return WAVE_OK;
}

int wv_film(double n0, const double *n, const double *d, int nl, double ns, double lambda,
            double th, double *Rs, double *Rp)
{
    if (!(n0 > 0) || !(ns > 0) || nl < 0 || (nl && (!n || !d)) || !(lambda > 0)) return WAVE_EINVAL;
    double complex c0 = cos(th), cs = cos_t(n0, ns, th);
    for (int pol = 0; pol < 2; pol++) {
        double complex m11 = 1, m12 = 0, m21 = 0, m22 = 1;
        for (int j = 0; j < nl; j++) {
            if (!(n[j] > 0) || !(d[j] >= 0)) return WAVE_EINVAL;
            double complex cj = cos_t(n0, n[j], th);
            double complex eta = pol == 0 ? n[j] * cj : n[j] / cj;
            double complex dl = 2 * WV_PI * n[j] * d[j] * cj / lambda;
            double complex a = ccos(dl), b = -I * csin(dl) / eta, c = -I * eta * csin(dl);
            double complex t11 = m11 * a + m12 * c, t12 = m11 * b + m12 * a;
            double complex t21 = m21 * a + m22 * c, t22 = m21 * b + m22 * a;
            m11 = t11; m12 = t12; m21 = t21; m22 = t22;
        }
        double complex e0 = pol == 0 ? n0 * c0 : n0 / c0, es = pol == 0 ? ns * cs : ns / cs;
        double complex r = (e0 * m11 + e0 * es * m12 - m21 - es * m22) /
                           (e0 * m11 + e0 * es * m12 + m21 + es * m22);
        double R = creal(r) * creal(r) + cimag(r) * cimag(r);
        if (pol == 0) { if (Rs) *Rs = R; }
        else if (Rp) *Rp = R;
    }
    return WAVE_OK;
}
