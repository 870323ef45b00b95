/* scene_geom.c -- the trace front end's geometry: the rays of a point source that
 * fills a pupil (the engine makes the other kinds of source itself), and the
 * tessellation of analytic surfaces into triangle meshes whose vertices lie on the
 * surface (for the error-against-run-time table).  libc and libm only. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "scene.h"

#ifndef PI
#define PI 3.14159265358979323846
#endif

static double g_dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void g_cross(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}
static int g_unit(double *v)
{
    double m = sqrt(g_dot(v, v));
    if (!(m > 0) || !isfinite(m)) return -1;
    v[0] /= m; v[1] /= m; v[2] /= m;
    return 0;
}

/* A unit vector g_perp to unit d: the axis least aligned with d, projected. */
static void g_perp(const double *d, double *u)
{
    double m;
    int k = fabs(d[0]) < fabs(d[1]) ? (fabs(d[0]) < fabs(d[2]) ? 0 : 2)
                                    : (fabs(d[1]) < fabs(d[2]) ? 1 : 2);
    u[0] = u[1] = u[2] = 0;
    u[k] = 1;
    m = g_dot(u, d);
    for (int i = 0; i < 3; i++) u[i] -= m * d[i];
    g_unit(u);
}

long sc_point_count(const sc_source *s) { return 1 + 3L * s->rings * (s->rings + 1); }

void sc_point_rays(const sc_source *s, sc_ray *out)
{
    double d[3], u[3], v[3];
    long n = sc_point_count(s), i = 0;
    for (int k = 0; k < 3; k++) d[k] = s->toward[k] - s->from[k];
    g_unit(d);
    g_perp(d, u);
    g_cross(d, u, v);
    for (int r = 0; r <= s->rings; r++)
        for (int j = 0; j < (r ? 6 * r : 1); j++, i++) {
            double rho = s->rings ? s->radius * r / s->rings : 0;
            double phi = r ? 2 * PI * j / (6 * r) : 0;
            memcpy(out[i].o, s->from, sizeof out[i].o);
            for (int k = 0; k < 3; k++)
                out[i].d[k] = s->toward[k] - s->from[k] +
                              rho * (cos(phi) * u[k] + sin(phi) * v[k]);
            g_unit(out[i].d);
            out[i].power = s->power / (double)n;
        }
}

/* ---- tessellation --------------------------------------------------------------- */

typedef struct mesh { double *t; long n, cap; } mesh;

static int put(mesh *m, const double *a, const double *b, const double *c)
{
    if (m->n == m->cap) {
        long cap = m->cap ? 2 * m->cap : 64;
        double *t = realloc(m->t, (size_t)cap * 9 * sizeof *t);
        if (!t) return -1;
        m->t = t;
        m->cap = cap;
    }
    memcpy(m->t + 9 * m->n, a, 3 * sizeof *a);
    memcpy(m->t + 9 * m->n + 3, b, 3 * sizeof *b);
    memcpy(m->t + 9 * m->n + 6, c, 3 * sizeof *c);
    m->n++;
    return 0;
}

/* Sag of an axial surface at distance s from the axis. */
static double sag(const sc_surface *f, double s)
{
    double c = f->radius != 0 ? 1 / f->radius : 0, s2 = s * s, z, p = s2;
    double q = 1 - (1 + f->conic) * c * c * s2;
    z = c * s2 / (1 + sqrt(q > 0 ? q : 0));
    for (int i = 0; i < f->ncoef; i++, p *= s2) z += f->coef[i] * p;
    return z;
}

/* Point of an axial surface or disc at polar (s, phi) in the frame (u, v, axis). */
static void axial_point(const sc_surface *f, const double *u, const double *v, double s,
                        double phi, double *p)
{
    double z = f->shape == SC_PLANE ? 0 : sag(f, s);
    for (int k = 0; k < 3; k++)
        p[k] = f->at[k] + z * f->axis[k] + s * (cos(phi) * u[k] + sin(phi) * v[k]);
}

