/* t_published.c -- the trace engine on a published lens: Sasian's Cooke triplet
 * (tests/published/sasian_triplet.txt; source: Sasian's OPTI 517 course as
 * reproduced in the ray-optics documentation, docs/source/examples/SasianTriplet/
 * SasianTriplet.rst of github.com/mjhoptics/ray-optics).  Checks the first-order
 * data ray-optics prints (4 digits), the real chief ray aimed through the stop's
 * centre, the spot figures of tests/trace/pub.h (what bench_published reports)
 * against tt.h's independent double trace of the same rays, and the Fresnel power
 * of the axial ray against the product of the surfaces' normal-incidence
 * transmittances. */
#include "pub.h"

static int fails;
#define CHECK(c, ...) do { if (c) printf("PASS "); else { printf("FAIL "); fails++; } \
                           printf(__VA_ARGS__); printf("\n"); } while (0)

static int near4(double v, double pub)    /* published with 4 significant digits */
{
    return fabs(v - pub) <= 0.5 * pow(10, floor(log10(fabs(pub))) - 3);
}

/* RMS about the chief ray of the same rays by tt_real_trace (no engine code). */
static double independent_rms(const pub_lens *pl, const trace_ray *r, long n, double zd)
{
    double p[3], d[3], c[3], s2 = 0;
    long m = 0;
    if (tt_real_trace(&pl->lens, r[0].o, r[0].d, zd, c, d)) return NAN;
    for (long i = 1; i < n; i++) {
        if (tt_real_trace(&pl->lens, r[i].o, r[i].d, zd, p, d)) continue;
        s2 += (p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]);
        m++;
    }
    return 1e3 * sqrt(s2 / m);
}

