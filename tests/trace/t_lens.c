/* t_lens.c -- sequential lenses through the trace engine: a real fan with ray heights
 * going to 0 meets the paraxial image (computed here, independently) to 1e-9; the
 * aberration grows as h^2; double-precision hits agree with an independent double
 * trace of a Cooke triplet where single-precision hits do not; results are bit for
 * bit the same for 1, 2 and 3 threads. */
#include <stdio.h>
#include "unit.h"
#include "tt.h"

static void paraxial_limit(const trace_api *tr)
{
    trace_lens_surface s[TT_NSURF];
    trace_lens l;
    char err[256];
    tt_triplet(s, &l, 0);
    double zlast = s[TT_NSURF - 1].z;
    double zobj[2] = {-INFINITY, -300};
    for (int k = 0; k < 2; k++) {
        double zp = tt_paraxial_image(&l, zobj[k]);
        double h[4] = {1e-7, 1e-6, 1e-3, 2e-3};
        trace_fan_ray out[4];
        int rc = tr->lens_fan(&l, zobj[k], 0, zp, 4, h, out, err, sizeof err);
        CHECK(rc == TRACE_OK, "fan traced (object z %g): %s", zobj[k], rc ? err : "");
        if (rc) continue;
        double rel = fabs(out[0].z_cross - zp) / (zp - zlast);
        CHECK(out[0].status == 0 && rel < 1e-9,
              "object z %g: ray at h=1e-7 crosses at %.15g, paraxial %.15g (rel %.2e)",
              zobj[k], out[0].z_cross, zp, rel);
        rel = fabs(out[1].z_cross - zp) / (zp - zlast);
        CHECK(rel < 1e-9, "object z %g: h=1e-6 rel %.2e", zobj[k], rel);
        double q = out[3].lsa / out[2].lsa;
        CHECK(fabs(q - 4) < 0.01, "LSA grows as h^2 near the axis: LSA(2h)/LSA(h) = %.5f",
              q);
    }
}

static int tt_collect(void *ctx, const trace_hit *h)
{
    double (*p)[3] = ctx;
    memcpy(p[h->ray], h->pos, sizeof h->pos);
    return 0;
}

static void double_beats_float(const trace_api *tr)
{
    trace_lens_surface s[TT_NSURF];
    trace_lens l;
    tt_triplet(s, &l, 0);
    double zp = tt_paraxial_image(&l, -INFINITY);
    l.z_detector = zp;
    enum { N = 41 };
    trace_ray rays[N];
    double ref[N][3];
    for (int i = 0; i < N; i++) {
        double h = TT_EPD / 2 * (i - N / 2) / (N / 2), dd[3];
        double o[3] = {0.3 * h, h, -10}, d[3] = {0, 0.05, 1};   /* off-axis, skew */
        double dl = sqrt(d[1] * d[1] + 1);
        d[1] /= dl; d[2] /= dl;
        memcpy(rays[i].o, o, sizeof o);
        memcpy(rays[i].d, d, sizeof d);
        rays[i].power = 1;
        if (tt_real_trace(&l, o, d, zp, ref[i], dd)) { printf("FAIL ref trace %d\n", i); return; }
    }
    double errmax[2] = {0, 0};
    for (int fl = 0; fl < 2; fl++) {
        trace_scene *sc = tr->scene_new();
        trace_source src = {0};
        src.type = TRACE_SRC_RAYS; src.count = N; src.ray = rays;
        tr->add_lens(sc, &l);
        tr->add_source(sc, &src, NULL);
        trace_options o;
        tr->options_default(&o);
        o.fresnel = 0; o.reflections = 0; o.threads = 1; o.float_hits = fl;
        double pos[N][3];
        trace_summary sum;
        trace_sink sink = {pos, NULL, tt_collect, NULL};
        int rc = tr->run(sc, &o, &sink, &sum);
        CHECK(rc == TRACE_OK && sum.hits == N, "%s trace: %llu hits of %d", fl ? "float" :
              "double", (unsigned long long)sum.hits, N);
        for (int i = 0; i < N; i++) {
            double e = hypot(pos[i][0] - ref[i][0], pos[i][1] - ref[i][1]);
            if (e > errmax[fl]) errmax[fl] = e;
        }
        tr->scene_free(sc);
    }
    CHECK(errmax[0] < 1e-10, "double hits: spot positions within %.2e mm of the "
          "independent double trace", errmax[0]);
    CHECK(errmax[1] > 1e3 * errmax[0] && errmax[1] > 1e-7,
          "single-precision hits are off by %.2e mm (double: %.2e)", errmax[1], errmax[0]);
}

/* ---- thread count must not change a single bit ---- */
typedef struct rec { trace_hit *h; size_t n, cap; } rec;
static int keep(void *ctx, const trace_hit *h)
{
    rec *r = ctx;
    if (r->n == r->cap) {
        r->cap = r->cap ? 2 * r->cap : 4096;
        r->h = realloc(r->h, r->cap * sizeof *r->h);
        if (!r->h) return 1;
    }
    r->h[r->n++] = *h;
    return 0;
}

