/* ds_merit.c -- the merit function: every operand's value for the lens as it is now
 * (first order by the paraxial engine per wavelength, real rays aimed at the stop by
 * the trace engine's rx_aim) and the residual vector damped least squares works on.
 *
 * MF^2 = sum_i w_i (v_i - t_i)^2 / sum_i w_i (OpticStudio's definition; a bound
 * counts only when violated).  An RMS spot operand with target 0 enters as its rays:
 * one residual per ray and coordinate, sqrt(w_i q_k / W) (x_k - x_c), whose squares
 * sum to w_i RMS^2 / W -- the same merit, but a Jacobian with a row per ray, which is
 * what makes the least squares converge like OpticStudio's TRAC operands.
 *
 * Pupil sampling (Forbes' Gaussian quadrature, as OpticStudio's default merit): R
 * rings at rho_i = sqrt(u_i), u_i the Gauss-Legendre nodes of (0, 1) in rho^2 (so the
 * rings are exact for polynomials up to rho^(4R-2)), A arms at angles (j + 1/2) 2pi/A
 * from +y; weights w_i / A.  For a field in the y-z plane the pupil's x > 0 half is
 * traced and mirrored when the rx is symmetric under x -> -x (ds_problem.xsym: no break
 * decentres in x or turns about y or z).  The set-up of the lens (pupils, rx, folded
 * and perturbed) is ds_setup.c's. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "ds_int.h"

#define DEG (3.14159265358979323846 / 180)

static int aim_from(const ds_problem *p, const ds_wl *w, const ln_field *f, double px,
                    double py, const double *g, trace_aim_ray *out);

/* Slot of pupil point `pt` (rings * arms: the chief ray) of field fi at w. */
static long slot(const ds_problem *p, const ds_wl *w, int fi, int pt)
{
    int nwl = p->lens.nwl ? p->lens.nwl : 1;
    return ((long)fi * nwl + w->index) * (p->rings * p->arms + 1) + pt;
}

/* Aim one ray; while optimising, from the solution the same ray had at the last
 * evaluation (the lens moved little: one Newton step instead of three or four), and
 * from the paraxial guess again if that fails. */
static int aim_at(ds_problem *p, const ds_wl *w, int fi, int pt, double px, double py,
                  trace_aim_ray *out)
{
    const ln_field *f = &p->lens.field[fi];
    long k = slot(p, w, fi, pt);
    int warm = p->warm && !p->aim_paraxial && k >= 0 && (size_t)k < p->nguess;
    if (warm && p->gok[k] && aim_from(p, w, f, px, py, p->guess + 2 * k, out) == 0) {
        p->guess[2 * k] = out->v[0];
        p->guess[2 * k + 1] = out->v[1];
        return 0;
    }
    int rc = aim_from(p, w, f, px, py, NULL, out);
    if (warm) {
        p->gok[k] = rc == 0;
        if (rc == 0) { p->guess[2 * k] = out->v[0]; p->guess[2 * k + 1] = out->v[1]; }
    }
    return rc;
}

static int aim_from(const ds_problem *p, const ds_wl *w, const ln_field *f, double px,
                    double py, const double *g, trace_aim_ray *out)
{
    const px_pupil *pp = &w->p;
    trace_aim_req rq;
    char err[256];
    memset(&rq, 0, sizeof rq);
    rq.px = px;
    rq.py = py;
    if (isinf(p->lens.object)) {
        double tx = tan(f->x * DEG), ty = tan(f->y * DEG), n = sqrt(tx * tx + ty * ty + 1);
        rq.infinite = 1;
        rq.dir[0] = tx / n; rq.dir[1] = ty / n; rq.dir[2] = 1 / n;
        rq.guess[0] = tx * pp->yb[0] + px * pp->y[0] * w->s;
        rq.guess[1] = ty * pp->yb[0] + py * pp->y[0] * w->s;
    } else {
        rq.obj[0] = f->x; rq.obj[1] = f->y; rq.obj[2] = -p->lens.object;
        rq.guess[0] = f->x * pp->ub[0] + px * pp->u[0] * w->s;
        rq.guess[1] = f->y * pp->ub[0] + py * pp->u[0] * w->s;
    }
    if (p->aim_paraxial) {
        /* OpticStudio's "ray aiming off": straight at the paraxial entrance pupil */
        double o[3], d[3], e[3] = {px * pp->r_ep * w->s, py * pp->r_ep * w->s, pp->z_ep};
        if (!isfinite(pp->z_ep)) return -1;
        if (rq.infinite) {
            double t = (fmin(e[2], 0) - 1 - e[2]) / rq.dir[2];
            for (int k = 0; k < 3; k++) { d[k] = rq.dir[k]; o[k] = e[k] + t * d[k]; }
        } else {
            double L = 0;
            for (int k = 0; k < 3; k++) { o[k] = rq.obj[k]; d[k] = e[k] - o[k]; L += d[k] * d[k]; }
            L = sqrt(L);
            for (int k = 0; k < 3; k++) d[k] /= L;
        }
        if (p->tr->rx_trace(&w->rx, o, d, NULL, out, err, sizeof err) != TRACE_OK) return -1;
        return out->status == TRACE_AIM_OK ? 0 : -1;
    }
    if (g) { rq.guess[0] = g[0]; rq.guess[1] = g[1]; }
    if (p->tr->rx_aim(&w->rx, &rq, out, err, sizeof err) != TRACE_OK) return -1;
    return out->status == TRACE_AIM_OK ? 0 : -1;
}

