/* bench_glass.c -- figures of the glass catalogue and the per-wavelength paraxial
 * engine (scripts/bench_glass.sh):
 *  - glass_nd_max_err, glass_vd_max_err: the largest disagreement, over every
 *    catalogue entry with published values, between the formula's nd (Vd) and the
 *    value the source prints, in units of the printed last place (0.5 or less: the
 *    formula rounds to the printed value);
 *  - paraxial_efl_err, paraxial_bfl_err: Thorlabs AC254-100-A (prescription from
 *    Thorlabs' Zemax file, see tests/unit_glass.c) against the product page's
 *    f = 100.1 mm and BFL = 97.1 mm at 587.6 nm, relative;
 *  - paraxial_fc_shift: its F-C focal shift bfd(F) - bfd(C), mm, and
 *    paraxial_fc_vs_singlet: that shift over an N-BK7 singlet's of the same f;
 *  - glass_index_per_s: px_glass_index by name (look-up + Sellmeier) against the
 *    baseline of the same Sellmeier with the coefficients in hand, medians of runs;
 *  - paraxial_chromatic_err (issue 22): Laikin's cemented achromat
 *    (tests/published/laikin_achromat.txt), its F-C focal shift bfd(F) - bfd(C) by
 *    the paraxial engine against real rays near the axis traced here (exact
 *    refraction at spheres, the h -> 0 limit by Richardson from h = 1e-3, 5e-4),
 *    relative; paraxial_chromatic_shift, the shift itself; and
 *    paraxial_chromatic_first_order_err: the Seidel estimate -CI/(n' u'^2) against it
 *    (the peer's printed -0.015 is checked in tests/unit_chromatic.c);
 *  - glass_count: the materials the catalogues give (built-in plus every AGF file
 *    found: $LENSMAT_GLASS_PATH, data/agf, ../shared/glass), and glass_catalogs. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "paraxial/paraxial.h"
#include "meridional.h"
#include "bench_util.h"

/* |v - printed| in units of the printed string's last place */
static double last_places(double v, const char *printed)
{
    const char *dot = strchr(printed, '.');
    int dec = dot ? (int)strlen(dot + 1) : 0;
    return fabs(v - atof(printed)) * pow(10, dec);
}

#define NLOOK 200000
static double by_name(double *sink)
{
    static const char *names[] = {"N-BK7", "SF5", "N-SF6", "F_SILICA", "CAF2", "N-BAF10"};
    double t0 = now(), s = 0, n;
    for (int i = 0; i < NLOOK; i++) {
        px_glass_index(names[i % 6], 0.4 + 1e-6 * (i % 1000), &n);
        s += n;
    }
    *sink += s;
    return now() - t0;
}

static double baseline(double *sink)
{
    static const double c[6][6] = {
        {1.03961212, 0.00600069867, 0.231792344, 0.0200179144, 1.01046945, 103.560653},
        {1.46141885, 0.0111826126, 0.247713019, 0.0508594669, 0.949995832, 112.041888},
        {1.77931763, 0.0133714182, 0.338149866, 0.0617533621, 2.08734474, 174.01759},
        {0.6961663, 0.0684043 * 0.0684043, 0.4079426, 0.1162414 * 0.1162414, 0.8974794,
         9.896161 * 9.896161},
        {0.5675888, 0.050263605 * 0.050263605, 0.4710914, 0.1003909 * 0.1003909, 3.8484723,
         34.649040 * 34.649040},
        {1.5851495, 0.00926681282, 0.143559385, 0.0424489805, 1.08521269, 105.613573},
    };
    double t0 = now(), s = 0;
    for (int i = 0; i < NLOOK; i++) {
        const double *k = c[i % 6];
        double l = 0.4 + 1e-6 * (i % 1000), l2 = l * l;
        s += sqrt(1 + k[0] * l2 / (l2 - k[1]) + k[2] * l2 / (l2 - k[3]) +
                  k[4] * l2 / (l2 - k[5]));
    }
    *sink += s;
    return now() - t0;
}

