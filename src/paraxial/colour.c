/* colour.c -- first-order optics per wavelength: a prescription by thickness with
 * glass names, built once per wavelength from the catalogue's indices, and the
 * chromatic differences between F and C (longitudinal and lateral colour). */
#include <math.h>
#include <string.h>
#include "paraxial.h"

int px_colour_run(const px_csurf *s, int nsurf, const char *obj_glass,
                  const double *lambda, int nwl, px_colour *out)
{
    memset(out, 0, sizeof *out);
    out->bad_surface = -2;
    if (nsurf < 1 || nwl < 1 || nwl > PX_COLOUR_MAXWL) return PX_BAD;
    out->nwl = nwl;
    for (int w = 0; w < nwl; w++) {
        double n0, n;
        px_system sys;
        int r;
        out->lambda[w] = lambda[w];
        if ((r = px_glass_index(obj_glass, lambda[w], &n0)) != PX_OK) {
            out->bad_surface = -1;
            return r;
        }
        px_system_init(&sys, n0);
        for (int i = 0; i < nsurf; i++) {
            if ((r = px_glass_index(s[i].glass, lambda[w], &n)) != PX_OK) {
                out->bad_surface = i;
                px_system_free(&sys);
                return r;
            }
            if (i > 0 && (r = px_system_gap(&sys, s[i - 1].t)) != PX_OK) {
                out->bad_surface = i - 1;
                px_system_free(&sys);
                return r;
            }
            if ((r = px_system_surface(&sys, s[i].r == 0 ? INFINITY : s[i].r, n))
                != PX_OK) {
                out->bad_surface = i;
                px_system_free(&sys);
                return r;
            }
        }
        r = px_first_order(&sys, &out->first[w]);
        px_system_free(&sys);
        if (r != PX_OK) return r;
    }
    return PX_OK;
}

int px_colour_fdc(const px_csurf *s, int nsurf, const char *obj_glass, px_colour *out)
{
    const double fdc[3] = {PX_LAMBDA_F, PX_LAMBDA_D, PX_LAMBDA_C};
    int r = px_colour_run(s, nsurf, obj_glass, fdc, 3, out);
    if (r != PX_OK) return r;
    if (out->first[0].afocal || out->first[1].afocal || out->first[2].afocal)
        return PX_AT_INFINITY;
    out->long_colour = out->first[0].bfd.v - out->first[2].bfd.v;
    out->lat_colour_rel = (out->first[0].efl.v - out->first[2].efl.v) / out->first[1].efl.v;
    return PX_OK;
}
