/* t_mesh.c -- triangle meshes in the trace engine: rays fired exactly at the edges
 * and vertices of closed meshes (from outside and inside) never leak; no
 * self-intersection acne on meshes or analytic surfaces, and thin features are not
 * skipped; hits refined in double to the triangle plane or the underlying analytic
 * surface; bad meshes and parameters are refused with a message. */
#include <stdio.h>
#include "unit.h"
#include "tt.h"
#include "mesh.h"

static const trace_api *tr;

static int balance_ok(const trace_summary *s)
{
    double e = s->detected + s->absorbed + s->escaped + s->cutoff;
    return s->emitted > 0 && fabs(e - s->emitted) <= 1e-9 * s->emitted;
}

/* Targets on the mesh: every vertex, and points at 1/2 and 1/4 along every edge. */
static double *targets(const tmesh *m, long *n)
{
    double *p = malloc((size_t)(m->nv + 6 * m->nt) * 3 * sizeof(double));
    long k = 0;
    for (long i = 0; i < m->nv; i++, k++)
        for (int q = 0; q < 3; q++) p[3 * k + q] = m->v[3 * i + q];
    for (long t = 0; t < m->nt; t++)
        for (int e = 0; e < 3; e++) {
            const double *a = m->v + 3 * m->t[3 * t + e];
            const double *b = m->v + 3 * m->t[3 * t + (e + 1) % 3];
            for (int f = 1; f <= 2; f++, k++)
                for (int q = 0; q < 3; q++)
                    p[3 * k + q] = a[q] + (b[q] - a[q]) / (2.0 * f);
        }
    *n = k;
    return p;
}

static void leaks(const char *what, tmesh *m, int inside)
{
    long nt;
    double *tp = targets(m, &nt);
    long nr = inside ? nt : 7 * nt;
    trace_ray *rays = malloc((size_t)nr * sizeof *rays);
    long k = 0;
    for (long i = 0; i < nt; i++) {
        int reps = inside ? 1 : 7;
        for (int r = 0; r < reps; r++, k++) {
            double *o = rays[k].o, *d = rays[k].d;
            if (inside) { o[0] = 0.01; o[1] = -0.02; o[2] = 0.015; }
            else {
                /* origins around the target, outside: along the radial direction
                 * tilted by a few angles */
                double a = 0.4 + 0.7 * r, b = 0.3 * r - 0.9;
                double rad[3] = {tp[3 * i], tp[3 * i + 1], tp[3 * i + 2]};
                double l = sqrt(rad[0] * rad[0] + rad[1] * rad[1] + rad[2] * rad[2]);
                for (int q = 0; q < 3; q++) o[q] = tp[3 * i + q] + 3 * rad[q] / l;
                o[0] += 0.8 * cos(a) * sin(b); o[1] += 0.8 * sin(a) * sin(b);
                o[2] += 0.8 * cos(b) * 0.5;
            }
            for (int q = 0; q < 3; q++) d[q] = tp[3 * i + q] - o[q];
            rays[k].power = 1;
        }
    }
    trace_scene *sc = tr->scene_new();
    trace_mesh mesh = {m->v, m->nv, m->t, m->nt, NULL, NULL, 0, 0};
    trace_material ab = {TRACE_ABSORB, 1, 1};
    int id = tr->add_mesh(sc, &mesh, &ab);
    trace_source src = {0};
    src.type = TRACE_SRC_RAYS; src.count = nr; src.ray = rays;
    int rc = tr->add_source(sc, &src, NULL);
    trace_summary sum;
    if (id >= 0 && rc == 0) rc = tr->run(sc, NULL, NULL, &sum);
    CHECK(id >= 0 && rc == 0 && sum.absorbed == sum.emitted && sum.escaped == 0 &&
          sum.rays == (uint64_t)nr,
          "%s, %s: %ld rays aimed at vertices and edges, all absorbed (%llu escaped)",
          what, inside ? "from inside" : "from outside", nr,
          (unsigned long long)(rc == 0 ? (uint64_t)(sum.escaped * nr / sum.emitted) : 0));
    tr->scene_free(sc);
    free(rays);
    free(tp);
}

