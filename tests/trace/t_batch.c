/* t_batch.c -- the batch sink (trace_batch_sink, trace_api.run_batches) against the
 * one-by-one sink (trace_sink, run): the same segments and hits, byte for byte and in
 * the same order, the same summary, for one thread and several, with reflections
 * followed (hits at many depths, a batch's records out of the lanes and the one-ray
 * code) and with polarization on (each hit's record just before the call holding it,
 * so such hits come one a call); every call holds n >= 1 records in ray order, at most
 * one call per batch and callback without polarization; a sink that cancels stops the
 * run with TRACE_ECANCEL after the records before it, as the one-by-one sink does. */
#include <stdio.h>
#include "unit.h"
#include "tt.h"

static const trace_api *tr;

typedef struct {
    unsigned char *p;
    size_t n, cap;          /* bytes */
} bytes;

static int put(bytes *b, const void *x, size_t len)
{
    if (b->n + len > b->cap) {
        size_t cap = b->cap ? b->cap : 1 << 16;
        while (cap < b->n + len) cap *= 2;
        void *q = realloc(b->p, cap);
        if (!q) return 1;
        b->p = q;
        b->cap = cap;
    }
    memcpy(b->p + b->n, x, len);
    b->n += len;
    return 0;
}

typedef struct {
    bytes seg, hit;
    long seg_calls, hit_calls, batches, empty, disorder;
    uint64_t last_ray;
    int polar;              /* polarization on: its records are counted */
    long npol, pol_bad;     /* records; hits not just after their own record */
    uint64_t pol_ray;
    long stop_at;           /* cancel at this hit call (1-based; 0: never) */
} rec;

static int seg1(void *c, const trace_segment *s) { return put(&((rec *)c)->seg, s, sizeof *s); }
static int hit1(void *c, const trace_hit *h)
{
    rec *r = c;
    r->hit_calls++;
    if (r->stop_at && r->hit_calls >= r->stop_at) return 1;
    return put(&r->hit, h, sizeof *h);
}
static int segn(void *c, const trace_segment *s, size_t n)
{
    rec *r = c;
    r->seg_calls++;
    if (!n) r->empty++;
    return put(&r->seg, s, n * sizeof *s);
}
static int hitn(void *c, const trace_hit *h, size_t n)
{
    rec *r = c;
    r->hit_calls++;
    if (!n) r->empty++;
    for (size_t i = 0; i < n; i++) {
        if (h[i].ray < r->last_ray) r->disorder++;
        r->last_ray = h[i].ray;
    }
    if (r->polar && (n != 1 || r->npol != (long)(r->hit.n / sizeof *h) + 1 ||
                     r->pol_ray != h[0].ray))
        r->pol_bad++;
    if (r->stop_at && r->hit_calls >= r->stop_at) return 1;
    return put(&r->hit, h, n * sizeof *h);
}
static int progress(void *c, uint64_t done, uint64_t total)
{
    (void)done;
    (void)total;
    ((rec *)c)->batches++;
    return 0;
}
static int pol(void *c, const trace_polar_hit *ph)
{
    rec *r = c;
    r->npol++;
    r->pol_ray = ph->ray;
    return 0;
}

/* The triplet with mounts and a detector at its paraxial focus, a collimated grid of
 * count x count rays over the pupil; polar: polarization on (record sink x). */
static trace_scene *triplet(long count, int polar, rec *x)
{
    trace_scene *sc = tt_triplet_grid(tr, count, TT_EPD / 2 * 1.3);   /* some on the mounts */
    if (!sc || (polar && tr->polarization(sc, 1, NULL, pol, x) != TRACE_OK)) {
        printf("FAIL cannot make the triplet scene\n");
        exit(1);
    }
    return sc;
}

/* The summary without its timings (they differ from run to run). */
static void untimed(trace_summary *s) { s->build_ms = s->trace_ms = 0; }

static void free_rec(rec *r)
{
    free(r->seg.p);
    free(r->hit.p);
}

