/* t_oblique.c -- the beam's oblique incidence on the cornea (rig_api.spot_chain,
 * spot_pose, cornea_curvature and the scan of rig_api.spots; rg_spotscan.c) against
 * models written here:
 *  1. Coddington's focal lines by geometric rays: a small bundle of parallel rays
 *     traced by hand off a convex sphere at 30 deg incidence, the tangential and the
 *     sagittal fans' (virtual) crossings along the reflected chief ray, against
 *     f_t = -(R/2) cos(theta) and f_s = -R / (2 cos(theta)), and the engine's
 *     spot_chain at the same incidence against both;
 *  2. theta = 0 (k_t = k_s = 1/R) reproduces rig_api.spots' apex figures bit for bit,
 *     with and without a lens, M^2 and a given waist;
 *  3. per pose, on a conic, a tilted biconic (principal directions off the plane of
 *     incidence) and a sphere: the incidence from the tests' own forward model
 *     (tests/rig/rt.h), the normal curvatures from circles fitted to the surface's
 *     normal sections (bisection on the sag typed again), the twist from the 45 deg
 *     section; the power matrix P = 2 [k_t/cos, k_ts; k_ts, k_s cos] diagonalised by
 *     hand and the astigmatic beam carried as two round ones by Self's thin-lens
 *     formula (S. A. Self, Appl. Opt. 22, 658 (1983)) and w(z) = w0 sqrt(1 + (z/zR)^2);
 *     the footprint's area w_t w_s / cos(detector incidence);
 *  4. the scan's extremes against the tests' own loop over the documented targets,
 *     the centroid's sigma = (axis/2)/sqrt(N), N scaled by the pose's reflectance;
 *  5. the cornea's Fresnel reflectance per pose against Hecht's formulas written
 *     here; two laser fields at right angles sharing s and p (shares add to 1, the
 *     reflectances average to the unpolarized one); laser_polarization's refusals;
 *  6. the lens balanced over the scan recomputed pose by pose through spot_pose, no
 *     better 0.5 % either side, nor with the apex model's lens or none.
 * argv[1]: golden/rig/example.rig, argv[2]: golden/rig/wide-zone.rig. */
#define _DEFAULT_SOURCE
#include "unit.h"
#include "rig/rt.h"

static const rig_api *rg;
static char *base;

static double rel(double a, double b) { return fabs(a - b) / fabs(b); }

static int load(const char *text, const char *extra, rg_rig *r, char *err, size_t cap)
{
    static char buf[(1 << 20) + 4096];
    snprintf(buf, sizeof buf, "%s\n%s", text, extra);
    return rg->rig_parse(buf, strlen(buf), "x.rig", r, err, cap);
}

/* ---- 1. geometric rays off a sphere ------------------------------------------- */
/* Convex sphere of radius R about the origin; the chief ray meets it at (0,0,-R)
 * (outward normal -z) travelling along (sin th, 0, cos th).  Returns the (signed)
 * distances along the reflected chief ray of the tangential and sagittal fans'
 * crossings (negative: virtual, behind the mirror), rays offset by eps. */
static void reflect_ray(double R, const double o[3], const double d[3], double h[3], double r[3])
{
    /* |o + t d| = R, the first root */
    double b = rt_dot(o, d), c = rt_dot(o, o) - R * R, t = -b - sqrt(b * b - c), n[3];
    for (int i = 0; i < 3; i++) h[i] = o[i] + t * d[i];
    for (int i = 0; i < 3; i++) n[i] = h[i] / R;
    rt_reflect(d, n, r);
}
static void coddington_rays(double R, double th, double eps, double *ft, double *fs)
{
    double d[3] = {sin(th), 0, cos(th)}, P0[3] = {0, 0, -R}, dr[3] = {sin(th), 0, -cos(th)};
    double tin[3] = {cos(th), 0, -sin(th)}, h[2][3], r[2][3], o[3];
    for (int k = 0; k < 2; k++) {               /* the tangential fan: +-eps in-plane */
        double e = k ? -eps : eps;
        for (int i = 0; i < 3; i++) o[i] = P0[i] - 10 * d[i] + e * tin[i];
        reflect_ray(R, o, d, h[k], r[k]);
    }
    /* h0 + a r0 = h1 + b r1 in (x, z) */
    double det = r[0][0] * (-r[1][2]) - (-r[1][0]) * r[0][2];
    double bx = h[1][0] - h[0][0], bz = h[1][2] - h[0][2];
    double a = (bx * (-r[1][2]) - (-r[1][0]) * bz) / det, X[3];
    for (int i = 0; i < 3; i++) X[i] = h[0][i] + a * r[0][i] - P0[i];
    *ft = rt_dot(X, dr);
    /* the sagittal ray: offset eps across the plane; where it crosses y = 0 */
    for (int i = 0; i < 3; i++) o[i] = P0[i] - 10 * d[i];
    o[1] += eps;
    reflect_ray(R, o, d, h[0], r[0]);
    a = -h[0][1] / r[0][1];
    for (int i = 0; i < 3; i++) X[i] = h[0][i] + a * r[0][i] - P0[i];
    *fs = rt_dot(X, dr);
}

