/* rg_spots.c -- the laser's Gaussian beam through the rig for the apex pose (issue 21,
 * section 46): its radius on the cornea and on the detector, the focus lens that
 * balances the two, and the centroid's shot-noise limit for the photons the dose
 * allows.  The geometry half solves the apex pose (path lengths); the beam goes
 * through the paraxial engine's public functions (paraxial.h: px_beam_*, linked into
 * this module as hidden objects, like the trace module's glass catalogue).  Flat
 * mirrors are the identity; the cornea is a convex mirror of its apex radius, on axis
 * (unfolded: a thin lens of power -2/R).  The oblique incidence, pose by pose over a
 * scan, is rg_spotscan.c's (called at the end). */
#include <math.h>
#include <stdio.h>
#include "rig/rg_hw.h"
#include "rig/rg_vec.h"
#include "paraxial/paraxial.h"

#define H_PLANCK 6.62607015e-34
#define C_LIGHT 299792458.0

typedef struct chain {
    const rg_spots *s;          /* the laser's waist (w0, waist_before_m1) and path */
} chain;

/* The beam from the laser's waist along path (laser->m1, m1->m2, m2->cornea) to the
 * cornea with a lens of focal length f at `at` mm before it (f = 0: no lens): *b at the
 * cornea, w[0..2] the radii at m1, m2 and the cornea; 0 or PX_BAD.  The apex model
 * (run) and the oblique one (rg_spotscan.c) share it. */
int rg_spots_to_cornea(const rg_spots *s, const double path[4], double f, double at,
                       px_beam *b, double w[3])
{
    px_beam_at p;
    double l2 = path[2];
    if (px_beam_waist(s->w0, s->waist_before_m1, s->lambda_mm, s->m2, 1, b)) return PX_BAD;
    px_beam_props(b, &p); w[0] = p.w;
    if (px_beam_apply(b, px_translation(path[1]), 1)) return PX_BAD;
    px_beam_props(b, &p); w[1] = p.w;
    if (f != 0) {
        px_mat lens = {1, 0, -1 / f, 1};
        if (px_beam_apply(b, px_translation(l2 - at), 1) || px_beam_apply(b, lens, 1) ||
            px_beam_apply(b, px_translation(at), 1))
            return PX_BAD;
    } else if (px_beam_apply(b, px_translation(l2), 1)) return PX_BAD;
    px_beam_props(b, &p); w[2] = p.w;
    return 0;
}

/* Radii at m1, m2, the cornea and the detector with a lens of focal length f at `at`
 * mm before the apex (f = 0: no lens); 0 or PX_BAD. */
static int run(const chain *c, double f, double at, double w[4])
{
    const rg_spots *s = c->s;
    px_beam b;
    px_beam_at p;
    if (rg_spots_to_cornea(s, s->path, f, at, &b, w)) return PX_BAD;
    px_mat mirror = {1, 0, 2 / s->R, 1};             /* power -2/R: C = +2/R */
    if (px_beam_apply(&b, mirror, 1) || px_beam_apply(&b, px_translation(s->path[3]), 1))
        return PX_BAD;
    px_beam_props(&b, &p); w[3] = p.w;
    return 0;
}

/* The longest single exposure (ms) the dose allows, at most max_on_ms; 0: none.  A
 * rig file's max_on_ms is already within the dose (the reader checks it with the
 * heartbeat's hold), so from a file this is max_on_ms; the search serves rigs built
 * in code. */
static double longest_exposure(const rg_rig *rig)
{
    rg_dose d;
    char e[RG_ERRMAX];
    double lo = 0.018, hi = rig->max_on_ms > 0 ? rig->max_on_ms : 200;
    if (rg_dose_rig(rig, hi, 1, &d, e, sizeof e) == 0) return hi;
    if (rg_dose_rig(rig, lo, 1, &d, e, sizeof e) != 0) return 0;
    for (int i = 0; i < 200 && hi - lo > 1e-9 * hi; i++) {
        double mid = 0.5 * (lo + hi);
        if (rg_dose_rig(rig, mid, 1, &d, e, sizeof e) == 0) lo = mid; else hi = mid;
    }
    return lo;
}

