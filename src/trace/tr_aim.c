/* tr_aim.c -- real rays aimed at the aperture stop: a sequential prescription with
 * conics and aspheres traced surface by surface in double (the engine's own
 * intersections, tr_geom.c, and Snell law, tr_optics.c; no Embree: one ray at a
 * time, in order), and Newton's method on the ray's stop crossing.
 *
 * Why our own Newton and not GSL's multiroot solvers: the unknowns are two, the
 * Jacobian is a 2x2 by central differences, and a trial ray may miss a surface or be
 * totally reflected -- an evaluation that fails.  GSL's solvers give up on a failed
 * evaluation (GSL_EBADFUNC); here the step is halved until the trial ray traces and
 * the residual falls, which is what brings a wide-angle ray in from a paraxial guess
 * that misses the stop by a large fraction of its size.
 *
 * Folded and tilted systems (ABI 2).  A mirror reflects (d - 2 (d.n) n, the normal of
 * the same conic or asphere a refracting surface uses); z then runs backwards, as
 * OpticStudio's negative thicknesses after a mirror say, so planes and the image
 * plane are crossed forwards or backwards alike.  A coordinate break moves the frame
 * the following surfaces are given in: the ray (point and direction) is taken into
 * the new frame there and traced on in it, so every crossing, the stop target and
 * the image point are in the local frame of their surface.  The new frame's axes are
 * the old ones turned right-handed about x by tilt[0], then about the new y, then
 * the new z (order 0, after the decentre), or about z, new y, new x and then
 * decentred along the turned axes (order 1): order 1 with every value negated undoes
 * an order-0 break exactly (OpticStudio's convention).  Its origin keeps the z the
 * break stands at, so thicknesses run on across it. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "tr_int.h"

typedef struct aim_sys {
    const trace_rx *rx;
    tr_shape *g;               /* one shape per surface, unbounded by clear apertures */
    int *plane;                /* 1: a plane (crossed in closed form, t >= 0 kept) */
    double (*rot)[9];          /* a coordinate break's M (new axes as columns) */
    double scale;              /* the system's size */
} aim_sys;

#define AIM_DEG (3.14159265358979323846 / 180)

/* a = a * (rotation by deg about axis i), both row-major 3x3 */
static void turn(double a[9], int i, double deg)
{
    double c = cos(deg * AIM_DEG), s = sin(deg * AIM_DEG), r[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1},
           o[9];
    int j = (i + 1) % 3, k = (i + 2) % 3;
    if (deg == 0) return;
    r[3 * j + j] = c; r[3 * j + k] = -s;
    r[3 * k + j] = s; r[3 * k + k] = c;
    for (int p = 0; p < 3; p++)
        for (int q = 0; q < 3; q++)
            o[3 * p + q] = a[3 * p] * r[q] + a[3 * p + 1] * r[3 + q] + a[3 * p + 2] * r[6 + q];
    memcpy(a, o, sizeof o);
}

