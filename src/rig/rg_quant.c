/* rg_quant.c -- what steppers can really do: a solved pose rounded to the joints'
 * step grids in the order that lets later axes absorb earlier errors -- the stage
 * first, the four angles re-solved (Newton, exact model) so the beam still runs along
 * the backward ray from the quantised centre; then m1's angles, m2's re-solved to
 * hit the target, then m2's -- trying the grid corners around m1's re-solved pair and
 * keeping the commanded pose that lands nearest the target (a quarter smaller worst
 * error than rounding each joint to its nearest step) -- and the real landing errors
 * of the commanded pose on the exact forward model. */
#include <stdio.h>
#include <string.h>
#include "rig/rg_geom.h"
#include "rig/rg_vec.h"

static double qstep(const rg_joint *j, double x)
{
    return j->steps_per > 0 ? nearbyint(x * j->steps_per) / j->steps_per : x;
}

/* The grid values on either side of x (one when x is on the grid or continuous). */
static int corners(const rg_joint *j, double x, double out[2])
{
    if (!(j->steps_per > 0)) { out[0] = x; return 1; }
    double f = floor(x * j->steps_per), c = ceil(x * j->steps_per);
    out[0] = f / j->steps_per;
    out[1] = c / j->steps_per;
    return f == c ? 1 : 2;
}

static void land(const rg_geometry *g, const rg_pose *p, const double target[3],
                 rg_beam *b, double *ec, double *ed, int checks)
{
    if (rg_forward_path(g, p, b, checks)) { *ec = *ed = INFINITY; return; }
    *ec = v3dist(b->spot, target);
    *ed = isfinite(b->det[0]) ? v3dist(b->det, g->detector) : INFINITY;
}

int rg_quantise(const rg_geometry *g, const rg_target *t, const rg_solution *s,
                rg_quantised *q, char *err, size_t errcap)
{
    (void)t;
    const double tol = 1e-12;
    double in[3], res;
    memset(q, 0, sizeof *q);
    v3scale(in, s->back, -1);
    q->pose = s->pose;
    const unsigned ANG = 1u << RG_J_M1A | 1u << RG_J_M1B | 1u << RG_J_M2A |
                         1u << RG_J_M2B;
    q->pose.j[RG_J_U] = qstep(&g->joint[RG_J_U], s->pose.j[RG_J_U]);
    q->pose.j[RG_J_V] = qstep(&g->joint[RG_J_V], s->pose.j[RG_J_V]);
    double c2[3], n1[3], n2[3], h1[3], d1[3];
    rg_m2_center(g, q->pose.j[RG_J_U], q->pose.j[RG_J_V], c2);
    rg_gimbal_normal(&g->m1, s->pose.j[RG_J_M1A], s->pose.j[RG_J_M1B], n1);
    rg_gimbal_normal(&g->m2, s->pose.j[RG_J_M2A], s->pose.j[RG_J_M2B], n2);
    /* the four angles for the quantised centre: the construction, then Newton's check */
    if (rg_aim_stage(g, s->target, s->back, c2, n1, n2) < 0 ||
        rg_gimbal_angles(&g->m1, n1, &q->pose.j[RG_J_M1A], &q->pose.j[RG_J_M1B]) ||
        rg_gimbal_angles(&g->m2, n2, &q->pose.j[RG_J_M2A], &q->pose.j[RG_J_M2B])) {
        for (int k = 0; k < RG_NJOINTS; k++)     /* Newton from the solution's angles */
            if (k != RG_J_U && k != RG_J_V) q->pose.j[k] = s->pose.j[k];
    }
    if (rg_newton(g, &q->pose, ANG, s->target, in, tol, 30, &res) < 0)
        q->diag |= RG_D_NO_CONVERGE;
    rg_beam b;
    land(g, &q->pose, s->target, &b, &q->err_cornea_resolved, &q->err_detector_resolved,
         0);
    /* m1 on its grid -- each of the 4 grid corners around its re-solved angles --,
     * m2's angles re-aimed at the target from where m1 then sends the beam and
     * rounded to their nearest steps: of the 4 commanded poses the one landing nearest
     * the target.  (m1's choice decides where m2's rounding falls; trying m2's corners
     * too, 16 poses, gains under 4 % more.) */
    rg_pose cont = q->pose, best = q->pose;
    double best_err = INFINITY;
    double a1[2], b1[2];
    int na1 = corners(&g->joint[RG_J_M1A], cont.j[RG_J_M1A], a1);
    int nb1 = corners(&g->joint[RG_J_M1B], cont.j[RG_J_M1B], b1);
    for (int i = 0; i < na1; i++)
        for (int k = 0; k < nb1; k++) {
            rg_pose p = cont;
            p.j[RG_J_M1A] = a1[i];
            p.j[RG_J_M1B] = b1[k];
            rg_pose keep = p;
            rg_gimbal_normal(&g->m1, p.j[RG_J_M1A], p.j[RG_J_M1B], n1);
            rg_gimbal_normal(&g->m2, p.j[RG_J_M2A], p.j[RG_J_M2B], n2);
            int ok = rg_aim_m1_beam(g, n1, h1, d1) == 0 &&
                     rg_aim_m2(g, s->target, h1, d1, c2, n2) >= 0 &&
                     rg_gimbal_angles(&g->m2, n2, &p.j[RG_J_M2A], &p.j[RG_J_M2B]) == 0;
            if (!ok) {
                p = keep;
                if (rg_newton(g, &p, 1u << RG_J_M2A | 1u << RG_J_M2B, s->target, in, tol,
                              30, &res) < 0)
                    p = keep;   /* m2's angles stay as re-solved for the stage */
            }
            p.j[RG_J_M2A] = qstep(&g->joint[RG_J_M2A], p.j[RG_J_M2A]);
            p.j[RG_J_M2B] = qstep(&g->joint[RG_J_M2B], p.j[RG_J_M2B]);
            double ec, ed;
            land(g, &p, s->target, &b, &ec, &ed, 0);
            if (ec < best_err) { best_err = ec; best = p; }
        }
    q->pose = best;
    for (int k = 0; k < RG_NJOINTS; k++)
        q->steps[k] = g->joint[k].steps_per > 0
                    ? (int64_t)llround(q->pose.j[k] * g->joint[k].steps_per) : 0;
    land(g, &q->pose, s->target, &q->beam, &q->err_cornea, &q->err_detector, 1);
    q->diag |= q->beam.diag;
    if (q->diag & RG_D_FATAL) {
        char txt[512];
        snprintf(err, errcap, "quantised pose: %s", rg_diag_text(q->diag, txt, sizeof txt));
        return (q->diag & RG_D_FATAL) == RG_D_TRAVEL ? RG_ETRAVEL : RG_EUNREACH;
    }
    if (errcap) err[0] = 0;
    return RG_OK;
}