int ds_field_rays(ds_problem *p, ds_wl *w, int nwl, int fi, double z_image, double *pts,
                  double *dirs, double *wt, int cap)
{
    const ln_lens *l = &p->lens;
    const ln_field *f = &l->field[fi];
    int sym = f->x == 0 && p->xsym, n = 0, fails = 0;
    double wsum = 0;
    for (int k = 0; k < nwl; k++) wsum += l->nwl ? l->wl_weight[k] : 1;
    for (int k = 0; k < nwl; k++) {
        double wk = (l->nwl ? l->wl_weight[k] : 1) / wsum;
        w[k].rx.z_image = z_image;
        for (int i = 0; i < p->rings; i++)
            for (int j = 0; j < p->arms; j++) {
                double a = (j + 0.5) * 2 * 3.14159265358979323846 / p->arms, rho = sqrt(p->ru[i]);
                double px = rho * sin(a), py = rho * cos(a), q = wk * p->rw[i] / p->arms;
                trace_aim_ray r;
                if (sym && px < 0) continue;
                if (n + 2 > cap) return -1;
                if (aim_at(p, &w[k], fi, i * p->arms + j, px, py, &r)) {
                    fails++;
                    continue;
                }
                pts[2 * n] = r.img[0]; pts[2 * n + 1] = r.img[1];
                if (dirs) {
                    dirs[2 * n] = r.img_dir[0] / r.img_dir[2];
                    dirs[2 * n + 1] = r.img_dir[1] / r.img_dir[2];
                }
                wt[n++] = q;
                if (sym) {                     /* the mirror image x -> -x */
                    pts[2 * n] = -r.img[0]; pts[2 * n + 1] = r.img[1];
                    if (dirs) {
                        dirs[2 * n] = -dirs[2 * n - 2];
                        dirs[2 * n + 1] = dirs[2 * n - 1];
                    }
                    wt[n++] = q;
                }
            }
        if (p->stop && p->stop(p->stop_ctx)) { p->stopped = 1; return -2; }
    }
    return fails ? -1 : n;
}

int ds_chief(ds_problem *p, ds_wl *w, int fi, double z_image, double pt[2], double sl[2])
{
    trace_aim_ray r;
    w->rx.z_image = z_image;
    if (aim_at(p, w, fi, p->rings * p->arms, 0, 0, &r) || r.img_dir[2] == 0) return -1;
    pt[0] = r.img[0];
    pt[1] = r.img[1];
    sl[0] = r.img_dir[0] / r.img_dir[2];
    sl[1] = r.img_dir[1] / r.img_dir[2];
    return 0;
}

static double unit_mm(const char *u)
{
    return !strcmp(u, "cm") ? 10 : !strcmp(u, "m") ? 1000 : !strcmp(u, "in") ? 25.4 : 1;
}

/* The optical path of ray r to the reference sphere (centre c, radius R; sign: which
 * of its two crossings), counted from the object point, or for an object at infinity
 * from the incoming plane wavefront through the origin (Welford's W, as --pupil). */
