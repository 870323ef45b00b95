/* bench_mesh.c -- the BVH path against bare Embree, per segment, on the scenes users
 * trace (issue 23): every scene is traced as a user's scene file is (Fresnel on,
 * reflections followed, the default cutoff, one thread, the build done before the
 * clock starts), its segments collected in a second run, and the same segments then
 * asked of a bare Embree scene holding the same triangles with the same flags, and
 * each of the scene's planes (detectors, a window) as two triangles, a square over
 * its disc (rtcIntersect1, one query per segment: the least any tracer must do; bare
 * Embree has no analytic surfaces, and without them it would be spared finding the
 * detector every segment that ends there must find).  Scenes:
 *   refract   a glass sphere (n 1.5) of 100 352 triangles with a detector 50 mm away
 *             (disc 50), as in a scene file: the figure
 *   alone     the same sphere with no detector (Embree's box is the sphere's)
 *   mirror    the sphere as a mirror
 *   tir       a right-angle glass prism mesh (8 triangles) whose hypotenuse totally
 *             reflects, a detector beyond the exit face
 *   mix       the sphere behind an analytic plane window
 * The comment line of each gives what bare Embree's packet query rtcIntersect8 makes of
 * the same segments taken 8 at a time in the order they were traced (depth first: a
 * ray's segments one after the other), and in generation order (depth, direction
 * along z, ray: grid neighbours side by side, as a breadth-first tracer would ask),
 * against rtcIntersect1: the most packets could give the tracer.
 * Prints BENCH trace_mesh_vs_raw_embree (refract) and
 * trace_mesh_vs_raw_embree_{alone,mirror,tir,mix}: (segments per second traced) /
 * (segments per second replayed), medians of three back-to-back pairs. */
#include <embree3/rtcore.h>
#include <stdio.h>
#include "tt.h"
#include "mesh.h"
#include "bench_util.h"

static const trace_api *tr;

typedef struct segs { float *o, *d; long *key; long n, cap; } segs;
static int keep_seg(void *ctx, const trace_segment *s)
{
    segs *g = ctx;
    if (g->n == g->cap) {
        long cap = g->cap ? 2 * g->cap : 1 << 16;
        float *o = realloc(g->o, (size_t)cap * 3 * sizeof *o), *d;
        if (!o) return 1;
        g->o = o;
        if (!(d = realloc(g->d, (size_t)cap * 3 * sizeof *d))) return 1;
        g->d = d;
        long *k = realloc(g->key, (size_t)cap * sizeof *k);
        if (!k) return 1;
        g->key = k;
        g->cap = cap;
    }
    for (int i = 0; i < 3; i++) {
        g->o[3 * g->n + i] = (float)s->p0[i];
        g->d[3 * g->n + i] = (float)(s->p1[i] - s->p0[i]);
    }
    /* generation by generation: depth, then going +z or -z, then the ray */
    g->key[g->n] = ((long)s->depth << 40) | ((long)(s->p1[2] < s->p0[2]) << 39) | (long)s->ray;
    g->n++;
    return 0;
}

static void opts(trace_options *o)
{
    tr->options_default(o);     /* Fresnel on, reflections on, the default cutoff */
    o->threads = 1;
}

/* full trace, build excluded: segments per second */
static double traced(trace_scene *sc, uint64_t *nseg)
{
    trace_options o;
    trace_summary sum;
    opts(&o);
    tr->build(sc, NULL);
    double t0 = now();
    if (tr->run(sc, &o, NULL, &sum)) { fprintf(stderr, "%s\n", tr->error(sc)); exit(1); }
    double dt = now() - t0;
    if (nseg) *nseg = sum.segments;
    return sum.segments / dt;
}

static segs collect(trace_scene *sc)
{
    segs g = {0};
    trace_options o;
    opts(&o);
    trace_sink sink = {&g, keep_seg, NULL, NULL};
    tr->run(sc, &o, &sink, NULL);
    return g;
}

/* The scene's planes, for the bare side: centre, two unit axes in the plane, the
 * square's half side (the disc's radius). */
typedef struct quad { double c[3], u[3], v[3], h; } quad;
static quad planes[4];
static int nplanes;