/* glass ball meshed: rays from inside toward every vertex/edge must cross the mesh */
static void glass_edges(void)
{
    tmesh m = {0};
    tm_sphere(&m, 1, 6);
    long nt;
    double *tp = targets(&m, &nt);
    trace_ray *rays = malloc((size_t)nt * sizeof *rays);
    for (long i = 0; i < nt; i++) {
        rays[i].o[0] = rays[i].o[1] = rays[i].o[2] = 0;
        for (int q = 0; q < 3; q++) rays[i].d[q] = tp[3 * i + q];
        rays[i].power = 1;
    }
    trace_scene *sc = tr->scene_new();
    trace_mesh mesh = {m.v, m.nv, m.t, m.nt, NULL, NULL, 0, 0};
    trace_material g = {TRACE_REFRACT, 1.0, 1.5};
    tr->add_mesh(sc, &mesh, &g);
    trace_surface det = {0};
    trace_material md = {TRACE_DETECT, 1, 1};
    det.shape = TRACE_SPHERE; det.radius = 5;
    tr->add_surface(sc, &det, &md);
    trace_source src = {0};
    src.type = TRACE_SRC_RAYS; src.count = nt; src.ray = rays; src.n_medium = 1.5;
    tr->add_source(sc, &src, NULL);
    trace_options o;
    tr->options_default(&o);
    o.reflections = 0;
    trace_summary sum;
    int rc = tr->run(sc, &o, NULL, &sum);
    /* every ray interacts with the mesh once (refraction or TIR) before anything */
    CHECK(rc == 0 && sum.medium_mismatch == 0 && sum.interactions >= (uint64_t)nt &&
          balance_ok(&sum),
          "glass geodesic sphere: %ld rays from inside at vertices/edges all meet the "
          "mesh (%llu interactions, %llu mismatches)", nt,
          (unsigned long long)sum.interactions, (unsigned long long)sum.medium_mismatch);
    tr->scene_free(sc);
    free(rays); free(tp); free(m.v); free(m.t);
}

typedef struct acne { long short_seg, n; double minlen; } acne;
static int seg_len(void *ctx, const trace_segment *s)
{
    acne *a = ctx;
    double l = sqrt(pow(s->p1[0] - s->p0[0], 2) + pow(s->p1[1] - s->p0[1], 2) +
                    pow(s->p1[2] - s->p0[2], 2));
    a->n++;
    if (s->depth > 0 && l < a->minlen) a->short_seg++;
    return 0;
}

static void no_acne(void)
{
    for (int mesh_or_not = 0; mesh_or_not < 2; mesh_or_not++) {
        tmesh m = {0};
        trace_scene *sc = tr->scene_new();
        trace_material g = {TRACE_REFRACT, 1.0, 1.5};
        if (mesh_or_not) {
            tm_sphere(&m, 1, 12);
            trace_mesh mesh = {m.v, m.nv, m.t, m.nt, NULL, NULL, 0, 0};
            tr->add_mesh(sc, &mesh, &g);
        } else {
            trace_surface s = {0};
            s.shape = TRACE_SPHERE; s.radius = 1;
            tr->add_surface(sc, &s, &g);
        }
        trace_source src = {0};
        src.type = TRACE_SRC_GRID; src.at[2] = -3; src.dir[2] = 1; src.radius = 0.999;
        src.count = 40;
        tr->add_source(sc, &src, NULL);
        trace_options o;
        tr->options_default(&o);
        o.cutoff = 1e-7;
        o.max_depth = 40;
        acne a = {0, 0, 1e-6};
        trace_sink sink = {&a, seg_len, NULL, NULL};
        trace_summary sum;
        int rc = tr->run(sc, &o, &sink, &sum);
        CHECK(rc == 0 && a.short_seg == 0 && a.n > 1000 && balance_ok(&sum),
              "%s glass sphere: %ld segments, none shorter than 1e-6 after an "
              "interaction (acne), energy balance", mesh_or_not ? "meshed" : "analytic",
              a.n);
        tr->scene_free(sc);
        free(m.v); free(m.t);
    }
    /* a thin film: two analytic planes 1e-9 apart are both met */
    trace_scene *sc = tr->scene_new();
    trace_surface p = {0};
    trace_material g1 = {TRACE_REFRACT, 1, 1.5}, g2 = {TRACE_REFRACT, 1.5, 1};
    p.shape = TRACE_PLANE; p.aperture = TRACE_AP_DISC; p.r_outer = 10; p.axis[2] = 1;
    tr->add_surface(sc, &p, &g1);
    p.at[2] = 1e-9;
    tr->add_surface(sc, &p, &g2);
    trace_ray r = {{0, 0, -1}, {0.2, 0, 1}, 1};
    trace_source src = {0};
    src.type = TRACE_SRC_RAYS; src.count = 1; src.ray = &r;
    tr->add_source(sc, &src, NULL);
    trace_options o;
    tr->options_default(&o);
    o.reflections = 0;
    trace_summary sum;
    tr->run(sc, &o, NULL, &sum);
    CHECK(sum.interactions == 2 && sum.medium_mismatch == 0,
          "film 1e-9 thick: both faces met (%llu interactions)",
          (unsigned long long)sum.interactions);
    tr->scene_free(sc);
}

