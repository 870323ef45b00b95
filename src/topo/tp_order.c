/* tp_order.c -- the scan on the machine (doc/scan-time.md): the planned points visited in
 * the order the rig engine's planner finds fastest, stop and go (move, settle, expose,
 * rig_api.scan_order / scan_time) or, where the rig file allows it, in one continuous
 * motion with the laser pulsed as each point is passed (rig_api.sweep / sweep_time:
 * the planner's order or the pattern's own, whichever it predicts faster).  Each
 * exposure's time on the machine's clock, the pose the motors held (on the fly: their
 * mean over the exposure) and its smear; a smear the centroid does not tolerate
 * rejects the point.  The machine's own checks (travel, dose, interlock, heartbeat)
 * stay where they are: this file only chooses the order and reads the results. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "tp_int.h"

#define PI 3.14159265358979323846

static double unit(const rg_rig *rig, int j)
{
    return rig->axis[j].linear ? 1 : PI / 180;
}

static void to_pose(const rg_rig *rig, const double *steps, rg_pose *p)
{
    for (int j = 0; j < RG_NJOINTS; j++) p->j[j] = steps[j] / rig->axis[j].steps_per * unit(rig, j);
}

static void to_posel(const rg_rig *rig, const long *steps, rg_pose *p)
{
    double d[RG_NJOINTS];
    for (int j = 0; j < RG_NJOINTS; j++) d[j] = (double)steps[j];
    to_pose(rig, d, p);
}

/* What set a sweep's time, in words: the joints whose limits capped most legs. */
static void sweep_limit(const rig_api *rg, const rg_sweep_stats *st, char *buf, size_t cap)
{
    size_t k = 0;
    long legs = st->n > 1 ? st->n - 1 : 1;
    buf[0] = 0;
#define ADD(cnt, fmt, name) do { if ((cnt) > 0.05 * legs && k < cap)                         \
        k += (size_t)snprintf(buf + k, cap - k, "%s" fmt " %.0f %%", k ? ", " : "", name,     \
                              100.0 * (cnt) / legs); } while (0)
    for (int j = 0; j < RG_NJOINTS; j++) {
        ADD(st->lim_speed[j], "the speed of %s", rg->joint_name(j));
        ADD(st->lim_turn[j], "the turns of %s", rg->joint_name(j));
    }
    ADD(st->lim_expose, "%s", "one exposure a leg");
    if (k < cap)
        snprintf(buf + k, cap - k, "%s(of %ld legs; ramps within half of each joint's "
                 "acceleration)", k ? " " : "", legs);
#undef ADD
}

/* The smear of point q's exposure on the nominal eye: the largest distance between
 * the beams of its poses (the counted steps' samples, and the smooth path's at the
 * light's start and end: shafts that move continuously), on the detector plane and
 * on the cornea; *lag: the counted steps' mean pose against the smooth path's middle
 * on the detector (0 at rest). */
static void smear(const tp_run *r, tp_point *q, const rg_sweep_shot *sh, double *lag)
{
    rg_beam b[10];
    rg_pose p[10];
    char e[RG_ERRMAX];
    int np = 0, ok[10];
    q->blur_det = q->blur_cornea = *lag = 0;
    for (int i = 0; i < q->npath && i < 8; i++) p[np++] = q->path[i];
    if (sh) {
        double mid[RG_NJOINTS];
        to_pose(r->rig, sh->c_on, &p[np++]);
        to_pose(r->rig, sh->c_off, &p[np++]);
        for (int j = 0; j < RG_NJOINTS; j++) mid[j] = 0.5 * (sh->c_on[j] + sh->c_off[j]);
        rg_pose pm;
        rg_beam bm, bq;
        to_pose(r->rig, mid, &pm);
        if (!r->rg->forward(r->g, &pm, &bm, e, sizeof e) &&
            !r->rg->forward(r->g, &q->pose, &bq, e, sizeof e)) {
            double d = 0;
            for (int i = 0; i < 3; i++) d += (bm.det[i] - bq.det[i]) * (bm.det[i] - bq.det[i]);
            if (isfinite(d)) *lag = sqrt(d);
        }
    }
    for (int i = 0; i < np; i++) ok[i] = !r->rg->forward(r->g, &p[i], &b[i], e, sizeof e);
    for (int a = 0; a < np; a++)
        for (int c = 0; c < a; c++) {
            double dd = 0, dc = 0;
            if (!ok[a] || !ok[c]) continue;
            for (int i = 0; i < 3; i++) {
                dd += (b[a].det[i] - b[c].det[i]) * (b[a].det[i] - b[c].det[i]);
                dc += (b[a].spot[i] - b[c].spot[i]) * (b[a].spot[i] - b[c].spot[i]);
            }
            /* the smear is within one sample set: the counted steps among themselves,
               the smooth path's two ends together */
            int same = (a < q->npath) == (c < q->npath);
            if (!same) continue;
            if (isfinite(dd) && sqrt(dd) > q->blur_det) q->blur_det = sqrt(dd);
            if (isfinite(dc) && sqrt(dc) > q->blur_cornea) q->blur_cornea = sqrt(dc);
        }
}