#include "beam_forms.h"       /* self(), wz(): the closed forms */
/* The laser's waist to the cornea along path with the rig's lens (lens_at before
 * the cornea): the waist (*w0) and its distance before the cornea (*sc); then through a
 * mirror of focal length fm to path[3]: the radius there. */
static double closed_plane(const rg_spots *s, const double path[4], double fm, double *wc)
{
    double lm = s->m2 * s->lambda_mm, w0 = s->w0, sc;
    double z = s->waist_before_m1 + path[1] + path[2];
    if (s->lens_at > 0) {
        double d = z - s->lens_at;
        self(s->lens_f, lm, &w0, &d);
        sc = s->lens_at - d;
    } else sc = z;
    *wc = wz(w0, sc, lm);
    self(fm, lm, &w0, &sc);
    return wz(w0, path[3] - sc, lm);
}

/* ---- 3. the surface's normal sections, by hand --------------------------------- */
/* depth below the tangent plane at P along -n of the surface point over P + x u */
static double depth(const rg_cornea *c, const double P[3], const double n[3],
                    const double u[3], double x)
{
    double lo = -0.01, hi = 0.01;
    for (int k = 0; k < 100; k++) {
        double m = 0.5 * (lo + hi), q[3];
        for (int i = 0; i < 3; i++) q[i] = P[i] + x * u[i] - m * n[i];
        if (rt_above(c, q) > 0) lo = m; else hi = m;
    }
    return 0.5 * (lo + hi);
}
static double section_k(const rg_cornea *c, const double P[3], const double n[3],
                        const double u[3])
{
    double x = 2e-3;
    return (depth(c, P, n, u, x) + depth(c, P, n, u, -x)) / (x * x);
}

typedef struct mine { double theta, kt, ks, kts, wt, ws, psi; } mine;
/* The tests' own figures for a solved pose p (its path from the engine's record). */
static int own_pose(const rg_rig *r, const rg_spots *s, const rg_spot_pose *sp, mine *m)
{
    rt_path tp;
    if (rt_forward(&r->geom, &sp->pose, &tp)) return -1;
    const double *n = tp.nc, *d = tp.d2;
    double dn = rt_dot(d, n), t[3], sv[3], dg[3];
    m->theta = acos(fabs(dn));
    for (int i = 0; i < 3; i++) t[i] = d[i] - dn * n[i];
    rt_unit(t);
    sv[0] = n[1] * t[2] - n[2] * t[1]; sv[1] = n[2] * t[0] - n[0] * t[2];
    sv[2] = n[0] * t[1] - n[1] * t[0];
    for (int i = 0; i < 3; i++) dg[i] = (t[i] + sv[i]) / sqrt(2);
    m->kt = section_k(&r->geom.cornea, tp.spot, n, t);
    m->ks = section_k(&r->geom.cornea, tp.spot, n, sv);
    m->kts = section_k(&r->geom.cornea, tp.spot, n, dg) - 0.5 * (m->kt + m->ks);
    /* P and its eigen-axes by hand: tan(2 psi) = 2 P_ts / (P_tt - P_ss) */
    double c = cos(m->theta), a = 2 * m->kt / c, b = 2 * m->kts, e = 2 * m->ks * c;
    double mean = 0.5 * (a + e), rad = sqrt(0.25 * (a - e) * (a - e) + b * b);
    double l1 = a >= e ? mean + rad : mean - rad, l2 = a >= e ? mean - rad : mean + rad;
    double wc;
    m->psi = 0.5 * atan(2 * b / (a - e));
    if (b == 0) m->psi = 0;
    m->wt = closed_plane(s, sp->path, -1 / l1, &wc);
    m->ws = closed_plane(s, sp->path, -1 / l2, &wc);
    return 0;
}

