/* rg_quant.c -- what steppers can really do: a solved pose rounded to the joints'
 * step grids in the order that lets later axes absorb earlier errors -- the stage
 * first, the four angles re-solved (Newton, exact model) so the beam still runs along
 * the backward ray from the quantised centre; then m1's angles, m2's re-solved to
 * hit the target; then m2's -- and the real landing errors of the commanded pose. */
#include <stdio.h>
#include <string.h>
#include "rig/rg_geom.h"
#include "rig/rg_vec.h"

static double qstep(const rg_joint *j, double x)
{
    return j->steps_per > 0 ? nearbyint(x * j->steps_per) / j->steps_per : x;
}

static void land(const rg_geometry *g, const rg_pose *p, const double target[3],
                 rg_beam *b, double *ec, double *ed)
{
    if (rg_forward_beam(g, p, b)) { *ec = *ed = INFINITY; return; }
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
    if (rg_newton(g, &q->pose, ANG, s->target, in, tol, 30, &res) < 0)
        q->diag |= RG_D_NO_CONVERGE;
    rg_beam b;
    land(g, &q->pose, s->target, &b, &q->err_cornea_resolved, &q->err_detector_resolved);
    q->pose.j[RG_J_M1A] = qstep(&g->joint[RG_J_M1A], q->pose.j[RG_J_M1A]);
    q->pose.j[RG_J_M1B] = qstep(&g->joint[RG_J_M1B], q->pose.j[RG_J_M1B]);
    rg_pose keep = q->pose;
    if (rg_newton(g, &q->pose, 1u << RG_J_M2A | 1u << RG_J_M2B, s->target, in, tol,
                  30, &res) < 0)
        q->pose = keep;     /* m2's angles stay as re-solved for the stage */
    q->pose.j[RG_J_M2A] = qstep(&g->joint[RG_J_M2A], q->pose.j[RG_J_M2A]);
    q->pose.j[RG_J_M2B] = qstep(&g->joint[RG_J_M2B], q->pose.j[RG_J_M2B]);
    for (int k = 0; k < RG_NJOINTS; k++)
        q->steps[k] = g->joint[k].steps_per > 0
                    ? (int64_t)llround(q->pose.j[k] * g->joint[k].steps_per) : 0;
    land(g, &q->pose, s->target, &q->beam, &q->err_cornea, &q->err_detector);
    q->diag |= q->beam.diag;
    if (q->diag & RG_D_FATAL) {
        char txt[512];
        snprintf(err, errcap, "quantised pose: %s", rg_diag_text(q->diag, txt, sizeof txt));
        return (q->diag & RG_D_FATAL) == RG_D_TRAVEL ? RG_ETRAVEL : RG_EUNREACH;
    }
    if (errcap) err[0] = 0;
    return RG_OK;
}
