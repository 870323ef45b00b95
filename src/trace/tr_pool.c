/* tr_pool.c -- the run: options, the thread pool and its window of batches, the
 * delivery of records to the sinks in ray order (one by one, or a batch at a time),
 * and the summary summed in ray order (so every result is the same to the last bit
 * for any thread count). */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <unistd.h>
#include "tr_eng.h"

void tr_options_default(trace_options *o)
{
    memset(o, 0, sizeof *o);
    o->max_depth = 16;
    o->cutoff = 1e-6;
    o->fresnel = 1;
    o->reflections = 1;
    o->threads = 0;
    o->escape_length = 1;
    o->batch = 0;
    o->float_hits = 0;
    o->sequential = 1;
}

/* A compensated sum (Neumaier): s + c carries the sum of every term added, in the
 * order added, to about one rounding of the result however many terms there are
 * (a plain sum of 1e8 ray powers drifts by 2e-9). */
typedef struct tr_ksum {
    double s, c;
} tr_ksum;

static inline void ksum_add(tr_ksum *k, double x)
{
    /* the rounding error of s + x, exactly (Knuth's two-sum: the same value as
     * Neumaier's branch on |s| >= |x|, without the branch) */
    double t = k->s + x, z = t - k->s;
    k->c += (k->s - (t - z)) + (x - z);
    k->s = t;
}

static inline double ksum(const tr_ksum *k) { return k->s + k->c; }

/* A delivered batch (counts c, powers pw[0..n-1]) into the summary: the powers ray
 * by ray, in ray order, each into its compensated sum k[0..4] (emitted, detected,
 * absorbed, escaped, cut off), whose value the summary shows. */
static void add_batch(trace_summary *s, tr_ksum k[5], const trace_summary *c,
                      const tr_power *pw, uint64_t n)
{
    s->rays += c->rays;
    s->segments += c->segments;
    s->interactions += c->interactions;
    s->tir += c->tir;
    s->hits += c->hits;
    s->cut_depth += c->cut_depth;
    s->cut_power += c->cut_power;
    s->cut_reflection += c->cut_reflection;
    s->medium_mismatch += c->medium_mismatch;
    s->failures += c->failures;
    if (c->max_depth_seen > s->max_depth_seen) s->max_depth_seen = c->max_depth_seen;
    tr_ksum e = k[0], d = k[1], a = k[2], x = k[3], q = k[4];
    for (uint64_t i = 0; i < n; i++) {   /* a zero term changes no bit: skipped */
        ksum_add(&e, pw[i].emitted);
        if (pw[i].detected != 0) ksum_add(&d, pw[i].detected);
        if (pw[i].absorbed != 0) ksum_add(&a, pw[i].absorbed);
        if (pw[i].escaped != 0) ksum_add(&x, pw[i].escaped);
        if (pw[i].cutoff != 0) ksum_add(&q, pw[i].cutoff);
    }
    k[0] = e; k[1] = d; k[2] = a; k[3] = x; k[4] = q;
    s->emitted = ksum(&e); s->detected = ksum(&d); s->absorbed = ksum(&a);
    s->escaped = ksum(&x); s->cutoff = ksum(&q);
}

/* ---------------- the run: a pool of workers and a window of batches ----------------
 * The rays are cut into batches of fixed size; batch b always holds the same rays,
 * whatever the thread count.  Threads (the caller and nthr-1 workers, created once
 * per run) claim the next batch in order and trace it into a slot of a ring of nslot
 * slots: its records, in ray order, the powers of each ray and the batch's counts.
 * Batch b may be claimed only once batch b-nslot has been delivered, so at most nslot
 * batches are in memory.
 * The caller delivers completed batches in batch order -- the sinks see every record
 * in ray order, from the calling thread -- and adds their powers ray by ray, in ray
 * order: every sum is the same to the last bit for any thread count (and any batch
 * size).  The caller delivers whatever is ready before it traces a batch itself, so
 * with cheap sinks it spends nearly all its time tracing, and with costly ones the
 * workers keep tracing ahead while it delivers. */

typedef struct tr_slot {
    tr_power *power;             /* one per ray of the batch */
    trace_summary counts;        /* the batch's counts (no powers) */
    tr_out out;                  /* the batch's records (buffers reused) */
    tr_failure fail;             /* its first numerical failure */
    uint64_t batch;              /* which batch the slot holds */
    int done, nomem;
} tr_slot;

