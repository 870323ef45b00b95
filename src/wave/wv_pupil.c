/* wv_pupil.c -- the pupil's amplitude: the unit circle sampled at cell centres (the
 * same cells the dialogue aims rays at), a central obscuration, Gaussian apodisation.
 * A hard edge, not a grey one: the autocorrelation of hard cells converges to the
 * circle's MTF (5.7e-5 at n = 512), grey edge cells overweight the overlap (1.2e-3). */
#include <math.h>
#include "wv_int.h"

int wv_pupil_mask(wave_pupil *p, double obsc, double apod)
{
    int count = 0;
    if (!p || p->n < 2 || !p->amp || !(obsc >= 0 && obsc < 1)) return WAVE_EINVAL;
    for (int i = 0; i < p->n; i++)
        for (int k = 0; k < p->n; k++) {
            double x = wv_cell(p->n, k), y = wv_cell(p->n, i), r2 = x * x + y * y;
            double a = 0;
            if (r2 <= 1 && r2 >= obsc * obsc) {
                a = apod > 0 ? exp(-r2 / (apod * apod)) : 1;
                count++;
            }
            p->amp[(size_t)i * p->n + k] = a;
        }
    return count;
}
