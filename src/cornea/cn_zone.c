/* cn_zone.c -- curvature of a fitted surface as topographers show it: axial
 * (sagittal) and tangential (meridional) curvature along the meridian through a
 * point, and Sim K over the 3 mm zone (the axial curvature on the ring of height
 * 1.5 mm, its mean and second harmonic), in the surface's own eye frame. */
#include <math.h>
#include "cn_int.h"

/* Slope along the unit direction (ex, ey) at (x, y); -1 off the surface. */
static int radial_slope(const cn_surf *s, double x, double y, double ex, double ey,
                        double *zr)
{
    double z, zx, zy;
    if (cn_sag(s, x, y, &z, &zx, &zy)) return -1;
    *zr = zx * ex + zy * ey;
    return 0;
}

int cn_curvatures(const cn_surf *s, double x, double y, double *axial, double *tang)
{
    double r = hypot(x, y), ex = 1, ey = 0, zr, za, zb;
    const double h = 1e-4;                 /* slope difference step (mm) */
    if (r > 0) { ex = x / r; ey = y / r; }
    if (radial_slope(s, x, y, ex, ey, &zr) ||
        radial_slope(s, x + h * ex, y + h * ey, ex, ey, &za) ||
        radial_slope(s, x - h * ex, y - h * ey, ex, ey, &zb))
        return -1;
    double zrr = (za - zb) / (2 * h), q = 1 + zr * zr;
    *tang = zrr / (q * sqrt(q));
    /* axial: 1 / (distance along the normal from the point to the axis); its limit
     * at the apex is the tangential curvature */
    *axial = r > 1e-6 ? zr / (r * sqrt(q)) : *tang;
    return 0;
}

int cn_zone_simk(const cn_surf *s, double h, double *km, double *amp, double *steep_deg)
{
    enum { N = 72 };
    double sum = 0, a = 0, b = 0;
    for (int j = 0; j < N; j++) {
        double phi = 2 * M_PI * j / N, ax, tg;
        if (cn_curvatures(s, h * cos(phi), h * sin(phi), &ax, &tg)) return -1;
        sum += ax;
        a += ax * cos(2 * phi);
        b += ax * sin(2 * phi);
    }
    *km = sum / N;
    a *= 2.0 / N;
    b *= 2.0 / N;
    *amp = hypot(a, b);
    double st = 0.5 * atan2(b, a) * 180 / M_PI;
    *steep_deg = st < 0 ? st + 180 : st;
    return 0;
}