/* bare Embree on the triangles of m and the planes (built once), the segments
 * replayed */
typedef struct raw { RTCDevice dev; RTCScene scn; } raw;
static raw raw_new(const tmesh *m)
{
    raw r;
    r.dev = rtcNewDevice(NULL);
    r.scn = rtcNewScene(r.dev);
    rtcSetSceneFlags(r.scn, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(r.scn, RTC_BUILD_QUALITY_MEDIUM);
    RTCGeometry geo = rtcNewGeometry(r.dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *v = rtcSetNewGeometryBuffer(geo, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                       12, (size_t)(m->nv + 4 * nplanes));
    unsigned *ix = rtcSetNewGeometryBuffer(geo, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                           12, (size_t)(m->nt + 2 * nplanes));
    for (long i = 0; i < 3 * m->nv; i++) v[i] = (float)m->v[i];
    memcpy(ix, m->t, (size_t)m->nt * 12);
    for (int k = 0; k < nplanes; k++) {
        const quad *q = &planes[k];
        unsigned b = (unsigned)(m->nv + 4 * k), *t = ix + 3 * (m->nt + 2 * k);
        for (int c = 0; c < 4; c++) {
            double su = c & 1 ? q->h : -q->h, sv = c & 2 ? q->h : -q->h;
            for (int j = 0; j < 3; j++)
                v[3 * (b + c) + j] = (float)(q->c[j] + su * q->u[j] + sv * q->v[j]);
        }
        t[0] = b; t[1] = b + 1; t[2] = b + 3;
        t[3] = b; t[4] = b + 3; t[5] = b + 2;
    }
    rtcCommitGeometry(geo);
    rtcAttachGeometry(r.scn, geo);
    rtcReleaseGeometry(geo);
    rtcCommitScene(r.scn);
    return r;
}

static double replayed(const raw *r, const segs *g)
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    long hits = 0;
    double t0 = now();
    for (long i = 0; i < g->n; i++) {
        struct RTCRayHit rh;
        rh.ray.org_x = g->o[3 * i]; rh.ray.org_y = g->o[3 * i + 1]; rh.ray.org_z = g->o[3 * i + 2];
        rh.ray.dir_x = g->d[3 * i]; rh.ray.dir_y = g->d[3 * i + 1]; rh.ray.dir_z = g->d[3 * i + 2];
        rh.ray.tnear = 1e-4f; rh.ray.tfar = INFINITY; rh.ray.time = 0;
        rh.ray.mask = 0xFFFFFFFFu; rh.ray.id = 0; rh.ray.flags = 0;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(r->scn, &ctx, &rh);
        hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    }
    double dt = now() - t0;
    if (hits == 0) fprintf(stderr, "bench_mesh: raw Embree found no hits\n");
    return g->n / dt;
}

/* The same segments as packets of 8 consecutive ones (rtcIntersect8: what Embree's
 * packet queries would give the tracer on coherent rays, at most) */
static double replayed8(const raw *r, const segs *g)
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    long hits = 0;
    double t0 = now();
    for (long i = 0; i < g->n; i += 8) {
        struct RTCRayHit8 rh;
        int valid[8];
        for (int k = 0; k < 8; k++) {
            long j = i + k < g->n ? i + k : g->n - 1;
            valid[k] = i + k < g->n ? -1 : 0;
            rh.ray.org_x[k] = g->o[3 * j]; rh.ray.org_y[k] = g->o[3 * j + 1];
            rh.ray.org_z[k] = g->o[3 * j + 2];
            rh.ray.dir_x[k] = g->d[3 * j]; rh.ray.dir_y[k] = g->d[3 * j + 1];
            rh.ray.dir_z[k] = g->d[3 * j + 2];
            rh.ray.tnear[k] = 1e-4f; rh.ray.tfar[k] = INFINITY; rh.ray.time[k] = 0;
            rh.ray.mask[k] = 0xFFFFFFFFu; rh.ray.id[k] = 0; rh.ray.flags[k] = 0;
            rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect8(valid, r->scn, &ctx, &rh);
        for (int k = 0; k < 8; k++) hits += valid[k] && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
    }
    double dt = now() - t0;
    if (hits == 0) fprintf(stderr, "bench_mesh: raw Embree (x8) found no hits\n");
    return g->n / dt;
}

/* The segments in generation order (depth, direction along z, ray: what a tracer
 * going breadth-first would ask, neighbours in the grid side by side), as a copy. */
static segs *cmp_keys;
static int cmp_gen(const void *a, const void *b)
{
    long i = *(const long *)a, j = *(const long *)b;
    long ki = cmp_keys->key[i], kj = cmp_keys->key[j];
    return ki < kj ? -1 : ki > kj ? 1 : (i > j) - (i < j);
}
static segs by_generation(segs *g)
{
    segs h = {0};
    long *ix = malloc((size_t)g->n * sizeof *ix);
    h.o = malloc((size_t)g->n * 3 * sizeof *h.o);
    h.d = malloc((size_t)g->n * 3 * sizeof *h.d);
    if (!ix || !h.o || !h.d) { fprintf(stderr, "bench_mesh: out of memory\n"); exit(1); }
    for (long i = 0; i < g->n; i++) ix[i] = i;
    cmp_keys = g;
    qsort(ix, (size_t)g->n, sizeof *ix, cmp_gen);
    for (long i = 0; i < g->n; i++) {
        memcpy(h.o + 3 * i, g->o + 3 * ix[i], 3 * sizeof *h.o);
        memcpy(h.d + 3 * i, g->d + 3 * ix[i], 3 * sizeof *h.d);
    }
    h.n = g->n;
    free(ix);
    return h;
}

static void add_plane(trace_scene *sc, double z, double r, int kind, double n2)
{
    trace_surface p = {0};
    p.shape = TRACE_PLANE;
    p.at[2] = z;
    p.axis[2] = 1;
    p.aperture = TRACE_AP_DISC;
    p.r_outer = r;
    trace_material m = {kind, 1, n2};
    if (tr->add_surface(sc, &p, &m) < 0) { fprintf(stderr, "%s\n", tr->error(sc)); exit(1); }
    planes[nplanes++] = (quad){{0, 0, z}, {1, 0, 0}, {0, 1, 0}, r};
}

static void add_grid(trace_scene *sc, double z, double radius, double y0, long across)
{
    trace_source s = {0};
    s.type = TRACE_SRC_GRID;
    s.at[1] = y0; s.at[2] = z; s.dir[2] = 1; s.up[1] = 1;
    s.radius = radius;
    s.count = across;
    tr->add_source(sc, &s, NULL);
}

static trace_scene *mesh_scene(const tmesh *m, int kind, double n)
{
    trace_scene *sc = tr->scene_new();
    nplanes = 0;
    trace_mesh mesh = {m->v, m->nv, m->t, m->nt, NULL, NULL, 0, 0};
    trace_material g = {kind, 1.0, n};
    if (tr->add_mesh(sc, &mesh, &g) < 0) { fprintf(stderr, "%s\n", tr->error(sc)); exit(1); }
    return sc;
}

/* A right-angle prism, 90-degree edge along x through the origin, legs 2 (z = 0 and
 * y = 0), hypotenuse y + z = 2, x from -1 to 1: 8 triangles, normals out. */
static void prism(tmesh *m)
{
    long a = tm_vertex(m, -1, 0, 0), b = tm_vertex(m, -1, 2, 0), c = tm_vertex(m, -1, 0, 2);
    long d = tm_vertex(m, 1, 0, 0), e = tm_vertex(m, 1, 2, 0), f = tm_vertex(m, 1, 0, 2);
    tm_tri(m, a, c, b);                         /* x = -1 */
    tm_tri(m, d, e, f);                         /* x = +1 */
    tm_tri(m, a, b, e); tm_tri(m, a, e, d);     /* z = 0 */
    tm_tri(m, a, d, f); tm_tri(m, a, f, c);     /* y = 0 */
    tm_tri(m, b, c, f); tm_tri(m, b, f, e);     /* hypotenuse */
}

static void ratio(const char *name, trace_scene *sc, const tmesh *m)
{
    uint64_t nseg;
    traced(sc, &nseg);                                  /* warm up */
    segs g = collect(sc), h = by_generation(&g);
    raw r = raw_new(m);
    int np = nplanes;                   /* ... and without the planes (before 2026-12) */
    nplanes = 0;
    raw r0 = raw_new(m);
    nplanes = np;
    double q[3], q0[3], tf[3], p8[3], g8[3];
    for (int i = 0; i < 3; i++) {                       /* pairs back to back */
        tf[i] = traced(sc, NULL);
        double one = replayed(&r, &g);
        q[i] = tf[i] / one;
        q0[i] = np ? traced(sc, NULL) / replayed(&r0, &g) : q[i];
        p8[i] = replayed8(&r, &g) / one;
        g8[i] = replayed8(&r, &h) / one;
    }
    qsort(q, 3, sizeof *q, cmp);
    qsort(q0, 3, sizeof *q0, cmp);
    qsort(tf, 3, sizeof *tf, cmp);
    qsort(p8, 3, sizeof *p8, cmp);
    qsort(g8, 3, sizeof *g8, cmp);
    printf("# %s: %ld triangles, %llu segments a run, %.3f Msegments/s traced; bare "
           "Embree's rtcIntersect8 on 8 consecutive segments %.2f x its rtcIntersect1 "
           "(%.2f x taken generation by generation); the ratio against bare Embree "
           "without the scene's %d plane%s: %.3f\n",
           name, m->nt, (unsigned long long)nseg, tf[1] / 1e6, p8[1], g8[1], np,
           np == 1 ? "" : "s", q0[1]);
    printf("BENCH trace_mesh_vs_raw_embree%s%s %.3f ratio\n", strcmp(name, "refract") ? "_" : "",
           strcmp(name, "refract") ? name : "", q[1]);
    rtcReleaseScene(r.scn);
    rtcReleaseDevice(r.dev);
    rtcReleaseScene(r0.scn);
    rtcReleaseDevice(r0.dev);
    free(g.o);
    free(g.d);
    free(g.key);
    free(h.o);
    free(h.d);
}

int main(int argc, char **argv)
{
    int quick = argc > 1 && !strcmp(argv[1], "quick");
    long across = quick ? 120 : 250;
    tr = tt_api();
    tmesh ball = {0}, pr = {0};
    tm_sphere(&ball, 1, 112);
    trace_scene *sc = mesh_scene(&ball, TRACE_REFRACT, 1.5);
    add_plane(sc, 50, 50, TRACE_DETECT, 1);
    add_grid(sc, -3, 0.999, 0, across);
    ratio("refract", sc, &ball);
    tr->scene_free(sc);

    sc = mesh_scene(&ball, TRACE_REFRACT, 1.5);
    add_grid(sc, -3, 0.999, 0, across);
    ratio("alone", sc, &ball);
    tr->scene_free(sc);

    sc = mesh_scene(&ball, TRACE_MIRROR, 1);
    add_plane(sc, -10, 50, TRACE_DETECT, 1);
    add_grid(sc, -3, 0.999, 0, across);
    ratio("mirror", sc, &ball);
    tr->scene_free(sc);

    prism(&pr);
    sc = mesh_scene(&pr, TRACE_REFRACT, 1.5);
    trace_surface p = {0};                 /* a detector beyond the exit face y = 0 */
    p.shape = TRACE_PLANE;
    p.at[1] = -5; p.at[2] = 1;
    p.axis[1] = -1;
    p.aperture = TRACE_AP_DISC;
    p.r_outer = 20;
    trace_material dm = {TRACE_DETECT, 1, 1};
    tr->add_surface(sc, &p, &dm);
    planes[nplanes++] = (quad){{0, -5, 1}, {1, 0, 0}, {0, 0, 1}, 20};
    add_grid(sc, -1, 0.4, 0.6, across);
    ratio("tir", sc, &pr);
    tr->scene_free(sc);

    sc = mesh_scene(&ball, TRACE_REFRACT, 1.5);
    add_plane(sc, -2, 3, TRACE_REFRACT, 1);     /* a window: index 1 both sides */
    add_plane(sc, 50, 50, TRACE_DETECT, 1);
    add_grid(sc, -3, 0.999, 0, across);
    ratio("mix", sc, &ball);
    tr->scene_free(sc);
    return 0;
}