typedef struct tr_pool {
    const trace_scene *sc;
    pthread_mutex_t mu;
    pthread_cond_t more;         /* workers wait here: a slot freed, or stop */
    pthread_cond_t ready;        /* the caller waits here: a batch done */
    uint64_t nbatch, next;       /* batches; the next one to claim */
    uint64_t delivered;          /* batches handed to the sinks */
    long batch;                  /* rays per batch */
    tr_slot *slot;
    int nslot;
    int stop;                    /* no more claims (cancel, error) */
    tr_ksum power[5];            /* the delivered powers' sums (add_batch) */
    tr_failure fail;             /* the first failure delivered (in ray order) */
} tr_pool;

typedef struct tr_thread {
    tr_pool *pool;
    tr_worker *w;
} tr_thread;

/* Under the lock: claim the next batch if the window has room; its slot, or NULL. */
static tr_slot *claim(tr_pool *p, uint64_t *b)
{
    if (p->stop || p->next >= p->nbatch || p->next >= p->delivered + (uint64_t)p->nslot)
        return NULL;
    *b = p->next++;
    tr_slot *s = &p->slot[*b % (uint64_t)p->nslot];
    s->batch = *b;
    s->done = 0;
    return s;
}

/* Outside the lock: trace batch b into its slot (the slot is this thread's alone). */
static void fill(tr_pool *p, tr_worker *w, tr_slot *s, uint64_t b)
{
    uint64_t b0 = b * (uint64_t)p->batch, left = p->sc->nrays - b0;
    w->first = b0;
    w->count = left < (uint64_t)p->batch ? left : (uint64_t)p->batch;
    w->power = s->power;
    memset(&s->counts, 0, sizeof s->counts);
    w->counts = &s->counts;
    w->out = s->out;                       /* the slot's buffers, emptied */
    w->out.seg.n = w->out.hit.n = w->out.pol.n = 0;
    w->nomem = 0;
    w->fail.cause = TR_FAIL_NONE;
    /* The packet path (tr_trace_batch's lanes) does not apply Beer-Lambert: a scene
     * with an absorbing medium goes ray by ray, the general path (same physics
     * otherwise).  Every other scene takes tr_trace_batch, which picks packets when
     * its own conditions hold (a sequential lens, AVX-512). */
    if (p->sc->polar) tr_polar_batch(w);          /* P per ray: tr_polar.c */
    else if (p->sc->absorbing) tr_trace_batch_rays(w);
    else tr_trace_batch(w);
    s->fail = w->fail;
    s->out = w->out;
    s->nomem = w->nomem;
}

static void *worker_main(void *arg)
{
    tr_thread *t = arg;
    tr_pool *p = t->pool;
    pthread_mutex_lock(&p->mu);
    for (;;) {
        uint64_t b;
        tr_slot *s = claim(p, &b);
        if (!s) {
            if (p->stop || p->next >= p->nbatch) break;
            pthread_cond_wait(&p->more, &p->mu);      /* the window is full */
            continue;
        }
        pthread_mutex_unlock(&p->mu);
        fill(p, t->w, s, b);
        pthread_mutex_lock(&p->mu);
        s->done = 1;
        if (b == p->delivered) pthread_cond_signal(&p->ready);
    }
    pthread_mutex_unlock(&p->mu);
    return NULL;
}

/* The sinks of a run: trace_sink's (one record a call) or trace_batch_sink's (a batch's
 * records a call), whichever the run was given. */
typedef struct tr_sinks {
    void *ctx;
    int (*segment)(void *ctx, const trace_segment *seg);
    int (*hit)(void *ctx, const trace_hit *hit);
    int (*segments)(void *ctx, const trace_segment *seg, size_t n);
    int (*hits)(void *ctx, const trace_hit *hit, size_t n);
    int (*progress)(void *ctx, uint64_t done, uint64_t total);
} tr_sinks;

/* Hand a batch's records to the sinks (segments, then hits: each in ray order; a hit's
 * polarization record just before it). */
static int deliver(const trace_scene *sc, const tr_slot *s, const tr_sinks *k)
{
    const trace_segment *seg = s->out.seg.p;
    const trace_hit *hit = s->out.hit.p;
    size_t nseg = s->out.seg.n, nhit = s->out.hit.n;
    size_t npol = s->out.pol.n < nhit ? s->out.pol.n : nhit;
    if (k->segments && nseg && k->segments(k->ctx, seg, nseg)) return TRACE_ECANCEL;
    for (size_t i = 0; k->segment && i < nseg; i++)
        if (k->segment(k->ctx, seg + i)) return TRACE_ECANCEL;
    if (!k->hit && !k->hits) return TRACE_OK;
    for (size_t i = 0; i < nhit; i++) {
        if (k->hits && i >= npol)   /* the rest (all, without polarization) at once */
            return k->hits(k->ctx, hit + i, nhit - i) ? TRACE_ECANCEL : TRACE_OK;
        if (i < npol && tr_polar_deliver(sc, (const trace_polar_hit *)s->out.pol.p + i))
            return TRACE_ECANCEL;
        if (k->hits ? k->hits(k->ctx, hit + i, 1) : k->hit(k->ctx, hit + i))
            return TRACE_ECANCEL;
    }
    return TRACE_OK;
}