/* The smear a centroid tolerates: a uniform smear of length L over a Gaussian spot of
 * sigma s (s = w/2 for the 1/e^2 radius w) leaves the centroid at the smear's middle
 * (the motors' mean pose is the one fitted: to first order its beam is the mean of
 * the smeared beams) and widens the spot to sqrt(s^2 + L^2/12), the centroid's sigma
 * with it; we accept it half as large again: L <= sqrt(12 (1.5^2 - 1)) s = 3.87 s,
 * about the spot's 1/e^2 diameter (beyond it the spot is no longer the Gaussian the
 * centroider fits). */
double tp_blur_tol(const tp_run *r)
{
    double w = r->cam.spot_w > 0 ? r->cam.spot_w : 3, pitch = r->cam.pitch > 0 ? r->cam.pitch : 0.014;
    return sqrt(12 * (1.5 * 1.5 - 1)) * 0.5 * w * pitch;
}

int tp_scan_machine(tp_run *r, tp_exposed_fn after, void *ctx, char *err, size_t cap)
{
    const rig_api *rg = r->rg;
    int n = r->npoints, m = 0, rc = 0;
    long start[RG_NJOINTS];
    char e[RG_ERRMAX];
    int *idx = malloc(sizeof *idx * (size_t)(n ? n : 1));
    long *st = malloc(sizeof *st * RG_NJOINTS * (size_t)(n ? n : 1));
    long *sp = malloc(sizeof *sp * RG_NJOINTS * (size_t)(n ? n : 1));
    long *ord = malloc(sizeof *ord * (size_t)(n ? n : 1));
    rg_sweep_shot *shot = NULL;
    memset(&r->sc, 0, sizeof r->sc);
    r->sc.blur_tol = tp_blur_tol(r);
    if (!idx || !st || !sp || !ord) { snprintf(err, cap, "out of memory"); rc = CN_ENOMEM; goto out; }
    for (int k = 0; k < n; k++) {
        tp_point *q = &r->pt[k];
        q->t_s = NAN;
        if (!q->planned) continue;
        if (rg->pose_steps(r->rig, &q->pose, st + (size_t)m * RG_NJOINTS, e, sizeof e)) {
            q->planned = 0;
            snprintf(q->why, sizeof q->why, "not moved: %.80s", e);
            continue;
        }
        idx[m++] = k;
    }
    rg->position(r->m, start, NULL);
    /* on the fly only for a pulse that fits between two control steps' STEP edges
       (rig_api.sweep): a longer exposure would see the motors step during it, and one
       mirror step moves the spot 0.2-0.4 mm on the detector, several times what the
       centroid tolerates (doc/scan-time.md) */
    int fly = r->rig->expose_moving && !(r->rig->shutter_ms > 0) && rg->sweep && rg->sweep_time &&
              r->expose_ms * 1e3 <= 0.5 * r->rig->tick_us;
    if (m > 0 && rg->scan_order(r->rig, start, st, m, ord, e, sizeof e)) {
        snprintf(err, cap, "the scan order: %.400s", e);
        rc = CN_EINVAL;
        goto out;
    }
    for (int i = 0; i < m; i++) memcpy(sp + (size_t)i * RG_NJOINTS, st + ord[i] * RG_NJOINTS,
                                       sizeof *sp * RG_NJOINTS);
    double t_own, t_plan;
    if (fly) {
        rg_sweep_stats so, sq;
        if (rg->sweep_time(r->rig, start, st, m, r->expose_ms, &so, e, sizeof e) ||
            rg->sweep_time(r->rig, start, sp, m, r->expose_ms, &sq, e, sizeof e)) {
            snprintf(err, cap, "the sweep: %.400s", e);
            rc = CN_EINVAL;
            goto out;
        }
        t_own = so.t_total;
        t_plan = sq.t_total;
        sweep_limit(rg, t_plan < t_own ? &sq : &so, r->sc.limit, sizeof r->sc.limit);
    } else {
        rg_scan_stats so, sq;
        if (rg->scan_time(r->rig, start, st, NULL, m, r->expose_ms, &so, e, sizeof e) ||
            rg->scan_time(r->rig, start, st, ord, m, r->expose_ms, &sq, e, sizeof e)) {
            snprintf(err, cap, "the scan time: %.400s", e);
            rc = CN_EINVAL;
            goto out;
        }
        t_own = so.t_total;
        t_plan = sq.t_total;
        rg->scan_limit_text(t_plan < t_own ? &sq : &so, r->sc.limit, sizeof r->sc.limit);
    }
    r->sc.on_fly = fly;
    r->sc.reordered = t_plan < t_own;
    r->sc.pred_s = fmin(t_plan, t_own);
    r->sc.pred_own_s = t_own;
    if (!r->sc.reordered) {
        for (int i = 0; i < m; i++) ord[i] = i;
        memcpy(sp, st, sizeof *sp * RG_NJOINTS * (size_t)m);
    }
    double t0 = rg->clock_s(r->m);
    if (fly && m > 0) {
        if (!(shot = calloc((size_t)m, sizeof *shot))) { snprintf(err, cap, "out of memory"); rc = CN_ENOMEM; goto out; }
        int src = rg->sweep(r->m, sp, m, r->expose_ms, r->stop, r->stop_ctx, shot, e, sizeof e);
        if (src) {
            rc = src == RG_ESTOP ? CN_ESTOP : CN_EINVAL;
            snprintf(err, cap, "%.400s", src == RG_ESTOP ? "stopped" : e);
            goto out;
        }
    }
    for (int i = 0, seq = 0; i < m; i++) {
        tp_point *q = &r->pt[idx[ord[i]]];
        const long *s = sp + (size_t)i * RG_NJOINTS;
        if (fly) {
            to_pose(r->rig, shot[i].mean, &q->pose);
            q->npath = shot[i].nat;
            for (int c = 0; c < q->npath; c++) to_posel(r->rig, shot[i].at[c], &q->path[c]);
            q->t_s = shot[i].t_on + r->expose_ms / 2e3 - t0;
        } else {
            long at[RG_NJOINTS];
            int src = rg->move_steps(r->m, s, r->stop, r->stop_ctx, e, sizeof e);
            if (!src) src = rg->expose(r->m, r->expose_ms, r->stop, r->stop_ctx, e, sizeof e);
            if (src) {
                rc = src == RG_ESTOP || (r->stop && r->stop(r->stop_ctx)) ? CN_ESTOP : CN_EINVAL;
                if (rc == CN_ESTOP) snprintf(err, cap, "stopped");
                else snprintf(err, cap, "point %d: %.400s", idx[ord[i]] + 1, e);
                goto out;
            }
            q->t_s = rg->clock_s(r->m) - r->expose_ms / 2e3 - t0;
            if (rg->motors(r->m, at)) to_posel(r->rig, at, &q->pose);  /* where they stood */
            q->path[0] = q->pose;
            q->npath = 1;
        }
        q->seq = ++seq;
        r->nexposed++;
        double lag;
        smear(r, q, fly ? &shot[i] : NULL, &lag);
        if (lag > r->sc.step_det_max) r->sc.step_det_max = lag;
        if (q->blur_det > r->sc.blur_det_max) r->sc.blur_det_max = q->blur_det;
        if (q->blur_cornea > r->sc.blur_cornea_max) r->sc.blur_cornea_max = q->blur_cornea;
        if (after && (rc = after(r, idx[ord[i]], ctx, err, cap))) goto out;
        if (q->blur_det > r->sc.blur_tol) {
            r->sc.blur_over++;
            q->planned = 0;
            snprintf(q->why, sizeof q->why, "smeared %.3g um on the detector during the "
                     "exposure (the centroid tolerates %.3g um)", q->blur_det * 1e3,
                     r->sc.blur_tol * 1e3);
        }
    }
    r->sc.sim_s = rg->clock_s(r->m) - t0;
out:
    free(idx); free(st); free(sp); free(ord); free(shot);
    return rc;
}
