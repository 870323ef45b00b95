/* rg_solve.c -- the backward solution of section 38: from a target point on the
 * cornea and the fixed detector point to the six joints, in closed form (tangent
 * plane, reflected backward ray, m2's centre on p2, both normals bisecting), refined
 * by Newton on the exact model when a mirror surface is off its rotation axes; the
 * diagnostics of section 39 and the condition number of the joints-to-spot map. */
#include <stdio.h>
#include <string.h>
#include <gsl/gsl_linalg.h>
#include "rig/rg_geom.h"
#include "rig/rg_vec.h"

void rg_opts_fill(const rg_solve_opts *in, rg_solve_opts *o)
{
    if (in) *o = *in; else memset(o, 0, sizeof *o);
    if (!(o->min_p2_angle > 0)) o->min_p2_angle = 2 * RG_PI / 180;
    if (!(o->max_incidence > 0)) o->max_incidence = 80 * RG_PI / 180;
    if (!(o->cond_max > 0)) o->cond_max = 1e4;
    if (!(o->tol > 0)) o->tol = 1e-12;
    if (o->max_iter <= 0) o->max_iter = 30;
    if (!(o->trace_tol > 0)) o->trace_tol = 1e-6;
}

/* ---- Newton on the exact model ------------------------------------------------- */
typedef struct nt_ctx {
    const rg_geometry *g;
    const double *target, *dir;
    double e1[3], e2[3];       /* across dir */
    int nres;                  /* 2: hit the target; 4: the line; 6: line + m2 centre */
} nt_ctx;

static int residual(const nt_ctx *c, const rg_pose *p, double *F)
{
    rg_beam b;
    if (rg_mirrors_ap(c->g, p, &b, 0)) return -1;
    double rel[3], q[3], dd[3];
    v3sub(rel, c->target, b.h2);
    double along = v3dot(rel, b.d2);
    if (!(along > 0)) return -1;
    v3axpy(q, b.h2, along, b.d2);        /* the beam's point nearest the target */
    v3sub(q, q, c->target);
    F[0] = v3dot(q, c->e1);
    F[1] = v3dot(q, c->e2);
    if (c->nres == 2) return 0;
    v3sub(dd, b.d2, c->dir);
    F[2] = v3dot(dd, c->e1) * along;    /* direction error, as mm at the target */
    F[3] = v3dot(dd, c->e2) * along;
    if (c->nres == 4) return 0;
    double n2[3], c2[3], m[3], f1[3], f2[3];
    rg_gimbal_normal(&c->g->m2, p->j[RG_J_M2A], p->j[RG_J_M2B], n2);
    rg_m2_center(c->g, p->j[RG_J_U], p->j[RG_J_V], c2);
    v3axpy(m, c2, c->g->m2.offset, n2);
    v3sub(m, b.h2, m);
    v3basis(n2, c->g->p2_u, f1, f2);
    F[4] = v3dot(m, f1);
    F[5] = v3dot(m, f2);
    return 0;
}

static double maxabs(const double *F, int n)
{
    double m = 0;
    for (int i = 0; i < n; i++) m = fmax(m, fabs(F[i]));
    return m;
}