static void pose_checks(const char *name, const rg_rig *r, const rg_spots *s, int sphere)
{
    char err[RG_ERRMAX];
    double worst_k = 0, worst_w = 0, worst_th = 0, worst_area = 0, worst_cod = 0, kts_max = 0;
    double worst_psi = 0;
    int n = 0, bad = 0;
    for (int k = 0; k < 24; k++) {
        rg_target t = {RG_T_HEIGHT, 0.8 * s->scan_h * sqrt((k + 0.5) / 24),
                       fmod(k * 137.508, 360) * RT_DEG};
        rg_spot_pose p;
        mine m;
        if (rg->spot_pose(r, s, &t, &p, err, sizeof err)) { bad++; continue; }
        if (own_pose(r, s, &p, &m)) { bad++; continue; }
        n++;
        worst_th = fmax(worst_th, fabs(p.theta - m.theta));
        worst_k = fmax(worst_k, fmax(fabs(p.k_t - m.kt), fmax(fabs(p.k_s - m.ks), fabs(p.k_ts - m.kts))));
        worst_w = fmax(worst_w, fmax(rel(p.w_t, m.wt), rel(p.w_s, m.ws)));
        worst_psi = fmax(worst_psi, fabs(p.psi - m.psi));
        kts_max = fmax(kts_max, fabs(m.kts));
        worst_area = fmax(worst_area, rel(p.foot_major * p.foot_minor,
                                          p.w_t * p.w_s / cos(p.det_inc)));
        if (sphere)
            worst_cod = fmax(worst_cod, fmax(rel(p.f_t, -r->geom.cornea.R / 2 * cos(m.theta)),
                                             rel(p.f_s, -r->geom.cornea.R / (2 * cos(m.theta)))));
    }
    CHECK(n >= 12 && worst_th < 1e-8, "%s: %d poses (%d not solved): incidence = the tests' "
          "forward model's to %.1e rad", name, n, bad, worst_th);
    CHECK(worst_k < 2e-6 * (1 / r->geom.cornea.R), "%s: k_t, k_s, k_ts = normal-section "
          "circles to %.1e /mm (largest twist %.3g /mm)", name, worst_k, kts_max);
    CHECK(worst_w < 1e-5 && worst_psi < 1e-3, "%s: w_t, w_s = the two planes by Self's "
          "formula to %.1e relative; psi to %.1e rad", name, worst_w, worst_psi);
    CHECK(worst_area < 1e-9, "%s: footprint area = section area / cos(detector incidence) "
          "to %.1e", name, worst_area);
    if (sphere)
        CHECK(worst_cod < 1e-10, "sphere: f_t, f_s = Coddington's -(R/2) cos, -R/(2 cos) to "
              "%.1e", worst_cod);
}

/* Hecht's rs, rp from air onto n = 1.376 (Gullstrand's cornea), written again here */
static void hecht_rsp(double th, double *Rs, double *Rp)
{
    const double n = 1.376;
    double st = sin(th) / n, ct = sqrt(1 - st * st), ci = cos(th);
    double rs = (ci - n * ct) / (ci + n * ct), rp = (n * ci - ct) / (n * ci + ct);
    *Rs = rs * rs;
    *Rp = rp * rp;
}
static double hecht_unpol(double th)
{
    double a, b;
    hecht_rsp(th, &a, &b);
    return 0.5 * (a + b);
}

/* 5. the cornea's Fresnel reflectance pose by pose: unpolarized = Hecht's mean at the
 * pose's incidence; two laser fields at right angles share s and p between them (the
 * ideal mirrors keep them at right angles), so their s shares add to 1 and their
 * reflectances average to the unpolarized one at every pose; Brewster's angle from
 * the p reflectance's zero */