/* The caller's loop: deliver the next batch when it is done, else trace one, else
 * wait.  Returns TRACE_OK or the first error; the tallies go into *sum. */
static int drive(trace_scene *sc, tr_pool *p, tr_worker *w, const tr_sinks *sink,
                 trace_summary *sum)
{
    int rc = TRACE_OK;
    pthread_mutex_lock(&p->mu);
    while (p->delivered < p->nbatch) {
        tr_slot *s = &p->slot[p->delivered % (uint64_t)p->nslot];
        uint64_t b;
        if (p->delivered < p->next && s->batch == p->delivered && s->done) {
            pthread_mutex_unlock(&p->mu);
            uint64_t b0 = p->delivered * (uint64_t)p->batch, left = sc->nrays - b0;
            uint64_t nb = left < (uint64_t)p->batch ? left : (uint64_t)p->batch;
            if (s->nomem) rc = tr_scene_fail(sc, TRACE_ENOMEM, "out of memory for trace output");
            else if ((rc = deliver(sc, s, sink)) != TRACE_OK)
                tr_scene_fail(sc, rc, "the trace was cancelled");
            if (rc == TRACE_OK) add_batch(sum, p->power, &s->counts, s->power, nb);
            if (rc == TRACE_OK && s->fail.cause && !p->fail.cause) p->fail = s->fail;
            if (rc == TRACE_OK && sink->progress &&
                sink->progress(sink->ctx, b0 + nb, sc->nrays))
                rc = tr_scene_fail(sc, TRACE_ECANCEL, "the trace was cancelled");
            pthread_mutex_lock(&p->mu);
            if (rc != TRACE_OK) break;
            p->delivered++;
            pthread_cond_broadcast(&p->more);          /* a slot is free */
        } else if ((s = claim(p, &b)) != NULL) {
            pthread_mutex_unlock(&p->mu);
            fill(p, w, s, b);
            pthread_mutex_lock(&p->mu);
            s->done = 1;
        } else {
            pthread_cond_wait(&p->ready, &p->mu);
        }
    }
    p->stop = 1;
    pthread_cond_broadcast(&p->more);
    pthread_mutex_unlock(&p->mu);
    return rc;
}

/* A trace whose results are not all finite is an error, with its cause: never a
 * success with NaN in the summary. */
static int numeric_check(trace_scene *sc, const trace_summary *s, const tr_failure *f)
{
    static const char *why[] = {
        [TR_FAIL_POINT] = "its hit point is not a finite number",
        [TR_FAIL_DIR] = "its direction is not finite (indices or angles beyond what "
                        "double precision holds)",
        [TR_FAIL_POWER] = "its power is not a finite number"};
    char msg[400];
    if (s->failures) {
        char at[48] = "";
        if (f->surf >= 0) snprintf(at, sizeof at, " after surface %d", f->surf + 1);
        snprintf(msg, sizeof msg, "%llu ray path%s failed numerically (of %llu source "
                 "rays); the first, from source ray %llu, failed%s: %s",
                 (unsigned long long)s->failures, s->failures == 1 ? "" : "s",
                 (unsigned long long)s->rays, (unsigned long long)f->ray, at,
                 f->cause > 0 && f->cause <= TR_FAIL_POWER ? why[f->cause] : "?");
        return tr_scene_fail(sc, TRACE_EINVAL, msg);
    }
    if (!(isfinite(s->emitted) && isfinite(s->detected) && isfinite(s->absorbed) &&
          isfinite(s->escaped) && isfinite(s->cutoff)))
        return tr_scene_fail(sc, TRACE_EINVAL, "the summed powers are not finite "
                             "(a source's power per ray beyond double precision)");
    return TRACE_OK;
}

