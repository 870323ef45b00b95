/* tp_adapt.c -- the clinical zone (issue 19 item 4): a measurement planned for the eye
 * it finds.  A plain scan solves every pose on the rig's nominal cornea (R 7.8), so on
 * a 6.5 mm sphere the outer reflections miss the sensor (102 of 300 spots lost on the
 * example rig).  Here coarse passes, out to 1.2 mm and then 3 mm from the axis, are
 * fitted (a sphere, then a biconic: it carries the cylinder and the eye's pose), each
 * pass planned on the fit before it, and the scan asked for is planned on the last
 * fit: its beams then meet the eye found where the targets lie and reflect onto the
 * detector point.  Also the two hooks the loop (tp_loop.c) calls: an outside forward
 * model (tests) and the quick model's sensor edge. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "tp_int.h"

/* The beam's hit from the caller's own forward model: 0, or -1 (status NONE, why). */
int tp_outside_hit(const tp_run *r, const cn_plane *pl, tp_point *q, double hit[3])
{
    if (r->hit(r->hit_ctx, &q->spot.ray, &q->hit_u, &q->hit_v) ||
        !isfinite(q->hit_u) || !isfinite(q->hit_v)) {
        q->hit_u = q->hit_v = NAN;
        snprintf(q->why, sizeof q->why, "the beam misses the eye");
        return -1;
    }
    for (int i = 0; i < 3; i++) hit[i] = pl->at[i] + q->hit_u * pl->e1[i] + q->hit_v * pl->e2[i];
    return 0;
}

/* The quick model with sensor_cut: a spot whose traced hit lies within two spot radii
 * of the sensor's edge (or past it) is lost, as a frame's centroid would be.  1: lost. */
int tp_off_sensor(const tp_run *r, tp_point *q)
{
    const tp_camera *c = &r->cam;
    if (!(c->width > 0 && c->height > 0 && c->pitch > 0)) return 0;
    double m = 2 * c->spot_w * c->pitch;
    if (fabs(q->hit_u) <= 0.5 * c->width * c->pitch - m &&
        fabs(q->hit_v) <= 0.5 * c->height * c->pitch - m)
        return 0;
    q->spot.status = CN_S_NONE;
    q->spot.u = q->spot.v = NAN;
    snprintf(q->why, sizeof q->why, "no spot: it lands off the sensor");
    return 1;
}

static int located(const tp_run *r)
{
    int n = 0;
    for (int k = 0; k < r->npoints; k++) n += r->pt[k].planned && r->pt[k].spot.status == CN_S_OK;
    return n;
}

