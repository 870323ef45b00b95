/* rg_forward.c -- the analytic forward model: a pose's beam from the laser off m1
 * and m2 (surfaces off the rotation axes by their offsets, finite semi-diameters) to
 * the placed cornea, its reflection to the detector plane; what blocks it (mirror
 * bodies across the other legs) and joints outside their travel. */
#include <stdio.h>
#include "rig/rg_geom.h"
#include "rig/rg_vec.h"

void rg_m2_center(const rg_geometry *g, double u, double v, double c[3])
{
    for (int i = 0; i < 3; i++) c[i] = g->m2.center[i] + u * g->p2_u[i] + v * g->p2_v[i];
}

void rg_detector_normal(const rg_geometry *g, double w[3])
{
    v3sub(w, g->detector, g->cornea.trans);
    v3norm(w);
}

/* Ray o + t d onto mirror m (gimbal centre c, normal n): 0 with hit and reflected
 * direction; -1 when it meets the back or misses the aperture. */
static int mirror_hit(const rg_gimbal *m, const double c[3], const double n[3],
                      const double o[3], const double d[3], double h[3],
                      double out[3], double *inc, int ap)
{
    double p0[3], rel[3];
    v3axpy(p0, c, m->offset, n);
    double dn = v3dot(d, n);
    if (!(dn < 0)) return -1;
    v3sub(rel, p0, o);
    double t = v3dot(rel, n) / dn;
    if (!(t > 0)) return -1;
    v3axpy(h, o, t, d);
    if (ap && m->radius > 0 && v3dist(h, p0) > m->radius) return -1;
    v3reflect(out, d, n);
    *inc = -dn;                 /* the cosine; rg_forward_path makes it an angle */
    return 0;
}

int rg_mirrors(const rg_geometry *g, const rg_pose *p, rg_beam *b)
{
    return rg_mirrors_ap(g, p, b, 1);
}

int rg_mirrors_ap(const rg_geometry *g, const rg_pose *p, rg_beam *b, int ap)
{
    return rg_mirrors_nn(g, p, b, ap, NULL, NULL);
}

int rg_mirrors_nn(const rg_geometry *g, const rg_pose *p, rg_beam *b, int ap,
                  double n1[3], double n2[3])
{
    double nn1[3], nn2[3], c2[3];
    if (!n1) {
        n1 = nn1;
        rg_gimbal_normal(&g->m1, p->j[RG_J_M1A], p->j[RG_J_M1B], n1);
    }
    if (!n2) {
        n2 = nn2;
        rg_gimbal_normal(&g->m2, p->j[RG_J_M2A], p->j[RG_J_M2B], n2);
    }
    b->diag = 0;
    if (mirror_hit(&g->m1, g->m1.center, n1, g->laser_at, g->laser_dir, b->h1, b->d1,
                   &b->inc1, ap)) {
        b->diag |= RG_D_MISS_MIRROR;
        return -1;
    }
    rg_m2_center(g, p->j[RG_J_U], p->j[RG_J_V], c2);
    if (mirror_hit(&g->m2, c2, n2, b->h1, b->d1, b->h2, b->d2, &b->inc2, ap)) {
        b->diag |= RG_D_MISS_MIRROR;
        return -1;
    }
    return 0;
}

/* Segment a-b against the mirror's solid: the disc (or mount cylinder) of radius
 * max(radius, mount_radius) about the surface centre, from the surface back to
 * mount_depth behind it.  The segment's own end points do not count (it is shrunk
 * by 1e-9 mm at both ends): a leg that starts on this mirror is not blocked by it. */
int rg_blocks(const rg_gimbal *m, const double c[3], const double n[3],
              const double a[3], const double b[3])
{
    double p0[3], ab[3], w0[3], wd[3], rel[3];
    double R = fmax(m->radius, m->mount_radius);
    if (!(R > 0)) return 0;
    v3axpy(p0, c, m->offset, n);
    v3sub(ab, b, a);
    double len = v3len(ab);
    if (!(len > 2e-9)) return 0;
    double lo = 1e-9 / len, hi = 1 - lo;
    v3sub(rel, a, p0);
    double h0 = v3dot(rel, n), hd = v3dot(ab, n);
    double hlo = -fmax(m->mount_depth, 0), hhi = 0;
    if (fabs(hd) < 1e-15 * len) {
        if (h0 < hlo - 1e-12 || h0 > hhi + 1e-12) return 0;
    } else {
        double t1 = (hlo - h0) / hd, t2 = (hhi - h0) / hd;
        lo = fmax(lo, fmin(t1, t2));
        hi = fmin(hi, fmax(t1, t2));
    }
    if (lo > hi) return 0;
    v3axpy(w0, rel, -h0, n);
    v3axpy(wd, ab, -hd, n);
    double A = v3dot(wd, wd), B = v3dot(w0, wd), C = v3dot(w0, w0) - R * R;
    if (A < 1e-30) return C <= 0;
    double disc = B * B - A * C;
    if (disc < 0) return 0;
    double sq = sqrt(disc);
    lo = fmax(lo, (-B - sq) / A);
    hi = fmin(hi, (-B + sq) / A);
    return lo <= hi;
}

