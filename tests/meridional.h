/* meridional.h -- an exact meridional ray trace through spheres, independent of every
 * lensmat engine, for the tests and benchmarks that check the paraxial engine against
 * real rays (tests/unit_chromatic.c, tests/bench_glass.c).  Header-only. */
#ifndef MERIDIONAL_H
#define MERIDIONAL_H
#include <math.h>
#include "paraxial/paraxial.h"

/* A ray parallel to the axis at height h through spheres (vertex radii r, gaps t,
 * glasses by name), in air: the distance from the last vertex to where it crosses
 * the axis (NaN: a glass without an index at lam). */
static double mer_focus(const px_csurf *s, int ns, double lam, double h)
{
    double z = -1, y = h, dz = 1, dy = 0, n1 = 1, zv = 0, zlast = 0;
    for (int k = 0; k < ns; k++) {
        double R = s[k].r, n2, cz = zv + R, oz = z - cz, b, c, t, Nz, Ny, mu, ci, ct;
        if (px_glass_index(s[k].glass, lam, &n2) != PX_OK) return NAN;
        b = oz * dz + y * dy;
        c = oz * oz + y * y - R * R;
        t = -b + (R > 0 ? -1 : 1) * sqrt(b * b - c);      /* the vertex side of the sphere */
        z += t * dz;
        y += t * dy;
        Nz = (z - cz) / R;                                  /* unit normal */
        Ny = y / R;
        if (Nz * dz + Ny * dy > 0) { Nz = -Nz; Ny = -Ny; }  /* against the ray */
        mu = n1 / n2;                                       /* vector Snell */
        ci = -(Nz * dz + Ny * dy);
        ct = sqrt(1 - mu * mu * (1 - ci * ci));
        dz = mu * dz + (mu * ci - ct) * Nz;
        dy = mu * dy + (mu * ci - ct) * Ny;
        n1 = n2;
        zlast = zv;
        zv += s[k].t;
    }
    return z - y / dy * dz - zlast;
}

/* bfd(lf) - bfd(lc) by real rays, the h -> 0 limit by Richardson from h and h/2 (the
 * remainder is even in h, so its leading h^2 term cancels). */
static double mer_colour(const px_csurf *s, int ns, double lf, double lc, double h)
{
    double d1 = mer_focus(s, ns, lf, h) - mer_focus(s, ns, lc, h);
    double d2 = mer_focus(s, ns, lf, h / 2) - mer_focus(s, ns, lc, h / 2);
    return d2 + (d2 - d1) / 3;
}
#endif