int rg_newton(const rg_geometry *g, rg_pose *p, unsigned free, const double target[3],
              const double dir[3], double tol, int max_iter, double *res)
{
    nt_ctx c = {.g = g, .target = target, .dir = dir};
    int idx[RG_NJOINTS], n = 0;
    for (int k = 0; k < RG_NJOINTS; k++)
        if (free & (1u << k)) idx[n++] = k;
    if (n != 2 && n != 4 && n != 6) return -1;
    c.nres = n;
    double hint[3] = {0, 0, 1};
    v3basis(dir, hint, c.e1, c.e2);
    double F[6], Fn[6], J[36], dx[6];
    if (residual(&c, p, F)) { *res = INFINITY; return -1; }
    double f = maxabs(F, n);
    int it = 0, status = -1;
    for (;;) {
        if (f <= tol) { status = it; break; }
        if (it >= max_iter) break;
        it++;
        /* forward-difference Jacobian: near the root Newton still gains ~7 digits a
         * step, and the root itself does not depend on the Jacobian's accuracy */
        int bad = 0;
        for (int cidx = 0; cidx < n && !bad; cidx++) {
            rg_pose q = *p;
            double h = 1e-7 * (1 + fabs(p->j[idx[cidx]]));
            q.j[idx[cidx]] += h;
            if (residual(&c, &q, Fn)) { bad = 1; break; }
            for (int r = 0; r < n; r++) J[r * n + cidx] = (Fn[r] - F[r]) / h;
        }
        if (bad) break;
        double rhs[6];
        for (int r = 0; r < n; r++) rhs[r] = -F[r];
        gsl_matrix_view A = gsl_matrix_view_array(J, n, n);
        gsl_vector_view B = gsl_vector_view_array(rhs, n);
        gsl_vector_view X = gsl_vector_view_array(dx, n);
        gsl_permutation perm;
        size_t pd[6];
        perm.size = n;
        perm.data = pd;
        int sg;
        /* GSL reports a singular matrix through its global error handler (abort by
         * default, and not ours to change in a thread-safe engine): look first */
        int finite = 1;
        for (int r = 0; r < n * n; r++) finite &= isfinite(J[r]);
        if (!finite || gsl_linalg_LU_decomp(&A.matrix, &perm, &sg)) break;
        double dmax = 0, dmin = INFINITY;
        for (int r = 0; r < n; r++) {
            dmax = fmax(dmax, fabs(J[r * n + r]));
            dmin = fmin(dmin, fabs(J[r * n + r]));
        }
        if (!(dmin > 1e-14 * dmax) ||
            gsl_linalg_LU_solve(&A.matrix, &perm, &B.vector, &X.vector))
            break;
        /* damped: halve the step until the residual falls */
        double lam = 1;
        int ok = 0;
        for (int k = 0; k < 30; k++) {
            rg_pose q = *p;
            for (int r = 0; r < n; r++) q.j[idx[r]] += lam * dx[r];
            if (!residual(&c, &q, Fn)) {
                double fn = maxabs(Fn, n);
                if (fn < f || fn <= tol) {
                    *p = q;
                    memcpy(F, Fn, sizeof F);
                    f = fn;
                    ok = 1;
                    break;
                }
            }
            lam *= 0.5;
        }
        if (!ok) break;     /* no descent: at the rounding floor or stuck */
    }
    *res = f;
    if (status < 0 && f <= tol * 1e3) status = it;   /* at the rounding floor */
    return status;
}

/* ---- joints-to-spot map ---------------------------------------------------------- */
/* Spot coordinates of a pose: 2 in the tangent plane of the base spot, 2 in the
 * detector plane. */
static int spot4(const rg_geometry *g, const rg_pose *p, const double base[3],
                 const double t1[3], const double t2[3], const double dbase[3],
                 const double e1[3], const double e2[3], double out[4],
                 const double n1b[3], const double n2b[3], int k)
{
    rg_beam b;
    double n1[3], n2[3];
    /* only the moved joint's mirror turns */
    if (k == RG_J_M1A || k == RG_J_M1B)
        rg_gimbal_normal(&g->m1, p->j[RG_J_M1A], p->j[RG_J_M1B], n1);
    else v3copy(n1, n1b);
    if (k == RG_J_M2A || k == RG_J_M2B)
        rg_gimbal_normal(&g->m2, p->j[RG_J_M2A], p->j[RG_J_M2B], n2);
    else v3copy(n2, n2b);
    if (rg_forward_nn(g, p, &b, 0, n1, n2) || !isfinite(b.det[0])) return -1;
    double d[3];
    v3sub(d, b.spot, base);
    out[0] = v3dot(d, t1);
    out[1] = v3dot(d, t2);
    v3sub(d, b.det, dbase);
    out[2] = v3dot(d, e1);
    out[3] = v3dot(d, e2);
    return 0;
}

