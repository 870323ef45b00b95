/* rg_spotscan.c -- the laser's Gaussian beam with the cornea's oblique incidence (issue
 * 21, section 46; rig_api.spot_chain, spot_pose, and the scan part of rig_api.spots):
 * per pose, the incidence angle where the forward model's beam meets the cornea, the
 * surface's normal curvatures along the plane of incidence and across it (and the
 * twist), the reflection's power matrix in the reflected beam's section,
 *     P = 2 [k_t / cos(theta), k_ts; k_ts, k_s cos(theta)]
 * (a sphere: Coddington's f_t = -(R/2) cos(theta), f_s = -R / (2 cos(theta))), and the
 * q parameter carried along P's two eigen-axes to the detector plane: the spot's
 * radii in the beam's section and its ellipse in the detector plane.  The beam reaches
 * the cornea round (flat mirrors, a thin round lens: rg_spots_to_cornea), so the
 * reflected beam is simple astigmatic with fixed axes whatever the twist: the rotated
 * case is exact, not bounded.  Over the scan of rg_spots: the extremes. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "rig/rg_hw.h"
#include "rig/rg_vec.h"
#include "paraxial/paraxial.h"

#define PI 3.14159265358979323846
#define DEG (PI / 180)

/* Symmetric [a b; b c]: the eigenvalue l1 whose eigenvector is at psi (|psi| <= pi/4)
 * from the first axis, and l2.  b == 0: psi 0, l1 = a, l2 = c exactly. */
static void eig_near(double a, double b, double c, double *l1, double *l2, double *psi)
{
    if (b == 0) { *l1 = a; *l2 = c; *psi = 0; return; }
    double p = 0.5 * atan(2 * b / (a - c)), cs = cos(p), sn = sin(p);
    *psi = p;
    *l1 = a * cs * cs + 2 * b * sn * cs + c * sn * sn;
    *l2 = a * sn * sn - 2 * b * sn * cs + c * cs * cs;
}

int rg_spot_chain(const rg_spots *s, const double path[4], double theta, double k_t,
                  double k_s, double k_ts, rg_spot_pose *p, char *err, size_t cap)
{
    px_beam b, bt, bs;
    px_beam_at at;
    double w[3], P1, P2, psi, f = s->lens_at > 0 ? s->lens_f : 0, ct = cos(theta);
    if (f != 0 && !(s->lens_at < path[2])) {
        snprintf(err, cap, "the focus lens %g mm before the cornea is not on the m2-cornea "
                 "leg (%.6g mm long)", s->lens_at, path[2]);
        return RG_EINVAL;
    }
    if (!(ct > 0) || !(s->w0 > 0)) {
        snprintf(err, cap, "no beam: incidence %g deg on the cornea, waist %g mm",
                 theta / DEG, s->w0);
        return RG_EINVAL;
    }
    memcpy(p->path, path, sizeof p->path);
    p->theta = theta;
    p->k_t = k_t; p->k_s = k_s; p->k_ts = k_ts;
    if (rg_spots_to_cornea(s, path, f, s->lens_at, &b, w)) goto bad;
    p->w_cornea = w[2];
    /* the power matrix in the reflected beam's section (t, s), C = +P in the unfolded
     * ABCD convention of rg_spots.c (a convex mirror's C = +2/R) */
    eig_near(2 * k_t / ct, 2 * k_ts, 2 * k_s * ct, &P1, &P2, &psi);
    p->psi = psi;
    p->f_t = -1 / P1;
    p->f_s = -1 / P2;
    bt = bs = b;
    px_mat mt = {1, 0, P1, 1}, ms = {1, 0, P2, 1};
    if (px_beam_apply(&bt, mt, 1) || px_beam_apply(&bt, px_translation(path[3]), 1) ||
        px_beam_apply(&bs, ms, 1) || px_beam_apply(&bs, px_translation(path[3]), 1))
        goto bad;
    px_beam_props(&bt, &at); p->w_t = at.w;
    px_beam_props(&bs, &at); p->w_s = at.w;
    return RG_OK;
bad:
    snprintf(err, cap, "the beam through the rig is not a beam (a singular optic?)");
    return RG_EINVAL;
}