static void fresnel_checks(const char *name)
{
    rg_rig r, rx, ry;
    rg_spots s, sx, sy;
    rg_spot_pose p, px, py;
    char err[RG_ERRMAX];
    int ok = load(base, "", &r, err, sizeof err) == 0 && rg->spots(&r, &s, err, sizeof err) == 0 &&
             s.photons > 0;
    /* the example's laser_dir: fields across it, x and the third axis */
    const double *ld = r.geom.laser_dir;
    double e1[3], e2[3], a[3] = {1, 0, 0}, l = sqrt(ld[0] * ld[0] + ld[1] * ld[1] + ld[2] * ld[2]);
    if (fabs(ld[0]) > 0.9 * l) { a[0] = 0; a[1] = 1; }
    e1[0] = a[1] * ld[2] - a[2] * ld[1]; e1[1] = a[2] * ld[0] - a[0] * ld[2];
    e1[2] = a[0] * ld[1] - a[1] * ld[0];
    e2[0] = ld[1] * e1[2] - ld[2] * e1[1]; e2[1] = ld[2] * e1[0] - ld[0] * e1[2];
    e2[2] = ld[0] * e1[1] - ld[1] * e1[0];
    char kx[256], ky[256];
    snprintf(kx, sizeof kx, "laser_polarization %.17g %.17g %.17g\n", e1[0], e1[1], e1[2]);
    snprintf(ky, sizeof ky, "laser_polarization %.17g %.17g %.17g\n", e2[0], e2[1], e2[2]);
    ok = ok && load(base, kx, &rx, err, sizeof err) == 0 && rg->spots(&rx, &sx, err, sizeof err) == 0 &&
         load(base, ky, &ry, err, sizeof err) == 0 && rg->spots(&ry, &sy, err, sizeof err) == 0;
    CHECK(ok && rx.laser_pol_set && !r.laser_pol_set, "%s: three lasers (unpolarized, two "
          "fields at right angles): %s", name, ok ? "" : err);
    if (!ok) return;
    double wu = 0, wsum = 0, wavg = 0, smin = 1, smax = 0;
    int n = 0;
    for (int k = 0; k < RG_SPOTS_POSES; k++) {
        rg_target t = {RG_T_HEIGHT, s.scan_h * sqrt((k + 0.5) / RG_SPOTS_POSES),
                       fmod(k * 137.50776405, 360) * RT_DEG};
        if (rg->spot_pose(&r, &s, &t, &p, err, sizeof err) ||
            rg->spot_pose(&rx, &sx, &t, &px, err, sizeof err) ||
            rg->spot_pose(&ry, &sy, &t, &py, err, sizeof err))
            continue;
        n++;
        double Rs, Rp;
        hecht_rsp(p.theta, &Rs, &Rp);
        wu = fmax(wu, rel(p.reflectance, 0.5 * (Rs + Rp)));
        wsum = fmax(wsum, fabs(px.s_frac + py.s_frac - 1));
        wavg = fmax(wavg, rel(0.5 * (px.reflectance + py.reflectance), p.reflectance));
        smin = fmin(smin, px.s_frac);
        smax = fmax(smax, px.s_frac);
        wu = fmax(wu, rel(px.photons, s.photons * px.reflectance / s.reflectance));
    }
    CHECK(n > 50 && wu < 1e-12, "%s: %d poses: unpolarized R = (Rs + Rp)/2 of Hecht's at each "
          "incidence, photons scaled by R/R0 (worst %.1e)", name, n, wu);
    CHECK(n > 50 && wsum < 1e-12 && wavg < 1e-12 && smax - smin > 0.01,
          "%s: fields at right angles: s shares add to 1 (%.1e), R average to the "
          "unpolarized (%.1e); the share varies over the scan (%.3f..%.3f)", name, wsum, wavg,
          smin, smax);
    /* the s share by the test's own forward model (tests/rig/rt.h) and the mirrors'
     * Fresnel form in their own s, p frames (rs = -1, rp = +1, Hecht), not a
     * Householder reflection as the engine writes it */
    double wshare = 0;
    int m = 0;
    for (int k = 0; k < RG_SPOTS_POSES; k += 7) {
        rg_target t = {RG_T_HEIGHT, s.scan_h * sqrt((k + 0.5) / RG_SPOTS_POSES),
                       fmod(k * 137.50776405, 360) * RT_DEG};
        rt_path tp;
        if (rg->spot_pose(&rx, &sx, &t, &px, err, sizeof err) || rt_forward(&rx.geom, &px.pose, &tp))
            continue;
        double E[3], k0[3], *ks[3] = {k0, tp.d1, tp.d2}, *ns[3] = {tp.n1, tp.n2, tp.nc};
        memcpy(k0, ld, sizeof k0);
        rt_unit(k0);
        memcpy(E, e1, sizeof E);
        rt_unit(E);
        for (int q = 0; q < 3; q++) {
            const double *ki = ks[q], *nn = ns[q];
            double sv[3] = {ki[1] * nn[2] - ki[2] * nn[1], ki[2] * nn[0] - ki[0] * nn[2],
                            ki[0] * nn[1] - ki[1] * nn[0]};
            rt_unit(sv);
            if (q == 2) {           /* at the cornea: the share in s */
                double c = rt_dot(E, sv);
                wshare = fmax(wshare, fabs(c * c - px.s_frac));
                m++;
                break;
            }
            double ko[3], pin[3], pout[3], es = rt_dot(E, sv);
            rt_reflect(ki, nn, ko);
            pin[0] = ki[1] * sv[2] - ki[2] * sv[1]; pin[1] = ki[2] * sv[0] - ki[0] * sv[2];
            pin[2] = ki[0] * sv[1] - ki[1] * sv[0];
            pout[0] = ko[1] * sv[2] - ko[2] * sv[1]; pout[1] = ko[2] * sv[0] - ko[0] * sv[2];
            pout[2] = ko[0] * sv[1] - ko[1] * sv[0];
            double ep = rt_dot(E, pin);
            for (int i = 0; i < 3; i++) E[i] = -es * sv[i] + ep * pout[i];
        }
    }
    CHECK(m > 10 && wshare < 1e-9, "%s: the s share at %d poses = the test's own forward "
          "model with Fresnel's mirror form in s, p frames (worst %.1e)", name, m, wshare);
    /* refusals */
    CHECK(load(base, "laser_polarization 1 0\n", &rx, err, sizeof err) != 0 &&
          strstr(err, "x.rig:") && strstr(err, "laser_polarization"), "laser_polarization with "
          "two numbers refused: %s", err);
    CHECK(load(base, "laser_polarization 0 0 0\n", &rx, err, sizeof err) != 0,
          "laser_polarization 0 0 0 refused: %s", err);
    char along[256];
    snprintf(along, sizeof along, "laser_polarization %.17g %.17g %.17g\n", ld[0], ld[1], ld[2]);
    CHECK(load(base, along, &rx, err, sizeof err) == 0 && rg->spots(&rx, &sx, err, sizeof err) != 0 &&
          strstr(err, "lies along the beam"), "a field along laser_dir refused at its line: %s", err);
    CHECK(load(base, "laser_polarization unpolarized\n", &rx, err, sizeof err) == 0 &&
          !rx.laser_pol_set, "laser_polarization unpolarized taken");
}

