/* tr_optics.c -- the physics at one interface, in double: exact vector Snell law
 * (square-root form, valid at every angle: the seed's refrac used 1-cos^2 where
 * sin = sqrt(1-cos^2) belongs), total internal reflection, Fresnel amplitude and power
 * coefficients for s and p (section 51, Born & Wolf), and the rotation of a ray's
 * polarisation state into the s/p basis of the interface. */
#include <math.h>
#include "tr_int.h"

/* cos_t^2 = 1 - (n1/n2)^2 (1 - cos_i^2), written to keep its digits at grazing. */
static double cos_t2(double n1, double n2, double ci)
{
    double eta = n1 / n2;
    return (1.0 - eta * eta) + eta * eta * ci * ci;
}

void tr_fresnel(double n1, double n2, double ci, trace_fresnel_coef *f)
{
    double c2;
    if (ci < 0) ci = -ci;
    if (ci > 1) ci = 1;
    c2 = cos_t2(n1, n2, ci);
    f->rs_phase = f->rp_phase = 0;
    if (c2 <= 0) {                    /* TIR: |r| = 1, phase from the evanescent wave */
        double kap = sqrt(-c2);       /* cos_t = i*kap */
        f->tir = 1;
        f->cos_t = 0;
        f->rs = f->rp = 1;
        f->ts = f->tp = 0;
        f->rs_phase = -2 * atan2(n2 * kap, n1 * ci);
        f->rp_phase = -2 * atan2(n1 * kap, n2 * ci);
        /* at the critical angle itself both phases are 0 and r = +1 */
        f->Rs = f->Rp = 1;
        f->Ts = f->Tp = 0;
        return;
    }
    double ct = sqrt(c2);
    double ds = n1 * ci + n2 * ct, dp = n2 * ci + n1 * ct;
    f->tir = 0;
    f->cos_t = ct;
    if (ds == 0 || dp == 0) {         /* grazing incidence: everything reflected */
        f->rs = -1; f->rp = 1; f->ts = f->tp = 0;
        f->Rs = f->Rp = 1; f->Ts = f->Tp = 0;
        return;
    }
    double is = 1.0 / ds, ip = 1.0 / dp;
    f->rs = (n1 * ci - n2 * ct) * is;
    f->rp = (n2 * ci - n1 * ct) * ip;
    f->ts = 2 * n1 * ci * is;
    f->tp = 2 * n1 * ci * ip;
    if (f->rs < 0) { f->rs = -f->rs; f->rs_phase = TR_PI; }
    if (f->rp < 0) { f->rp = -f->rp; f->rp_phase = TR_PI; }
    f->Rs = f->rs * f->rs;
    f->Rp = f->rp * f->rp;
    /* T = (n2 cos_t / n1 cos_i) t^2, without dividing by cos_i */
    double q = 4 * n1 * n2 * ci * ct;
    f->Ts = q * is * is;
    f->Tp = q * ip * ip;
}

int tr_refract(const double d[3], const double nrm[3], double n1, double n2,
               double out[3])
{
    double dn = v_dot(d, nrm), m[3];
    /* m: unit normal pointing back into the incident medium */
    double sgn = dn > 0 ? -1.0 : 1.0;
    for (int i = 0; i < 3; i++) m[i] = sgn * nrm[i];
    double ci = -v_dot(d, m);
    double c2 = cos_t2(n1, n2, ci);
    if (c2 < 0) {
        for (int i = 0; i < 3; i++) out[i] = d[i] + 2 * ci * m[i];
        v_unit(out);
        return 0;
    }
    double eta = n1 / n2, k = eta * ci - sqrt(c2);
    for (int i = 0; i < 3; i++) out[i] = eta * d[i] + k * m[i];
    v_unit(out);
    return 1;
}

/* tr_pol_rotate, the rotation of the polarisation state into an interface's s/p
 * basis, is inline in tr_int.h (the trace loop calls it at every interface). */