unsigned rg_travel_check(const rg_geometry *g, const rg_pose *p)
{
    for (int k = 0; k < RG_NJOINTS; k++) {
        const rg_joint *j = &g->joint[k];
        if (j->lo < j->hi && (p->j[k] < j->lo || p->j[k] > j->hi)) return RG_D_TRAVEL;
    }
    return 0;
}

int rg_forward_beam(const rg_geometry *g, const rg_pose *p, rg_beam *b)
{
    return rg_forward_path(g, p, b, 1);
}

int rg_forward_path(const rg_geometry *g, const rg_pose *p, rg_beam *b, int checks)
{
    double n1[3], n2[3];
    rg_gimbal_normal(&g->m1, p->j[RG_J_M1A], p->j[RG_J_M1B], n1);
    rg_gimbal_normal(&g->m2, p->j[RG_J_M2A], p->j[RG_J_M2B], n2);
    return rg_forward_nn(g, p, b, checks, n1, n2);
}

int rg_forward_nn(const rg_geometry *g, const rg_pose *p, rg_beam *b, int checks,
                  double n1[3], double n2[3])
{
    double c2[3], w[3];
    for (int i = 0; i < 3; i++)
        b->spot[i] = b->normal[i] = b->d3[i] = b->det[i] = NAN;
    b->inc3 = NAN;
    if (rg_mirrors_nn(g, p, b, 1, n1, n2)) return -1;
    if (rg_cornea_hit(&g->cornea, b->h2, b->d2, b->spot, b->normal, NULL)) {
        b->diag |= RG_D_MISS_CORNEA;
        return -1;
    }
    if (g->cornea.zone > 0 && rg_cornea_height(&g->cornea, b->spot) >
                                  g->cornea.zone * (1 + 1e-12))
        b->diag |= RG_D_OFF_CORNEA;
    v3reflect(b->d3, b->d2, b->normal);
    rg_detector_normal(g, w);
    double dn = v3dot(b->d3, w);
    if (dn > 0) {
        double rel[3];
        v3sub(rel, g->detector, b->spot);
        v3axpy(b->det, b->spot, v3dot(rel, w) / dn, b->d3);
    }
    if (!checks) {
        b->inc1 = b->inc2 = NAN;
        return 0;
    }
    b->inc1 = acos(fmin(1, b->inc1));
    b->inc2 = acos(fmin(1, b->inc2));
    b->inc3 = acos(fmin(1, fabs(v3dot(b->d2, b->normal))));
    /* what stands in the way: m2 across the detector leg and the incoming laser, m1
     * across the legs to and from the cornea */
    rg_m2_center(g, p->j[RG_J_U], p->j[RG_J_V], c2);
    if (rg_blocks(&g->m2, c2, n2, b->spot, g->detector) ||
        rg_blocks(&g->m2, c2, n2, g->laser_at, b->h1))
        b->diag |= RG_D_M2_BLOCKS;
    if (rg_blocks(&g->m1, g->m1.center, n1, b->h2, b->spot) ||
        rg_blocks(&g->m1, g->m1.center, n1, b->spot, g->detector))
        b->diag |= RG_D_M1_BLOCKS;
    b->diag |= rg_travel_check(g, p);
    return 0;
}

int rg_forward(const rg_geometry *g, const rg_pose *p, rg_beam *b, char *err,
               size_t errcap)
{
    char txt[512];
    int r = rg_forward_beam(g, p, b);
    if (r || (b->diag & RG_D_FATAL)) {
        snprintf(err, errcap, "%s", rg_diag_text(b->diag, txt, sizeof txt));
        return (b->diag & RG_D_FATAL) == RG_D_TRAVEL ? RG_ETRAVEL : RG_EUNREACH;
    }
    return RG_OK;
}