static void break_matrix(const trace_rx_surface *s, double m[9])
{
    static const double id[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    memcpy(m, id, sizeof id);
    if (s->order == 0) for (int i = 0; i < 3; i++) turn(m, i, s->tilt[i]);
    else for (int i = 2; i >= 0; i--) turn(m, i, s->tilt[i]);
}

/* The ray o, d into the frame after break s (matrix m). */
static void break_apply(const trace_rx_surface *s, const double m[9], double o[3],
                        double d[3])
{
    double p[3] = {o[0], o[1], o[2] - s->z}, q[3], e[3];
    if (s->order == 0) { p[0] -= s->decenter[0]; p[1] -= s->decenter[1]; }
    for (int i = 0; i < 3; i++) {            /* M^T p, M^T d */
        q[i] = m[i] * p[0] + m[3 + i] * p[1] + m[6 + i] * p[2];
        e[i] = m[i] * d[0] + m[3 + i] * d[1] + m[6 + i] * d[2];
    }
    if (s->order != 0) { q[0] -= s->decenter[0]; q[1] -= s->decenter[1]; }
    o[0] = q[0]; o[1] = q[1]; o[2] = q[2] + s->z;
    v_set(d, e);
}

static int is_plane(const trace_rx_surface *s)
{
    return (s->radius == 0 || isinf(s->radius)) && s->nasph == 0;
}

static int check_rx(const trace_rx *rx, char *err, size_t cap)
{
    if (!rx || rx->nsurf < 1 || !rx->surf) {
        tr_set_err(err, cap, "a prescription needs at least one surface");
        return -1;
    }
    if (!(rx->n_object > 0) || !isfinite(rx->n_object)) {
        tr_set_err(err, cap, "the object medium's index must be a positive number");
        return -1;
    }
    if (rx->stop < 0 || rx->stop >= rx->nsurf) {
        tr_set_err(err, cap, "the stop (%d) is not one of the %d surfaces", rx->stop + 1,
                   rx->nsurf);
        return -1;
    }
    if (!(rx->stop_radius >= 0) || !isfinite(rx->stop_radius)) {
        tr_set_err(err, cap, "the stop's semi-diameter must be a number >= 0");
        return -1;
    }
    int folded = 0;
    for (int i = 0; i < rx->nsurf; i++) folded |= rx->surf[i].mirror || rx->surf[i].coordbrk;
    for (int i = 0; i < rx->nsurf; i++) {
        const trace_rx_surface *s = &rx->surf[i];
        if (s->coordbrk) {
            if (!isfinite(s->z) || !isfinite(s->decenter[0]) || !isfinite(s->decenter[1]) ||
                !isfinite(s->tilt[0]) || !isfinite(s->tilt[1]) || !isfinite(s->tilt[2]) ||
                (s->order != 0 && s->order != 1) || s->mirror) {
                tr_set_err(err, cap, "surface %d: a coordinate break needs a finite "
                           "position, decentres and tilts, order 0 or 1, and no mirror",
                           i + 1);
                return -1;
            }
            if (i == rx->stop) {
                tr_set_err(err, cap, "surface %d: a coordinate break cannot be the stop",
                           i + 1);
                return -1;
            }
            if (!(s->n_right > 0 && isfinite(s->n_right))) {
                tr_set_err(err, cap, "surface %d: bad index", i + 1);
                return -1;
            }
            continue;
        }
        if (!isfinite(s->z) || isnan(s->radius) || !isfinite(s->conic) ||
            !(s->n_right > 0 && isfinite(s->n_right)) || s->nasph < 0 ||
            s->nasph > TRACE_MAXASPH || !(s->semi_diameter >= 0) ||
            !isfinite(s->semi_diameter)) {
            tr_set_err(err, cap, "surface %d: bad position, radius, conic, index, "
                       "aspheric terms or semi-diameter", i + 1);
            return -1;
        }
        /* folded or tilted: z may run backwards (a ray that cannot go on misses) */
        if (!folded && i && s->z < rx->surf[i - 1].z) {
            tr_set_err(err, cap, "surface %d lies left of surface %d", i + 1, i);
            return -1;
        }
    }
    return 0;
}

static void sys_free(aim_sys *a)
{
    free(a->g);
    free(a->plane);
    free(a->rot);
}

static int sys_init(aim_sys *a, const trace_rx *rx, char *err, size_t cap)
{
    memset(a, 0, sizeof *a);
    if (check_rx(rx, err, cap)) return -1;
    a->rx = rx;
    a->scale = fabs(rx->surf[rx->nsurf - 1].z - rx->surf[0].z);
    for (int i = 0; i < rx->nsurf; i++) {
        const trace_rx_surface *s = &rx->surf[i];
        if (isfinite(s->radius)) a->scale = fmax(a->scale, fabs(s->radius));
        a->scale = fmax(a->scale, s->semi_diameter);
    }
    a->scale = fmax(fmax(a->scale, rx->stop_radius), 1e-3);
    a->g = calloc((size_t)rx->nsurf, sizeof *a->g);
    a->plane = calloc((size_t)rx->nsurf, sizeof *a->plane);
    a->rot = calloc((size_t)rx->nsurf, sizeof *a->rot);
    if (!a->g || !a->plane || !a->rot) {
        sys_free(a);
        tr_set_err(err, cap, "out of memory");
        return -1;
    }
    for (int i = 0; i < rx->nsurf; i++) {
        const trace_rx_surface *rs = &rx->surf[i];
        trace_surface s;
        char e[200];
        if (rs->coordbrk) {
            break_matrix(rs, a->rot[i]);
            continue;
        }
        memset(&s, 0, sizeof s);
        s.shape = TRACE_AXIAL;
        s.at[2] = rs->z;
        s.axis[2] = 1;
        s.radius = isfinite(rs->radius) ? rs->radius : 0;
        s.conic = rs->conic;
        s.nasph = rs->nasph;
        memcpy(s.asph, rs->asph, sizeof s.asph);
        s.aperture = TRACE_AP_DISC;
        /* spheres and ellipsoids reach their own limit; the rest get a generous bound
         * (clear apertures are checked apart, after aiming) */
        if (s.radius == 0 || rs->conic <= -1 || rs->nasph)
            s.r_outer = fmax(10 * a->scale, 4 * rs->semi_diameter);
        if (s.radius != 0 && rs->conic > -1 && s.r_outer > 0) {
            double lim = fabs(s.radius) / sqrt(1 + rs->conic);
            if (s.r_outer > lim) s.r_outer = lim;
        }
        if (tr_shape_init(&a->g[i], &s, e, sizeof e)) {
            tr_set_err(err, cap, "surface %d: %s", i + 1, e);
            sys_free(a);
            return -1;
        }
        a->plane[i] = is_plane(rs);
    }
    return 0;
}

/* Trace o, d through the surfaces in order.  check_ap: clear apertures count;
 * to_image: carry on to z_image.  Fills out (status, surface, stop, img, opl). */
static int run_ray(const aim_sys *a, const double o0[3], const double d0[3], int check_ap,
                   int to_image, double *pts, trace_aim_ray *out)
{
    const trace_rx *rx = a->rx;
    double o[3], d[3], n = rx->n_object, opl = 0;
    v_set(o, o0);
    v_set(d, d0);
    out->surface = -1;
    out->img[0] = out->img[1] = out->img[2] = NAN;
    for (int k = 0; k < rx->nsurf; k++) {
        const trace_rx_surface *s = &rx->surf[k];
        const tr_shape *g = &a->g[k];
        double t, p[3], q[3], nrm[3], dn[3];
        if (s->coordbrk) {                   /* the ray into the new frame */
            break_apply(s, a->rot[k], o, d);
            if (pts) v_set(pts + 3 * k, o);
            n = s->n_right;
            continue;
        }
        if (a->plane[k]) {
            if (d[2] == 0) { out->surface = k; return out->status = TRACE_AIM_MISSED; }
            t = (s->z - o[2]) / d[2];
            if (t < 0) {
                if (t < -1e-12 * a->scale) {
                    out->surface = k;
                    return out->status = TRACE_AIM_MISSED;
                }
                t = 0;
            }
            q[0] = o[0] + t * d[0];
            q[1] = o[1] + t * d[1];
            q[2] = s->z;
            nrm[0] = nrm[1] = 0;
            nrm[2] = 1;
        } else {
            int h = tr_shape_hit_t(g, o, d, 0, &t, p);
            if (!h) { out->surface = k; return out->status = TRACE_AIM_MISSED; }
            if (h == 2) tr_shape_world(g, p, q);
            else for (int j = 0; j < 3; j++) q[j] = o[j] + t * d[j];
            tr_shape_hit_normal(g, p, nrm);
        }
        if (check_ap && s->semi_diameter > 0 &&
            hypot(q[0], q[1]) > s->semi_diameter * (1 + 1e-12)) {
            out->surface = k;
            return out->status = TRACE_AIM_VIGNETTED;
        }
        if (pts) v_set(pts + 3 * k, q);
        if (k == rx->stop) v_set(out->stop, q);
        opl += n * t;
        if (s->mirror) {                     /* law of reflection */
            double dd = v_dot(d, nrm);
            for (int j = 0; j < 3; j++) dn[j] = d[j] - 2 * dd * nrm[j];
            v_unit(dn);
        } else if (!tr_refract(d, nrm, n, s->n_right, dn)) {
            out->surface = k;
            return out->status = TRACE_AIM_TIR;
        }
        v_set(d, dn);
        v_set(o, q);
        n = s->n_right;
    }
    v_set(out->img_dir, d);
    if (to_image && isfinite(rx->z_image)) {
        if (d[2] == 0) { out->surface = rx->nsurf; return out->status = TRACE_AIM_MISSED; }
        double t = (rx->z_image - o[2]) / d[2];
        for (int j = 0; j < 3; j++) out->img[j] = o[j] + t * d[j];
        opl += n * t;
    }
    out->opl = opl;
    return out->status = TRACE_AIM_OK;
}

static int check_req(const aim_sys *a, const trace_aim_req *rq, char *err, size_t cap)
{
    if (!rq || !isfinite(rq->px) || !isfinite(rq->py) || !isfinite(rq->guess[0]) ||
        !isfinite(rq->guess[1]) || !(rq->tol >= 0) || rq->max_iter < 0) {
        tr_set_err(err, cap, "the pupil coordinates, guess or tolerance are not numbers");
        return -1;
    }
    if (rq->infinite) {
        double dl = v_norm(rq->dir);
        if (!(dl > 0) || !isfinite(dl) || !(rq->dir[2] > 0) || !isfinite(rq->z_ref)) {
            tr_set_err(err, cap, "a beam from infinity needs a direction with dz > 0 and "
                       "a reference plane");
            return -1;
        }
    } else {
        if (!isfinite(rq->obj[0]) || !isfinite(rq->obj[1]) || !isfinite(rq->obj[2]) ||
            !(rq->obj[2] < a->rx->surf[0].z)) {
            tr_set_err(err, cap, "the object point must lie left of the first surface");
            return -1;
        }
    }
    return 0;
}

/* The ray of the unknowns v: origin o (where the trace starts) and direction d; q is
 * what the result reports as its origin (the object, or the crossing of z_ref). */
static void make_ray(const aim_sys *a, const trace_aim_req *rq, const double v[2],
                     double o[3], double d[3], double q[3])
{
    if (rq->infinite) {
        /* start left of the first surface; behind leading breaks the first surface
         * is turned and may reach back past the breaks' z by its own depth and up to
         * its size times the sine of the turn (the path counts from z_ref whatever the
         * start, but a start far back costs rounding in the stop residual) */
        const trace_rx *rx = a->rx;
        double z0;
        if (rx->surf[0].coordbrk) {
            double turn = 0;
            int k = 0;
            while (k + 1 < rx->nsurf && rx->surf[k].coordbrk) {
                turn += fabs(rx->surf[k].tilt[0]) + fabs(rx->surf[k].tilt[1]);
                k++;
            }
            double back = rx->surf[k].coordbrk ? 0 : fmax(0, rx->surf[k].z - a->g[k].lo[2]);
            back += a->scale * sin(fmin(turn, 90) * AIM_DEG);
            z0 = fmin(rq->z_ref, fmin(rx->surf[0].z, rx->surf[k].z) - back) - 1e-3 * a->scale;
        } else {
            z0 = fmin(rq->z_ref, a->g[0].lo[2]) - 1e-3 * a->scale;
        }
        v_set(d, rq->dir);
        v_unit(d);
        q[0] = v[0]; q[1] = v[1]; q[2] = rq->z_ref;
        double t = (z0 - rq->z_ref) / d[2];
        for (int j = 0; j < 3; j++) o[j] = q[j] + t * d[j];
    } else {
        d[0] = v[0]; d[1] = v[1]; d[2] = 1;
        v_unit(d);
        v_set(o, rq->obj);
        v_set(q, rq->obj);
    }
}

typedef struct aim_eval {
    const aim_sys *a;
    const trace_aim_req *rq;
    double target[2];
    int traces;
    trace_aim_ray last;
} aim_eval;

/* F(v) = stop crossing - target; the ray's status. */
static int eval(aim_eval *e, const double v[2], double f[2])
{
    double o[3], d[3], q[3];
    make_ray(e->a, e->rq, v, o, d, q);
    e->traces++;
    int st = run_ray(e->a, o, d, 0, 0, NULL, &e->last);
    if (st != TRACE_AIM_OK) return st;
    f[0] = e->last.stop[0] - e->target[0];
    f[1] = e->last.stop[1] - e->target[1];
    return isfinite(f[0]) && isfinite(f[1]) ? TRACE_AIM_OK : TRACE_AIM_MISSED;
}

/* Jacobian column i by central differences (one-sided where a side fails). */
static int column(aim_eval *e, const double v[2], const double f[2], int i, double h,
                  double col[2])
{
    double vp[2] = {v[0], v[1]}, vm[2] = {v[0], v[1]}, fp[2], fm[2];
    vp[i] += h;
    vm[i] -= h;
    int sp = eval(e, vp, fp), sm = eval(e, vm, fm);
    if (sp == TRACE_AIM_OK && sm == TRACE_AIM_OK) {
        col[0] = (fp[0] - fm[0]) / (2 * h);
        col[1] = (fp[1] - fm[1]) / (2 * h);
    } else if (sp == TRACE_AIM_OK) {
        col[0] = (fp[0] - f[0]) / h;
        col[1] = (fp[1] - f[1]) / h;
    } else if (sm == TRACE_AIM_OK) {
        col[0] = (f[0] - fm[0]) / h;
        col[1] = (f[1] - fm[1]) / h;
    } else {
        return sp;
    }
    return TRACE_AIM_OK;
}

int tr_rx_trace(const trace_rx *rx, const double o[3], const double d[3],
                       double *pts, trace_aim_ray *out, char *err, size_t cap)
{
    aim_sys a;
    double dd[3];
    if (!out || !o || !d) {
        tr_set_err(err, cap, "no ray or no result");
        return TRACE_EINVAL;
    }
    memset(out, 0, sizeof *out);
    if (sys_init(&a, rx, err, cap)) return TRACE_EINVAL;
    v_set(dd, d);
    if (!isfinite(o[0]) || !isfinite(o[1]) || !isfinite(o[2]) || v_unit(dd)) {
        sys_free(&a);
        tr_set_err(err, cap, "the ray's origin or direction is not finite");
        return TRACE_EINVAL;
    }
    v_set(out->o, o);
    v_set(out->d, dd);
    run_ray(&a, o, dd, 1, 1, pts, out);
    out->traces = 1;
    sys_free(&a);
    return TRACE_OK;
}

int tr_rx_aim(const trace_rx *rx, const trace_aim_req *rq, trace_aim_ray *out,
                     char *err, size_t cap)
{
    aim_sys a;
    aim_eval e;
    double v[2], f[2], r, tol, fine, vscale;
    int st, maxit;
    if (!out) {
        tr_set_err(err, cap, "no result");
        return TRACE_EINVAL;
    }
    memset(out, 0, sizeof *out);
    out->surface = -1;
    if (sys_init(&a, rx, err, cap)) return TRACE_EINVAL;
    if (check_req(&a, rq, err, cap)) {
        sys_free(&a);
        return TRACE_EINVAL;
    }
    memset(&e, 0, sizeof e);
    e.a = &a;
    e.rq = rq;
    e.target[0] = rq->px * rx->stop_radius;
    e.target[1] = rq->py * rx->stop_radius;
    tol = rq->tol > 0 ? rq->tol : 1e-10 * fmax(1, rx->stop_radius);
    /* the residual rounding leaves: a few ulps of the stop's coordinates */
    fine = 8 * DBL_EPSILON * (fmax(fabs(e.target[0]), fabs(e.target[1])) +
                              fabs(rx->surf[rx->stop].z) + rx->stop_radius);
    maxit = rq->max_iter ? rq->max_iter : 40;
    v[0] = rq->guess[0];
    v[1] = rq->guess[1];
    if (rq->infinite) vscale = fmax(rx->stop_radius, 1e-6 * a.scale);
    else vscale = fmax(rx->stop_radius, 1e-6 * a.scale) /
                  fmax(rx->surf[rx->stop].z - rq->obj[2], 1e-6 * a.scale);
    st = eval(&e, v, f);
    if (st != TRACE_AIM_OK) {           /* the paraxial guess itself does not trace */
        out->status = st;
        out->surface = e.last.surface;
        out->traces = e.traces;
        out->residual = INFINITY;
        sys_free(&a);
        return TRACE_OK;
    }
    r = hypot(f[0], f[1]);
    while (r > fine && out->iterations < maxit) {
        double J[2][2], c0[2], c1[2], det, dv[2], lam = 1;
        double h0 = 1e-7 * fmax(fabs(v[0]), vscale), h1 = 1e-7 * fmax(fabs(v[1]), vscale);
        if (column(&e, v, f, 0, h0, c0) != TRACE_AIM_OK ||
            column(&e, v, f, 1, h1, c1) != TRACE_AIM_OK)
            break;
        J[0][0] = c0[0]; J[1][0] = c0[1]; J[0][1] = c1[0]; J[1][1] = c1[1];
        det = J[0][0] * J[1][1] - J[0][1] * J[1][0];
        if (!(fabs(det) > 0) || !isfinite(det)) break;
        dv[0] = -(J[1][1] * f[0] - J[0][1] * f[1]) / det;
        dv[1] = -(-J[1][0] * f[0] + J[0][0] * f[1]) / det;
        int took = 0;
        for (int halve = 0; halve < 40; halve++, lam *= 0.5) {
            double vt[2] = {v[0] + lam * dv[0], v[1] + lam * dv[1]}, ft[2];
            if (eval(&e, vt, ft) != TRACE_AIM_OK) continue;
            double rt = hypot(ft[0], ft[1]);
            if (rt < r) {
                v[0] = vt[0]; v[1] = vt[1]; f[0] = ft[0]; f[1] = ft[1]; r = rt;
                took = 1;
                break;
            }
        }
        if (!took) break;               /* no step lowers the residual: rounding */
        out->iterations++;
    }
    out->residual = r;
    out->v[0] = v[0];
    out->v[1] = v[1];
    {
        double o[3], d[3], q[3];
        make_ray(&a, rq, v, o, d, q);
        e.traces++;
        run_ray(&a, o, d, 1, 1, NULL, out);
        v_set(out->o, q);
        v_set(out->d, d);
        if (rq->infinite)                /* the path counts from the z_ref plane */
            out->opl -= rx->n_object * (rq->z_ref - o[2]) / d[2];
    }
    out->traces = e.traces;
    if (out->status == TRACE_AIM_OK && !(r <= tol)) out->status = TRACE_AIM_NOCONV;
    sys_free(&a);
    return TRACE_OK;
}