static int check_options(trace_scene *sc, const trace_options *o)
{
    if (o->max_depth < 1 || o->max_depth > 10000)
        return tr_scene_fail(sc, TRACE_EINVAL, "depth limit must be 1..10000");
    if (!(o->cutoff >= 0 && o->cutoff < 1))
        return tr_scene_fail(sc, TRACE_EINVAL, "intensity cutoff must be in [0, 1)");
    if (o->threads < 0 || o->threads > 1024)
        return tr_scene_fail(sc, TRACE_EINVAL, "thread count must be 0..1024");
    if (!(o->escape_length >= 0 && isfinite(o->escape_length)))
        return tr_scene_fail(sc, TRACE_EINVAL, "escape length must be a non-negative number");
    if (o->batch < 0) return tr_scene_fail(sc, TRACE_EINVAL, "batch must be >= 0");
    return TRACE_OK;
}

/* Rays per batch: the option, else 8192 with sinks (records wait in memory) and
 * 65536 without; with several threads smaller, so that there are enough batches for
 * the last ones to end together and the window (nslot batches) stays within about a
 * million rays. */
static long batch_size(const trace_options *o, int sinks, int nthr, int nslot,
                       uint64_t nrays)
{
    if (o->batch) return o->batch;
    long b = sinks ? 8192 : 65536;
    while (b > 1024 && nthr > 1 &&
           (nrays / (uint64_t)b < 8 * (uint64_t)nthr || (uint64_t)b * nslot > (1u << 20)))
        b /= 2;
    return b;
}

static void free_worker(tr_worker *w)
{
    if (!w) return;
    free(w->stack);
    for (int l = 0; l < TR_LANES; l++) {
        free(w->lane[l].out.seg.p);
        free(w->lane[l].out.hit.p);
    }
    free(w);
}

/* A worker with its stacks (one for itself, one per lane); NULL: out of memory.
 * Each is its own allocation, a cache line apart from the others. */
static tr_worker *new_worker(const trace_scene *sc, const trace_options *o, int want_seg,
                             int want_hit)
{
    size_t size = (sizeof(tr_worker) + 63) / 64 * 64;
    tr_worker *w = aligned_alloc(64, size);
    if (!w) return NULL;
    memset(w, 0, sizeof *w);
    w->sc = sc;
    w->o = o;
    w->want_seg = want_seg;
    w->want_hit = want_hit;
    size_t depth = (size_t)o->max_depth + 4;
    w->stack = malloc((TR_LANES + 1) * depth * sizeof(tr_wray));
    if (!w->stack) { free(w); return NULL; }
    for (int l = 0; l < TR_LANES; l++) {
        w->lane[l].stack = w->stack + (size_t)(l + 1) * depth;
        w->lane[l].out.seg.size = sizeof(trace_segment);
        w->lane[l].out.hit.size = sizeof(trace_hit);
    }
    return w;
}

/* How many surfaces the lens shortcut names (when tr_hit.c's seq_cands may use it). */
static int lens_surfaces(const trace_scene *sc, const trace_options *o)
{
    if (!o->sequential || o->float_hits || sc->seq_nsurf != sc->nsurf || sc->nentry <= 0)
        return 0;
    char *in = calloc((size_t)sc->nsurf, 1);
    int n = 0;
    if (!in) return 0;
    for (int k = 0; k < sc->nentry; k++) in[sc->entry[k]] = 1;
    for (int i = 0; i < sc->nsurf; i++)
        for (int k = 0; k < sc->surf[i]->nseq; k++) in[sc->surf[i]->seq[k]] = 1;
    for (int i = 0; i < sc->nsurf; i++) n += in[i];
    free(in);
    return n;
}