/* 6. the lens balanced over the scan, recomputed through the public API: every pose of
 * the scan with that lens (spot_pose with s's lens set to it), its worst, no better
 * with f 0.5 % either side, no worse than the apex model's lens or none there */
static double worst_with(const rg_rig *r, const rg_spots *s0, double f, double at, double *c,
                         double *d)
{
    rg_spots s = *s0;
    rg_spot_pose p;
    char err[RG_ERRMAX];
    double w = 0;
    s.lens_f = f;
    s.lens_at = f != 0 ? at : 0;
    *c = *d = 0;
    rg_target t0 = {RG_T_ANGLES, 0, 0};
    for (int k = -1; k < RG_SPOTS_POSES; k++) {
        rg_target t = k < 0 ? t0 : (rg_target){RG_T_HEIGHT, s.scan_h * sqrt((k + 0.5) / RG_SPOTS_POSES),
                                               fmod(k * 137.50776405, 360) * RT_DEG};
        if (k < 0 && s.ref_not_apex) continue;
        if (rg->spot_pose(r, &s, &t, &p, err, sizeof err)) continue;
        *c = fmax(*c, p.w_cornea);
        *d = fmax(*d, p.foot_major);
        w = fmax(w, fmax(p.w_cornea, p.foot_major));
    }
    return w;
}

