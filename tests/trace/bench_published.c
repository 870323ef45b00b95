/* bench_published.c -- the tracer on a published lens (run by
 * scripts/bench_trace_published.sh): Sasian's Cooke triplet (tests/published/
 * sasian_triplet.txt, its source named there), indices at d, image plane at the
 * prescription's 41.2365 mm, and, as the second row for the history, the Cooke
 * triplet bench_trace has always used (tests/trace/tt.h, Zemax tutorial).  For each:
 *   trace_lens_<lens>_mrays_per_s     on axis, 1128 x 1128 grid over the 12.5 mm
 *                                      pupil (about 1e6 rays), Fresnel on,
 *                                      reflections off, one thread, median of 3
 *   trace_lens_<lens>_rms_chief_um    RMS spot radius about the chief ray,
 *                                      unweighted (as lens tracers report it)
 *   trace_lens_<lens>_rms_power_um    power-weighted (Fresnel s + p) about the
 *                                      power centroid (= bench_trace's figure)
 *   trace_lens_<lens>_transmitted     detected / emitted power
 *   trace_lens_sasian_vs_triplet      the two lenses' Mrays/s, same run, alternated
 * and for Sasian's published fields 14.14 and 20 degrees (0.707 and 1 of the field):
 * the real chief ray aimed through the stop's centre, a 256 x 256 grid over the
 * paraxial entrance pupil about it, RMS unweighted and power-weighted about the
 * chief ray, and about the power centroid.  BENCH_QUICK=1: fewer rays. */
#include <stdlib.h>
#include "pub.h"

static int cmpd(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* One on-axis run of each lens, alternated three times (the machine's speed drifts:
 * the ratio of the same run's medians is the figure to compare). */
static void axis_rows(const trace_api *tr, const char *const name[2], const pub_lens *pl[2],
                      const double zd[2], const double r_pupil[2], long across)
{
    pub_result r[2][3];
    double v[2][3];
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 2; k++) {
            if (pub_trace(tr, pl[k], zd[k], NULL, across, r_pupil[k], 1, &r[k][i])) {
                fprintf(stderr, "bench_published: %s failed\n", name[k]);
                exit(1);
            }
            v[k][i] = r[k][i].rays_per_s;
        }
    for (int k = 0; k < 2; k++) {
        qsort(v[k], 3, sizeof v[k][0], cmpd);
        printf("BENCH trace_lens_%s_mrays_per_s %.3f Mrays/s\n", name[k], v[k][1] / 1e6);
        printf("BENCH trace_lens_%s_rms_chief_um %.3f um\n", name[k], r[k][0].rms_chief_um);
        printf("BENCH trace_lens_%s_rms_power_um %.3f um\n", name[k], r[k][0].rms_power_centroid_um);
        printf("BENCH trace_lens_%s_transmitted %.4f ratio\n", name[k], r[k][0].transmitted);
        printf("BENCH trace_lens_%s_rays %ld rays\n", name[k], r[k][0].rays);
    }
    printf("BENCH trace_lens_%s_vs_%s %.3f ratio\n", name[0], name[1], v[0][1] / v[1][1]);
}

int main(void)
{
    const trace_api *tr = tt_api();
    int quick = getenv("BENCH_QUICK") && *getenv("BENCH_QUICK");
    long across = quick ? 300 : 1128, field_across = quick ? 96 : 256;
    pub_lens sas, cooke;
    trace_lens_surface s[TT_NSURF];
    trace_lens l;

    if (pub_read(PUB_SASIAN, pub_sasian_sd, &sas)) return 1;
    double zd = sas.s[sas.nsurf - 1].z + PUB_SASIAN_IMAGE;

    /* the second row: bench_trace's triplet, detector at its paraxial image */
    tt_triplet(s, &l, 1);
    memset(&cooke, 0, sizeof cooke);
    memcpy(cooke.s, s, sizeof s);
    cooke.nsurf = TT_NSURF;
    cooke.lens = l;
    cooke.lens.surf = cooke.s;
    {
        const char *const names[2] = {"sasian", "triplet"};
        const pub_lens *lenses[2] = {&sas, &cooke};
        const double zds[2] = {zd, tt_paraxial_image(&cooke.lens, -INFINITY)};
        const double radii[2] = {PUB_SASIAN_EPD / 2, TT_EPD / 2};
        axis_rows(tr, names, lenses, zds, radii, across);
    }

    double enp = pub_enp(&sas, PUB_SASIAN_STOP), z0 = -10;
    static const struct { const char *tag; double frac; } fld[2] = {{"14deg", 0.707}, {"20deg", 1}};
    for (int f = 0; f < 2; f++) {
        double th = fld[f].frac * PUB_SASIAN_FIELD * PUB_PI / 180, yc;
        trace_ray *rays = NULL;
        pub_result r;
        if (!isfinite(pub_aim_chief(&sas, PUB_SASIAN_STOP, th, z0, enp, &yc))) return 1;
        long n = pub_field_rays(th, z0, yc, enp, PUB_SASIAN_EPD / 2, field_across, &rays);
        if (n < 0 || pub_trace_field(tr, &sas, zd, rays, n, 1, &r)) return 1;
        printf("BENCH trace_lens_sasian_%s_rms_chief_um %.3f um\n", fld[f].tag, r.rms_chief_um);
        printf("BENCH trace_lens_sasian_%s_rms_power_chief_um %.3f um\n", fld[f].tag,
               r.rms_power_chief_um);
        printf("BENCH trace_lens_sasian_%s_rms_power_um %.3f um\n", fld[f].tag,
               r.rms_power_centroid_um);
        printf("BENCH trace_lens_sasian_%s_transmitted %.4f ratio\n", fld[f].tag, r.transmitted);
        free(rays);
    }
    return 0;
}