typedef struct spot { double p[400][3]; int n; } spot;
static int keep_pos(void *ctx, const trace_hit *h)
{
    spot *s = ctx;
    if (h->ray < 400) { memcpy(s->p[h->ray], h->pos, sizeof h->pos); s->n++; }
    return 0;
}

/* Lens of two spherical caps: analytic, and meshed with each refinement. */
static double ball_lens(int how, int float_hits, spot *sp)
{
    trace_scene *sc = tr->scene_new();
    trace_material g = {TRACE_REFRACT, 1.0, 1.5};
    trace_surface s = {0};
    s.shape = TRACE_SPHERE; s.radius = 1;
    tmesh m = {0};
    if (how < 0) tr->add_surface(sc, &s, &g);
    else {
        tm_sphere(&m, 1, 24);
        trace_mesh mesh = {m.v, m.nv, m.t, m.nt, NULL, &s, how, 0};
        tr->add_mesh(sc, &mesh, &g);
    }
    trace_surface det = {0};
    trace_material md = {TRACE_DETECT, 1, 1};
    det.shape = TRACE_PLANE; det.aperture = TRACE_AP_DISC; det.r_outer = 100;
    det.at[2] = 3; det.axis[2] = 1;
    tr->add_surface(sc, &det, &md);
    trace_source src = {0};
    src.type = TRACE_SRC_GRID; src.at[2] = -3; src.dir[2] = 1; src.radius = 0.5;
    src.count = 20; src.up[1] = 1;
    tr->add_source(sc, &src, NULL);
    trace_options o;
    tr->options_default(&o);
    o.reflections = 0;
    o.float_hits = float_hits;
    sp->n = 0;
    trace_sink sink = {sp, NULL, keep_pos, NULL};
    tr->run(sc, &o, &sink, NULL);
    tr->scene_free(sc);
    free(m.v); free(m.t);
    return 0;
}

static void refinement(void)
{
    static spot ref, none, normal, full;
    ball_lens(-1, 0, &ref);
    ball_lens(TRACE_REFINE_NONE, 0, &none);
    ball_lens(TRACE_REFINE_NORMAL, 0, &normal);
    ball_lens(TRACE_REFINE_FULL, 0, &full);
    double e[3] = {0, 0, 0};
    spot *s[3] = {&none, &normal, &full};
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < ref.n; i++)
            e[k] = fmax(e[k], hypot(s[k]->p[i][0] - ref.p[i][0], s[k]->p[i][1] - ref.p[i][1]));
    CHECK(ref.n > 250 && full.n == ref.n && e[2] < 1e-9,
          "meshed ball lens refined to its sphere: spots within %.1e of the analytic "
          "trace (%d rays)", e[2], ref.n);
    CHECK(e[0] > 1e-3 && e[1] < e[0] && e[2] < 1e-6 * e[0],
          "refinement matters: flat facets off by %.1e, tangent plane %.1e", e[0], e[1]);
}

