/* t_lens.c -- sequential lenses through the trace engine: a real fan with ray heights
 * going to 0 meets the paraxial image (computed here, independently) to 1e-9; the
 * aberration grows as h^2; double-precision hits agree with an independent double
 * trace of a Cooke triplet where single-precision hits do not; results are bit for
 * bit the same for 1, 2 and 3 threads, and so is the whole stream of sink calls
 * (segments, hits and progress, interleaved), a cancelled trace included. */
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
/* Records kept from a sink, in order. */
typedef struct rec { void *p; size_t n, cap; } rec;
static int push(rec *r, const void *x, size_t size)
{
    if (r->n == r->cap) {
        size_t cap = r->cap ? 2 * r->cap : 4096;
        void *p = realloc(r->p, cap * size);
        if (!p) return 1;
        r->p = p;
        r->cap = cap;
    }
    memcpy((char *)r->p + r->n++ * size, x, size);
    return 0;
}
static int keep(void *ctx, const trace_hit *h) { return push(ctx, h, sizeof *h); }

/* The triplet with mounts and a detector at the paraxial focus, lit by a collimated
 * grid of count x count rays filling the pupil. */
static trace_scene *triplet_grid(const trace_api *tr, long count)
{
    return tt_triplet_grid(tr, count, TT_EPD / 2);
}