/* One scene traced both ways (threads, batch size, reflections, polarization). */
static void both(const char *what, long count, int threads, long batch, int reflections,
                 int polar)
{
    rec a = {0}, b = {0};
    trace_options o;
    tr->options_default(&o);
    o.threads = threads;
    o.batch = batch;
    o.reflections = reflections;
    o.cutoff = reflections ? 1e-4 : 1e-6;   /* a few reflected paths a ray */
    trace_summary sa, sb;
    b.polar = polar;
    trace_scene *sc = triplet(count, polar, &a);
    trace_sink one = {&a, seg1, hit1, progress};
    int ra = tr->run(sc, &o, &one, &sa);
    tr->scene_free(sc);
    sc = triplet(count, polar, &b);
    trace_batch_sink many = {&b, segn, hitn, progress};
    int rb = tr->run_batches(sc, &o, &many, &sb);
    tr->scene_free(sc);
    untimed(&sa);
    untimed(&sb);
    size_t nh = a.hit.n / sizeof(trace_hit), ns = a.seg.n / sizeof(trace_segment);
    CHECK(ra == TRACE_OK && rb == TRACE_OK && nh > 0 && ns > nh,
          "%s: both runs succeed (%zu hits, %zu segments, %ld batches)", what, nh, ns,
          a.batches);
    CHECK(a.hit.n == b.hit.n && (a.hit.n == 0 || memcmp(a.hit.p, b.hit.p, a.hit.n) == 0),
          "%s: the batch sink's hits are the one-by-one sink's, byte for byte", what);
    CHECK(a.seg.n == b.seg.n && (a.seg.n == 0 || memcmp(a.seg.p, b.seg.p, a.seg.n) == 0),
          "%s: the batch sink's segments are the one-by-one sink's, byte for byte", what);
    CHECK(memcmp(&sa, &sb, sizeof sa) == 0 && sa.hits == nh && sa.segments == ns,
          "%s: the same summary (%llu hits)", what, (unsigned long long)sb.hits);
    CHECK(b.empty == 0 && b.disorder == 0, "%s: every call holds records, in ray order "
          "(%ld hit calls, %ld segment calls)", what, b.hit_calls, b.seg_calls);
    if (polar)
        CHECK(b.pol_bad == 0 && b.npol == (long)nh && b.hit_calls == (long)nh,
              "%s: with polarization each hit comes alone, just after its record (%ld "
              "records)", what, b.npol);
    else
        CHECK(b.hit_calls <= b.batches && b.seg_calls <= b.batches && b.hit_calls > 1,
              "%s: one call per batch at most (%ld hit calls, %ld batches)", what,
              b.hit_calls, b.batches);
    free_rec(&a);
    free_rec(&b);
}

/* A hits sink that cancels at its k-th call: TRACE_ECANCEL, and what came before is
 * the start of the full run's hits; the one-by-one sink stopping at the same hit keeps
 * the same ones. */
static void cancel(void)
{
    rec full = {0}, a = {0}, b = {0};
    trace_options o;
    tr->options_default(&o);
    o.threads = 2;
    o.batch = 256;
    trace_scene *sc = triplet(80, 0, NULL);
    trace_batch_sink all = {&full, NULL, hitn, progress};
    int rf = tr->run_batches(sc, &o, &all, NULL);
    tr->scene_free(sc);
    b.stop_at = 4;
    sc = triplet(80, 0, NULL);
    trace_batch_sink many = {&b, NULL, hitn, progress};
    int rb = tr->run_batches(sc, &o, &many, NULL);
    tr->scene_free(sc);
    a.stop_at = (long)(b.hit.n / sizeof(trace_hit)) + 1;   /* the same hit */
    sc = triplet(80, 0, NULL);
    trace_sink one = {&a, NULL, hit1, progress};
    int ra = tr->run(sc, &o, &one, NULL);
    tr->scene_free(sc);
    CHECK(rf == TRACE_OK && rb == TRACE_ECANCEL && ra == TRACE_ECANCEL && b.hit_calls == 4,
          "a hits sink that cancels at its 4th call stops the run: TRACE_ECANCEL (both "
          "sinks)");
    CHECK(b.hit.n > 0 && b.hit.n < full.hit.n && memcmp(b.hit.p, full.hit.p, b.hit.n) == 0 &&
          a.hit.n == b.hit.n && memcmp(a.hit.p, b.hit.p, a.hit.n) == 0,
          "the hits before the cancel are the full run's first %zu, as the one-by-one "
          "sink's", b.hit.n / sizeof(trace_hit));
    free_rec(&full);
    free_rec(&a);
    free_rec(&b);
}

int main(void)
{
    tr = tt_api();
    both("triplet, 1 thread", 120, 1, 0, 0, 0);
    both("triplet, 1 thread, batches of 1000", 120, 1, 1000, 0, 0);
    both("triplet, reflections, 3 threads, batches of 300", 70, 3, 300, 1, 0);
    both("triplet, reflections, 1 thread, batches of 64", 40, 1, 64, 1, 0);
    both("triplet, polarization, 2 threads, batches of 128", 30, 2, 128, 1, 1);
    cancel();
    /* no sink at all */
    trace_scene *sc = triplet(10, 0, NULL);
    trace_summary s;
    CHECK(tr->run_batches(sc, NULL, NULL, &s) == TRACE_OK && s.hits > 0,
          "run_batches without a sink traces (%llu hits)", (unsigned long long)s.hits);
    tr->scene_free(sc);
    return unit_failed();
}
