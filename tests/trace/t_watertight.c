/* t_watertight.c -- open meshes never leak and never count a crossing twice: rays
 * aimed at every vertex and at points along every edge of an open tessellated cap
 * (the scene reader's own tessellation) and of an open OBJ grid sheet (read by the
 * scene reader's OBJ parser, a triangle soup), from both sides and several tilts,
 * cross the index-matched mesh exactly once before the detector; the same hits, bit
 * for bit, with 1 and 2 threads. */
#include <stdio.h>
#include "unit.h"
#include "tt.h"
#include "trace/scene.h"

static const trace_api *tr;

static int same3(const double *a, const double *b)
{
    return a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
}

/* Is edge (a, b) of the soup used by one triangle only (a boundary edge)? */
static int boundary_edge(const double *tri, long ntri, const double *a, const double *b)
{
    int uses = 0;
    for (long t = 0; t < ntri; t++)
        for (int e = 0; e < 3; e++) {
            const double *p = tri + 9 * t + 3 * e, *q = tri + 9 * t + 3 * ((e + 1) % 3);
            if ((same3(p, a) && same3(q, b)) || (same3(p, b) && same3(q, a))) uses++;
        }
    return uses == 1;
}

/* Is vertex a on a boundary edge of the soup? */
static int on_boundary(const double *tri, long ntri, const double *a)
{
    for (long t = 0; t < ntri; t++)
        for (int e = 0; e < 3; e++) {
            const double *p = tri + 9 * t + 3 * e, *q = tri + 9 * t + 3 * ((e + 1) % 3);
            if ((same3(p, a) || same3(q, a)) && boundary_edge(tri, ntri, p, q)) return 1;
        }
    return 0;
}

/* Targets: every vertex, points at 1/2 and 1/4 of every edge.  Boundary edges'
 * points (and vertices on them) move 1e-9 of the edge toward the triangle's centroid:
 * the true ray meets the mesh there (a ray aimed at the boundary itself may pass
 * either side by rounding), far closer to its boundary than single
 * precision can tell. */
static double *targets(const double *tri, long ntri, long *n)
{
    double *p = malloc((size_t)ntri * 9 * 3 * sizeof(double));
    long k = 0;
    for (long t = 0; t < ntri; t++) {
        const double *v = tri + 9 * t;
        double c[3];
        for (int q = 0; q < 3; q++) c[q] = (v[q] + v[3 + q] + v[6 + q]) / 3;
        for (int e = 0; e < 3; e++) {
            const double *a = v + 3 * e, *b = v + 3 * ((e + 1) % 3);
            int bd = boundary_edge(tri, ntri, a, b), bv = on_boundary(tri, ntri, a);
            for (int f = 0; f < 3; f++, k++)
                for (int q = 0; q < 3; q++) {
                    double x = f == 0 ? a[q] : a[q] + (b[q] - a[q]) / (2.0 * f);
                    p[3 * k + q] = (f == 0 ? bv : bd) ? x + 1e-9 * (c[q] - x) : x;
                }
        }
    }
    *n = k;
    return p;
}

typedef struct rec { int *depth; double *pos, *cross; long n, bad; } rec;

/* Where each ray first crosses the mesh (the end of its first segment). */
static int on_seg(void *ctx, const trace_segment *g)
{
    rec *r = ctx;
    if ((long)g->ray >= r->n) { r->bad++; return 0; }
    if (g->depth == 0 && g->end == TRACE_END_NONE)
        for (int q = 0; q < 3; q++) r->cross[3 * g->ray + q] = g->p1[q];
    return 0;
}

static int on_hit(void *ctx, const trace_hit *h)
{
    rec *r = ctx;
    if ((long)h->ray >= r->n) { r->bad++; return 0; }
    r->depth[h->ray] = h->depth;
    for (int q = 0; q < 3; q++) r->pos[3 * h->ray + q] = h->pos[q];
    return 0;
}

/* Trace rays aimed at the targets through the soup (index 1 both sides: every
 * crossing is one interaction, the ray goes on straight) to a detector sphere. */