/* Hexapolar rings: ring k holds 6k vertices; neighbouring rings are zipped by angle.
 * With v = u x axis the triangles' normals point along -axis: their front side is
 * the surface's n1 side (trace.h). */
static int tess_axial(const sc_surface *f, int level, mesh *m)
{
    double u[3], v[3], a = f->aperture;
    g_perp(f->axis, u);
    g_cross(u, f->axis, v);
    for (int k = 1; k <= level; k++) {
        long nin = k == 1 ? 1 : 6L * (k - 1), nout = 6L * k, i = 0, j = 0;
        double rin = a * (k - 1) / level, rout = a * k / level;
        while (i < (k == 1 ? 0 : nin) || j < nout) {
            double p[3], q[3], r[3];
            /* angles by index, the seam's last index being index 0 (2 pi is not 0
             * for sin): neighbours share their vertices bit for bit */
            double ai = 2 * PI * (double)(i + 1) / (double)nin;
            double aj = 2 * PI * (double)(j + 1) / (double)nout;
            axial_point(f, u, v, rin, 2 * PI * (double)(i % nin) / (double)nin, p);
            axial_point(f, u, v, rout, 2 * PI * (double)(j % nout) / (double)nout, q);
            if (j < nout && (k == 1 || i == nin || aj <= ai)) {
                axial_point(f, u, v, rout, 2 * PI * (double)((j + 1) % nout) / (double)nout, r);
                j++;
            } else {
                axial_point(f, u, v, rin, 2 * PI * (double)((i + 1) % nin) / (double)nin, r);
                i++;
            }
            if (put(m, p, q, r)) return -1;
        }
    }
    return 0;
}

static int tess_rect(const sc_surface *f, int level, mesh *m)
{
    double v[3], u[3];
    memcpy(v, f->up, sizeof v);
    g_cross(f->axis, v, u);       /* u x v = -axis: normals toward the n1 side */
    for (int i = 0; i < level; i++)
        for (int j = 0; j < level; j++) {
            double c[4][3];
            for (int q = 0; q < 4; q++) {
                double x = ((double)(i + (q == 1 || q == 2)) / level - 0.5) * f->rect[0];
                double y = ((double)(j + (q >= 2)) / level - 0.5) * f->rect[1];
                for (int k = 0; k < 3; k++) c[q][k] = f->at[k] + x * u[k] + y * v[k];
            }
            if (put(m, c[0], c[1], c[2]) || put(m, c[0], c[2], c[3])) return -1;
        }
    return 0;
}

/* Put triangle a b c turned so that its normal points away from `centre`. */
static int put_outward(mesh *m, const double *a, const double *b, const double *c,
                       const double *centre)
{
    double e1[3], e2[3], n[3], mid[3];
    for (int k = 0; k < 3; k++) {
        e1[k] = b[k] - a[k];
        e2[k] = c[k] - a[k];
        mid[k] = (a[k] + b[k] + c[k]) / 3 - centre[k];
    }
    g_cross(e1, e2, n);
    return g_dot(n, mid) >= 0 ? put(m, a, b, c) : put(m, a, c, b);
}

/* Latitude bands x 2 level longitudes; the bands at the poles are fans. */
static int tess_sphere(const sc_surface *f, int level, mesh *m)
{
    int nlon = 2 * level;
    for (int i = 0; i < level; i++)
        for (int j = 0; j < nlon; j++) {
            double c[4][3];   /* (i, j) (i, j+1) (i+1, j+1) (i+1, j) */
            for (int q = 0; q < 4; q++) {
                /* vertices by index: the seam's longitude nlon is longitude 0 and the
                 * poles are one point each, exactly (sin(pi) and sin(2 pi) are not 0
                 * in double: they left a hole at the pole and a crack on the seam) */
                int a = i + (q >= 2), b = (j + (q == 1 || q == 2)) % nlon;
                double th = PI * a / level, ph = 2 * PI * b / nlon;
                double st = a == 0 || a == level ? 0 : sin(th);
                double ct = a == 0 ? 1 : a == level ? -1 : cos(th);
                c[q][0] = f->at[0] + f->radius * st * cos(ph);
                c[q][1] = f->at[1] + f->radius * st * sin(ph);
                c[q][2] = f->at[2] + f->radius * ct;
            }
            if (i > 0 && put_outward(m, c[0], c[1], c[2], f->at)) return -1;
            if (i < level - 1 && put_outward(m, c[0], c[2], c[3], f->at)) return -1;
        }
    return 0;
}