static void threads_bitwise(const trace_api *tr)
{
    rec r[3] = {{0}};
    trace_summary sum[3];
    for (int k = 0; k < 3; k++) {
        trace_scene *sc = triplet_grid(tr, 60);
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
        int same = r[k].n == r[0].n && !memcmp(r[k].p, r[0].p, r[0].n * sizeof(trace_hit));
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
    for (int k = 0; k < 3; k++) free(r[k].p);
}

/* Every sink call folded into one hash, in the order the calls come. */
typedef struct stream {
    uint64_t hash, calls, hits, progress_last, progress_total;
    int progress_ok;           /* done goes up, total stays */
    long cancel_at;            /* cancel at this hit (-1: never) */
    long after_cancel;         /* calls that came after a cancel */
    int cancelled;
} stream;

static void st_mix(stream *st, int kind, const void *p, size_t n)
{
    const unsigned char *c = p;
    if (st->cancelled) st->after_cancel++;
    st->hash = (st->hash ^ (unsigned)kind) * 1099511628211ULL;
    for (size_t i = 0; i < n; i++) st->hash = (st->hash ^ c[i]) * 1099511628211ULL;
    st->calls++;
}
static int st_seg(void *ctx, const trace_segment *g)
{
    st_mix(ctx, 1, g, sizeof *g);
    return 0;
}
static int st_hit(void *ctx, const trace_hit *h)
{
    stream *st = ctx;
    st_mix(st, 2, h, sizeof *h);
    if ((long)st->hits++ == st->cancel_at) st->cancelled = 1;
    return st->cancelled;
}
static int st_progress(void *ctx, uint64_t done, uint64_t total)
{
    stream *st = ctx;
    uint64_t v[2] = {done, total};
    st_mix(st, 3, v, sizeof v);
    if (done <= st->progress_last || (st->progress_total && total != st->progress_total))
        st->progress_ok = 0;
    st->progress_last = done;
    st->progress_total = total;
    return 0;
}

/* The stream of sink calls is the same for 1, 2 and 3 threads, a cancel stops it for
 * good, and the summary does not depend on the batch size either (no sinks: bigger
 * batches). */
static void threads_stream(const trace_api *tr)
{
    trace_scene *sc = triplet_grid(tr, 90);
    trace_source cone = {0};                 /* a second source: skew rays, ghosts */
    cone.type = TRACE_SRC_CONE;
    cone.at[1] = 8; cone.at[2] = -60; cone.dir[1] = -8; cone.dir[2] = 60;
    cone.half_angle = 0.09; cone.rings = 20;
    tr->add_source(sc, &cone, NULL);
    stream st[3], cut[3];
    trace_summary sum[3], bare;
    int rc[3], crc[3];
    for (int k = 0; k < 3; k++) {
        trace_options o;
        tr->options_default(&o);
        o.threads = k + 1;
        o.cutoff = 1e-4;
        o.batch = 700;
        st[k] = (stream){.hash = 14695981039346656037ULL, .progress_ok = 1, .cancel_at = -1};
        trace_sink sink = {&st[k], st_seg, st_hit, st_progress};
        rc[k] = tr->run(sc, &o, &sink, &sum[k]);
        cut[k] = (stream){.hash = 14695981039346656037ULL, .progress_ok = 1,
                          .cancel_at = 2500};
        trace_sink sink2 = {&cut[k], st_seg, st_hit, st_progress};
        crc[k] = tr->run(sc, &o, &sink2, NULL);
    }
    trace_options o;
    tr->options_default(&o);
    o.threads = 2;
    o.cutoff = 1e-4;
    tr->run(sc, &o, NULL, &bare);
    CHECK(rc[0] == TRACE_OK && st[0].hits > 5000 && st[0].progress_ok &&
          st[0].progress_last == sum[0].rays,
          "stream: %llu calls, %llu hits, progress up to %llu of %llu rays",
          (unsigned long long)st[0].calls, (unsigned long long)st[0].hits,
          (unsigned long long)st[0].progress_last, (unsigned long long)sum[0].rays);
    for (int k = 1; k < 3; k++) {
        CHECK(rc[k] == TRACE_OK && st[k].calls == st[0].calls && st[k].hash == st[0].hash &&
              st[k].progress_ok,
              "%d threads: the same %llu sink calls in the same order (hash %016llx)",
              k + 1, (unsigned long long)st[k].calls, (unsigned long long)st[k].hash);
        CHECK(crc[k] == TRACE_ECANCEL && cut[k].after_cancel == 0 &&
              cut[k].calls == cut[0].calls && cut[k].hash == cut[0].hash,
              "%d threads: cancelled at hit 2500 like 1 thread (%llu calls before, %ld "
              "after)", k + 1, (unsigned long long)cut[k].calls, cut[k].after_cancel);
    }
    CHECK(crc[0] == TRACE_ECANCEL && cut[0].after_cancel == 0 && cut[0].hits == 2501,
          "1 thread: cancelled at hit 2500, no call after it");
    int same = !memcmp(&bare.emitted, &sum[0].emitted, 5 * sizeof(double)) &&
               bare.segments == sum[0].segments && bare.hits == sum[0].hits &&
               bare.tir == sum[0].tir && bare.max_depth_seen == sum[0].max_depth_seen;
    CHECK(same, "no sinks, default batches, 2 threads: the summary of 700-ray batches "
          "bit for bit (cut off %.17g)", bare.cutoff);
    tr->scene_free(sc);
}

/* Hits and segments, compared bytewise (records zero their padding). */
typedef struct both { rec h, s; } both;
static int both_hit(void *ctx, const trace_hit *h) { return keep(&((both *)ctx)->h, h); }
static int both_seg(void *ctx, const trace_segment *g)
{
    return push(&((both *)ctx)->s, g, sizeof *g);
}

/* The lens shortcut (no BVH between consecutive surfaces; eight rays at a time in
 * vector registers, tr_pk_kernel.h; each kernel against the others: t_isa.c) changes
 * no bit: hits, segments,
 * energy figures and counts equal the BVH trace's, with and without Fresnel and
 * reflected rays, for skew rays some of which the mounts stop. */
static void sequential_same(const trace_api *tr)
{
    trace_lens_surface s[TT_NSURF];
    trace_lens l;
    tt_triplet(s, &l, 1);
    l.z_detector = tt_paraxial_image(&l, -INFINITY);
    for (int v = 0; v < 4; v++) {
        int fresnel = v != 1, reflections = v >= 2, segs = v == 3;
        both r[2];
        trace_summary sum[2];
        double ms[2];
        memset(r, 0, sizeof r);
        for (int k = 0; k < 2; k++) {
            trace_scene *sc = tr->scene_new();
            trace_source src = {0};
            src.type = TRACE_SRC_CONE;             /* from an off-axis point: skew rays */
            src.at[1] = 8; src.at[2] = -60; src.dir[1] = -8; src.dir[2] = 60;
            src.half_angle = 0.09; src.rings = reflections ? 12 : 30;
            tr->add_lens(sc, &l);
            tr->add_source(sc, &src, NULL);
            trace_options o;
            tr->options_default(&o);
            o.fresnel = fresnel;
            o.reflections = reflections;
            o.sequential = k;
            o.threads = 1;
            trace_sink sink = {&r[k], segs ? both_seg : NULL, both_hit, NULL};
            tr->run(sc, &o, &sink, &sum[k]);
            ms[k] = sum[k].trace_ms;
            tr->scene_free(sc);
        }
        int same = r[0].h.n == r[1].h.n && r[0].h.n > 1000 && r[0].s.n == r[1].s.n &&
                   (!segs || r[0].s.n > r[0].h.n) &&
                   !memcmp(r[0].h.p, r[1].h.p, r[0].h.n * sizeof(trace_hit)) &&
                   (!segs || !memcmp(r[0].s.p, r[1].s.p, r[0].s.n * sizeof(trace_segment))) &&
                   !memcmp(&sum[0].rays, &sum[1].rays, 10 * sizeof(uint64_t)) &&
                   sum[0].max_depth_seen == sum[1].max_depth_seen &&
                   !memcmp(&sum[0].emitted, &sum[1].emitted, 5 * sizeof(double));
        CHECK(same, "lens shortcut (Fresnel %s, reflections %s%s): %zu hits%s and the "
              "summary bit-identical to the BVH trace (%.0f ms vs %.0f ms; %llu rays, %llu "
              "rays cut for power)", fresnel ? "on" : "off",
              reflections ? "on" : "off", segs ? ", segments" : "", r[1].h.n,
              segs ? ", the segments" : "", ms[1], ms[0], (unsigned long long)sum[1].rays,
              (unsigned long long)sum[1].cut_power);
        for (int k = 0; k < 2; k++) { free(r[k].h.p); free(r[k].s.p); }
    }
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
    threads_stream(tr);
    sequential_same(tr);
    return unit_failed();
}
