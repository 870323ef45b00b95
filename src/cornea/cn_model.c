/* cn_model.c -- the fit's analytic forward model: a beam (leaving m2) meets the cornea
 * of a parameter vector (power-vector biconic placed by decentration and tilt),
 * reflects, and crosses the fixed detector plane.  Also the detector plane of a rig
 * geometry and the conversion of an rg_cornea into parameters. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "cn_int.h"

static const char *const names[CN_NPARAM] = {"R", "C0", "C45", "Q_flat", "Q_steep",
                                              "dx", "dy", "dz", "tilt_x", "tilt_y",
                                              "A4", "A6"};
const char *cn_param_name(int k) { return k >= 0 && k < CN_NPARAM ? names[k] : NULL; }

static double dot3(const double a[3], const double b[3])
{ return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void unit3(double a[3])
{ double l = sqrt(dot3(a, a)); if (l > 0) { a[0] /= l; a[1] /= l; a[2] /= l; } }
static void cross3(double c[3], const double a[3], const double b[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

void cn_plane_of(const rg_geometry *g, cn_plane *pl)
{
    /* normal along nominal apex -> detector, as rig_api.forward's plane; e1 the
     * horizontal axis of the plane (rig x projected), e2 = w x e1 */
    for (int i = 0; i < 3; i++) {
        pl->at[i] = g->detector[i];
        pl->w[i] = g->detector[i] - g->cornea.trans[i];
    }
    unit3(pl->w);
    double x[3] = {1, 0, 0};
    if (fabs(pl->w[0]) > 0.9) { x[0] = 0; x[1] = 1; }
    double k = dot3(x, pl->w);
    for (int i = 0; i < 3; i++) pl->e1[i] = x[i] - k * pl->w[i];
    unit3(pl->e1);
    cross3(pl->e2, pl->w, pl->e1);
}

/* The biconic of p: flat and steep apex curvatures, their Q, the flat axis. */
void cn_surface(int model, const cn_params *p, cn_surf *s)
{
    double cm = 1 / p->p[CN_R];
    double c0 = 0, c45 = 0, qf = 0, qs = 0;
    if (model != CN_SPHERE) qf = qs = p->p[CN_QF];
    if (model == CN_BICONIC) { c0 = p->p[CN_C0]; c45 = p->p[CN_C45]; qs = p->p[CN_QS]; }
    double amp = hypot(c0, c45);
    s->cf = cm - amp;
    s->cs = cm + amp;
    s->qf = qf;
    s->qs = qs;
    s->alpha = amp > 0 ? 0.5 * (atan2(c45, c0) + M_PI) : 0;
    s->ca = cos(s->alpha);
    s->sa = sin(s->alpha);
    s->a4 = model == CN_ASPHERE ? p->p[CN_A4] : 0;
    s->a6 = model == CN_ASPHERE ? p->p[CN_A6] : 0;
    memset(&s->bump, 0, sizeof s->bump);
}

/* Sag and slopes in the eye frame; -1 beyond the surface's edge. */
static int sag(const cn_surf *s, double x, double y, double *z, double *zx, double *zy);
int cn_sag(const cn_surf *s, double x, double y, double *z, double *zx, double *zy)
{ return sag(s, x, y, z, zx, zy); }
static int sag(const cn_surf *s, double x, double y, double *z, double *zx, double *zy)
{
    double xp = s->ca * x + s->sa * y, yp = -s->sa * x + s->ca * y;
    double A = s->cf * xp * xp + s->cs * yp * yp;
    double B = 1 - (1 + s->qf) * s->cf * s->cf * xp * xp -
               (1 + s->qs) * s->cs * s->cs * yp * yp;
    if (B <= 0) return -1;
    double S = sqrt(B), D = 1 + S;
    *z = A / D;
    /* d/dx' and d/dy' of A / (1 + S), dS = dB / (2S) */
    double Bx = -2 * (1 + s->qf) * s->cf * s->cf * xp, By = -2 * (1 + s->qs) * s->cs * s->cs * yp;
    double zxp = (2 * s->cf * xp * D - A * Bx / (2 * S)) / (D * D);
    double zyp = (2 * s->cs * yp * D - A * By / (2 * S)) / (D * D);
    *zx = s->ca * zxp - s->sa * zyp;
    *zy = s->sa * zxp + s->ca * zyp;
    if (s->a4 != 0 || s->a6 != 0) {        /* even asphere: + a4 s^4 + a6 s^6 */
        double s2 = x * x + y * y, ds = 4 * s->a4 * s2 + 6 * s->a6 * s2 * s2;
        *z += (s->a4 + s->a6 * s2) * s2 * s2;
        *zx += ds * x;
        *zy += ds * y;
    }
    if (s->bump.h != 0 && s->bump.w > 0) { /* the cone: a Gaussian toward -z */
        double bx = x - s->bump.x0, by = y - s->bump.y0, w2 = s->bump.w * s->bump.w;
        double e = s->bump.h * exp(-(bx * bx + by * by) / (2 * w2));
        *z -= e;
        *zx += e * bx / w2;
        *zy += e * by / w2;
    }
    return 0;
}