static void lens_checks(const char *name, const rg_rig *r, const rg_spots *s)
{
    double c, d, c1, d1, c2, d2, ca, da, cn, dn;
    double w = worst_with(r, s, s->scan_best_is_none ? 0 : s->scan_best_f, s->scan_at, &c, &d);
    double wp = worst_with(r, s, s->scan_best_f * 1.005, s->scan_at, &c1, &d1);
    double wm = worst_with(r, s, s->scan_best_f * 0.995, s->scan_at, &c2, &d2);
    double wa = worst_with(r, s, s->best_is_none ? 0 : s->best_f, s->scan_at, &ca, &da);
    double wn = worst_with(r, s, 0, s->scan_at, &cn, &dn);
    CHECK(rel(c, s->scan_best_cornea) < 1e-12 && rel(d, s->scan_best_det) < 1e-12 &&
          rel(ca, s->apexlens_worst_cornea) < 1e-12 && rel(da, s->apexlens_worst_det) < 1e-12,
          "%s: the scan-balanced lens f %.6g mm: worst cornea %.4g, detector %.4g mm as "
          "recomputed pose by pose; the apex model's lens %.4g, %.4g mm", name, s->scan_best_f,
          c, d, ca, da);
    CHECK(w <= wp && w <= wm && w <= wa && w <= wn, "%s: no better 0.5 %% either side (%.6g, "
          "%.6g against %.6g), nor with the apex model's lens (%.6g) or none (%.6g)", name, wm,
          wp, w, wa, wn);
}

static void scan_checks(const char *name, const rg_rig *r, const rg_spots *s)
{
    char err[RG_ERRMAX];
    /* the apex first, unless the rig cannot reach it (then it counts as not solved) */
    double big = s->apex.foot_major, small = s->apex.foot_major, steep = s->apex.theta;
    long got = !s->ref_not_apex, bad = s->ref_not_apex;
    for (int k = 0; k < RG_SPOTS_POSES; k++) {
        rg_target t = {RG_T_HEIGHT, s->scan_h * sqrt((k + 0.5) / RG_SPOTS_POSES),
                       fmod(k * 137.50776405, 360) * RT_DEG};
        rg_spot_pose p;
        if (rg->spot_pose(r, s, &t, &p, err, sizeof err)) { bad++; continue; }
        if (!got++) big = small = p.foot_major, steep = p.theta;
        big = fmax(big, p.foot_major);
        small = fmin(small, p.foot_major);
        steep = fmax(steep, p.theta);
    }
    CHECK(got == s->scan_n && bad == s->scan_bad && big == s->big.foot_major &&
          small == s->small.foot_major && steep == s->steep.theta,
          "%s: the scan's extremes over %ld poses (%ld not solved): largest %.4g x %.4g mm "
          "(h %.3g mm, %.1f deg incidence), smallest %.4g x %.4g mm, incidence up to %.2f deg",
          name, got, bad, s->big.foot_major, s->big.foot_minor, s->big.target.a,
          s->big.theta / RT_DEG, s->small.foot_major, s->small.foot_minor, s->steep.theta / RT_DEG);
    if (s->photons > 0)
        CHECK(rel(s->big.sigma_major_um, 1e3 * s->big.foot_major / 2 /
                  sqrt(s->photons * hecht_unpol(s->big.theta) / hecht_unpol(0))) < 1e-12 &&
              rel(s->small.sigma_minor_um, 1e3 * s->small.foot_minor / 2 /
                  sqrt(s->photons * hecht_unpol(s->small.theta) / hecht_unpol(0))) < 1e-12,
              "%s: centroid sigma (axis/2)/sqrt(N), N the photons scaled by the pose's unpolarized "
              "Fresnel reflectance: %.3g x %.3g um at the largest spot, "
              "%.3g x %.3g um at the smallest", name, s->big.sigma_major_um,
              s->big.sigma_minor_um, s->small.sigma_major_um, s->small.sigma_minor_um);
}

