/* t_seqscan.c -- a sequential lens found inside a scene built through the table
 * (tr_seqscan.c): add_lens's own hints are kept while the lens is alone; a surface or
 * mesh added after it makes the engine look again (stale hints never used), a mesh
 * between two elements cuts the lens there, a rebuild after another surface finds it
 * anew; every trace gives the bits of the BVH trace (sequential off): hits, segments
 * and summary compared bytewise; so do 300 random stacks of caps, conics, aspheres,
 * planes, spheres and meshes of every kind (decentred and tilted now and then, some
 * within another's sag) lit from both sides and from inside.  The summary says how
 * many surfaces took the lens path (trace_summary.lens_surfaces). */
#include <stdio.h>
#include "unit.h"
#include "tt.h"

typedef struct rec { void *p; size_t n, cap, size; } rec;
static int push(rec *r, const void *x, size_t size)
{
    if (r->n == r->cap) {
        r->cap = r->cap ? 2 * r->cap : 1024;
        r->p = realloc(r->p, r->cap * size);
        if (!r->p) return 1;
    }
    memcpy((char *)r->p + r->n++ * size, x, size);
    return 0;
}
typedef struct both { rec h, s; } both;
static int both_hit(void *ctx, const trace_hit *h) { return push(&((both *)ctx)->h, h, sizeof *h); }
static int both_seg(void *ctx, const trace_segment *g)
{
    return push(&((both *)ctx)->s, g, sizeof *g);
}

/* Trace sc with the lens path on (k = 1) and off; 1 if every record and the summary
 * are the same bits; *lens: the surfaces the lens path took. */
static int same_both_ways(const trace_api *tr, trace_scene *sc, int fresnel,
                          int reflections, int *lens, uint64_t *hits)
{
    both r[2];
    trace_summary sum[2];
    memset(r, 0, sizeof r);
    for (int k = 1; k >= 0; k--) {
        trace_options o;
        tr->options_default(&o);
        o.fresnel = fresnel;
        o.reflections = reflections;
        o.sequential = k;
        o.threads = 1;
        trace_sink sink = {&r[k], both_seg, both_hit, NULL};
        if (tr->run(sc, &o, &sink, &sum[k])) { printf("# %s\n", tr->error(sc)); return 0; }
    }
    *lens = sum[1].lens_surfaces;
    *hits = sum[1].hits;
    int same = sum[0].lens_surfaces == 0 && r[0].h.n == r[1].h.n && r[0].s.n == r[1].s.n &&
               (!r[0].h.n || !memcmp(r[0].h.p, r[1].h.p, r[0].h.n * sizeof(trace_hit))) &&
               (!r[0].s.n || !memcmp(r[0].s.p, r[1].s.p, r[0].s.n * sizeof(trace_segment))) &&
               !memcmp(&sum[0].rays, &sum[1].rays, 10 * sizeof(uint64_t)) &&
               sum[0].max_depth_seen == sum[1].max_depth_seen &&
               !memcmp(&sum[0].emitted, &sum[1].emitted, 5 * sizeof(double));
    for (int k = 0; k < 2; k++) { free(r[k].h.p); free(r[k].s.p); }
    return same;
}

static void add_grid(const trace_api *tr, trace_scene *sc, double z, long n)
{
    trace_source src = {0};
    src.type = TRACE_SRC_GRID;
    src.at[1] = 0.3; src.at[2] = z; src.dir[1] = 0.02; src.dir[2] = 1; src.up[1] = 1;
    src.radius = 7.9;
    src.count = n;
    tr->add_source(sc, &src, NULL);
}

static int add_plane(const trace_api *tr, trace_scene *sc, int kind, double z, double r)
{
    trace_surface p;
    trace_material m = {kind, 1, 1};
    memset(&p, 0, sizeof p);
    p.shape = TRACE_PLANE;
    p.at[2] = z;
    p.axis[2] = 1;
    p.aperture = TRACE_AP_DISC;
    p.r_outer = r;
    return tr->add_surface(sc, &p, &m);
}

