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
 * case is exact, not bounded.  The cornea's Fresnel reflectance at each pose's incidence
 * (n 1.376; the laser's field, `laser_polarization`, carried off the two ideal mirrors
 * onto s and p; unpolarized: the mean) scales the photons and so the centroid.  Over
 * the scan of rg_spots: the extremes, and the lens that balances the worst pose
 * (each pose's geometry solved once, the lens searched on the beams alone). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
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

/* The beam of rg_spot_chain with a lens of focal length f at `at` before the cornea
 * (f 0: none). */
static int chain_f(const rg_spots *s, const double path[4], double theta, double k_t,
                   double k_s, double k_ts, double f, double at, rg_spot_pose *p, char *err,
                   size_t cap)
{
    px_beam b, bt, bs;
    px_beam_at pa;
    double w[3], P1, P2, psi, ct = cos(theta);
    if (f != 0 && !(at < path[2])) {
        snprintf(err, cap, "the focus lens %g mm before the cornea is not on the m2-cornea "
                 "leg (%.6g mm long)", at, path[2]);
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
    if (rg_spots_to_cornea(s, path, f, at, &b, w)) goto bad;
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
    px_beam_props(&bt, &pa); p->w_t = pa.w;
    px_beam_props(&bs, &pa); p->w_s = pa.w;
    return RG_OK;
bad:
    snprintf(err, cap, "the beam through the rig is not a beam (a singular optic?)");
    return RG_EINVAL;
}

int rg_spot_chain(const rg_spots *s, const double path[4], double theta, double k_t,
                  double k_s, double k_ts, rg_spot_pose *p, char *err, size_t cap)
{
    return chain_f(s, path, theta, k_t, k_s, k_ts, s->lens_at > 0 ? s->lens_f : 0,
                   s->lens_at, p, err, cap);
}

/* Fresnel's |rs|^2 and |rp|^2 from air onto the cornea (n) at incidence theta. */
static void fresnel_cornea(double theta, double *rs2, double *rp2)
{
    const double n = RG_N_CORNEA;
    double ci = cos(theta), si = sin(theta), ct = sqrt(1 - si * si / (n * n));
    double rs = (ci - n * ct) / (ci + n * ct), rp = (n * ci - ct) / (n * ci + ct);
    *rs2 = rs * rs;
    *rp2 = rp * rp;
}

/* A pose's geometry, which no lens changes: the solved path, the cornea's curvatures
 * in the plane of incidence, the footprint's frame and the laser field's share in s. */
typedef struct pgeom {
    rg_target t;
    rg_pose pose;
    double path[4], theta, K[3];
    double tout[3], es[3], e1[3], e2[3], det_inc, s_frac;
} pgeom;

static int pose_geom(const rg_rig *rig, const rg_target *t, pgeom *q, char *err, size_t cap)
{
    const rig_api *geo = rg_geom_api();
    const rg_geometry *g = &rig->geom;
    rg_solution sol;
    double et[3], wn[3], x1[3] = {1, 0, 0};
    memset(q, 0, sizeof *q);
    if (!geo || !geo->solve || !geo->cornea_curvature) {
        snprintf(err, cap, "the rig engine has no geometry");
        return RG_EINVAL;
    }
    if (geo->solve(g, t, NULL, &sol, err, cap)) return RG_EUNREACH;
    const rg_beam *bm = &sol.beam;
    q->path[0] = v3dist(g->laser_at, bm->h1);
    q->path[1] = v3dist(bm->h1, bm->h2);
    q->path[2] = v3dist(bm->h2, bm->spot);
    q->path[3] = v3dist(bm->spot, bm->det);
    if (!isfinite(q->path[3])) {
        snprintf(err, cap, "the beam never crosses the detector plane");
        return RG_EUNREACH;
    }
    /* the plane of incidence: the incoming beam d2 and the normal; t along its trace on
     * the tangent plane (any direction there at normal incidence), s = n x t */
    v3axpy(et, bm->d2, -v3dot(bm->d2, bm->normal), bm->normal);
    if (v3len(et) < 1e-12) v3basis(bm->normal, x1, et, q->es);
    v3norm(et);
    v3cross(q->es, bm->normal, et);
    v3norm(q->es);
    if (geo->cornea_curvature(&g->cornea, bm->spot, et, q->es, q->K)) {
        snprintf(err, cap, "the cornea has no curvature where the beam meets it");
        return RG_EUNREACH;
    }
    q->t = *t;
    q->pose = sol.pose;
    q->theta = bm->inc3;
    v3axpy(q->tout, et, -v3dot(et, bm->d3), bm->d3);
    v3norm(q->tout);
    v3sub(wn, g->detector, g->cornea.trans);
    v3norm(wn);
    q->det_inc = acos(fmin(1, fabs(v3dot(bm->d3, wn))));
    v3basis(wn, x1, q->e1, q->e2);
    /* the laser's field off two ideal mirrors (E -> -(E - 2 (E.n) n)) onto s */
    q->s_frac = 0.5;
    if (rig->laser_pol_set) {
        double ld[3], e[3], n1[3], n2[3];
        v3copy(ld, g->laser_dir);
        v3norm(ld);
        v3axpy(e, rig->laser_pol, -v3dot(rig->laser_pol, ld), ld);
        v3sub(n1, bm->d1, ld);
        v3sub(n2, bm->d2, bm->d1);
        if (v3norm(e) > 0 && v3norm(n1) > 0 && v3norm(n2) > 0) {
            v3axpy(e, e, -2 * v3dot(e, n1), n1);
            v3axpy(e, e, -2 * v3dot(e, n2), n2);
            double c = v3dot(e, q->es) / v3len(e);
            q->s_frac = c * c;
        }
    }
    return RG_OK;
}

/* The beam through pose q with a lens f at `at` (0: none): footprint, reflectance,
 * photons, centroid. */
static int pose_beam(const rg_spots *s, const pgeom *q, double f, double at, rg_spot_pose *p,
                     char *err, size_t cap)
{
    int rc;
    memset(p, 0, sizeof *p);
    if ((rc = chain_f(s, q->path, q->theta, q->K[0], q->K[1], q->K[2], f, at, p, err, cap)))
        return rc;
    p->target = q->t;
    p->pose = q->pose;
    /* the ellipse in the detector plane: the beam's axes a1 (psi from the plane of
     * incidence's trace t_out on the reflected section) and a2; a plane point x lies on
     * the ray through the section point x - (x.d3) d3, so its intensity is
     * exp(-2 sum_i (x.a_i)^2 / w_i^2) */
    double a[2][3], M[3] = {0, 0, 0}, wi[2] = {p->w_t, p->w_s};
    for (int i = 0; i < 3; i++) {
        a[0][i] = cos(p->psi) * q->tout[i] + sin(p->psi) * q->es[i];
        a[1][i] = -sin(p->psi) * q->tout[i] + cos(p->psi) * q->es[i];
    }
    p->det_inc = q->det_inc;
    for (int k = 0; k < 2; k++) {
        double u = v3dot(a[k], q->e1), v = v3dot(a[k], q->e2), r = 1 / (wi[k] * wi[k]);
        M[0] += r * u * u; M[1] += r * u * v; M[2] += r * v * v;
    }
    double mean = 0.5 * (M[0] + M[2]), rad = hypot(0.5 * (M[0] - M[2]), M[1]);
    p->foot_major = 1 / sqrt(mean - rad);
    p->foot_minor = 1 / sqrt(mean + rad);
    /* 0.5 atan2(2 M01, M00 - M11): the larger eigenvalue's axis (the minor one) */
    double ang = 0.5 * atan2(2 * M[1], M[0] - M[2]) + 0.5 * PI;
    if (ang > 0.5 * PI) ang -= PI;
    p->foot_angle = ang;
    fresnel_cornea(q->theta, &p->refl_s, &p->refl_p);
    p->s_frac = q->s_frac;
    p->reflectance = q->s_frac * p->refl_s + (1 - q->s_frac) * p->refl_p;
    if (s->photons > 0 && s->reflectance > 0) {
        p->photons = s->photons * p->reflectance / s->reflectance;
        p->sigma_major_um = 1e3 * (p->foot_major / 2) / sqrt(p->photons);
        p->sigma_minor_um = 1e3 * (p->foot_minor / 2) / sqrt(p->photons);
    }
    return RG_OK;
}

int rg_spot_pose_run(const rg_rig *rig, const rg_spots *s, const rg_target *t,
                     rg_spot_pose *p, char *err, size_t cap)
{
    pgeom q;
    int rc;
    if ((rc = pose_geom(rig, t, &q, err, cap))) { memset(p, 0, sizeof *p); return rc; }
    return pose_beam(s, &q, s->lens_at > 0 ? s->lens_f : 0, s->lens_at, p, err, cap);
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

/* The scan's worst pose with a lens f at `at` (0: none): the larger of the beam radius
 * on the cornea and the detector spot's major semi-axis; *cw, *dw the worst of each;
 * INFINITY when a pose has no beam (the lens off its leg, a singular optic). */
static double scan_worst(const rg_spots *s, const pgeom *q, int n, double f, double at,
                         double *cw, double *dw)
{
    rg_spot_pose p;
    char e[RG_ERRMAX];
    double worst = 0, c = 0, d = 0;
    for (int i = 0; i < n; i++) {
        if (pose_beam(s, &q[i], f, at, &p, e, sizeof e)) return INFINITY;
        c = fmax(c, p.w_cornea);
        d = fmax(d, p.foot_major);
        worst = fmax(worst, fmax(p.w_cornea, p.foot_major));
    }
    if (cw) *cw = c;
    if (dw) *dw = d;
    return worst;
}

/* The lens balanced over the scan: both signs log-spaced over +-[at/20, 1e5] mm (as the
 * apex model's search), then golden section in log f around the best. */
static void scan_lens(rg_spots *s, const pgeom *q, int n)
{
    enum { NF = 241 };
    double at = s->scan_at, lo = log(at / 20), hi = log(1e5), step = (hi - lo) / (NF - 1);
    double best = scan_worst(s, q, n, 0, at, &s->scan_best_cornea, &s->scan_best_det);
    int bk = -1, bsign = 1;
    for (int sign = 1; sign >= -1; sign -= 2)
        for (int k = 0; k < NF; k++) {
            double v = scan_worst(s, q, n, sign * exp(lo + k * step), at, NULL, NULL);
            if (v < best) { best = v; bk = k; bsign = sign; }
        }
    s->scan_best_is_none = bk < 0;
    s->scan_best_f = 0;
    if (bk >= 0) {
        double a = lo + (bk > 0 ? bk - 1 : 0) * step, b = lo + (bk < NF - 1 ? bk + 1 : bk) * step;
        const double g = 0.6180339887498949;
        for (int i = 0; i < 80 && b - a > 1e-12; i++) {
            double x1 = b - g * (b - a), x2 = a + g * (b - a);
            if (scan_worst(s, q, n, bsign * exp(x1), at, NULL, NULL) <
                scan_worst(s, q, n, bsign * exp(x2), at, NULL, NULL))
                b = x2;
            else a = x1;
        }
        double f = bsign * exp(0.5 * (a + b)), fb = bsign * exp(lo + bk * step);
        if (scan_worst(s, q, n, f, at, NULL, NULL) > best) f = fb;   /* never worse */
        s->scan_best_f = f;
        scan_worst(s, q, n, f, at, &s->scan_best_cornea, &s->scan_best_det);
    }
    scan_worst(s, q, n, s->best_is_none ? 0 : s->best_f, at, &s->apexlens_worst_cornea,
               &s->apexlens_worst_det);
}

int rg_spots_scan(const rg_rig *rig, rg_spots *s, char *err, size_t cap)
{
    rg_target t = {RG_T_ANGLES, 0, 0};
    rg_spot_pose p;
    char e[RG_ERRMAX] = "";
    int rc, n = 0;
    pgeom *q = malloc((RG_SPOTS_POSES + 1) * sizeof *q);
    if (!q) {
        snprintf(err, cap, "out of memory");
        return RG_ENOMEM;
    }
    s->scan_h = rg_spots_height(rig);
    s->scan_n = s->scan_bad = 0;
    if (!s->ref_not_apex) {
        if ((rc = pose_geom(rig, &t, &q[0], err, cap)) ||
            (rc = pose_beam(s, &q[0], s->lens_at > 0 ? s->lens_f : 0, s->lens_at, &s->apex,
                            err, cap))) {
            free(q);
            return rc;
        }
        s->big = s->small = s->steep = s->dim = s->apex;
        s->scan_n = n = 1;
    } else s->scan_bad = 1;
    for (int k = 0; k < RG_SPOTS_POSES; k++) {
        t = rg_spots_target(rig, k);
        if (pose_geom(rig, &t, &q[n], e, sizeof e) ||
            pose_beam(s, &q[n], s->lens_at > 0 ? s->lens_f : 0, s->lens_at, &p, e, sizeof e)) {
            s->scan_bad++;
            continue;
        }
        n++;
        if (!s->scan_n++) s->big = s->small = s->steep = s->dim = p;
        if (p.foot_major > s->big.foot_major) s->big = p;
        if (p.foot_major < s->small.foot_major) s->small = p;
        if (p.theta > s->steep.theta) s->steep = p;
        if (p.reflectance < s->dim.reflectance) s->dim = p;
    }
    if (!s->scan_n) {
        free(q);
        snprintf(err, cap, "no pose of the scan has a beam to the detector: %s", e);
        return RG_EINVAL;
    }
    scan_lens(s, q, n);
    free(q);
    return RG_OK;
}