int sc_tessellate(const sc_surface *s, int level, double **tri, long *ntri, char *err)
{
    mesh m = {0};
    int rc;
    *tri = NULL;
    *ntri = 0;
    if (level < 1 || (s->shape == SC_SPHERE && level < 2)) {
        snprintf(err, SC_ERRMAX, "tessellate %d: too coarse for this surface", level);
        return -1;
    }
    switch (s->shape) {
    case SC_PLANE: rc = s->aperture > 0 ? tess_axial(s, level, &m) : tess_rect(s, level, &m); break;
    case SC_SPHERE: rc = tess_sphere(s, level, &m); break;
    case SC_CAP: case SC_CONIC: case SC_ASPHERE: rc = tess_axial(s, level, &m); break;
    default:
        snprintf(err, SC_ERRMAX, "only analytic surfaces can be tessellated");
        return -1;
    }
    if (rc) {
        free(m.t);
        snprintf(err, SC_ERRMAX, "out of memory tessellating (level %d)", level);
        return -1;
    }
    if (sc_check_triangles(m.t, m.n, "tessellation", err)) {
        free(m.t);
        return -1;
    }
    *tri = m.t;
    *ntri = m.n;
    return 0;
}

/* ---- coincident surfaces ----------------------------------------------------------- */

/* The same underlying surface at the same place (apertures aside)?  *flip: a plane
 * whose normal is reversed (its n1 and n2 swap sides). */
static int same_surface(const sc_surface *a, const sc_surface *b, int *flip)
{
    int axial_a = a->shape >= SC_CAP && a->shape <= SC_ASPHERE;
    int axial_b = b->shape >= SC_CAP && b->shape <= SC_ASPHERE;
    *flip = 0;
    if (a->shape == SC_MESH || b->shape == SC_MESH) return 0;
    if (a->shape != b->shape && !(axial_a && axial_b)) return 0;
    for (int i = 0; i < 3; i++) if (a->at[i] != b->at[i]) return 0;
    if (a->shape == SC_SPHERE) return a->radius == b->radius;
    int same = 1, opp = 1;
    for (int i = 0; i < 3; i++) {
        same &= a->axis[i] == b->axis[i];
        opp &= a->axis[i] == -b->axis[i];
    }
    if (a->shape == SC_PLANE) { *flip = !same && opp; return same || opp; }
    if (!same || a->radius != b->radius || a->conic != b->conic) return 0;
    int n = a->ncoef > b->ncoef ? a->ncoef : b->ncoef;
    for (int i = 0; i < n; i++)
        if ((i < a->ncoef ? a->coef[i] : 0) != (i < b->ncoef ? b->coef[i] : 0)) return 0;
    return 1;
}

/* Their apertures: 1 the same, 0 disjoint (a disc inside an annulus's hole: a lens
 * face and its mount), -1 overlapping in part. */
static int same_aperture(const sc_surface *a, const sc_surface *b)
{
    if (a->shape == SC_SPHERE) return 1;
    int ra = a->shape == SC_PLANE && !(a->aperture > 0), rb = b->shape == SC_PLANE && !(b->aperture > 0);
    if (ra || rb) {
        if (ra && rb && a->rect[0] == b->rect[0] && a->rect[1] == b->rect[1]) {
            for (int i = 0; i < 3; i++)
                if (fabs(a->up[i]) != fabs(b->up[i])) return -1;
            return 1;
        }
        return -1;
    }
    if (a->aperture == b->aperture && a->hole == b->hole) return 1;
    return a->aperture <= b->hole || b->aperture <= a->hole ? 0 : -1;
}

