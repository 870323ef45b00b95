/* unit_beam.c -- Gaussian beams (src/paraxial/beam.c) against closed forms written
 * here independently: free propagation w(z) = w0 sqrt(1 + (z/zR)^2),
 * R(z) = z + zR^2/z; Self's thin-lens waist formula (S. A. Self, Applied Optics 22,
 * 658 (1983)); a plane interface (w kept, R scaled by n2/n1); 4f relays; extreme
 * scales; (w, R) -> beam -> (w, R). */
#include <math.h>
#include "unit.h"
#include "paraxial/paraxial.h"

static const double PI = 3.14159265358979323846;
static double rel(double a, double b) { return a == b ? 0 : fabs(a - b) / fabs(b); }

static void free_space(double w0, double lambda, double m2)
{
    double zr = PI * w0 * w0 / (m2 * lambda);
    static const double zs[] = {0, 1e-3, -1, 10, 794.33, -5e3, 1e4, 1e7};
    double worst_w = 0, worst_r = 0;
    for (unsigned i = 0; i < sizeof zs / sizeof zs[0]; i++) {
        double z = zs[i] * zr / 794.33;
        px_beam b;
        px_beam_at at;
        px_beam_waist(w0, 0, lambda, m2, 1, &b);
        px_beam_apply(&b, px_translation(z), 1);
        px_beam_props(&b, &at);
        double w = w0 * sqrt(1 + (z / zr) * (z / zr));
        double r = z == 0 ? INFINITY : z + zr * zr / z;
        if (rel(at.w, w) > worst_w) worst_w = rel(at.w, w);
        if (!(isinf(r) && isinf(at.r)) && rel(at.r, r) > worst_r) worst_r = rel(at.r, r);
    }
    CHECK(worst_w < 1e-13 && worst_r < 1e-13,
          "free space w0 %g lambda %g M2 %g: w and R to %.2g, %.2g relative", w0, lambda,
          m2, worst_w, worst_r);
}

/* Self (1983), eq. 9a and 10: an input waist a distance s before a thin lens f (air) */
static void self_lens(double w0, double lambda, double s, double f)
{
    double zr = PI * w0 * w0 / lambda;
    double sf = s - f;
    double s2 = 1 / (1 / f - 1 / (s + zr * zr / sf));   /* 1/(s + zR^2/(s-f)) + 1/s'' = 1/f */
    if (sf == 0) s2 = f;
    double m = 1 / sqrt((1 - s / f) * (1 - s / f) + (zr / f) * (zr / f));
    px_beam b;
    px_beam_at at;
    px_beam_waist(w0, s, lambda, 1, 1, &b);            /* s past the waist: at the lens */
    px_beam_apply(&b, (px_mat){1, 0, -1 / f, 1}, 1);
    px_beam_props(&b, &at);
    CHECK(rel(at.z_waist, s2) < 1e-12 && rel(at.w0, m * w0) < 1e-12,
          "Self's lens formula, s %g f %g zR %g: waist at %.15g (Self %.15g), w0 %.15g (Self %.15g)",
          s, f, zr, at.z_waist, s2, at.w0, m * w0);
}

int main(void)
{
    free_space(0.4, 632.8e-6, 1);
    free_space(0.4, 632.8e-6, 3.5);
    free_space(1e3, 1e-6, 1);           /* zR ~ 3e12 */
    free_space(1e-4, 1.06e-3, 1.2);     /* zR ~ 3e-5 */

    self_lens(0.4, 632.8e-6, 100, 50);
    self_lens(0.4, 632.8e-6, 50, 50);   /* waist in the front focal plane: out at f */
    self_lens(0.4, 632.8e-6, 2000, 250);
    self_lens(0.05, 532e-6, 10, -100);  /* diverging lens */
    self_lens(2, 1064e-6, 1e4, 1e3);

    {   /* a plane interface into glass: w unchanged, R -> R n2/n1, zR inside n2 zR */
        px_beam b;
        px_beam_at a0, a1;
        px_beam_waist(0.4, 300, 632.8e-6, 1, 1, &b);
        px_beam_props(&b, &a0);
        px_beam_apply(&b, px_refraction(1, 1.5, INFINITY), 1.5);
        px_beam_props(&b, &a1);
        CHECK(rel(a1.w, a0.w) < 1e-15 && rel(a1.r, 1.5 * a0.r) < 1e-14 &&
              rel(a1.zr, 1.5 * a0.zr) < 1e-14 && rel(a1.z_waist, 1.5 * a0.z_waist) < 1e-14,
              "plane interface into n 1.5: w %.3g, R %.3g, zR %.3g, waist distance %.3g relative",
              rel(a1.w, a0.w), rel(a1.r, 1.5 * a0.r), rel(a1.zr, 1.5 * a0.zr),
              rel(a1.z_waist, 1.5 * a0.z_waist));
    }
    {   /* 500 4f relays (f = 37): each images the waist onto itself inverted, so the
           beam comes back; the imaginary part is kept by construction */
        px_beam b, b0;
        px_beam_at at, a0;
        px_beam_waist(0.3, -12, 632.8e-6, 1.3, 1, &b);
        b0 = b;
        double f = 37;
        px_mat lens = {1, 0, -1 / f, 1}, gap = px_translation(f);
        for (int i = 0; i < 500; i++) {
            px_beam_apply(&b, gap, 1); px_beam_apply(&b, lens, 1);
            px_beam_apply(&b, px_translation(2 * f), 1); px_beam_apply(&b, lens, 1);
            px_beam_apply(&b, gap, 1);
        }
        px_beam_props(&b, &at);
        px_beam_props(&b0, &a0);
        CHECK(rel(at.w0, a0.w0) < 1e-9 && fabs(at.z_waist - a0.z_waist) < 1e-9 * f,
              "500 4f relays: waist %.3g relative, its place %.3g f", rel(at.w0, a0.w0),
              fabs(at.z_waist - a0.z_waist) / f);
    }
    {   /* (w, R) -> beam -> (w, R), converging and diverging, and a flat front */
        static const double rs[] = {-250, 1e5, INFINITY, 3};
        double worst = 0;
        for (int i = 0; i < 4; i++) {
            px_beam b;
            px_beam_at at;
            px_beam_local(1.7, rs[i], 780e-6, 1.1, 1.336, &b);
            px_beam_props(&b, &at);
            double e = rel(at.w, 1.7);
            if (!isinf(rs[i]) && rel(at.r, rs[i]) > e) e = rel(at.r, rs[i]);
            if (isinf(rs[i]) && !isinf(at.r)) e = 1;
            if (e > worst) worst = e;
        }
        CHECK(worst < 1e-14, "local (w, R) round trip to %.2g relative", worst);
    }
    {   /* bad inputs are refused */
        px_beam b;
        CHECK(px_beam_waist(0, 0, 1e-3, 1, 1, &b) == PX_BAD &&
              px_beam_waist(1, 0, 1e-3, 0.9, 1, &b) == PX_BAD &&
              px_beam_waist(1, NAN, 1e-3, 1, 1, &b) == PX_BAD &&
              px_beam_local(1, 0, 1e-3, 1, 1, &b) == PX_BAD,
              "zero waist, M2 < 1, NaN place, R = 0: refused");
        px_beam_waist(1, 0, 1e-3, 1, 1, &b);
        CHECK(px_beam_apply(&b, (px_mat){1, 0, INFINITY, 1}, 1) == PX_BAD,
              "an infinite-power element: refused");
    }
    return unit_failed();
}