int rg_jacobian(const rg_geometry *g, const rg_pose *p, double *J, double *cond,
                char *err, size_t errcap)
{
    rg_beam b;
    if (rg_forward_beam(g, p, &b) || !isfinite(b.det[0])) {
        snprintf(err, errcap, "the beam of this pose does not reach the detector");
        return RG_EUNREACH;
    }
    double t1[3], t2[3], w[3], e1[3], e2[3], hint[3] = {0, 0, 1}, n1b[3], n2b[3];
    rg_gimbal_normal(&g->m1, p->j[RG_J_M1A], p->j[RG_J_M1B], n1b);
    rg_gimbal_normal(&g->m2, p->j[RG_J_M2A], p->j[RG_J_M2B], n2b);
    v3basis(b.normal, g->p2_u, t1, t2);
    rg_detector_normal(g, w);
    v3basis(w, hint, e1, e2);
    double At[RG_NJOINTS * 4];          /* J^T, scaled: 6 x 4 */
    for (int k = 0; k < RG_NJOINTS; k++) {
        /* forward differences: relative accuracy ~1e-7, plenty for a condition
         * number and for predicting moves; half the forward passes of central ones */
        double h = 1e-7, sp[4];     /* spot moves from the base spot */
        rg_pose q = *p;
        q.j[k] += h;
        if (spot4(g, &q, b.spot, t1, t2, b.det, e1, e2, sp, n1b, n2b, k)) {
            q.j[k] = p->j[k] - h;   /* at an edge: the other side */
            h = -h;
            if (spot4(g, &q, b.spot, t1, t2, b.det, e1, e2, sp, n1b, n2b, k)) {
                snprintf(err, errcap, "the beam leaves the detector within 1e-7 of "
                         "joint %s", rg_joint_name(k));
                return RG_EUNREACH;
            }
        }
        double col2 = 0;
        for (int r = 0; r < 4; r++) {
            J[r * RG_NJOINTS + k] = sp[r] / h;
            col2 += J[r * RG_NJOINTS + k] * J[r * RG_NJOINTS + k];
        }
        double sc = g->joint[k].steps_per > 0 ? 1 / g->joint[k].steps_per
                  : (col2 > 0 ? 1 / sqrt(col2) : 0);
        for (int r = 0; r < 4; r++) At[k * 4 + r] = J[r * RG_NJOINTS + k] * sc;
    }
    if (cond) {
        double V[16], S[4], work[4];
        gsl_matrix_view A = gsl_matrix_view_array(At, RG_NJOINTS, 4);
        gsl_matrix_view Vv = gsl_matrix_view_array(V, 4, 4);
        gsl_vector_view Sv = gsl_vector_view_array(S, 4);
        gsl_vector_view Wv = gsl_vector_view_array(work, 4);
        /* (finite input: the only error SV_decomp can raise is non-convergence) */
        int bad = 0;
        for (int r = 0; r < RG_NJOINTS * 4; r++) bad |= !isfinite(At[r]);
        if (!bad) bad = gsl_linalg_SV_decomp(&A.matrix, &Vv.matrix, &Sv.vector, &Wv.vector);
        *cond = bad ? INFINITY : (S[3] > 0 ? S[0] / S[3] : INFINITY);
    }
    return RG_OK;
}

/* ---- the backward solution ------------------------------------------------------- */
/* The message: what the diagnostics say, and the figures behind them (which joint
 * wants how much of what travel, the angle to p2, the incidences, the condition). */
static void message(const rg_geometry *g, const rg_solution *s, char *err, size_t errcap)
{
    char txt[512];
    size_t l;
    snprintf(err, errcap, "%s", rg_diag_text(s->diag, txt, sizeof txt));
#define ADD(...) do { l = strlen(err); if (l < errcap) snprintf(err + l, errcap - l, __VA_ARGS__); } while (0)
    if (s->diag & RG_D_TRAVEL)
        for (int k = 0; k < RG_NJOINTS; k++) {
            const rg_joint *j = &g->joint[k];
            double u = k == RG_J_U || k == RG_J_V ? 1 : 180 / RG_PI;
            if (j->lo < j->hi && (s->pose.j[k] < j->lo || s->pose.j[k] > j->hi))
                ADD(" (%s needs %.4g, travel %.4g..%.4g %s)", rg_joint_name(k),
                    s->pose.j[k] * u, j->lo * u, j->hi * u, u == 1 ? "mm" : "deg");
        }
    if (s->diag & (RG_D_PARALLEL_P2 | RG_D_NEAR_PARALLEL))
        ADD(" (backward ray %.3g deg from p2)", s->p2_angle * 180 / RG_PI);
    if ((s->diag & RG_D_GRAZING) && isfinite(s->beam.inc1))
        ADD(" (incidence m1 %.3g, m2 %.3g, cornea %.3g deg)", s->beam.inc1 * 180 / RG_PI,
            s->beam.inc2 * 180 / RG_PI, s->beam.inc3 * 180 / RG_PI);
    else if (s->diag & RG_D_GRAZING)
        ADD(" (incidence on the cornea %.3g deg)", s->beam.inc3 * 180 / RG_PI);
    if (s->diag & RG_D_ILLCOND) ADD(" (condition number %.3g)", s->cond);
    if (s->diag & RG_D_TRACE_MISS) ADD(" (by %.3g mm)", s->traced_err);
#undef ADD
}