/* Eye rotation Ry(ty) Rx(tx) (rig_api.eye_pose with rz = 0), row-major. */
static void rotation(double tx, double ty, double m[9])
{
    double cx = cos(tx), sx = sin(tx), cy = cos(ty), sy = sin(ty);
    double r[9] = {cy, sy * sx, sy * cx, 0, cx, -sx, -sy, cy * sx, cy * cx};
    memcpy(m, r, sizeof r);
}

int cn_forward(int model, const cn_params *p, const double apex0[3], const cn_plane *pl,
               const cn_ray *r, double *u, double *v, double spot[3], double normal[3])
{
    return cn_forward_bump(model, p, NULL, apex0, pl, r, u, v, spot, normal);
}

void cn_to_eye(const cn_params *p, const double apex0[3], const double x[3], double e[3])
{
    double m[9], rel[3];
    rotation(p->p[CN_TX], p->p[CN_TY], m);
    for (int i = 0; i < 3; i++) rel[i] = x[i] - apex0[i] - p->p[CN_DX + i];
    for (int i = 0; i < 3; i++) e[i] = m[i] * rel[0] + m[3 + i] * rel[1] + m[6 + i] * rel[2];
}

int cn_forward_bump(int model, const cn_params *p, const cn_bump *bump,
                    const double apex0[3], const cn_plane *pl, const cn_ray *r,
                    double *u, double *v, double spot[3], double normal[3])
{
    cn_surf s;
    double m[9], T[3], o[3], d[3], rel[3];
    cn_surface(model, p, &s);
    if (bump) s.bump = *bump;
    rotation(p->p[CN_TX], p->p[CN_TY], m);
    for (int i = 0; i < 3; i++) T[i] = apex0[i] + p->p[CN_DX + i];
    for (int i = 0; i < 3; i++) rel[i] = r->o[i] - T[i];
    for (int i = 0; i < 3; i++) {          /* to the eye frame: R^T (x - T) */
        o[i] = m[i] * rel[0] + m[3 + i] * rel[1] + m[6 + i] * rel[2];
        d[i] = m[i] * r->d[0] + m[3 + i] * r->d[1] + m[6 + i] * r->d[2];
    }
    if (d[2] <= 1e-9) return CN_EFIT;      /* the beam must travel into the eye */
    /* Newton on g(t) = sag(o + t d) - z(o + t d) from the apex tangent plane */
    double t = -o[2] / d[2], z = 0, zx = 0, zy = 0;
    {   /* a start on the apex's mean-curvature sphere: Newton then takes 2-3 steps
           where it took 5-6 from the apex plane (the forward model is most of a fit's
           time: its central-difference Jacobian calls it 2 nfree times a spot) */
        double cm = 0.5 * (s.cf + s.cs);
        if (cm > 1e-6) {
            double Rc = 1 / cm, oc[3] = {o[0], o[1], o[2] - Rc};
            double b = dot3(d, oc), c0 = dot3(oc, oc) - Rc * Rc, disc = b * b - c0;
            if (disc > 0 && -b - sqrt(disc) > 0) t = -b - sqrt(disc);
        }
    }
    int ok = 0;
    if (sag(&s, o[0] + t * d[0], o[1] + t * d[1], &z, &zx, &zy)) {
        /* a beam steep to the axis (a wide zone: up to 85 deg) crosses the apex plane
           past the surface's edge; start where it passes closest to the axis, inside
           the cornea if the beam meets it (Newton then walks back to the front) */
        double dl = d[0] * d[0] + d[1] * d[1];
        if (dl > 0) t = -(o[0] * d[0] + o[1] * d[1]) / dl;
    }
    for (int it = 0; it < 40; it++) {
        double x = o[0] + t * d[0], y = o[1] + t * d[1];
        if (sag(&s, x, y, &z, &zx, &zy)) return CN_EFIT;
        double gv = z - (o[2] + t * d[2]);
        double gd = zx * d[0] + zy * d[1] - d[2];
        if (gd >= 0) return CN_EFIT;       /* grazing or from behind */
        double dt = gv / gd, z2, zx2, zy2;
        /* a step past the surface's edge (from the closest-approach start) is
           halved until it lands on the surface */
        for (int h = 0; h < 40 && sag(&s, o[0] + (t - dt) * d[0], o[1] + (t - dt) * d[1],
                                      &z2, &zx2, &zy2); h++)
            dt *= 0.5;
        t -= dt;
        if (fabs(dt) < 1e-14 * (1 + fabs(t))) { ok = 1; break; }
    }
    if (!ok) return CN_EFIT;
    double pe[3] = {o[0] + t * d[0], o[1] + t * d[1], 0};
    if (sag(&s, pe[0], pe[1], &z, &zx, &zy)) return CN_EFIT;
    pe[2] = z;
    double ne[3] = {zx, zy, -1};
    unit3(ne);
    double dn = dot3(d, ne), d3e[3];
    for (int i = 0; i < 3; i++) d3e[i] = d[i] - 2 * dn * ne[i];
    double P[3], N[3], D3[3];
    for (int i = 0; i < 3; i++) {
        P[i] = m[3 * i] * pe[0] + m[3 * i + 1] * pe[1] + m[3 * i + 2] * pe[2] + T[i];
        N[i] = m[3 * i] * ne[0] + m[3 * i + 1] * ne[1] + m[3 * i + 2] * ne[2];
        D3[i] = m[3 * i] * d3e[0] + m[3 * i + 1] * d3e[1] + m[3 * i + 2] * d3e[2];
    }
    double den = dot3(D3, pl->w);
    if (den <= 1e-12) return CN_EFIT;
    double q[3], k;
    for (int i = 0; i < 3; i++) q[i] = pl->at[i] - P[i];
    k = dot3(q, pl->w) / den;
    double hit[3];
    for (int i = 0; i < 3; i++) hit[i] = P[i] + k * D3[i] - pl->at[i];
    *u = dot3(hit, pl->e1);
    *v = dot3(hit, pl->e2);
    if (spot) memcpy(spot, P, sizeof P);
    if (normal) memcpy(normal, N, sizeof N);
    return CN_OK;
}