static int laikin(void)
{
    const px_csurf s[3] = {{12.38401, 0.4340, "N-BAK1"}, {-7.94140, 0.3210, "SF2"},
                           {-48.44396, 19.6059, "air"}};
    px_colour c;
    px_seidel sd;
    double real, fo;
    if (px_colour_fdc(s, 3, "air", &c) != PX_OK || px_seidel_run(s, 3, "air", 1.7, 0, &sd) != PX_OK)
        return 1;
    real = mer_colour(s, 3, PX_LAMBDA_F, PX_LAMBDA_C, 1e-3);
    fo = -sd.total.c1 / (sd.n_last * sd.u_last * sd.u_last);
    printf("BENCH paraxial_chromatic_err %.2g rel\n", fabs(c.long_colour - real) / fabs(real));
    printf("BENCH paraxial_chromatic_shift %.6f mm\n", c.long_colour);
    printf("BENCH paraxial_chromatic_first_order_err %.2g rel\n", fabs(fo - c.long_colour) / fabs(c.long_colour));
    return 0;
}

int main(int argc, char **argv)
{
    int runs = argc > 1 ? atoi(argv[1]) : 21;
    double nd_err = 0, vd_err = 0, sink = 0;
    double *ta, *tb;
    px_colour c, single;
    const px_csurf ac[3] = {{1 / 1.593625498007969800E-002, 4.0, "N-BK7"},
                            {1 / -2.187705097352880100E-002, 2.5, "SF5"},
                            {1 / -7.798487093503899700E-003, 0, "air"}};
    const px_csurf bk7[2] = {{51.68, 2.0, "N-BK7"}, {INFINITY, 0, "air"}};
    if (runs < 1) runs = 1;
    for (int i = 0; i < px_glass_count(); i++) {
        const px_glass_rec *g = px_glass_at(i);
        double nd, vd;
        if (g->nd[0] == '-' || px_glass_index(g->name, PX_LAMBDA_D, &nd) != PX_OK) continue;
        nd_err = fmax(nd_err, last_places(nd, g->nd));
        if (g->vd[0] == '-' || px_glass_abbe(g->name, &vd) != PX_OK) continue;
        vd_err = fmax(vd_err, last_places(vd, g->vd));
    }
    printf("BENCH glass_nd_max_err %.2f last_place\n", nd_err);
    printf("BENCH glass_vd_max_err %.2f last_place\n", vd_err);
    if (px_colour_fdc(ac, 3, "air", &c) != PX_OK || px_colour_fdc(bk7, 2, "air", &single))
        return 1;
    printf("BENCH paraxial_efl_err %.2g rel\n", fabs(c.first[1].efl.v - 100.1) / 100.1);
    printf("BENCH paraxial_bfl_err %.2g rel\n", fabs(c.first[1].bfd.v - 97.1) / 97.1);
    printf("BENCH paraxial_fc_shift %.4f mm\n", c.long_colour);
    printf("BENCH paraxial_fc_vs_singlet %.3f ratio\n", c.long_colour / single.long_colour);
    if (laikin()) return 1;
    printf("BENCH glass_count %d materials\n", px_glass_total());
    printf("BENCH glass_catalogs %d agf_files\n", px_glass_cat_count());
    ta = malloc(sizeof *ta * runs);
    tb = malloc(sizeof *tb * runs);
    if (!ta || !tb) return 1;
    for (int r = 0; r < runs; r++) { ta[r] = by_name(&sink); tb[r] = baseline(&sink); }
    qsort(ta, runs, sizeof *ta, cmp);
    qsort(tb, runs, sizeof *tb, cmp);
    printf("BENCH glass_index_per_s %.0f lookups/s\n", NLOOK / ta[runs / 2]);
    printf("BENCH glass_index_vs_formula %.2f ratio\n", ta[runs / 2] / tb[runs / 2]);
    free(ta);
    free(tb);
    return sink == 0;   /* keeps the loops */
}