int tp_measure_zone(tp_run *r, char *err, size_t cap)
{
    static const double coarse_h[] = {1.2, 3.0};
    static const int coarse_model[] = {CN_SPHERE, CN_BICONIC};
    const int n_all = r->npoints, model = r->model;
    const double zone_h = r->zone_h;
    const char *save = r->save;
    cn_zfit *zf = r->zf;
    const rg_geometry *plan0 = r->plan_g;
    rg_machine *m = r->m;
    char e[RG_ERRMAX];
    int rc = 0;
    memset(&r->cover, 0, sizeof r->cover);
    r->npass = 0;
    if (!(zone_h > 0)) { snprintf(err, cap, "the zone's radius (mm) is not set"); return CN_EINVAL; }
    if (r->source == TP_SRC_CAMERA) {
        snprintf(err, cap, "a zone planned for the eye needs spots made for its poses: "
                 "frames read from a camera follow a scan planned beforehand");
        return CN_EINVAL;
    }
    int nc = n_all / 6 < 30 ? (n_all < 30 ? n_all : 30) : n_all / 6, npass = 0;
    for (size_t i = 0; i < sizeof coarse_h / sizeof *coarse_h; i++)
        npass += coarse_h[i] < 0.9 * zone_h;
    /* the dose of every pass together, against the MPE, before the first pulse */
    if (m && r->rg->dose_plan) {
        rg_dose dz;
        if (r->rg->dose_plan(m, r->expose_ms, (long)nc * npass + n_all, &dz, e, sizeof e)) {
            snprintf(err, cap, "the scan is refused before its first pulse: %.400s", e);
            return CN_EINVAL;
        }
    }
    r->zone_g = plan0 ? *plan0 : *r->g;
    const rg_geometry *plan = plan0;
    const cn_params *start0 = r->fit_start;
    cn_params start;
    int have_start = 0;
    for (int p = 0; p < npass; p++) {
        tp_pass *ps = &r->pass[r->npass++];
        r->npoints = nc;
        r->zone_h = coarse_h[p];
        r->plan_g = plan;
        r->zf = NULL;                   /* no surface: the fit is all a pass needs */
        r->save = NULL;
        r->model = coarse_model[p];
        r->fit_start = NULL;            /* the nominal: a coarse zone is met by any eye */
        rc = tp_measure(r, err, cap);
        ps->zone_h = coarse_h[p];
        ps->npoints = r->npoints;
        ps->nplanned = r->nplanned;
        ps->nok = located(r);
        ps->R = ps->Km = ps->cyl = NAN;
        ps->used = 0;
        if (rc == CN_ESTOP || (rc && rc != CN_EFIT)) goto out;
        rc = 0;
        /* a fit that failed, did not converge, lacks the eye's shape (rejected: its
           residuals are systematic, as on a cone, so its outer zone is a guess) or
           found no cornea (R outside 5-12 mm: a sphere on a small zone of a toric
           eye can run far, the radius trading with the distance) plans nothing: the
           last plan stays */
        if (!r->fitted || !r->res.converged || r->res.rejected_model ||
            !(r->res.k.R >= 5 && r->res.k.R <= 12))
            continue;
        ps->R = r->res.k.R;
        ps->Km = r->res.k.Km;
        ps->cyl = r->model == CN_BICONIC ? r->res.k.cyl : 0;
        r->zone_g = *r->g;
        r->cn->cornea_from_params(r->rg, r->model, &r->res.par, r->g->cornea.trans,
                                  &r->zone_g.cornea);
        r->zone_g.cornea.zone = 0;      /* the whole cap: the targets say how far */
        if (r->zone_g.cornea.model != RG_SPHERE) {
            /* a global fit of an irregular eye (a cone) may end oblate enough for its
               cap to stop short of the zone; the plan needs only the reflections on
               the sensor, so Q is kept to what corneas show */
            rg_cornea *c = &r->zone_g.cornea;
            c->Q = fmin(fmax(c->Q, -1.0), 0.3);
            c->Q2 = fmin(fmax(c->Q2, -1.0), 0.3);
        }
        plan = &r->zone_g;
        start = r->res.par;
        have_start = 1;
        ps->used = 1;
    }
    /* the final fit starts from the last pass's eye, in the final model's terms (the
       nominal start sends the outer beams past a 6.5 mm cornea: spots lost as misses) */
    if (have_start) {
        if (model != CN_BICONIC) start.p[CN_C0] = start.p[CN_C45] = 0;
        if (model == CN_SPHERE)
            start.p[CN_QF] = start.p[CN_QS] = start.p[CN_TX] = start.p[CN_TY] = 0;
        start.p[CN_QS] = model == CN_BICONIC ? start.p[CN_QS] : start.p[CN_QF];
        start.p[CN_A4] = start.p[CN_A6] = 0;
        r->fit_start = &start;
    }
    /* the scan asked for, planned on the last fit */
    tp_pass *ps = &r->pass[r->npass++];
    r->npoints = n_all;
    r->zone_h = zone_h;
    r->plan_g = plan;
    r->zf = zf;
    r->save = save;
    r->model = model;
    rc = tp_measure(r, err, cap);
    ps->zone_h = zone_h;
    ps->npoints = r->npoints;
    ps->nplanned = r->nplanned;
    ps->nok = located(r);
    ps->R = ps->Km = ps->cyl = NAN;
    if (!rc && r->have_z) tp_cover_zones(r, &r->cover);
out:
    r->npoints = n_all;
    r->zone_h = zone_h;
    r->zf = zf;
    r->save = save;
    r->model = model;
    r->plan_g = plan0;
    r->fit_start = start0;
    return rc;
}