/* ---- random scenes: whatever the engine makes of them, the same bits both ways ---- */
static uint64_t rng = 0x9e3779b97f4a7c15ULL;
static double rnd(void)                   /* [0, 1), xorshift64* */
{
    rng ^= rng >> 12; rng ^= rng << 25; rng ^= rng >> 27;
    return (double)((rng * 0x2545F4914F6CDD1DULL) >> 11) / 9007199254740992.0;
}
static double rr(double a, double b) { return a + (b - a) * rnd(); }

/* A stack of on-axis caps and planes (some the packet's, some not: a conic, an
 * asphere, a decentred or tilted one, a sphere, a mesh), of every kind, at random
 * places along z, with sources from both sides and from inside. */
static void random_scene(const trace_api *tr, trace_scene *sc)
{
    int ns = 3 + (int)(rnd() * 8);
    double z = 0;
    for (int i = 0; i < ns; i++) {
        trace_surface t;
        trace_material m = {TRACE_REFRACT, rr(1, 1.8), rr(1, 1.8)};
        memset(&t, 0, sizeof t);
        double q = rnd(), sd = rr(3, 10);
        t.axis[2] = 1;
        t.at[2] = z;
        t.aperture = TRACE_AP_DISC;
        if (q < 0.6) {                        /* a cap (a conic now and then) */
            t.shape = TRACE_AXIAL;
            double r = rr(1.2 * sd, 6 * sd);
            t.radius = rnd() < 0.5 ? r : -r;
            t.r_outer = sd;
            if (rnd() < 0.2) t.conic = rr(-1, 0.5);
            if (rnd() < 0.05) { t.nasph = 2; t.asph[1] = 1e-5; }
        } else if (q < 0.85) {                /* a plane: a window, stop or detector */
            t.shape = TRACE_PLANE;
            t.r_outer = rr(sd, 3 * sd);
            if (rnd() < 0.4) t.r_inner = rr(0.5, 0.9) * t.r_outer;
        } else {                              /* a sphere */
            t.shape = TRACE_SPHERE;
            t.at[2] = z + 2;
            t.at[0] = rr(-5, 5);
            t.radius = rr(1, 3);
        }
        if (rnd() < 0.08) t.at[0] = 0.5;      /* decentred */
        if (rnd() < 0.05) t.axis[1] = 0.1;    /* tilted */
        double k = rnd();
        if (k < 0.08) m.kind = TRACE_MIRROR;
        else if (k < 0.15) m.kind = TRACE_ABSORB;
        else if (k < 0.2) m.kind = TRACE_DETECT;
        tr->add_surface(sc, &t, &m);
        z += rnd() < 0.2 ? rr(0, 1) : rr(2, 8);   /* sometimes within the last's sag */
    }
    if (rnd() < 0.3) {                        /* a mesh somewhere along the way */
        double zm = rr(-5, z + 5), v[9] = {-8, -8, zm, 8, -8, zm + 0.5, 0, 8, zm};
        trace_mesh mesh = {v, 3, NULL, 1, NULL, NULL, 0, 0};
        trace_material g = {TRACE_REFRACT, 1, 1.3};
        tr->add_mesh(sc, &mesh, &g);
    }
    trace_surface d;
    trace_material md = {TRACE_DETECT, 1, 1};
    memset(&d, 0, sizeof d);
    d.shape = TRACE_PLANE;
    d.at[2] = z + rr(5, 40);
    d.axis[2] = 1;
    d.r_outer = 60;
    tr->add_surface(sc, &d, &md);
    trace_source a = {0};
    a.type = TRACE_SRC_CONE;
    a.at[0] = rr(-2, 2); a.at[2] = rr(-40, -5); a.dir[2] = 1;
    a.half_angle = rr(0.02, 0.3); a.rings = 8;
    tr->add_source(sc, &a, NULL);
    trace_source b = a;                      /* from the far side, or from inside */
    b.at[2] = rnd() < 0.5 ? z + rr(1, 4) : rr(0, z);
    b.dir[2] = rnd() < 0.5 ? -1 : 1;
    b.rings = 5;
    tr->add_source(sc, &b, NULL);
}