static int fail_g(const rg_geometry *g, rg_solution *s, unsigned bit, char *err,
                  size_t errcap)
{
    s->diag |= bit;
    message(g, s, err, errcap);
    return (s->diag & RG_D_FATAL) == RG_D_TRAVEL ? RG_ETRAVEL : RG_EUNREACH;
}
#define fail(s, bit, err, cap) fail_g(g, s, bit, err, cap)

int rg_solve(const rg_geometry *g, const rg_target *t, const rg_solve_opts *opts,
             rg_solution *s, char *err, size_t errcap)
{
    rg_solve_opts o;
    rg_opts_fill(opts, &o);
    memset(s, 0, sizeof *s);
    s->cond = NAN;
    s->p2_angle = NAN;
    s->beam.inc1 = s->beam.inc2 = s->beam.inc3 = NAN;
    s->traced_err = NAN;
    int rc = rg_cornea_point(&g->cornea, t, s->target, s->normal, err, errcap);
    if (rc == RG_EUNREACH) { s->diag |= RG_D_OFF_CORNEA; return rc; }
    if (rc) return rc;
    const double *P = s->target, *N = s->normal;

    /* the detector ray and, reflected at the tangent plane, the backward ray */
    double r[3];
    v3sub(r, g->detector, P);
    v3norm(r);
    double ci = v3dot(r, N);
    if (!(ci > 1e-9)) return fail(s, RG_D_DETECTOR_SIDE, err, errcap);
    s->beam.inc3 = acos(fmin(1, ci));
    if (s->beam.inc3 > o.max_incidence) return fail(s, RG_D_GRAZING, err, errcap);
    double *bk = s->back;
    v3scale(bk, N, 2 * ci);
    v3sub(bk, bk, r);
    v3norm(bk);

    /* m2's centre where the backward ray meets p2 */
    double np2[3], rel[3];
    v3cross(np2, g->p2_u, g->p2_v);
    v3norm(np2);
    double den = v3dot(bk, np2);
    s->p2_angle = asin(fmin(1, fabs(den)));
    if (s->p2_angle < o.min_p2_angle) return fail(s, RG_D_PARALLEL_P2, err, errcap);
    if (s->p2_angle < 2 * o.min_p2_angle) s->diag |= RG_D_NEAR_PARALLEL;
    v3sub(rel, g->p2_at, P);
    double tp = v3dot(rel, np2) / den;
    if (!(tp > 0)) return fail(s, RG_D_BEHIND_P2, err, errcap);
    double C2[3], d[3];
    v3axpy(C2, P, tp, bk);
    v3sub(d, C2, g->m2.center);
    double uu = v3dot(g->p2_u, g->p2_u), uv = v3dot(g->p2_u, g->p2_v),
           vv = v3dot(g->p2_v, g->p2_v), du = v3dot(d, g->p2_u), dv = v3dot(d, g->p2_v);
    double gd = uu * vv - uv * uv;
    s->pose.j[RG_J_U] = (du * vv - dv * uv) / gd;
    s->pose.j[RG_J_V] = (dv * uu - du * uv) / gd;

    /* both normals bisecting (out - in) */
    double d12[3], n1[3], n2[3];
    v3sub(d12, C2, g->m1.center);
    v3norm(d12);
    v3sub(n1, d12, g->laser_dir);
    v3scale(n2, bk, -1);
    v3sub(n2, n2, d12);
    if (v3norm(n1) < 1e-9 || v3norm(n2) < 1e-9) return fail(s, RG_D_GRAZING, err, errcap);
    /* mirror surfaces off the axes: the construction repeated until the surfaces
     * sit where the normals put them (rg_aim.c) */
    int offs = g->m1.offset != 0 || g->m2.offset != 0, passes = 0;
    if (offs && !o.newton_only) {
        passes = rg_aim_full(g, P, bk, n1, n2, C2);
        if (passes < 0) return fail(s, RG_D_NO_CONVERGE, err, errcap);
        v3sub(d, C2, g->m2.center);
        du = v3dot(d, g->p2_u);
        dv = v3dot(d, g->p2_v);
        s->pose.j[RG_J_U] = (du * vv - dv * uv) / gd;
        s->pose.j[RG_J_V] = (dv * uu - du * uv) / gd;
    }
    if (rg_gimbal_angles(&g->m1, n1, &s->pose.j[RG_J_M1A], &s->pose.j[RG_J_M1B]) ||
        rg_gimbal_angles(&g->m2, n2, &s->pose.j[RG_J_M2A], &s->pose.j[RG_J_M2B]))
        return fail(s, RG_D_GIMBAL, err, errcap);
    /* and checked on the exact model: Newton takes over if anything is left */
    if (offs) {
        double in[3];
        v3scale(in, bk, -1);
        int it = rg_newton(g, &s->pose, (1u << RG_NJOINTS) - 1, P, in, o.tol,
                           o.max_iter, &s->residual);
        if (it < 0) return fail(s, RG_D_NO_CONVERGE, err, errcap);
        s->iterations = passes + it;
    }

    /* forward through the pose: blocking, apertures, travel, grazing, exactness */
    if (rg_forward_beam(g, &s->pose, &s->beam)) {
        s->diag |= s->beam.diag;
        return fail(s, 0, err, errcap);
    }
    s->diag |= s->beam.diag;
    if (s->beam.inc1 > o.max_incidence || s->beam.inc2 > o.max_incidence)
        s->diag |= RG_D_GRAZING;
    double miss = v3dist(s->beam.spot, P);
    if (isfinite(s->beam.det[0])) miss = fmax(miss, v3dist(s->beam.det, g->detector));
    else miss = INFINITY;
    s->residual = fmax(s->residual, miss);
    if (!o.no_checks) {
        double J[4 * RG_NJOINTS];
        char e2[160];
        if (rg_jacobian(g, &s->pose, J, &s->cond, e2, sizeof e2)) s->cond = INFINITY;
        if (!(s->cond <= o.cond_max)) s->diag |= RG_D_ILLCOND;
    }
    if (o.trace && !(s->diag & RG_D_FATAL)) {
        /* the independent check, when the caller hands us the tracer */
        rg_verify v;
        char e2[256];
        if (rg_verify_pose(o.trace, g, &s->pose, P, &v, e2, sizeof e2)) {
            snprintf(err, errcap, "%s", e2);
            return RG_EIO;
        }
        s->traced_err = v.hit ? fmax(v.err_target, v.err_detector) : INFINITY;
        if (!(s->traced_err <= o.trace_tol)) s->diag |= RG_D_TRACE_MISS;
    }
    if (s->diag & RG_D_FATAL) return fail(s, 0, err, errcap);
    if (s->diag) message(g, s, err, errcap);
    else if (errcap) err[0] = 0;
    return RG_OK;
}