int rg_spot_pose_run(const rg_rig *rig, const rg_spots *s, const rg_target *t,
                 rg_spot_pose *p, char *err, size_t cap)
{
    const rig_api *geo = rg_geom_api();
    const rg_geometry *g = &rig->geom;
    rg_solution sol;
    double path[4], et[3], es[3], K[3], x1[3] = {1, 0, 0};
    int rc;
    memset(p, 0, sizeof *p);
    if (!geo || !geo->solve || !geo->cornea_curvature) {
        snprintf(err, cap, "the rig engine has no geometry");
        return RG_EINVAL;
    }
    if (geo->solve(g, t, NULL, &sol, err, cap)) return RG_EUNREACH;
    const rg_beam *bm = &sol.beam;
    path[0] = v3dist(g->laser_at, bm->h1);
    path[1] = v3dist(bm->h1, bm->h2);
    path[2] = v3dist(bm->h2, bm->spot);
    path[3] = v3dist(bm->spot, bm->det);
    if (!isfinite(path[3])) {
        snprintf(err, cap, "the beam never crosses the detector plane");
        return RG_EUNREACH;
    }
    /* the plane of incidence: the incoming beam d2 and the normal; t along its trace on
     * the tangent plane (any direction there at normal incidence), s = n x t */
    v3axpy(et, bm->d2, -v3dot(bm->d2, bm->normal), bm->normal);
    if (v3len(et) < 1e-12) v3basis(bm->normal, x1, et, es);
    v3norm(et);
    v3cross(es, bm->normal, et);
    v3norm(es);
    if (geo->cornea_curvature(&g->cornea, bm->spot, et, es, K)) {
        snprintf(err, cap, "the cornea has no curvature where the beam meets it");
        return RG_EUNREACH;
    }
    if ((rc = rg_spot_chain(s, path, bm->inc3, K[0], K[1], K[2], p, err, cap))) return rc;
    p->target = *t;
    p->pose = sol.pose;
    /* the ellipse in the detector plane: the beam's axes a1 (psi from the plane of
     * incidence's trace t_out on the reflected section) and a2; a plane point x lies on
     * the ray through the section point x - (x.d3) d3, so its intensity is
     * exp(-2 sum_i (x.a_i)^2 / w_i^2) */
    double tout[3], a[2][3], wn[3], e1[3], e2[3], M[3] = {0, 0, 0}, wi[2] = {p->w_t, p->w_s};
    v3axpy(tout, et, -v3dot(et, bm->d3), bm->d3);
    v3norm(tout);
    for (int i = 0; i < 3; i++) {
        a[0][i] = cos(p->psi) * tout[i] + sin(p->psi) * es[i];
        a[1][i] = -sin(p->psi) * tout[i] + cos(p->psi) * es[i];
    }
    v3sub(wn, g->detector, g->cornea.trans);
    v3norm(wn);
    p->det_inc = acos(fmin(1, fabs(v3dot(bm->d3, wn))));
    v3basis(wn, x1, e1, e2);
    for (int k = 0; k < 2; k++) {
        double u = v3dot(a[k], e1), v = v3dot(a[k], e2), q = 1 / (wi[k] * wi[k]);
        M[0] += q * u * u; M[1] += q * u * v; M[2] += q * v * v;
    }
    double mean = 0.5 * (M[0] + M[2]), rad = hypot(0.5 * (M[0] - M[2]), M[1]);
    p->foot_major = 1 / sqrt(mean - rad);
    p->foot_minor = 1 / sqrt(mean + rad);
    /* 0.5 atan2(2 M01, M00 - M11): the larger eigenvalue's axis (the minor one) */
    double ang = 0.5 * atan2(2 * M[1], M[0] - M[2]) + 0.5 * PI;
    if (ang > 0.5 * PI) ang -= PI;
    p->foot_angle = ang;
    if (s->photons > 0) {
        p->sigma_major_um = 1e3 * (p->foot_major / 2) / sqrt(s->photons);
        p->sigma_minor_um = 1e3 * (p->foot_minor / 2) / sqrt(s->photons);
    }
    return RG_OK;
}

double rg_spots_height(const rg_rig *rig)
{
    return rig->geom.cornea.zone > 0 ? rig->geom.cornea.zone : rig->geom.cornea.R / 2;
}

rg_target rg_spots_target(const rg_rig *rig, int k)
{
    rg_target t = {RG_T_HEIGHT, rg_spots_height(rig) * sqrt((k + 0.5) / RG_SPOTS_POSES),
                   fmod(k * 137.50776405, 360) * DEG};
    return t;
}

int rg_spots_scan(const rg_rig *rig, rg_spots *s, char *err, size_t cap)
{
    rg_target t = {RG_T_ANGLES, 0, 0};
    rg_spot_pose p;
    char e[RG_ERRMAX];
    int rc;
    s->scan_h = rg_spots_height(rig);
    s->scan_n = s->scan_bad = 0;
    if (!s->ref_not_apex) {
        if ((rc = rg_spot_pose_run(rig, s, &t, &s->apex, err, cap))) return rc;
        s->big = s->small = s->steep = s->apex;
        s->scan_n = 1;
    } else s->scan_bad = 1;
    for (int k = 0; k < RG_SPOTS_POSES; k++) {
        t = rg_spots_target(rig, k);
        if (rg_spot_pose_run(rig, s, &t, &p, e, sizeof e)) { s->scan_bad++; continue; }
        if (!s->scan_n++) s->big = s->small = s->steep = p;
        if (p.foot_major > s->big.foot_major) s->big = p;
        if (p.foot_major < s->small.foot_major) s->small = p;
        if (p.theta > s->steep.theta) s->steep = p;
    }
    if (!s->scan_n) {
        snprintf(err, cap, "no pose of the scan has a beam to the detector: %s", e);
        return RG_EINVAL;
    }
    return RG_OK;
}