int main(int argc, char **argv)
{
    rg_rig r;
    rg_spots s;
    rg_spot_pose p;
    char err[RG_ERRMAX], *wide;
    const char *t;
    if (argc < 3 || !(t = unit_slurp(argv[1])) || !(base = strdup(t)) ||
        !(t = unit_slurp(argv[2])) || !(wide = strdup(t))) {
        printf("FAIL usage: t_oblique EXAMPLE.rig WIDE.rig\n");
        return 1;
    }
    rg = rt_rig();
    CHECK(rg->spot_chain && rg->spot_pose && rg->cornea_curvature, "the engine has the ABI 2 "
          "entries");
    if (!rg->spot_chain || !rg->spot_pose || !rg->cornea_curvature) return 1;

    /* 1. Coddington by rays, and the engine at 30 deg */
    {
        double R = 7.8, th = 30 * RT_DEG, ft, fs, cft = -R / 2 * cos(th), cfs = -R / (2 * cos(th));
        coddington_rays(R, th, 1e-4, &ft, &fs);
        CHECK(rel(ft, cft) < 1e-3 && rel(fs, cfs) < 1e-3, "rays off a sphere at 30 deg, bundle "
              "1e-4 mm: tangential line %.9g mm (Coddington %.9g), sagittal %.9g mm (%.9g)",
              ft, cft, fs, cfs);
        CHECK(load(base, "", &r, err, sizeof err) == 0 && rg->spots(&r, &s, err, sizeof err) == 0,
              "example rig: %s", err);
        CHECK(rg->spot_chain(&s, s.path, th, 1 / R, 1 / R, 0, &p, err, sizeof err) == 0 &&
              rel(p.f_t, ft) < 1e-3 && rel(p.f_s, fs) < 1e-3 && p.psi == 0,
              "spot_chain at 30 deg: f_t %.9g, f_s %.9g mm = the rays' lines", p.f_t, p.f_s);
        /* the same with a bundle 10x wider: the error grows as the bundle squared */
        double ft2, fs2;
        coddington_rays(R, th, 1e-3, &ft2, &fs2);
        CHECK(rel(ft2, cft) > rel(ft, cft) && rel(ft2, cft) < 1e-3,
              "the rays converge on Coddington as the bundle shrinks (%.1e at 1e-3 mm, %.1e at "
              "1e-4 mm)", rel(ft2, cft), rel(ft, cft));
    }

    /* 2. theta = 0 is the apex model of spots, bit for bit */
    {
        static const char *const cases[] = {
            "", "beam_waist 0.3\nbeam_waist_at_mm 20\nbeam_m2 1.3\nfocus_lens_mm 50 30\n",
            "beam_waist 0.25\nbeam_m2 1\nfocus_lens_mm -40 20\n",
            "beam_waist 0.5\nbeam_waist_at_mm -100\nbeam_m2 2\n"};
        for (int k = 0; k < 4; k++) {
            int ok = load(base, cases[k], &r, err, sizeof err) == 0 &&
                     rg->spots(&r, &s, err, sizeof err) == 0;
            ok = ok && rg->spot_chain(&s, s.path, 0, 1 / s.R, 1 / s.R, 0, &p, err, sizeof err) == 0;
            CHECK(ok && p.w_t == s.w_det && p.w_s == s.w_det && p.w_cornea == s.w_cornea &&
                  rel(p.f_t, -s.R / 2) < 1e-15 && rel(p.f_s, -s.R / 2) < 1e-15,
                  "case %d, theta 0: detector %.15g x %.15g mm = spots' %.15g, cornea %.15g = "
                  "%.15g", k, p.w_t, p.w_s, s.w_det, p.w_cornea, s.w_cornea);
        }
    }

    /* 3. per pose: the example's conic, a biconic with its axes at 25 deg, a sphere;
     * the wide zone */
    CHECK(load(base, "focus_lens_mm 40 20\n", &r, err, sizeof err) == 0 &&
          rg->spots(&r, &s, err, sizeof err) == 0, "example + lens: %s", err);
    pose_checks("example conic, lens 40 mm", &r, &s, 0);
    CHECK(rel(s.apex.theta, 20 * RT_DEG) < 1e-6 && rel(s.apex.k_t, 1 / s.R) < 1e-12 &&
          rel(s.apex.f_t, -s.R / 2 * cos(s.apex.theta)) < 1e-12 &&
          rel(s.apex.f_s, -s.R / (2 * cos(s.apex.theta))) < 1e-12,
          "example apex pose: incidence %.6f deg (the detector 20 deg off axis, the beam in at 20 deg on the other side), "
          "Coddington f_t %.6g, f_s %.6g mm", s.apex.theta / RT_DEG, s.apex.f_t, s.apex.f_s);
    CHECK(s.apex.det_inc < 1e-6 && rel(s.apex.foot_major, fmax(s.apex.w_t, s.apex.w_s)) < 1e-9 &&
          rel(s.apex.foot_minor, fmin(s.apex.w_t, s.apex.w_s)) < 1e-9,
          "apex pose: the beam meets the detector square on (%.1e rad): footprint = section "
          "%.5g x %.5g mm", s.apex.det_inc, s.apex.foot_major, s.apex.foot_minor);
    /* the apex pose's plane of incidence is the rig's y-z plane and x' the rig's +x:
     * the tangential (larger) axis lies along y' */
    CHECK(s.apex.w_t > s.apex.w_s && fabs(fabs(s.apex.foot_angle) - 90 * RT_DEG) < 1e-6,
          "apex pose: the major axis at %.6f deg from x' (the plane of incidence: 90)",
          s.apex.foot_angle / RT_DEG);
    scan_checks("example, lens", &r, &s);
    CHECK(load(base, "cornea biconic\ncornea_R 7.9\ncornea_R2 7.3\ncornea_Q -0.2\n"
               "cornea_Q2 -0.1\ncornea_axis 25\n", &r, err, sizeof err) == 0 &&
          rg->spots(&r, &s, err, sizeof err) == 0, "biconic: %s", err);
    pose_checks("biconic 7.9/7.3 mm, axis 25 deg", &r, &s, 0);
    CHECK(fabs(s.apex.psi) > 1e-3, "biconic apex: the beam's axes %.2f deg off the plane of "
          "incidence (twist %.4g /mm)", s.apex.psi / RT_DEG, s.apex.k_ts);
    CHECK(load(base, "cornea sphere\ncornea_R 7.5\n", &r, err, sizeof err) == 0 &&
          rg->spots(&r, &s, err, sizeof err) == 0, "sphere: %s", err);
    pose_checks("sphere 7.5 mm", &r, &s, 1);
    CHECK(load(wide, "", &r, err, sizeof err) == 0 && rg->spots(&r, &s, err, sizeof err) == 0,
          "wide-zone rig: %s", err);
    pose_checks("wide zone", &r, &s, 0);
    scan_checks("wide zone", &r, &s);
    lens_checks("wide zone", &r, &s);
    CHECK(load(base, "", &r, err, sizeof err) == 0 && rg->spots(&r, &s, err, sizeof err) == 0,
          "example: %s", err);
    scan_checks("example", &r, &s);
    lens_checks("example", &r, &s);
    CHECK(load(base, "focus_lens_mm 40 20\n", &r, err, sizeof err) == 0 &&
          rg->spots(&r, &s, err, sizeof err) == 0, "example + lens: %s", err);
    lens_checks("example, lens 40 mm at 20", &r, &s);
    fresnel_checks("example");

    /* the curvature's own face: a point off the surface is refused */
    {
        double far[3] = {100, 0, 0}, e1[3] = {1, 0, 0}, e2[3] = {0, 1, 0}, K[3];
        CHECK(rg->cornea_curvature(&r.geom.cornea, far, e1, e2, K) == RG_EUNREACH,
              "cornea_curvature off the cap: RG_EUNREACH");
    }
    free(base);
    free(wide);
    return unit_failed();
}