const char *rg_diag_text(unsigned diag, char *buf, size_t cap)
{
    static const char *txt[] = {
        "target off the cornea (past its zone or edge)",
        "detector behind the tangent plane at the target",
        "backward ray (nearly) parallel to p2: m2 cannot be placed",
        "backward ray meets p2 behind the cornea",
        "m2 or its mount blocks the ray to the detector (or the laser)",
        "m1 or its mount blocks the beam",
        "beam lands outside a mirror",
        "grazing incidence on a mirror or the cornea",
        "a mount cannot turn its mirror to the needed normal",
        "a joint is outside its travel",
        "Newton on the exact model did not converge",
        "beam misses the cornea",
        "ill-conditioned pose",
        "backward ray close to parallel to p2",
        "the traced beam misses the target or the detector (a bug)",
    };
    size_t l = 0;
    if (cap) buf[0] = 0;
    for (unsigned i = 0; i < sizeof txt / sizeof *txt; i++)
        if (diag & (1u << i)) {
            int w = snprintf(buf + l, l < cap ? cap - l : 0, "%s%s", l ? "; " : "", txt[i]);
            if (w > 0) l += (size_t)w;
            if (l >= cap) break;
        }
    if (!diag && cap) snprintf(buf, cap, "ok");
    return buf;
}