static void crossings(const char *what, const double *tri, long ntri, const double up[3],
                      double det_radius)
{
    long nt;
    double *tp = targets(tri, ntri, &nt);
    const int reps = 6;
    long nr = reps * nt;
    trace_ray *rays = malloc((size_t)nr * sizeof *rays);
    for (long i = 0, k = 0; i < nt; i++)
        for (int r = 0; r < reps; r++, k++) {
            double s = r % 2 ? -1 : 1, a = 0.9 * r + 0.3, b = 0.25 + 0.2 * r;
            for (int q = 0; q < 3; q++) rays[k].o[q] = tp[3 * i + q] + 2 * s * up[q];
            rays[k].o[0] += b * cos(a); rays[k].o[1] += b * sin(a);
            rays[k].o[2] += 0.1 * b * sin(2 * a);
            for (int q = 0; q < 3; q++) rays[k].d[q] = tp[3 * i + q] - rays[k].o[q];
            rays[k].power = 1;
        }
    int *depth[2];
    double *pos[2];
    long wrong[2] = {0, 0}, leak[2] = {0, 0}, twice[2] = {0, 0}, off = 0;
    double *cross = calloc((size_t)nr * 3, sizeof(double)), worst = 0;
    int rc[2];
    for (int th = 0; th < 2; th++) {
        trace_scene *sc = tr->scene_new();
        trace_mesh mesh = {tri, 3 * ntri, NULL, ntri, NULL, NULL, 0, 0};
        trace_material clear = {TRACE_REFRACT, 1, 1};
        int id = tr->add_mesh(sc, &mesh, &clear);
        trace_surface det = {0};
        trace_material md = {TRACE_DETECT, 1, 1};
        det.shape = TRACE_SPHERE; det.radius = det_radius;
        tr->add_surface(sc, &det, &md);
        trace_source src = {0};
        src.type = TRACE_SRC_RAYS; src.count = nr; src.ray = rays;
        rc[th] = id >= 0 ? tr->add_source(sc, &src, NULL) : id;
        trace_options o;
        tr->options_default(&o);
        o.reflections = 0;
        o.threads = th + 1;
        depth[th] = malloc((size_t)nr * sizeof(int));
        pos[th] = calloc((size_t)nr * 3, sizeof(double));
        for (long k = 0; k < nr; k++) depth[th][k] = -1;
        rec r = {depth[th], pos[th], cross, nr, 0};
        trace_sink sink = {&r, th ? NULL : on_seg, on_hit, NULL};
        trace_summary sum;
        if (rc[th] == 0) rc[th] = tr->run(sc, &o, &sink, &sum);
        if (rc[th] == 0 && (r.bad || sum.hits != (uint64_t)nr)) rc[th] = -100;
        for (long k = 0; k < nr; k++) {
            wrong[th] += depth[th][k] != 1;
            leak[th] += depth[th][k] == 0;
            twice[th] += depth[th][k] >= 2;
        }
        tr->scene_free(sc);
    }
    /* each ray crosses the mesh at the point it was aimed at */
    for (long k = 0; k < nr; k++) {
        const double *t = tp + 3 * (k / reps), *c = cross + 3 * k;
        double e = sqrt((c[0] - t[0]) * (c[0] - t[0]) + (c[1] - t[1]) * (c[1] - t[1]) +
                        (c[2] - t[2]) * (c[2] - t[2]));
        if (!(e <= 1e-12 * 10)) off++;
        if (e > worst) worst = e;
    }
    CHECK(rc[0] == 0 && off == 0, "%s: every crossing is at its target (%ld off, "
          "worst %.3g)", what, off, worst);
    free(cross);
    CHECK(rc[0] == 0 && wrong[0] == 0,
          "%s (%ld triangles): %ld rays aimed at vertices and edges cross it exactly "
          "once (%ld leak, %ld cross twice or more, %ld other, rc %d)", what, ntri, nr,
          leak[0], twice[0], wrong[0] - leak[0] - twice[0], rc[0]);
    CHECK(rc[1] == 0 && wrong[1] == 0, "%s, 2 threads: exactly once too (%ld wrong)",
          what, wrong[1]);
    CHECK(rc[0] == 0 && rc[1] == 0 &&
          !memcmp(depth[0], depth[1], (size_t)nr * sizeof(int)) &&
          !memcmp(pos[0], pos[1], (size_t)nr * 3 * sizeof(double)),
          "%s: the same hits bit for bit with 1 and 2 threads", what);
    for (int th = 0; th < 2; th++) { free(depth[th]); free(pos[th]); }
    free(rays);
    free(tp);
}

/* The scene reader's open cap: radius 5, aperture 3, its pole and seam closed by
 * index. */
static void open_cap(void)
{
    sc_surface s = {0};
    s.shape = SC_CAP;
    s.kind = SC_REFRACT;
    s.n1 = s.n2 = 1;
    s.axis[2] = 1;
    s.radius = 5;
    s.aperture = 3;
    double *tri;
    long ntri;
    char err[SC_ERRMAX];
    int rc = sc_tessellate(&s, 8, &tri, &ntri, err);
    CHECK(rc == 0 && ntri > 100, "cap tessellated: %ld triangles %s", ntri,
          rc ? err : "");
    if (rc) return;
    double up[3] = {0, 0, 1};
    crossings("open tessellated cap", tri, ntri, up, 50);
    /* in a scene 1e4 times its size: Embree's float rays stray by more than its
     * triangles' margin can grow; still decided in double */
    crossings("open cap inside a detector of radius 1e5", tri, ntri, up, 1e5);
    free(tri);
}

/* An OBJ grid sheet, n x n squares cut along alternating diagonals, gently waved so
 * neighbouring triangles are not coplanar; read by the OBJ parser (a soup). */
static void obj_sheet(void)
{
    const int n = 12;
    size_t cap = 1 << 16, len = 0;
    char *txt = malloc(cap);
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            double x = -1 + 2.0 * i / n, y = -1 + 2.0 * j / n;
            len += (size_t)snprintf(txt + len, cap - len, "v %.17g %.17g %.17g\n", x, y,
                                    0.05 * sin(3 * x) * cos(2 * y));
        }
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            int a = j * (n + 1) + i + 1, b = a + 1, c = a + n + 1, d = c + 1;
            if ((i + j) % 2)
                len += (size_t)snprintf(txt + len, cap - len, "f %d %d %d\nf %d %d %d\n",
                                        a, b, d, a, d, c);
            else
                len += (size_t)snprintf(txt + len, cap - len, "f %d %d %d\nf %d %d %d\n",
                                        a, b, c, b, d, c);
        }
    double *tri;
    long ntri;
    char err[SC_ERRMAX];
    int rc = sc_parse_obj(txt, len, "sheet.obj", &tri, &ntri, err);
    CHECK(rc == 0 && ntri == 2 * n * n, "OBJ sheet read: %ld triangles %s", ntri,
          rc ? err : "");
    free(txt);
    if (rc) return;
    double up[3] = {0, 0, 1};
    crossings("open OBJ grid sheet", tri, ntri, up, 50);
    free(tri);
}

int main(void)
{
    tr = tt_api();
    open_cap();
    obj_sheet();
    return unit_failed();
}