/* A flat mesh far from the origin: double re-intersection vs Embree's float hit. */
static void mesh_double(void)
{
    double err[2];
    for (int fl = 0; fl < 2; fl++) {
        double v[12] = {-10, -10, 1000.123456789, 10, -10, 1000.123456789,
                        10, 10, 1000.123456789, -10, 10, 1000.123456789};
        uint32_t ix[6] = {0, 1, 2, 0, 2, 3};
        trace_scene *sc = tr->scene_new();
        trace_mesh mesh = {v, 4, ix, 2, NULL, NULL, 0, 0};
        trace_material md = {TRACE_DETECT, 1, 1};
        tr->add_mesh(sc, &mesh, &md);
        trace_source src = {0};
        src.type = TRACE_SRC_AIMED; src.count = 50;
        src.to0[0] = -9.1; src.to0[1] = 3.3; src.to0[2] = 1000.123456789;
        src.to1[0] = 8.7; src.to1[1] = -2.9; src.to1[2] = 1000.123456789;
        src.at[0] = 0.1; src.at[1] = 0.2; src.at[2] = 0.3;
        tr->add_source(sc, &src, NULL);
        static spot sp;
        sp.n = 0;
        trace_options o;
        tr->options_default(&o);
        o.float_hits = fl;
        trace_sink sink = {&sp, NULL, keep_pos, NULL};
        tr->run(sc, &o, &sink, NULL);
        err[fl] = 0;
        for (int i = 0; i < sp.n; i++) err[fl] = fmax(err[fl], fabs(sp.p[i][2] - 1000.123456789));
        tr->scene_free(sc);
    }
    CHECK(err[0] < 1e-11 && err[1] > 1e-6, "mesh hits re-intersected in double: %.1e off "
          "the plane (Embree's float hit: %.1e)", err[0], err[1]);
}