/* Where the line p0 + s e (in plane f) runs through the inside of f's disc or
 * rectangle: [*s0, *s1], or 0 if it misses it or only runs along its rim.  A line
 * along a rectangle's edge (parallel to it to 1e-12, within 1e-9 of its width of the
 * edge) is on the rim: two faces of a prism or a cube meet there, neither crosses the
 * other. */
static int plane_chord(const sc_surface *f, const double *p0, const double *e, double *s0,
                       double *s1)
{
    double q[3] = {p0[0] - f->at[0], p0[1] - f->at[1], p0[2] - f->at[2]};
    if (f->aperture > 0) {
        double b = g_dot(e, q), c = g_dot(q, q) - f->aperture * f->aperture;
        double disc = b * b - c;
        if (!(disc > 0)) return 0;
        *s0 = -b - sqrt(disc);
        *s1 = -b + sqrt(disc);
        return 1;
    }
    double u[3], lo = -INFINITY, hi = INFINITY;
    g_cross(f->up, f->axis, u);
    const double *ax[2] = {u, f->up};
    for (int k = 0; k < 2; k++) {
        double x = g_dot(q, ax[k]), dx = g_dot(e, ax[k]), h = f->rect[k] / 2;
        if (fabs(dx) < 1e-12) { if (!(fabs(x) < h * (1 - 1e-9))) return 0; continue; }
        double a = (-h - x) / dx, b = (h - x) / dx;
        if (a > b) { double t = a; a = b; b = t; }
        if (a > lo) lo = a;
        if (b < hi) hi = b;
    }
    if (!(lo < hi)) return 0;
    *s0 = lo;
    *s1 = hi;
    return 1;
}

/* Two refracting planes that cross each other inside both apertures (the media
 * between them would depend on which side of the other each ray is)?  Planes that
 * only meet along an edge of one of them (the faces of a prism, a cube: a solid they
 * bound) do not: one ends where it meets the other. */
static int planes_cross(const sc_surface *a, const sc_surface *b)
{
    double e[3], p0[3], m[3], n[3], sa0, sa1, sb0, sb1;
    g_cross(a->axis, b->axis, e);
    double ee = g_dot(e, e);
    if (!(ee > 1e-24)) return 0;                       /* parallel */
    double da = g_dot(a->axis, a->at), db = g_dot(b->axis, b->at);
    g_cross(b->axis, e, m);
    g_cross(e, a->axis, n);
    for (int i = 0; i < 3; i++) p0[i] = (da * m[i] + db * n[i]) / ee;
    g_unit(e);
    if (!plane_chord(a, p0, e, &sa0, &sa1) || !plane_chord(b, p0, e, &sb0, &sb1)) return 0;
    double lo = fmax(sa0, sb0), hi = fmin(sa1, sb1), size = (sa1 - sa0) + (sb1 - sb0);
    return hi - lo > 1e-9 * size;
}

/* Two refracting surfaces of revolution on one axis (caps, conics, aspheres, and discs
 * square to it) that cross inside both apertures: the gap between them changes sign. */
static int axial_cross(const sc_surface *a, const sc_surface *b)
{
    int pa = a->shape == SC_PLANE, pb = b->shape == SC_PLANE;
    if (a->shape == SC_SPHERE || b->shape == SC_SPHERE || a->shape == SC_MESH ||
        b->shape == SC_MESH || (pa && !(a->aperture > 0)) || (pb && !(b->aperture > 0)))
        return 0;
    double sb = 1, off[3], x[3];
    for (int i = 0; i < 3; i++) {
        if (a->axis[i] != b->axis[i]) sb = -1;
        off[i] = b->at[i] - a->at[i];
    }
    if (sb < 0) {                          /* only a plane may face the other way */
        if (!pb) return 0;
        for (int i = 0; i < 3; i++) if (a->axis[i] != -b->axis[i]) return 0;
    }
    g_cross(off, a->axis, x);              /* the vertices on one axis? */
    if (!(sqrt(g_dot(x, x)) <= 1e-12 * (sqrt(g_dot(off, off)) + a->aperture))) return 0;
    double dz = g_dot(off, a->axis), smax = fmin(a->aperture, b->aperture);
    double smin = fmax(pa ? a->hole : 0, pb ? b->hole : 0);
    double tol = 1e-12 * (fabs(dz) + smax), lo = 0, hi = 0;
    if (!(smax > smin)) return 0;
    for (int i = 0; i <= 256; i++) {
        double s = smin + (smax - smin) * i / 256;
        double g = (pb ? 0 : sag(b, s)) + dz - (pa ? 0 : sag(a, s));
        lo = fmin(lo, g);
        hi = fmax(hi, g);
    }
    return lo < -tol && hi > tol;
}