static int run_sinks(trace_scene *sc, const trace_options *oin, const tr_sinks *sink,
                     trace_summary *sum)
{
    trace_options o;
    trace_summary s;
    tr_pool p;
    int rc;
    if (!sc) return TRACE_EINVAL;
    if (oin) o = *oin; else tr_options_default(&o);
    memset(&s, 0, sizeof s);
    if (sum) memset(sum, 0, sizeof *sum);
    if ((rc = check_options(sc, &o))) return rc;
    if ((rc = tr_build(sc, &s.build_ms))) return rc;
    int nthr = o.threads ? o.threads : (int)sysconf(_SC_NPROCESSORS_ONLN);
    if (nthr < 1) nthr = 1;
    int want_seg = sink->segment || sink->segments, want_hit = sink->hit || sink->hits;
    memset(&p, 0, sizeof p);
    p.sc = sc;
    p.nslot = nthr == 1 ? 1 : 2 * nthr + 2;   /* one thread: trace, deliver, again */
    p.batch = batch_size(&o, want_seg || want_hit, nthr, p.nslot, sc->nrays);
    p.nbatch = (sc->nrays + (uint64_t)p.batch - 1) / (uint64_t)p.batch;
    if (p.nbatch < (uint64_t)p.nslot) p.nslot = p.nbatch ? (int)p.nbatch : 1;
    if (p.nbatch < (uint64_t)nthr) nthr = p.nbatch ? (int)p.nbatch : 1;
    tr_worker **w = calloc((size_t)nthr, sizeof *w);
    tr_thread *th = calloc((size_t)nthr, sizeof *th);
    pthread_t *tid = calloc((size_t)nthr, sizeof *tid);
    p.slot = calloc((size_t)p.nslot, sizeof *p.slot);
    rc = (w && th && tid && p.slot) ? TRACE_OK : TRACE_ENOMEM;
    size_t room = sc->nrays < (uint64_t)p.batch ? (size_t)sc->nrays + 1 : (size_t)p.batch;
    for (int i = 0; rc == TRACE_OK && i < p.nslot; i++) {
        p.slot[i].power = malloc(room * sizeof(tr_power));
        p.slot[i].out.seg.size = sizeof(trace_segment);
        p.slot[i].out.hit.size = sizeof(trace_hit);
        p.slot[i].out.pol.size = sizeof(trace_polar_hit);
        if (!p.slot[i].power) rc = TRACE_ENOMEM;
    }
    for (int i = 0; rc == TRACE_OK && i < nthr; i++)
        if (!(w[i] = new_worker(sc, &o, want_seg, want_hit))) rc = TRACE_ENOMEM;
    if (rc != TRACE_OK) tr_scene_fail(sc, rc, "out of memory");
    int mu = 0, more = 0, ready = 0, nstarted = 0;
    if (rc == TRACE_OK) {
        mu = pthread_mutex_init(&p.mu, NULL) == 0;
        more = pthread_cond_init(&p.more, NULL) == 0;
        ready = pthread_cond_init(&p.ready, NULL) == 0;
        if (!mu || !more || !ready) rc = tr_scene_fail(sc, TRACE_ENOMEM, "cannot make a lock");
    }
    double t0 = tr_now_ms();
    if (rc == TRACE_OK) {
        /* a worker that cannot be started leaves its share to the others */
        for (int i = 1; i < nthr; i++) {
            th[nstarted] = (tr_thread){&p, w[i]};
            if (pthread_create(&tid[nstarted], NULL, worker_main, &th[nstarted]) == 0)
                nstarted++;
        }
        rc = drive(sc, &p, w[0], sink, &s);
        for (int i = 0; i < nstarted; i++) pthread_join(tid[i], NULL);
    }
    s.trace_ms = tr_now_ms() - t0;
    s.lens_surfaces = lens_surfaces(sc, &o);
    if (s.lens_surfaces) {
        const char *k = sc->absorbing || sc->polar || !tr_pk_usable() ? "scalar" : trace_isa_active();
        snprintf(s.lens_kernel, sizeof s.lens_kernel, "%s", k);
    }
    if (rc == TRACE_OK) rc = numeric_check(sc, &s, &p.fail);
    if (mu) pthread_mutex_destroy(&p.mu);
    if (more) pthread_cond_destroy(&p.more);
    if (ready) pthread_cond_destroy(&p.ready);
    for (int i = 0; w && i < nthr; i++) free_worker(w[i]);
    for (int i = 0; p.slot && i < p.nslot; i++) {
        free(p.slot[i].power);
        free(p.slot[i].out.seg.p);
        free(p.slot[i].out.hit.p);
        free(p.slot[i].out.pol.p);
    }
    free(p.slot);
    free(w);
    free(th);
    free(tid);
    if (sum) *sum = s;
    return rc;
}

int tr_run(trace_scene *sc, const trace_options *oin, const trace_sink *sink,
           trace_summary *sum)
{
    tr_sinks k = {0};
    if (sink) {
        k.ctx = sink->ctx;
        k.segment = sink->segment;
        k.hit = sink->hit;
        k.progress = sink->progress;
    }
    return run_sinks(sc, oin, &k, sum);
}

int tr_run_batches(trace_scene *sc, const trace_options *oin, const trace_batch_sink *sink,
                   trace_summary *sum)
{
    tr_sinks k = {0};
    if (sink) {
        k.ctx = sink->ctx;
        k.segments = sink->segments;
        k.hits = sink->hits;
        k.progress = sink->progress;
    }
    return run_sinks(sc, oin, &k, sum);
}
