/* unit_chromatic.c -- the F-C focal shift of Laikin's cemented achromat
 * (tests/published/laikin_achromat.txt: M. Laikin, Lens Design, 4th ed., p. 45, as
 * reproduced by the peer Optiland, whose tutorial prints a first-order longitudinal
 * colour of -0.015 for it) three ways:
 *  1. lensmat's paraxial engine per wavelength: bfd(F) - bfd(C) (px_colour_fdc on
 *     the prescription file as the lens reader gives it);
 *  2. real rays near the axis, traced independently of every lensmat engine
 *     (tests/meridional.h: exact refraction at spheres), the h -> 0 limit by Richardson
 *     extrapolation from h and h/2 (the remainder is even in h);
 *  3. the first-order (Seidel) estimate: Warren Smith's per-surface sum, written here
 *     from his formula, against lensmat's Seidel CI (-CI/(n' u'^2)).
 * and the peer's printed -0.015 checked: it is Smith's sum with each surface's
 * marginal-ray height taken from the surface before, not the lens's value. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "unit.h"
#include "paraxial/paraxial.h"
#include "meridional.h"
#include "lens/lens.h"

/* Smith's first-order longitudinal axial colour (Modern Optical Engineering, 6.3):
 * sum over surfaces of -TAchC_k/u'_k, TAchC_k = -y_k i_k (dn_k - n_k/n'_k dn'_k) /
 * (n'_last u'_last), dn = n(0.4861) - n(0.6563) as the peer takes it; paraxial marginal
 * ray from infinity at height y1.  height_before: the peer's slip (y_{k-1} for y_k). */
static double smith_lchc(const px_csurf *s, int ns, double y1, int height_before)
{
    double n[8], nf[8], nc[8], y[8], u[8], ii[8], sum = 0, yy = y1;
    const char *g;
    for (int k = 0; k <= ns; k++) {
        g = k ? s[k - 1].glass : "air";
        px_glass_index(g, PX_LAMBDA_D, &n[k]);
        px_glass_index(g, 0.4861, &nf[k]);
        px_glass_index(g, 0.6563, &nc[k]);
    }
    u[0] = 0;
    for (int k = 0; k < ns; k++) {
        double c = 1 / s[k].r;
        y[k] = yy;
        ii[k] = y[k] * c + u[k];
        u[k + 1] = (n[k] * u[k] - y[k] * c * (n[k + 1] - n[k])) / n[k + 1];
        yy += s[k].t * u[k + 1];
    }
    for (int k = 0; k < ns; k++) {
        double yk = height_before && k ? y[k - 1] : y[k];
        double ta = -yk * ii[k] / (n[ns] * u[ns]) *
                    ((nf[k] - nc[k]) - n[k] / n[k + 1] * (nf[k + 1] - nc[k + 1]));
        sum += -ta / u[ns];
    }
    return sum;
}

static char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    char *b;
    if (!f) return NULL;
    b = malloc(1 << 16);
    *n = b ? fread(b, 1, (1 << 16) - 1, f) : 0;
    if (b) b[*n] = '\0';
    fclose(f);
    return b;
}

int main(void)
{
    size_t len = 0;
    char *text = slurp("tests/published/laikin_achromat.txt", &len);
    char err[LN_ERR_MAX] = "ok", names[8][LN_NAME_MAX];
    ln_lens l;
    ln_notes notes = {0};
    px_csurf cs[8];
    const char *obj;
    px_colour c;
    px_seidel sd;
    double par, real, h = 1e-3, fo, fo_slip, fo_ci;
    CHECK(text != NULL, "tests/published/laikin_achromat.txt is there");
    if (!text) return 1;
    CHECK(ln_read_rx(text, len, "laikin_achromat.txt", &l, &notes, err, sizeof err) == LN_OK,
          "the published prescription reads (%s)", err);
    free(text);
    ln_notes_free(&notes);
    CHECK(l.nsurf == 3 && !strcmp(l.surf[0].glass, "N-BAK1") && !strcmp(l.surf[1].glass, "SF2") &&
          l.ap_value == 3.4, "3 surfaces, N-BAK1 / SF2, EPD 3.4");
    CHECK(ln_to_csurf(&l, cs, names, &obj, err, sizeof err) == LN_OK, "as csurfs");
    CHECK(px_colour_fdc(cs, 3, obj, &c) == PX_OK, "per wavelength F d C");
    par = c.long_colour;
    CHECK(fabs(c.first[1].bfd.v - 19.6059) < 0.002, "bfd at d %.6f against the back distance 19.6059 "
          "(the book's, within 2 um)", c.first[1].bfd.v);
    {   /* real rays: h and h/2, Richardson (error ~ h^2) */
        double f1 = mer_focus(cs, 3, PX_LAMBDA_F, h), c1 = mer_focus(cs, 3, PX_LAMBDA_C, h);
        double d1 = f1 - c1;
        real = mer_colour(cs, 3, PX_LAMBDA_F, PX_LAMBDA_C, h);
        CHECK(fabs(real - par) <= 1e-6 * fabs(par), "F-C focal shift: paraxial %.9f, real rays "
              "near the axis %.9f (relative %.1e)", par, real, fabs(real - par) / fabs(par));
        CHECK(fabs(d1 - par) > 1e-10 && fabs(d1 - par) < 1e-5, "(the real rays at h = %g differ by "
              "%.2e: the trace is not the paraxial formula)", h, d1 - par);
    }
    CHECK(px_seidel_run(cs, 3, obj, 1.7, 0, &sd) == PX_OK, "Seidel sums");
    fo_ci = -sd.total.c1 / (sd.n_last * sd.u_last * sd.u_last);
    fo = smith_lchc(cs, 3, 1.7, 0);
    fo_slip = smith_lchc(cs, 3, 1.7, 1);
    CHECK(fabs(fo - fo_ci) < 2e-3 * fabs(fo), "first order: Smith's sum %.6f, lensmat's -CI/(n'u'^2) "
          "%.6f (the same to the F/C lines' rounding)", fo, fo_ci);
    CHECK(fabs(fo - par) < 0.01 * fabs(par), "first order %.6f within 1 %% of the exact %.6f",
          fo, par);
    CHECK(fabs(fo - -0.015) > 0.0005, "the peer's printed -0.015 is not the lens's first-order "
          "value %.6f (off by %.1f %%, beyond its printed half-unit 0.0005)", fo,
          100 * fabs(fo + 0.015) / fabs(fo));
    CHECK(fabs(fo_slip - -0.015) <= 0.0005, "it is Smith's sum with each surface's height from the "
          "surface before: %.6f, printed -0.015", fo_slip);
    ln_free(&l);
    return unit_failed();
}
