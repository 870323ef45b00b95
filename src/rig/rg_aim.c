/* rg_aim.c -- the exact model's solution when mirror surfaces sit off their rotation
 * axes, by the section-38 construction repeated: the beam must still run along the
 * backward ray and land on m2's surface centre, but where the surfaces are depends
 * on the normals being solved for.  Each pass places the surface points for the
 * current normals and bisects again; a pass shrinks the error by about offset / (2 x
 * mirror spacing) (~1/80 in the example rig), so a few passes reach rounding.  Newton
 * (rg_newton) stays as the fallback and the check. */
#include "rig/rg_geom.h"
#include "rig/rg_vec.h"

#define AIM_PASSES 40

/* Where the laser line meets m1's surface for normal n1. */
static int m1_point(const rg_geometry *g, const double n1[3], double h1[3])
{
    double p0[3], rel[3];
    v3axpy(p0, g->m1.center, g->m1.offset, n1);
    double dn = v3dot(g->laser_dir, n1);
    if (!(dn < 0)) return -1;
    v3sub(rel, p0, g->laser_at);
    v3axpy(h1, g->laser_at, v3dot(rel, n1) / dn, g->laser_dir);
    return 0;
}

/* Bisecting normals for the beam H1 -> M2 -> along `out`. */
static int bisect(const rg_geometry *g, const double h1[3], const double m2[3],
                  const double out[3], double n1[3], double n2[3])
{
    double d12[3];
    v3sub(d12, m2, h1);
    if (v3norm(d12) < 1e-9) return -1;
    v3sub(n1, d12, g->laser_dir);
    v3sub(n2, out, d12);
    return v3norm(n1) < 1e-12 || v3norm(n2) < 1e-12 ? -1 : 0;
}

static double change(const double a[3], const double b[3]) { return v3dist(a, b); }

/* Stage free: the beam along the backward ray from P (unit `back`), on m2's surface
 * centre, m2's gimbal centre on p2.  n1, n2: the zero-offset normals in, exact out;
 * c2: m2's gimbal centre.  Returns the passes or -1. */
int rg_aim_full(const rg_geometry *g, const double P[3], const double back[3],
                double n1[3], double n2[3], double c2[3])
{
    double np2[3], out[3], m2[3], h1[3], a1[3], a2[3], rel[3];
    v3cross(np2, g->p2_u, g->p2_v);
    v3norm(np2);
    v3scale(out, back, -1);
    double den = v3dot(back, np2);
    for (int k = 1; k <= AIM_PASSES; k++) {
        /* M2 on the ray with M2 - off2 n2 on p2 */
        double q[3];
        v3axpy(q, g->m2.center, g->m2.offset, n2);
        v3sub(rel, q, P);
        v3axpy(m2, P, v3dot(rel, np2) / den, back);
        if (m1_point(g, n1, h1)) return -1;
        v3copy(a1, n1);
        v3copy(a2, n2);
        if (bisect(g, h1, m2, out, n1, n2)) return -1;
        if (fmax(change(a1, n1), change(a2, n2)) < 1e-15) {
            v3axpy(c2, m2, -g->m2.offset, n2);
            return k;
        }
    }
    v3axpy(c2, m2, -g->m2.offset, n2);
    return AIM_PASSES;
}

/* Stage fixed (m2's gimbal centre c2): the four angles that keep the beam on the
 * backward ray; n1, n2 in (a start) and out. */
int rg_aim_stage(const rg_geometry *g, const double P[3], const double back[3],
                 const double c2[3], double n1[3], double n2[3])
{
    double out[3], m2[3], h1[3], a1[3], a2[3], q[3], rel[3];
    v3scale(out, back, -1);
    for (int k = 1; k <= AIM_PASSES; k++) {
        v3axpy(q, c2, g->m2.offset, n2);
        double den = v3dot(back, n2);
        if (fabs(den) < 1e-12) return -1;
        v3sub(rel, q, P);
        v3axpy(m2, P, v3dot(rel, n2) / den, back);
        if (m1_point(g, n1, h1)) return -1;
        v3copy(a1, n1);
        v3copy(a2, n2);
        if (bisect(g, h1, m2, out, n1, n2)) return -1;
        if (fmax(change(a1, n1), change(a2, n2)) < 1e-15) return k;
    }
    return AIM_PASSES;
}

/* m1 and the stage fixed: m2's normal that sends the beam from m1 (h1 along d1) to
 * the target P; n2 in and out. */
int rg_aim_m2(const rg_geometry *g, const double P[3], const double h1[3],
              const double d1[3], const double c2[3], double n2[3])
{
    double q[3], rel[3], m2[3], to[3], a2[3];
    for (int k = 1; k <= AIM_PASSES; k++) {
        v3axpy(q, c2, g->m2.offset, n2);
        double den = v3dot(d1, n2);
        if (fabs(den) < 1e-12) return -1;
        v3sub(rel, q, h1);
        v3axpy(m2, h1, v3dot(rel, n2) / den, d1);
        v3sub(to, P, m2);
        if (v3norm(to) < 1e-9) return -1;
        v3copy(a2, n2);
        v3sub(n2, to, d1);
        if (v3norm(n2) < 1e-12) return -1;
        if (change(a2, n2) < 1e-15) return k;
    }
    return AIM_PASSES;
}

/* The beam leaving m1 for normal n1: its hit point and direction. */
int rg_aim_m1_beam(const rg_geometry *g, const double n1[3], double h1[3], double d1[3])
{
    if (m1_point(g, n1, h1)) return -1;
    v3reflect(d1, g->laser_dir, n1);
    return 0;
}
