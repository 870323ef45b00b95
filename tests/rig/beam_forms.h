/* beam_forms.h -- the Gaussian beam's closed forms the rig's beam tests check against
 * (tests/rig/t_spots.c, t_oblique.c), written for the tests, not the engine's code:
 * Self's thin lens and the beam radius along z.  lm: M^2 times the wavelength. */
#ifndef BEAM_FORMS_H
#define BEAM_FORMS_H
#include <math.h>

/* Self's thin lens: (w0, s) -> (w0', s'); s before, s' after */
static void self(double f, double lm, double *w0, double *s)
{
    double zr = M_PI * *w0 * *w0 / lm, u = *s - f;
    double m = 1 / sqrt((1 - *s / f) * (1 - *s / f) + (zr / f) * (zr / f));
    *s = f + u * f * f / (u * u + zr * zr);
    *w0 *= m;
}
static double wz(double w0, double z, double lm)
{
    double zr = M_PI * w0 * w0 / lm;
    return w0 * sqrt(1 + (z / zr) * (z / zr));
}
#endif