int main(void)
{
    const trace_api *tr = tt_api();
    pub_lens pl, bare;
    if (pub_read(PUB_SASIAN, pub_sasian_sd, &pl) || pub_read(PUB_SASIAN, NULL, &bare)) {
        printf("FAIL reading %s\n", PUB_SASIAN);
        return 1;
    }
    int ns = pl.nsurf;
    double zl = pl.s[ns - 1].z, zd = zl + PUB_SASIAN_IMAGE;
    CHECK(ns == 6, "six surfaces");
    CHECK(fabs(pl.s[0].n_right - 1.69100) < 5e-6 && fabs(pl.s[2].n_right - 1.67271) < 5e-6,
          "N-LAK9 %.6f, N-SF5 %.6f at d from data/glass.txt (SCHOTT: 1.69100, 1.67271)",
          pl.s[0].n_right, pl.s[2].n_right);

    /* first order, as ray-optics prints it (first_order_data, %.4g) */
    double efl = tt_efl(&pl.lens), bfl = tt_paraxial_image(&pl.lens, -INFINITY) - zl;
    double enp = pub_enp(&pl, PUB_SASIAN_STOP);
    CHECK(near4(efl, 50), "efl %.5f (published 50)", efl);
    CHECK(near4(bfl, 41.24), "bfl %.5f (published 41.24)", bfl);
    CHECK(near4(enp, 11.68), "entrance pupil %.5f behind surface 1 (published 11.68)", enp);
    CHECK(near4(efl / PUB_SASIAN_EPD, 4), "f/%.5f (published 4)", efl / PUB_SASIAN_EPD);

    /* the real chief ray at 20 degrees through the stop's centre */
    double th = PUB_SASIAN_FIELD * PUB_PI / 180, z0 = -10, y0, ys;
    double res = pub_aim_chief(&pl, PUB_SASIAN_STOP, th, z0, enp, &y0);
    CHECK(fabs(res) < 1e-12, "real chief ray aimed: %.2g mm from the stop's centre", res);
    pub_at_stop(&pl, PUB_SASIAN_STOP, th, z0, -(enp - z0) * tan(th), &ys);
    printf("INFO the paraxial pupil's chief ray meets the stop %.4f mm off centre (pupil aberration)\n", ys);

    /* the spot figures through the engine against the independent trace */
    for (int f = 0; f < 2; f++) {
        double t = f ? th : 0, yc = 0;
        trace_ray *rays = NULL;
        pub_result r;
        if (f) pub_aim_chief(&pl, PUB_SASIAN_STOP, t, z0, enp, &yc);
        long n = pub_field_rays(t, z0, yc, enp, PUB_SASIAN_EPD / 2, 64, &rays);
        CHECK(n > 3000, "%ld rays in the %g degree field", n, f ? PUB_SASIAN_FIELD : 0.0);
        CHECK(pub_trace_field(tr, &pl, zd, rays, n, 1, &r) == 0, "traced");
        double ind = independent_rms(&pl, rays, n, zd);
        CHECK(fabs(r.rms_chief_um - ind) < 1e-9 * ind,
              "%g deg: RMS about the chief ray %.6f um, independent trace %.6f um",
              f ? PUB_SASIAN_FIELD : 0.0, r.rms_chief_um, ind);
        CHECK(r.hits == r.rays, "%g deg: no ray vignetted by the published semi-diameters (%ld of %ld)",
              f ? PUB_SASIAN_FIELD : 0.0, r.hits, r.rays);
        CHECK(r.rms_power_chief_um >= r.rms_power_centroid_um &&
              fabs(r.rms_power_chief_um - r.rms_chief_um) < 0.05 * r.rms_chief_um,
              "%g deg: power-weighted %.4f um about the chief ray, %.4f about the centroid; "
              "unweighted %.4f", f ? PUB_SASIAN_FIELD : 0.0, r.rms_power_chief_um,
              r.rms_power_centroid_um, r.rms_chief_um);
        if (f)
            printf("INFO 20 deg: chief ray image height %.5f mm, paraxial efl tan(20) %.5f\n",
                   r.chief_y, efl * tan(t));
        else
            CHECK(fabs(r.rms_power_centroid_um - r.rms_power_chief_um) < 1e-9 * r.rms_chief_um,
                  "on axis the centroid is the chief ray's hit");
        free(rays);
    }

    /* distortion: the real chief ray's height in the paraxial image plane minus
     * efl tan(theta) tends to the published third-order DST 0.018387 mm (20 deg)
     * scaled as tan^3; the rest is fifth order (relative part ~ theta^2).  At 20
     * degrees the higher orders cancel most of it (0.11 of the third order). */
    {
        double zp = tt_paraxial_image(&pl.lens, -INFINITY), dev[7], deg = PUB_SASIAN_FIELD;
        for (int k = 0; k < 7; k++, deg /= 2) {
            double t = deg * PUB_PI / 180, yc = 0, o[3], d[3], p[3], dd[3];
            pub_aim_chief(&bare, PUB_SASIAN_STOP, t, z0, enp, &yc);
            o[0] = 0; o[1] = yc; o[2] = z0;
            pub_dir(t, d);
            tt_real_trace(&bare.lens, o, d, zp, p, dd);
            double pred = 0.018387 * pow(tan(t) / tan(th), 3);
            dev[k] = (p[1] - efl * tan(t)) / pred - 1;
            printf("INFO %7.4f deg: real distortion / third order - 1 = %+.3e\n", deg, dev[k]);
        }
        for (int k = 3; k < 7; k++)
            CHECK(dev[k - 1] / dev[k] > 3.6 && dev[k - 1] / dev[k] < 4.4,
                  "field halved: the real distortion's departure from the third order falls by %.2f (4)",
                  dev[k - 1] / dev[k]);
        CHECK(fabs(dev[6]) < 3e-4, "at %.4g deg the real distortion is the published DST's to %.1e",
              PUB_SASIAN_FIELD / 64, fabs(dev[6]));
    }

    /* Fresnel: the axial ray alone transmits the product of the normal-incidence
     * transmittances 4 n n' / (n + n')^2 of the six surfaces */
    {
        trace_ray one[2] = {{{0, 0, z0}, {0, 0, 1}, 0}, {{0, 1e-6, z0}, {0, 0, 1}, 0}};
        pub_result r;
        double T = 1, n = 1;
        for (int i = 0; i < ns; i++) {
            double n2 = pl.s[i].n_right;
            T *= 4 * n * n2 / ((n + n2) * (n + n2));
            n = n2;
        }
        CHECK(pub_trace_field(tr, &pl, zd, one, 2, 1, &r) == 0 && fabs(r.transmitted - T) < 1e-12,
              "axial rays transmit %.12f of their power, product of Fresnel T %.12f",
              r.transmitted, T);
    }
    printf("%s\n", fails ? "some checks failed" : "all checks passed");
    return fails != 0;
}