int rg_spots_run(const rg_rig *rig, rg_spots *s, char *err, size_t cap)
{
    const rig_api *geo = rg_geom_api();
    rg_target t = {RG_T_ANGLES, 0, 0};
    rg_solution sol;
    chain c;
    double w[4];
    *s = (rg_spots){0};
    if (!(rig->wavelength_nm > 0)) {
        snprintf(err, cap, "%s: the beam needs 'wavelength_nm'", rig->path);
        return RG_EINVAL;
    }
    if (!rig->beam_waist_line && !(rig->beam_diameter_mm > 0)) {
        snprintf(err, cap, "%s: the beam needs 'beam_waist' or 'beam_diameter_mm'", rig->path);
        return RG_EINVAL;
    }
    if (!geo || !geo->solve) return RG_EINVAL;
    if (rig->laser_pol_set) {
        const double *e = rig->laser_pol, *d = rig->geom.laser_dir;
        double c[3];
        v3cross(c, e, d);
        if (!(v3len(c) > 1e-9 * v3len(e) * v3len(d))) {
            snprintf(err, cap, "%s:%d: 'laser_polarization': the field %g %g %g lies along "
                     "the beam (laser_dir): a field is across it", rig->path,
                     rig->laser_pol_line, e[0], e[1], e[2]);
            return RG_EINVAL;
        }
    }
    if (geo->solve(&rig->geom, &t, NULL, &sol, err, cap)) {
        /* a rig blind at the apex (the wide-zone rig: m2 in the way): the scan's first
         * target that solves (the spiral's heights grow) stands in for it */
        char e[RG_ERRMAX];
        int k = 0;
        for (; k < RG_SPOTS_POSES; k++) {
            t = rg_spots_target(rig, k);
            if (!geo->solve(&rig->geom, &t, NULL, &sol, e, sizeof e)) break;
        }
        if (k == RG_SPOTS_POSES) return RG_EINVAL;
        s->ref_not_apex = 1;
    }
    s->ref = t;
    s->path[0] = v3dist(rig->geom.laser_at, sol.beam.h1);
    s->path[1] = v3dist(sol.beam.h1, sol.beam.h2);
    s->path[2] = v3dist(sol.beam.h2, sol.beam.spot);
    s->path[3] = v3dist(sol.beam.spot, sol.beam.det);
    if (!isfinite(s->path[3])) {
        snprintf(err, cap, "the beam from the apex never crosses the detector plane");
        return RG_EINVAL;
    }
    s->lambda_mm = rig->wavelength_nm * 1e-6;
    s->m2 = rig->beam_m2 >= 1 ? rig->beam_m2 : 1;
    s->R = rig->geom.cornea.R;
    s->lens_f = rig->lens_f;
    s->lens_at = rig->lens_at;
    if (rig->lens_line && !(rig->lens_at < s->path[2])) {
        snprintf(err, cap, "%s:%d: 'focus_lens_mm': the lens %g mm before the apex is not on "
                 "the m2-cornea leg (%.6g mm long)", rig->path, rig->lens_line, rig->lens_at,
                 s->path[2]);
        return RG_EINVAL;
    }
    if (rig->beam_waist_line) {
        s->w0 = rig->beam_waist;
        s->waist_before_m1 = isnan(rig->beam_waist_at) ? s->path[0] : rig->beam_waist_at;
    } else {        /* a waist of the stated diameter at the apex, without the lens */
        s->waist_from_diameter = 1;
        s->w0 = rig->beam_diameter_mm / 2;
        s->waist_before_m1 = -(s->path[1] + s->path[2]);
    }
    c.s = s;
    if (run(&c, 0, 0, w)) goto bad;
    s->nolens_cornea = w[2];
    s->nolens_det = w[3];
    if (run(&c, rig->lens_line ? s->lens_f : 0, s->lens_at, w)) goto bad;
    s->w_m1 = w[0]; s->w_m2 = w[1]; s->w_cornea = w[2]; s->w_det = w[3];
    /* the scan: both signs, log-spaced; then golden section around the best point */
    s->scan_at = rig->lens_line ? s->lens_at : s->path[2] / 2;
    {
        double lo = log(s->scan_at / 20), hi = log(1e5), best = fmax(s->nolens_cornea,
                                                                      s->nolens_det);
        double bf = 0, step = (hi - lo) / (RG_SPOTS_SCAN - 1);
        int bk = -1, bsign = 1;
        for (int sign = 1; sign >= -1; sign -= 2)
            for (int k = 0; k < RG_SPOTS_SCAN; k++) {
                double f = sign * exp(lo + k * step);
                if (run(&c, f, s->scan_at, w)) continue;
                if (fmax(w[2], w[3]) < best) { best = fmax(w[2], w[3]); bf = f; bk = k;
                                                 bsign = sign; }
            }
        if (bk >= 0) {      /* refine in log f between the neighbours */
            double a = lo + (bk > 0 ? bk - 1 : 0) * step;
            double b = lo + (bk < RG_SPOTS_SCAN - 1 ? bk + 1 : bk) * step;
            const double g = 0.6180339887498949;
            for (int i = 0; i < 100 && b - a > 1e-13; i++) {
                double x1 = b - g * (b - a), x2 = a + g * (b - a), w1[4], w2[4];
                if (run(&c, bsign * exp(x1), s->scan_at, w1) ||
                    run(&c, bsign * exp(x2), s->scan_at, w2))
                    break;
                if (fmax(w1[2], w1[3]) < fmax(w2[2], w2[3])) b = x2; else a = x1;
            }
            double f = bsign * exp(0.5 * (a + b));
            if (!run(&c, f, s->scan_at, w) && fmax(w[2], w[3]) <= best) bf = f;
        }
        s->best_is_none = bk < 0;
        s->best_f = bf;
        if (bk < 0) { s->best_cornea = s->nolens_cornea; s->best_det = s->nolens_det; }
        else if (run(&c, bf, s->scan_at, w)) goto bad;
        else { s->best_cornea = w[2]; s->best_det = w[3]; }
    }
    /* the centroid: N photons, per-axis sigma of the spot's intensity w/2 */
    if (rig->laser_power_mw > 0 && rig->beam_diameter_mm > 0) {
        double n = RG_N_CORNEA;
        s->have_dose = 1;
        s->reflectance = ((n - 1) / (n + 1)) * ((n - 1) / (n + 1));
        s->expose_ms = longest_exposure(rig);
        s->photons = rig->laser_power_mw * 1e-3 * s->expose_ms * 1e-3 * s->reflectance *
                     (rig->wavelength_nm * 1e-9) / (H_PLANCK * C_LIGHT);
        if (s->photons > 0) {
            s->sigma_um = 1e3 * (s->w_det / 2) / sqrt(s->photons);
            s->sigma_best_um = 1e3 * (s->best_det / 2) / sqrt(s->photons);
        }
    }
    /* the oblique incidence over the scan (ABI 2; the figures above stay the apex's
     * at normal incidence) */
    return rg_spots_scan(rig, s, err, cap);
bad:
    snprintf(err, cap, "the beam through the rig is not a beam (a singular optic?)");
    return RG_EINVAL;
}