/* Surfaces at the same place (the same shape, position, axis and aperture) are traced
 * as one interface, each in turn in the order they are listed (a ray going along the
 * axis, or into a sphere, meets the first one first); refracting ones must then chain
 * their media, n1 -> n -> n2.  Refused, with both lines: a chain that breaks, the
 * same surface listed twice with apertures that overlap only in part, coincident
 * tessellated surfaces, refracting planes that cross inside both apertures, and
 * refracting surfaces of revolution on one axis that cross inside both. */
int sc_check_coincident(const sc_scene *sc, char *err)
{
    static const char *names[] = {"plane", "sphere", "cap", "conic", "asphere", "mesh"};
    for (int i = 0; i < sc->nsurf; i++)
        for (int j = i + 1; j < sc->nsurf; j++) {
            const sc_surface *a = &sc->surf[i], *b = &sc->surf[j];
            int flip, ap;
            if (a->shape == SC_PLANE && b->shape == SC_PLANE && a->kind == SC_REFRACT &&
                b->kind == SC_REFRACT && planes_cross(a, b)) {
                snprintf(err, SC_ERRMAX, "%s:%ld: this refracting plane crosses the one of "
                         "line %ld inside both their apertures: which medium lies between "
                         "them is ambiguous (end one where it meets the other)", b->src,
                         b->line, a->line);
                return -1;
            }
            if (a->kind == SC_REFRACT && b->kind == SC_REFRACT && axial_cross(a, b)) {
                snprintf(err, SC_ERRMAX, "%s:%ld: this refracting %s crosses the %s of line "
                         "%ld inside both their apertures: which medium lies between them "
                         "is ambiguous (end one where it meets the other)", b->src, b->line,
                         names[b->shape], names[a->shape], a->line);
                return -1;
            }
            if (!same_surface(a, b, &flip) || (ap = same_aperture(a, b)) == 0) continue;
            if (ap < 0) {
                snprintf(err, SC_ERRMAX, "%s:%ld: this %s lies on the %s of line %ld with "
                         "an aperture that overlaps it only in part: give coincident surfaces "
                         "the same aperture, or apertures that do not overlap",
                         b->src, b->line, names[b->shape], names[a->shape], a->line);
                return -1;
            }
            if (a->tessellate || b->tessellate) {
                snprintf(err, SC_ERRMAX, "%s:%ld: this %s coincides with the %s of line "
                         "%ld: coincident surfaces are taken in order only as analytic "
                         "surfaces (drop tessellate)", b->src, b->line, names[b->shape],
                         names[a->shape], a->line);
                return -1;
            }
            if (a->kind != SC_REFRACT || b->kind != SC_REFRACT) continue;
            /* the medium between them: a's n2 (or, a reversed plane, its n1) */
            double bn1 = flip ? b->n2 : b->n1;
            if (a->n2 != bn1) {
                snprintf(err, SC_ERRMAX, "%s:%ld: this %s coincides with the %s of line "
                         "%ld and their media do not chain: %g -> %g there, then %g -> %g "
                         "here (coincident surfaces are one interface, taken in the "
                         "order listed: n1 -> n -> n2)", b->src, b->line, names[b->shape],
                         names[a->shape], a->line, a->n1, a->n2, bn1, flip ? b->n1 : b->n2);
                return -1;
            }
        }
    return 0;
}
