/* rg_dose.c -- the dose at the cornea against the maximum permissible exposure.
 * The rig file gives the laser's power at the cornea, its wavelength and its 1/e^2
 * beam diameter there.  The MPE is IEC 60825-1:2014 Table A.1 (ocular exposure, the
 * same values as ICNIRP's 2013 laser guidelines and Directive 2006/25/EC Annex II) for
 * a small source (a collimated beam: angular subtense below alpha_min = 1.5 mrad, so
 * C6 = 1 and T2 = 10 s), 400-700 nm:
 *     1.8e-5 s <= t <= 10 s    H = 18 t^0.75 C6 J/m^2              (retinal thermal)
 *     10 s < t <= 3e4 s        E = 18 C6 T2^-0.25 W/m^2 = 10.1 W/m^2 (thermal) and,
 *                              400-600 nm, photochemical H = 100 C3 J/m^2 to 100 s,
 *                              E = 1 C3 W/m^2 beyond, C3 = 10^(0.02 (lambda - 450))
 *                              from 450 nm (1 below): the smaller limit applies.
 * The exposure is averaged over the 7 mm limiting aperture of the eye (the standard's
 * measurement condition for 400-1400 nm): a Gaussian beam of diameter d puts
 * 1 - exp(-2 (7/d)^2) of its power through it.  Repeated exposures (a scan): each
 * one against the MPE of its duration, and their sum against the MPE of their summed
 * on-time taken as one exposure (the standard's pulse-train rule with the train's
 * duration shortened to its on-time: never less strict, as the MPE grows with time).
 * An exposure of ms with a shutter lasts ms + 2 shutter_ms for the dose (the light
 * passes, partly, while it opens and closes). */
#define _DEFAULT_SOURCE
#include <math.h>
#include <stdio.h>
#include "rig/rg_hw.h"

#define APERTURE_M 7e-3

double rg_mpe(double wl, double t, const char **limit)
{
    double c3, thermal, photo;
    if (!(wl >= 400 && wl <= 700) || !(t >= 1.8e-5) || t > 3e4) {
        if (limit) *limit = "none: outside 400-700 nm or 18 us to 30000 s";
        return NAN;
    }
    if (t <= 10) {
        if (limit) *limit = "IEC 60825-1:2014 Table A.1, 400-700 nm, 1.8e-5 to 10 s: "
                            "H = 18 t^0.75 C6 J/m^2, C6 = 1";
        return 18 * pow(t, 0.75);
    }
    thermal = 18 * pow(10, -0.25) * t;
    if (wl >= 600) {
        if (limit) *limit = "IEC 60825-1:2014 Table A.1, 400-700 nm, 10 to 3e4 s (thermal): "
                            "E = 18 C6 T2^-0.25 W/m^2, C6 = 1, T2 = 10 s";
        return thermal;
    }
    c3 = wl < 450 ? 1 : pow(10, 0.02 * (wl - 450));
    photo = t <= 100 ? 100 * c3 : c3 * t;
    if (photo < thermal) {
        if (limit) *limit = "IEC 60825-1:2014 Table A.1, 400-600 nm, 10 to 3e4 s "
                            "(photochemical): H = 100 C3 J/m^2 (to 100 s), E = 1 C3 W/m^2";
        return photo;
    }
    if (limit) *limit = "IEC 60825-1:2014 Table A.1, 400-700 nm, 10 to 3e4 s (thermal): "
                        "E = 18 C6 T2^-0.25 W/m^2, C6 = 1, T2 = 10 s";
    return thermal;
}

static int dose(const rg_rig *rig, long n0, double t0, double ms, long n, rg_dose *d,
                char *err, size_t cap)
{
    double P = rig->laser_power_mw * 1e-3, dm = rig->beam_diameter_mm * 1e-3;
    double w = dm / 2, eta, t = (ms + 2 * rig->shutter_ms) * 1e-3;   /* shutter travel counts */
    const char *lim1 = NULL, *limt = NULL;
    *d = (rg_dose){0};
    if (!(rig->laser_power_mw > 0) || !(rig->wavelength_nm > 0) || !(rig->beam_diameter_mm > 0)) {
        snprintf(err, cap, "the rig file gives no laser_power_mw, wavelength_nm and "
                 "beam_diameter_mm: the dose at the cornea cannot be checked, so the laser "
                 "stays off");
        return RG_EINVAL;
    }
    eta = 1 - exp(-2 * (APERTURE_M / dm) * (APERTURE_M / dm));
    d->E_peak = 2 * P / (M_PI * w * w);
    d->E_aperture = eta * P / (M_PI * APERTURE_M * APERTURE_M / 4);
    d->H_one = d->E_aperture * t;
    d->n = n0 + n;
    d->t_total = t0 + n * t;
    d->H_total = d->E_aperture * d->t_total;
    d->mpe_one = rg_mpe(rig->wavelength_nm, t, &lim1);
    d->mpe_total = rg_mpe(rig->wavelength_nm, d->t_total, &limt);
    d->limit = limt;
    if (isnan(d->mpe_one) || isnan(d->mpe_total)) {
        snprintf(err, cap, "no MPE for %g nm and %g s (%s)", rig->wavelength_nm,
                 isnan(d->mpe_one) ? t : d->t_total, lim1);
        d->fraction = INFINITY;
        return RG_EINVAL;
    }
    d->fraction = fmax(d->H_one / d->mpe_one, d->H_total / d->mpe_total);
    if (d->fraction > 1) {
        snprintf(err, cap, "the dose would exceed the limit: %ld exposures of %g ms at "
                 "%g mW, %g nm give %.4g J/m^2 at the cornea (7 mm aperture) in %.4g s, "
                 "%.3g times the MPE %.4g J/m^2 (%s)", d->n, ms, rig->laser_power_mw,
                 rig->wavelength_nm, d->H_total, d->t_total, d->fraction, d->mpe_total,
                 d->limit);
        return RG_EDOSE;
    }
    return 0;
}

int rg_dose_rig(const rg_rig *rig, double ms, long n, rg_dose *d, char *err, size_t cap)
{
    return dose(rig, 0, 0, ms, n, d, err, cap);
}

int rg_dose_plan(const rg_machine *m, double ms, long n, rg_dose *d, char *err, size_t cap)
{
    return dose(&m->rig, m->dose_n, m->dose_t, ms, n, d, err, cap);
}
