/* t_seqscan.c -- a sequential lens found inside a scene built through the table
 * (tr_seqscan.c): add_lens's own hints are kept while the lens is alone; a surface or
 * mesh added after it makes the engine look again (stale hints never used), a mesh
 * between two elements cuts the lens there, a rebuild after another surface finds it
 * anew; every trace gives the bits of the BVH trace (sequential off): hits, segments
 * and summary compared bytewise.  The summary says how many surfaces took the lens
 * path (trace_summary.lens_surfaces). */
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
               !memcmp(r[0].h.p, r[1].h.p, r[0].h.n * sizeof(trace_hit)) &&
               !memcmp(r[0].s.p, r[1].s.p, r[0].s.n * sizeof(trace_segment)) &&
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
        trace_mesh m = {vane, 3, NULL, 1, NULL, NULL, 0};
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
    return unit_failed();
}