static void bad_input(void)
{
    trace_scene *sc = tr->scene_new();
    trace_material ok = {TRACE_REFRACT, 1, 1.5}, neg = {TRACE_REFRACT, -1, 1.5};
    double v[9] = {0, 0, 0, 1, 0, 0, 2, 0, 0};        /* collinear */
    trace_mesh mesh = {v, 3, NULL, 1, NULL, NULL, 0, 0};
    int rc = tr->add_mesh(sc, &mesh, &ok);
    CHECK(rc == TRACE_EINVAL && strstr(tr->error(sc), "triangle 1") &&
          strstr(tr->error(sc), "degenerate"), "degenerate triangle refused: %s",
          tr->error(sc));
    double w[9] = {0, 0, 0, 1, 0, 0, 0, NAN, 0};
    mesh.vertex = w;
    rc = tr->add_mesh(sc, &mesh, &ok);
    CHECK(rc == TRACE_EINVAL && strstr(tr->error(sc), "not finite"), "NaN vertex: %s",
          tr->error(sc));
    double u[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    uint32_t ix[3] = {0, 1, 7};
    trace_mesh m2 = {u, 3, ix, 1, NULL, NULL, 0, 0};
    rc = tr->add_mesh(sc, &m2, &ok);
    CHECK(rc == TRACE_EINVAL && strstr(tr->error(sc), "out of range"), "bad index: %s",
          tr->error(sc));
    double media[2] = {1.0, -1.5};
    trace_mesh m3 = {u, 3, NULL, 1, media, NULL, 0, 0};
    rc = tr->add_mesh(sc, &m3, &ok);
    CHECK(rc == TRACE_EINVAL && strstr(tr->error(sc), "indices"), "negative medium: %s",
          tr->error(sc));
    trace_surface s = {0};
    s.shape = TRACE_AXIAL; s.axis[2] = 1; s.radius = 10; s.r_outer = 11;
    rc = tr->add_surface(sc, &s, &ok);
    CHECK(rc == TRACE_EINVAL && strstr(tr->error(sc), "no real surface"),
          "conic beyond its rim: %s", tr->error(sc));
    s.r_outer = 5;
    rc = tr->add_surface(sc, &s, &neg);
    CHECK(rc == TRACE_EINVAL && strstr(tr->error(sc), "positive"), "negative index: %s",
          tr->error(sc));
    s.axis[2] = 0;
    rc = tr->add_surface(sc, &s, &ok);
    CHECK(rc == TRACE_EINVAL && strstr(tr->error(sc), "zero"), "zero axis: %s",
          tr->error(sc));
    trace_ray r = {{0, 0, 0}, {0, 0, 0}, 1};
    trace_source src = {0};
    src.type = TRACE_SRC_RAYS; src.count = 1; src.ray = &r;
    rc = tr->add_source(sc, &src, NULL);
    CHECK(rc == TRACE_EINVAL && strstr(tr->error(sc), "zero"), "zero-direction ray: %s",
          tr->error(sc));
    trace_options o;
    tr->options_default(&o);
    o.cutoff = 2;
    rc = tr->run(sc, &o, NULL, NULL);
    CHECK(rc == TRACE_EINVAL && strstr(tr->error(sc), "cutoff"), "bad cutoff: %s",
          tr->error(sc));
    CHECK(trace_get_api(TRACE_ABI + 1) == NULL, "a wrong ABI gets no table");
    tr->scene_free(sc);
}

/* A mesh used in place (trace_mesh.shared) traces as the copied one, to the bit: a
 * glass sphere with Fresnel and reflections, every segment's end point summed. */
typedef struct segsum { double x; long n; } segsum;
static int add_seg(void *ctx, const trace_segment *g)
{
    segsum *s = ctx;
    s->x += g->p1[0] + 3 * g->p1[1] + 7 * g->p1[2] + g->power;
    s->n++;
    return 0;
}
static void shared_mesh(void)
{
    tmesh m = {0};
    tm_sphere(&m, 1, 20);
    segsum r[2] = {{0, 0}, {0, 0}};
    trace_summary sum[2];
    for (int k = 0; k < 2; k++) {
        trace_scene *sc = tr->scene_new();
        trace_mesh mesh = {m.v, m.nv, m.t, m.nt, NULL, NULL, 0, k};
        trace_material g = {TRACE_REFRACT, 1.0, 1.5};
        tr->add_mesh(sc, &mesh, &g);
        trace_source src = {0};
        src.type = TRACE_SRC_GRID; src.at[2] = -3; src.dir[2] = 1; src.up[1] = 1;
        src.radius = 0.99; src.count = 40;
        tr->add_source(sc, &src, NULL);
        trace_sink sink = {&r[k], add_seg, NULL, NULL};
        tr->run(sc, NULL, &sink, &sum[k]);
        tr->scene_free(sc);
    }
    CHECK(r[0].n > 1000 && r[0].n == r[1].n && r[0].x == r[1].x &&
          sum[0].detected == sum[1].detected && sum[0].escaped == sum[1].escaped,
          "a mesh used in place traces as the copied one: %ld and %ld segments, sums "
          "%.17g and %.17g", r[0].n, r[1].n, r[0].x, r[1].x);
    free(m.v); free(m.t);
}

/* A mesh scene's few analytic surfaces are asked in double before Embree's query
 * (at most TR_INLINE_MAX = 4), more of them through Embree's user geometry: the same
 * bits either way.  A glass sphere mesh with Fresnel and reflections, a window plane,
 * a spherical shell of index 1, a tilted detector (not an aligned plane) and an
 * absorber; then the same with a fifth surface, a tiny absorber far off that no ray
 * meets, which sends all five through Embree.  Default and float hits. */
static void add_plane_at(trace_scene *sc, const double at[3], const double ax[3], double r,
                         int kind)
{
    trace_surface p = {0};
    trace_material m = {kind, 1, 1};
    p.shape = TRACE_PLANE;
    p.aperture = TRACE_AP_DISC;
    p.r_outer = r;
    memcpy(p.at, at, sizeof p.at);
    memcpy(p.axis, ax, sizeof p.axis);
    if (tr->add_surface(sc, &p, &m) < 0) CHECK(0, "plane: %s", tr->error(sc));
}
static void inline_analytic(void)
{
    tmesh m = {0};
    tm_sphere(&m, 1, 20);
    for (int fh = 0; fh < 2; fh++) {
        segsum r[2] = {{0, 0}, {0, 0}};
        trace_summary sum[2];
        for (int k = 0; k < 2; k++) {
            trace_scene *sc = tr->scene_new();
            trace_mesh mesh = {m.v, m.nv, m.t, m.nt, NULL, NULL, 0, 0};
            trace_material g = {TRACE_REFRACT, 1.0, 1.5};
            tr->add_mesh(sc, &mesh, &g);
            add_plane_at(sc, (double[3]){0, 0, -2}, (double[3]){0, 0, 1}, 3, TRACE_REFRACT);
            trace_surface sh = {0};
            trace_material one = {TRACE_REFRACT, 1, 1};
            sh.shape = TRACE_SPHERE;
            sh.radius = 2.5;
            if (tr->add_surface(sc, &sh, &one) < 0) CHECK(0, "shell: %s", tr->error(sc));
            add_plane_at(sc, (double[3]){0, 0, 6}, (double[3]){0, 0.6, 0.8}, 100, TRACE_DETECT);
            add_plane_at(sc, (double[3]){0, 0, -20}, (double[3]){0, 0, 1}, 100, TRACE_ABSORB);
            if (k)
                add_plane_at(sc, (double[3]){1000, 1000, 1000}, (double[3]){1, 0, 0}, 1e-3,
                             TRACE_ABSORB);
            trace_source src = {0};
            src.type = TRACE_SRC_GRID; src.at[2] = -3; src.dir[2] = 1; src.up[1] = 1;
            src.radius = 0.99; src.count = 30;
            tr->add_source(sc, &src, NULL);
            trace_options o;
            tr->options_default(&o);
            o.float_hits = fh;
            trace_sink sink = {&r[k], add_seg, NULL, NULL};
            int rc = tr->run(sc, &o, &sink, &sum[k]);
            CHECK(rc == 0, "inline analytic run: %s", tr->error(sc));
            tr->scene_free(sc);
        }
        CHECK(r[0].n > 1000 && r[0].n == r[1].n && r[0].x == r[1].x && sum[0].hits > 100 &&
              sum[0].hits == sum[1].hits && sum[0].detected == sum[1].detected &&
              sum[0].absorbed == sum[1].absorbed && sum[0].escaped == sum[1].escaped &&
              sum[0].interactions == sum[1].interactions,
              "four analytic surfaces asked before Embree trace as five through it%s: %ld "
              "and %ld segments, sums %.17g and %.17g, %llu and %llu hits",
              fh ? " (float hits)" : "", r[0].n, r[1].n, r[0].x, r[1].x,
              (unsigned long long)sum[0].hits, (unsigned long long)sum[1].hits);
    }
    free(m.v); free(m.t);
}

int main(void)
{
    tr = tt_api();
    tmesh oct = {0}, geo = {0};
    tm_octahedron(&oct, 1);
    tm_sphere(&geo, 1, 8);
    CHECK(geo.nt == 512 && geo.nv == 258, "geodesic sphere: %ld triangles, %ld shared "
          "vertices", geo.nt, geo.nv);
    leaks("octahedron", &oct, 0);
    leaks("octahedron", &oct, 1);
    leaks("geodesic sphere", &geo, 0);
    leaks("geodesic sphere", &geo, 1);
    glass_edges();
    no_acne();
    refinement();
    mesh_double();
    bad_input();
    shared_mesh();
    inline_analytic();
    free(oct.v); free(oct.t); free(geo.v); free(geo.t);
    return unit_failed();
}