static double sphere_path(const trace_aim_ray *r, int inf, double n0, double ni,
                          const double c[3], double R, double sign)
{
    double o = r->opl, pc[3], b, cc, disc;
    if (inf) o += n0 * (r->o[0] * r->d[0] + r->o[1] * r->d[1] + r->o[2] * r->d[2]);
    for (int k = 0; k < 3; k++) pc[k] = r->img[k] - c[k];
    b = r->img_dir[0] * pc[0] + r->img_dir[1] * pc[1] + r->img_dir[2] * pc[2];
    cc = pc[0] * pc[0] + pc[1] * pc[1] + pc[2] * pc[2] - R * R;
    disc = b * b - cc;
    if (disc < 0) return NAN;
    return o - ni * (b + sign * sqrt(disc));
}

int ds_field_wave(ds_problem *p, ds_wl *w, int nwl, int fi, double z_image, double *wv,
                  double *wt, int cap)
{
    const ln_lens *l = &p->lens;
    const ln_field *f = &l->field[fi];
    int sym = f->x == 0 && p->xsym, n = 0, inf = isinf(l->object);
    double wsum = 0, um = 1e-3 / unit_mm(l->unit);
    for (int k = 0; k < nwl; k++) wsum += l->nwl ? l->wl_weight[k] : 1;
    for (int k = 0; k < nwl; k++) {
        ds_wl *x = &w[k];
        trace_aim_ray ch, r;
        double wk = (l->nwl ? l->wl_weight[k] : 1) / wsum, lam = x->lambda * um;
        x->rx.z_image = z_image;
        if (aim_at(p, x, fi, p->rings * p->arms, 0, 0, &ch) || !isfinite(x->p.z_xp) ||
            ch.img_dir[2] == 0)
            return -1;
        /* the sphere: centred on the chief ray's image point, through its crossing of
         * the paraxial exit pupil's plane (the unfolded z taken into the folded frame;
         * after odd mirrors the rays run -z and t keeps its meaning) */
        double zxp = x->zl + x->sig * (x->p.z_xp - x->zl_u);
        double t = (zxp - ch.img[2]) / ch.img_dir[2], R = fabs(t), sign = t < 0 ? 1 : -1;
        double n0 = x->n[0], ni = x->n[l->nsurf];
        if (!(R > 0)) return -1;
        double w0 = sphere_path(&ch, inf, n0, ni, ch.img, R, sign);
        for (int i = 0; i < p->rings; i++)
            for (int j = 0; j < p->arms; j++) {
                double a = (j + 0.5) * 2 * 3.14159265358979323846 / p->arms, rho = sqrt(p->ru[i]);
                double px = rho * sin(a), py = rho * cos(a), q = wk * p->rw[i] / p->arms;
                if (sym && px < 0) continue;
                if (n + 2 > cap) return -1;
                if (aim_at(p, x, fi, i * p->arms + j, px, py, &r)) return -1;
                double v = (w0 - sphere_path(&r, inf, n0, ni, ch.img, R, sign)) / lam;
                if (!isfinite(v)) return -1;
                wv[n] = v;
                wt[n++] = q;
                if (sym) { wv[n] = v; wt[n++] = q; }
            }
        if (p->stop && p->stop(p->stop_ctx)) { p->stopped = 1; return -2; }
    }
    return n;
}

/* Distance of (vd/100, nd) outside the glass map (0 inside). */
static double outside_hull(const ds_problem *p, double nd, double vd)
{
    double x = vd / 100, y = nd, best = INFINITY;
    int inside = p->nhull >= 3;
    for (int i = 0; i < p->nhull; i++) {
        const double *a = p->hull + 2 * i, *b = p->hull + 2 * ((i + 1) % p->nhull);
        double ex = b[0] - a[0], ey = b[1] - a[1], L2 = ex * ex + ey * ey;
        double t = L2 > 0 ? ((x - a[0]) * ex + (y - a[1]) * ey) / L2 : 0;
        if (ex * (y - a[1]) - ey * (x - a[0]) < 0) inside = 0;
        t = t < 0 ? 0 : t > 1 ? 1 : t;
        double dx = x - a[0] - t * ex, dy = y - a[1] - t * ey;
        best = fmin(best, sqrt(dx * dx + dy * dy));
    }
    return inside || !isfinite(best) ? 0 : best;
}

static int op_nwl(const ds_problem *p, const ds_op *o)
{
    int nwl = p->lens.nwl ? p->lens.nwl : 1;
    return o->wave < 0 ? nwl : 1;
}