static void threads_bitwise(const trace_api *tr)
{
    trace_lens_surface s[TT_NSURF];
    trace_lens l;
    tt_triplet(s, &l, 1);
    l.z_detector = tt_paraxial_image(&l, -INFINITY);
    rec r[3] = {{0}};
    trace_summary sum[3];
    for (int k = 0; k < 3; k++) {
        trace_scene *sc = tr->scene_new();
        trace_source src = {0};
        src.type = TRACE_SRC_GRID;
        src.dir[2] = 1; src.at[2] = -5; src.radius = TT_EPD / 2; src.count = 60;
        src.up[1] = 1;
        tr->add_lens(sc, &l);
        tr->add_source(sc, &src, NULL);
        trace_options o;
        tr->options_default(&o);
        o.threads = k + 1;
        o.cutoff = 1e-5;          /* ghosts: reflections followed */
        o.batch = 1000;
        trace_sink sink = {&r[k], NULL, keep, NULL};
        tr->run(sc, &o, &sink, &sum[k]);
        tr->scene_free(sc);
    }
    for (int k = 1; k < 3; k++) {
        int same = r[k].n == r[0].n && !memcmp(r[k].h, r[0].h, r[0].n * sizeof *r[0].h);
        CHECK(same, "%d threads: %zu hits, bit-identical to 1 thread (%zu)", k + 1,
              r[k].n, r[0].n);
        same = !memcmp(&sum[k].emitted, &sum[0].emitted, 5 * sizeof(double)) &&
               sum[k].segments == sum[0].segments;
        CHECK(same, "%d threads: identical summary (detected %.17g)", k + 1,
              sum[k].detected);
    }
    double e = sum[0].detected + sum[0].absorbed + sum[0].escaped + sum[0].cutoff;
    CHECK(fabs(e - sum[0].emitted) <= 1e-9 * sum[0].emitted && sum[0].emitted > 0,
          "triplet with ghosts: energy balance %.3e", e / sum[0].emitted - 1);
    CHECK(sum[0].segments > 7 * sum[0].rays, "reflections were followed (%llu segments, "
          "%llu rays)", (unsigned long long)sum[0].segments,
          (unsigned long long)sum[0].rays);
    for (int k = 0; k < 3; k++) free(r[k].h);
}

/* The lens shortcut (no BVH between consecutive surfaces) changes no bit. */
static void sequential_same(const trace_api *tr)
{
    trace_lens_surface s[TT_NSURF];
    trace_lens l;
    tt_triplet(s, &l, 1);
    l.z_detector = tt_paraxial_image(&l, -INFINITY);
    rec r[2] = {{0}};
    trace_summary sum[2];
    double ms[2];
    for (int k = 0; k < 2; k++) {
        trace_scene *sc = tr->scene_new();
        trace_source src = {0};
        src.type = TRACE_SRC_CONE;             /* from an off-axis point: skew rays */
        src.at[1] = 8; src.at[2] = -60; src.dir[1] = -8; src.dir[2] = 60;
        src.half_angle = 0.09; src.rings = 30;
        tr->add_lens(sc, &l);
        tr->add_source(sc, &src, NULL);
        trace_options o;
        tr->options_default(&o);
        o.reflections = 0;
        o.sequential = k;
        o.threads = 1;
        trace_sink sink = {&r[k], NULL, keep, NULL};
        tr->run(sc, &o, &sink, &sum[k]);
        ms[k] = sum[k].trace_ms;
        tr->scene_free(sc);
    }
    int same = r[0].n == r[1].n && r[0].n > 1000 &&
               !memcmp(r[0].h, r[1].h, r[0].n * sizeof *r[0].h) &&
               !memcmp(&sum[0].emitted, &sum[1].emitted, 5 * sizeof(double));
    CHECK(same, "lens shortcut: %zu hits and the energy figures bit-identical to the "
          "BVH trace (%.0f ms vs %.0f ms; %llu of %llu rays vignetted)", r[1].n, ms[1],
          ms[0], (unsigned long long)(sum[1].rays - sum[1].hits),
          (unsigned long long)sum[1].rays);
    for (int k = 0; k < 2; k++) free(r[k].h);
}

int main(void)
{
    const trace_api *tr = tt_api();
    trace_lens_surface s[TT_NSURF];
    trace_lens l;
    tt_triplet(s, &l, 0);
    double f = tt_efl(&l);
    CHECK(fabs(f - 50) < 1.5, "the test triplet has f = %.4f mm (about 50)", f);
    paraxial_limit(tr);
    double_beats_float(tr);
    threads_bitwise(tr);
    sequential_same(tr);
    return unit_failed();
}