static void random_scenes(const trace_api *tr)
{
    int bad = 0, found = 0, n = 300;
    for (int i = 0; i < n; i++) {
        trace_scene *sc = tr->scene_new();
        random_scene(tr, sc);
        int v = i % 3, lens;
        uint64_t hits;
        if (!same_both_ways(tr, sc, v != 1, v == 2, &lens, &hits)) {
            bad++;
            printf("# random scene %d (Fresnel %d, reflections %d) differs\n", i, v != 1,
                   v == 2);
        }
        found += lens > 0;
        tr->scene_free(sc);
    }
    CHECK(bad == 0 && found > n / 4 && found < n,
          "%d random scenes (lens found in %d): the lens path gives the BVH's bits", n,
          found);
}

int main(void)
{
    const trace_api *tr = tt_api();
    trace_lens_surface s[TT_NSURF];
    trace_lens l;
    int lens;
    uint64_t hits;
    tt_triplet(s, &l, 1);
    double zi = tt_paraxial_image(&l, -INFINITY);

    for (int v = 0; v < 3; v++) {
        int fr = v != 1, rf = v >= 2;
        /* add_lens alone, its detector: its own hints (6 faces, 6 mounts, detector) */
        trace_scene *sc = tr->scene_new();
        l.z_detector = zi;
        tr->add_lens(sc, &l);
        add_grid(tr, sc, -5, 41);
        int ok = same_both_ways(tr, sc, fr, rf, &lens, &hits);
        CHECK(ok && lens == 13 && hits > 500, "add_lens alone (Fresnel %d, reflections %d): "
              "the lens path takes %d surfaces, %llu hits as by the BVH", fr, rf, lens,
              (unsigned long long)hits);
        tr->scene_free(sc);

        /* add_lens, then a mesh vane between elements 1 and 2 and a detector plane:
         * the lens is found again, from surface 3 on (4 faces, 4 mounts, detector) */
        sc = tr->scene_new();
        l.z_detector = NAN;
        tr->add_lens(sc, &l);
        double vane[9] = {-10, 2, 6, 10, 2, 6, 10, 4, 6.2};
        trace_mesh m = {vane, 3, NULL, 1, NULL, NULL, 0, 0};
        trace_material ab = {TRACE_ABSORB, 1, 1};
        int id = tr->add_mesh(sc, &m, &ab);
        add_plane(tr, sc, TRACE_DETECT, zi, 50);
        add_grid(tr, sc, -5, 41);
        ok = id >= 0 && same_both_ways(tr, sc, fr, rf, &lens, &hits);
        CHECK(ok && lens == 9, "add_lens + a mesh vane between elements + a detector "
              "(Fresnel %d, reflections %d): the lens path takes %d surfaces, the BVH's "
              "bits", fr, rf, lens);
        /* built and traced; one more surface (a window before the lens): built again,
         * the lens found anew (the window's slab is cut off from it by the vane) */
        add_plane(tr, sc, TRACE_REFRACT, -3, 30);
        ok = same_both_ways(tr, sc, fr, rf, &lens, &hits);
        CHECK(ok && lens == 9, "... a window added before it, rebuilt: %d surfaces, the "
              "BVH's bits", lens);
        tr->scene_free(sc);
    }

    /* a plane sheet through every element (on the axis, in every slab with a face and
     * its mount: three members): no slab is good, no lens */
    trace_scene *sc = tr->scene_new();
    l.z_detector = zi;
    tr->add_lens(sc, &l);
    trace_surface t;
    trace_material w = {TRACE_REFRACT, 1, 1};
    memset(&t, 0, sizeof t);
    t.shape = TRACE_PLANE;
    t.at[2] = 12;
    t.axis[1] = 1;                 /* the plane y = 0, from z = 12 - 20 to 12 + 20 */
    t.up[2] = 1;
    t.aperture = TRACE_AP_RECT;
    t.width = 30;
    t.height = 40;
    tr->add_surface(sc, &t, &w);
    add_grid(tr, sc, -5, 31);
    int ok = same_both_ways(tr, sc, 1, 1, &lens, &hits);
    CHECK(ok && lens == 0, "a tilted sheet through the whole lens: no lens path (%d), the "
          "BVH's bits", lens);
    tr->scene_free(sc);
    random_scenes(tr);
    return unit_failed();
}