void cn_params_from_cornea(const rg_cornea *c, const double apex0[3], double rx,
                           double ry, cn_params *p)
{
    memset(p, 0, sizeof *p);
    double cf = 1 / c->R, cs = 1 / c->R, qf = c->Q, qs = c->Q, a = 0;
    if (c->model == RG_SPHERE) qf = qs = 0;
    if (c->model == RG_BICONIC) { cs = 1 / c->R2; qs = c->Q2; a = c->axis; }
    if (c->model == RG_ASPHERE) {
        p->p[CN_A4] = c->nasph > 0 ? c->asph[0] : 0;
        p->p[CN_A6] = c->nasph > 1 ? c->asph[1] : 0;
    }
    double cm = (cf + cs) / 2, amp = (cs - cf) / 2;
    p->p[CN_R] = 1 / cm;
    p->p[CN_C0] = -amp * cos(2 * a);
    p->p[CN_C45] = -amp * sin(2 * a);
    p->p[CN_QF] = qf;
    p->p[CN_QS] = qs;
    for (int i = 0; i < 3; i++) p->p[CN_DX + i] = c->trans[i] - apex0[i];
    p->p[CN_TX] = rx;
    p->p[CN_TY] = ry;
}

int cn_ray_of_pose(const rig_api *rg, const rg_geometry *g, const rg_pose *pose,
                   cn_ray *r, char *err, size_t errcap)
{
    rg_beam b;
    char e[256];
    memset(&b, 0, sizeof b);
    rg->forward(g, pose, &b, e, sizeof e);   /* the mirror chain alone matters */
    for (int i = 0; i < 3; i++) { r->o[i] = b.h2[i]; r->d[i] = b.d2[i]; }
    if (!(isfinite(dot3(r->o, r->o)) && isfinite(dot3(r->d, r->d))) ||
        (b.diag & RG_D_MISS_MIRROR)) {
        snprintf(err, errcap, "pose gives no beam off m2: %s", e);
        return CN_EINVAL;
    }
    unit3(r->d);
    return CN_OK;
}

void cn_cornea_from_params(const rig_api *rg, int model, const cn_params *p,
                           const double apex0[3], rg_cornea *c)
{
    cn_surf s;
    cn_surface(model, p, &s);
    memset(c, 0, sizeof *c);
    c->model = model == CN_SPHERE ? RG_SPHERE : model == CN_CONIC ? RG_CONIC
             : model == CN_ASPHERE ? RG_ASPHERE : RG_BICONIC;
    if (model == CN_ASPHERE) {
        c->nasph = 2;
        c->asph[0] = p->p[CN_A4];
        c->asph[1] = p->p[CN_A6];
    }
    c->R = 1 / s.cf;
    c->Q = s.qf;
    c->R2 = 1 / s.cs;
    c->Q2 = s.qs;
    c->axis = s.alpha;
    double at[3];
    for (int i = 0; i < 3; i++) at[i] = apex0[i] + p->p[CN_DX + i];
    rg->eye_pose(c, p->p[CN_TX], p->p[CN_TY], 0, at);
}
