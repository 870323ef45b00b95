/* unit_lens_shape.c -- ln_shape_check (src/lens/lens_shape.c) against closed forms
 * written here: two spheres (centres c1 = z1 + R1, c2 = z2 + R2) meet on the circle
 * where (z - c1)^2 + h^2 = R1^2 and (z - c2)^2 + h^2 = R2^2, i.e. at
 * z = (R1^2 - R2^2 + c2^2 - c1^2) / (2 (c2 - c1)), h = sqrt(R1^2 - (z - c1)^2); a
 * sphere and a plane at zp meet at h = sqrt(R^2 - (zp - c)^2).  A lens is refused
 * exactly when that height lies inside both semi-diameters, at that height (the
 * message's %g: 6 digits), and a semi-diameter beyond |R| is refused. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "unit.h"
#include "lens/lens.h"

static double cross_spheres(double z1, double r1, double z2, double r2)
{
    double c1 = z1 + r1, c2 = z2 + r2;
    double z = (r1 * r1 - r2 * r2 + c2 * c2 - c1 * c1) / (2 * (c2 - c1));
    return sqrt(r1 * r1 - (z - c1) * (z - c1));
}

static int run(double r1, double z1, double s1, double r2, double z2, double s2,
               char *why, int *bad)
{
    ln_surface s[2];
    double z[2] = {z1, z2};
    memset(s, 0, sizeof s);
    ln_set_radius(&s[0], r1);
    ln_set_radius(&s[1], r2);
    s[0].semi = s1;
    s[1].semi = s2;
    return ln_shape_check(s, z, 2, bad, why, LN_ERR_MAX);
}

/* the height the message names */
static double said_height(const char *why)
{
    const char *p = strstr(why, "at height ");
    return p ? strtod(p + 10, NULL) : NAN;
}

int main(void)
{
    char why[LN_ERR_MAX];
    int bad = -1;
    /* biconvex 20/-20, 2 apart: sqrt(20^2 - 19^2) */
    double h = cross_spheres(0, 20, 2, -20);
    CHECK(fabs(h - sqrt(39.0)) < 1e-12, "closed form: biconvex 20/-20 t 2 meets at sqrt(39)");
    CHECK(run(20, 0, 12, -20, 2, 12, why, &bad) == LN_BAD && bad == 1 &&
          fabs(said_height(why) - h) < 1e-5 * h, "biconvex, semi 12: refused at %s", why);
    CHECK(run(20, 0, 6.2, -20, 2, 6.2, why, &bad) == LN_OK, "biconvex, semi 6.2 < 6.245: made");
    CHECK(run(20, 0, 6.3, -20, 2, 6.3, why, &bad) == LN_BAD, "biconvex, semi 6.3 > 6.245: refused");
    /* a meniscus of unequal radii: 30 then 50, 1 apart (the front is steeper: they
     * close towards the rim) */
    h = cross_spheres(0, 30, 1, 50);
    CHECK(h > 0 && h < 30, "closed form: meniscus 30/50 t 1 meets at %g", h);
    CHECK(run(30, 0, 0.99 * h, 50, 1, 0.99 * h, why, &bad) == LN_OK, "meniscus inside: made");
    CHECK(run(30, 0, 1.01 * h, 50, 1, 1.01 * h, why, &bad) == LN_BAD &&
          fabs(said_height(why) - h) < 1e-5 * h, "meniscus past %g: refused at %s", h, why);
    /* the crossing lies inside one zone only: made (semis 20 and 5 around 6.245) */
    CHECK(run(20, 0, 20, -20, 2, 5, why, &bad) == LN_OK, "one zone ends before the crossing: made");
    /* plano-convex: plane at 3 behind a radius-25 sphere: sqrt(25^2 - 22^2) */
    h = sqrt(25.0 * 25 - 22.0 * 22);
    CHECK(run(25, 0, 12, INFINITY, 3, 12, why, &bad) == LN_BAD &&
          fabs(said_height(why) - h) < 1e-5 * h, "plano-convex: refused at %s (want %g)", why, h);
    CHECK(run(25, 0, 11.8, INFINITY, 3, 11.8, why, &bad) == LN_OK, "plano-convex under %g: made", h);
    /* a semi-diameter on a sphere: up to |R| (a hemisphere), not past it */
    CHECK(run(20, 0, 20, INFINITY, 40, 20, why, &bad) == LN_OK, "hemisphere semi = |R|: made");
    CHECK(run(20, 0, 25, INFINITY, 40, 25, why, &bad) == LN_BAD && bad == 0 &&
          strstr(why, "surface 1 has radius 20, so its semi-diameter can be at most 20 (not 25)"),
          "semi 25 on radius 20: %s", why);
    CHECK(run(-20, 0, 5, -20, 10, 25, why, &bad) == LN_BAD && bad == 1 &&
          strstr(why, "surface 2 has radius -20"), "semi 25 on surface 2: %s", why);
    /* semis not given (0): nothing to check */
    CHECK(run(20, 0, 0, -20, 2, 0, why, &bad) == LN_OK, "no semi-diameters: not checked");
    return unit_failed();
}