/* Residuals an operand contributes: a ray-expanded RMS (target 0) 2 per ray. */
static long op_nres(const ds_problem *p, const ds_op *o)
{
    if (o->kind == DO_RMS && o->bound == 0 && o->target == 0)
        return 2L * p->rings * p->arms * op_nwl(p, o);
    if (o->kind == DO_RMSW && o->bound == 0 && o->target == 0)
        return (long)p->rings * p->arms * op_nwl(p, o);
    return 1;
}

long ds_nres(const ds_problem *p)
{
    long n = 0;
    for (int i = 0; i < p->nop; i++) n += op_nres(p, &p->op[i]);
    return n;
}

double ds_merit_of(const ds_problem *p, const double *f)
{
    long n = ds_nres(p);
    double s = 0;
    (void)p;
    for (long i = 0; i < n; i++) s += f[i] * f[i];
    return sqrt(s);
}

static double scalar_res(const ds_op *o)
{
    double d = o->value - o->target;
    if (o->bound > 0) return d < 0 ? d : 0;
    if (o->bound < 0) return d > 0 ? d : 0;
    return d;
}

int ds_eval(ds_problem *p, double *f, char *why, size_t cap)
{
    const ln_lens *l = &p->lens;
    int nwl = l->nwl ? l->nwl : 1;
    static _Thread_local ds_wl w[LN_WL_MAX];
    double W = 0, zi, zlast, fmax_deg = 0;
    long at = 0;
    p->evals++;
    if (ds_setup(p, l, w, nwl, why, cap)) return -1;
    zi = ds_image_z(l, &w[0]);
    if (!isfinite(zi)) { snprintf(why, cap, "the lens forms no image"); return -1; }
    zlast = w[0].zl_u;                     /* back focus: along the unfolded axis */
    for (int i = 0; i < l->nfield; i++) fmax_deg = fmax(fmax_deg, hypot(l->field[i].x, l->field[i].y));
    for (int i = 0; i < p->nop; i++) W += p->op[i].weight;
    if (!(W > 0)) W = 1;
    for (int i = 0; i < p->nop; i++) {
        ds_op *o = &p->op[i];
        double sw = sqrt(o->weight / W);
        switch (o->kind) {
        case DO_EFL: o->value = w[0].p.efl; break;
        case DO_BFD: o->value = w[0].p.z_img - zlast; break;
        case DO_TOTR: o->value = zi; break;
        case DO_CT: o->value = l->surf[o->surf].t; break;
        case DO_ET: {
            const ln_surface *a = &l->surf[o->surf], *b = &l->surf[o->surf + 1];
            double h = fmax(a->semi, b->semi);
            o->value = a->t + ln_sag(b, h) - ln_sag(a, h);
            if (!isfinite(o->value)) o->value = -1e3;   /* the conic has no point there */
            break;
        }
        case DO_AXCL: {
            int ks = 0, kl = 0;
            for (int k = 1; k < nwl; k++) {
                if (w[k].lambda < w[ks].lambda) ks = k;
                if (w[k].lambda > w[kl].lambda) kl = k;
            }
            o->value = w[ks].p.z_img - w[kl].p.z_img;
            break;
        }
        case DO_SPHA: case DO_COMA: case DO_ASTI: case DO_FCUR: case DO_SDIS:
        case DO_LACL: {
            /* Welford's Seidel sums (paraxial engine), marginal ray at the entrance
             * pupil's rim, chief ray at the largest field through the stop's centre */
            px_seidel sd;
            if (!isinf(l->object)) { snprintf(why, cap, "the Seidel operands need the object at infinity"); return -1; }
            if (px_seidel_run_stop(w[0].cs, w[0].nu, w[0].names[0], w[0].p.r_ep,
                                   tan(fmax(fmax_deg, 1) * DEG), w[0].stop_u, &sd) != PX_OK) {
                snprintf(why, cap, "the Seidel sums cannot be formed");
                return -1;
            }
            const px_seidel_sums *t = &sd.total;
            o->value = o->kind == DO_SPHA ? t->s1 : o->kind == DO_COMA ? t->s2 :
                       o->kind == DO_ASTI ? t->s3 : o->kind == DO_FCUR ? t->s4 :
                       o->kind == DO_SDIS ? t->s5 : t->c2;
            break;
        }
        case DO_GMAP: {
            double nd = 0, vd = 0;
            sscanf(l->surf[o->surf].glass, "%lf/%lf", &nd, &vd);
            o->value = outside_hull(p, nd, vd);
            break;
        }
        case DO_DIST: {
            const ln_field *fl = &l->field[o->field];
            trace_aim_ray r;
            const px_pupil *pp = &w[0].p;
            double fx = isinf(l->object) ? tan(fl->x * DEG) : fl->x;
            double fy = isinf(l->object) ? tan(fl->y * DEG) : fl->y;
            int N = w[0].nu - 1;
            double zu = w[0].zl_u + w[0].sig * (zi - w[0].zl);   /* the image, unfolded */
            double unit = pp->yb[N] + pp->ub[N + 1] * (zu - pp->z[N]);
            double rp = hypot(fx * unit, fy * unit);
            w[0].rx.z_image = zi;
            if (aim_at(p, &w[0], o->field, p->rings * p->arms, 0, 0, &r)) o->value = 100;
            else o->value = rp > 0 ? 100 * (hypot(r.img[0], r.img[1]) - rp) / rp : 0;
            break;
        }
        case DO_RMSW: {
            /* RMS wavefront (waves) about its mean: residuals sqrt(w q / W) (W_k - mean) */
            int k0 = o->wave < 0 ? 0 : o->wave, nk = op_nwl(p, o), cap2 = DS_MAXRING * DS_MAXARM * 2;
            double wv[2 * DS_MAXRING * DS_MAXARM], wt[2 * DS_MAXRING * DS_MAXARM], m = 0, q = 0, r2 = 0;
            long nr = op_nres(p, o);
            int n = ds_field_wave(p, w + k0, nk, o->field, zi, wv, wt, cap2);
            if (n == -2) return 1;
            if (n < 0) {
                o->value = 10;                 /* ten waves: a penalty, not a stop */
                if (f) for (long j = 0; j < nr; j++) f[at + j] = sw * o->value / sqrt((double)nr);
                at += nr;
                continue;
            }
            for (int j = 0; j < n; j++) { m += wt[j] * wv[j]; q += wt[j]; }
            m /= q;
            for (int j = 0; j < n; j++) {
                double d = wv[j] - m;
                r2 += wt[j] * d * d;
                if (f && nr > 1) f[at + j] = sw * sqrt(wt[j] / q) * d;
            }
            o->value = sqrt(r2 / q);
            if (f && nr > 1) {
                for (long j = n; j < nr; j++) f[at + j] = 0;
                at += nr;
            } else if (f) {
                f[at++] = sw * scalar_res(o);
            }
            continue;
        }
        case DO_RMS: {
            int k0 = o->wave < 0 ? 0 : o->wave, nk = op_nwl(p, o);
            int cap2 = 2 * p->rings * p->arms * nk;
            double pts[2 * 2 * DS_MAXRING * DS_MAXARM], wt[2 * DS_MAXRING * DS_MAXARM];
            double cx = 0, cy = 0, sq = 0, r2 = 0;
            int n;
            if (cap2 > 2 * DS_MAXRING * DS_MAXARM) cap2 = 2 * DS_MAXRING * DS_MAXARM;
            /* rays of the wavelengths asked, the weights normalised over them */
            n = ds_field_rays(p, w + k0, nk, o->field, zi, pts, NULL, wt, cap2);
            if (n == -2) return 1;
            long nr = op_nres(p, o);
            if (n < 0) {                       /* a ray failed: a penalty, not a stop */
                o->value = w[0].p.r_stop;
                if (f) for (long j = 0; j < nr; j++) f[at + j] = sw * o->value / sqrt((double)nr);
                at += nr;
                continue;
            }
            for (int j = 0; j < n; j++) { cx += wt[j] * pts[2 * j]; cy += wt[j] * pts[2 * j + 1]; sq += wt[j]; }
            cx /= sq;
            cy /= sq;
            for (int j = 0; j < n; j++) {
                double dx = pts[2 * j] - cx, dy = pts[2 * j + 1] - cy;
                r2 += wt[j] * (dx * dx + dy * dy);
                if (f && nr > 1) {
                    double s = sw * sqrt(wt[j] / sq);
                    f[at + 2 * j] = s * dx;
                    f[at + 2 * j + 1] = s * dy;
                }
            }
            o->value = sqrt(r2 / sq);
            if (f && nr > 1) {
                for (long j = 2L * n; j < nr; j++) f[at + j] = 0;
                at += nr;
            } else if (f) {
                f[at++] = sw * scalar_res(o);
            }
            continue;
        }
        }
        if (f) f[at++] = sw * scalar_res(o);
    }
    return 0;
}
