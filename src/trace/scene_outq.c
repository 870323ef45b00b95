/* scene_outq.c -- the ordered chunk queue under the hit and .npy writers (scene_out.c):
 * the trace's thread fills chunks of binary rows; formatter threads turn whole chunks
 * into text in parallel (CSV), each into its own buffer, and whoever finishes the
 * chunk that is next in the file writes it and the finished ones after it, so the
 * file gets the chunks in the order they were filled (one fwrite a chunk).  Without a
 * format (.npy) a chunk is written as it is, off the trace's thread.  When every
 * chunk is taken the trace's thread formats one itself instead of waiting: a trace
 * that makes rows faster than the formatters can take them gives its own time to the
 * digits, and a machine without spare cores is no slower than doing it inline.
 * The chunks live in a ring indexed by their number (chunk s in slot s % nslot): they
 * are written in order, so a slot is free again once its chunk is out.
 * A regular file is committed with an fsync (src/common/lm_out.c): the writer starts
 * the disk writes of what it has written every few MB (Linux: sync_file_range, no
 * wait), so that the fsync at the end waits for the last few MB, not for the whole
 * file, and the writeback's work is done beside the trace instead of after it. */
#ifdef __linux__
#define _GNU_SOURCE 1           /* sync_file_range */
#include <fcntl.h>
#endif
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include "scene_out.h"

enum { SYNC_EVERY = 8 << 20 };   /* bytes between two starts of writeback */

enum { Q_FREE, Q_FILL, Q_READY, Q_BUSY, Q_DONE };

typedef struct {
    unsigned char *rows;
    size_t n;                  /* bytes of rows */
    char *text;                /* the formatted chunk (CSV), or NULL: rows as they are */
    size_t tlen;
    int state;
} q_slot;

struct soq {
    FILE *f;
    soq_format fmt;            /* NULL: rows are written as they are */
    void *ctx;
    size_t chunk, text_cap, cache_size;
    int nslot, nthread;
    q_slot *slot;
    uint64_t fill, write;      /* the chunk being filled; the next to write */
    int writing, quit, err;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    pthread_t *th;
    void *own_cache;           /* the filling thread's, when it formats */
    int sync_fd;               /* a regular file's descriptor (early writeback), or -1 */
    off_t synced;              /* where the last writeback started */
};

/* After a write: the disk writes of the file from where the last ones started, once
 * SYNC_EVERY more bytes are in it (the writer's thread, lock not held; a hint: its
 * failure changes nothing, the fsync at the commit still reports any error). */
static void start_writeback(soq *q)
{
#ifdef __linux__
    off_t at = q->sync_fd >= 0 ? ftello(q->f) : -1;
    if (at < 0 || at - q->synced < SYNC_EVERY) return;
    sync_file_range(q->sync_fd, q->synced, at - q->synced, SYNC_FILE_RANGE_WRITE);
    q->synced = at;
#else
    (void)q;
#endif
}

/* Format slot s (lock not held), with the formatter's cache c. */
static void format_slot(soq *q, q_slot *s, void *c)
{
    if (q->fmt) s->tlen = q->fmt(q->ctx, c, s->rows, s->n, s->text);
}

/* Write every finished chunk that is next in line; one thread at a time, lock held
 * (dropped around each fwrite). */
static void write_ready(soq *q)
{
    if (q->writing) return;
    q->writing = 1;
    for (;;) {
        q_slot *s = &q->slot[q->write % (uint64_t)q->nslot];
        if (q->write >= q->fill || s->state != Q_DONE) break;
        pthread_mutex_unlock(&q->mu);
        const void *b = q->fmt ? (const void *)s->text : (const void *)s->rows;
        size_t n = q->fmt ? s->tlen : s->n;
        int bad = !q->err && n && fwrite(b, 1, n, q->f) != n;
        if (!bad) start_writeback(q);
        pthread_mutex_lock(&q->mu);
        q->err |= bad;
        s->state = Q_FREE;
        q->write++;
        pthread_cond_broadcast(&q->cv);
    }
    q->writing = 0;
}

/* The oldest chunk waiting to be formatted (lock held), or NULL. */
static q_slot *next_ready(soq *q)
{
    for (uint64_t k = q->write; k < q->fill; k++) {
        q_slot *s = &q->slot[k % (uint64_t)q->nslot];
        if (s->state == Q_READY) return s;
    }
    return NULL;
}

/* Take one waiting chunk, format it, write what is next (lock held on entry and
 * exit); 0 if there was none. */
static int work_one(soq *q, void *cache)
{
    q_slot *s = next_ready(q);
    if (!s) return 0;
    s->state = Q_BUSY;
    pthread_mutex_unlock(&q->mu);
    if (!q->err) format_slot(q, s, cache);
    pthread_mutex_lock(&q->mu);
    s->state = Q_DONE;
    write_ready(q);
    return 1;
}

static void *formatter(void *arg)
{
    soq *q = arg;
    void *cache = q->cache_size ? calloc(1, q->cache_size) : NULL;
    pthread_mutex_lock(&q->mu);
    if (q->cache_size && !cache) q->err = 1;   /* the others drain the queue */
    while (cache || !q->cache_size) {
        if (work_one(q, cache)) continue;
        if (q->quit) break;
        pthread_cond_wait(&q->cv, &q->mu);
    }
    pthread_mutex_unlock(&q->mu);
    free(cache);
    return NULL;
}


/* The queue's memory (its threads joined, or never started). */
static void release(soq *q)
{
    if (q->slot)
        for (int i = 0; i < q->nslot; i++) {
            free(q->slot[i].rows);
            free(q->slot[i].text);
        }
    free(q->slot);
    free(q->th);
    free(q->own_cache);
    free(q);
}

soq *soq_new(FILE *f, int nthread, size_t chunk, size_t text_cap, soq_format fmt,
             void *ctx, size_t cache_size)
{
    soq *q = calloc(1, sizeof *q);
    if (!q) return NULL;
    q->f = f;
    q->fmt = fmt;
    q->ctx = ctx;
    q->chunk = chunk;
    q->text_cap = text_cap;
    q->cache_size = cache_size;
    q->nslot = 2 * nthread + 2;
    q->slot = calloc((size_t)q->nslot, sizeof *q->slot);
    q->th = calloc((size_t)(nthread > 0 ? nthread : 1), sizeof *q->th);
    q->own_cache = cache_size ? calloc(1, cache_size) : NULL;
    if (!q->slot || !q->th || (cache_size && !q->own_cache)) goto bad;
    for (int i = 0; i < q->nslot; i++) {
        q->slot[i].rows = malloc(chunk);
        q->slot[i].text = fmt ? malloc(text_cap) : NULL;
        if (!q->slot[i].rows || (fmt && !q->slot[i].text)) goto bad;
    }
    q->slot[0].state = Q_FILL;
    struct stat st;
    q->sync_fd = fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode) ? fileno(f) : -1;
    pthread_mutex_init(&q->mu, NULL);
    pthread_cond_init(&q->cv, NULL);
    /* without threads (none could be made) the filling thread does it all */
    for (int i = 0; i < nthread; i++, q->nthread++)
        if (pthread_create(&q->th[i], NULL, formatter, q)) break;
    return q;
bad:
    release(q);
    return NULL;
}

unsigned char *soq_rows(soq *q) { return q->slot[q->fill % (uint64_t)q->nslot].rows; }

int soq_submit(soq *q, size_t used)
{
    pthread_mutex_lock(&q->mu);
    if (used) {
        q_slot *s = &q->slot[q->fill % (uint64_t)q->nslot];
        s->n = used;
        s->state = Q_READY;
        q->fill++;
        pthread_cond_broadcast(&q->cv);
        /* the next slot: free once its chunk is written; meanwhile format one */
        s = &q->slot[q->fill % (uint64_t)q->nslot];
        while (s->state != Q_FREE)
            if (!work_one(q, q->own_cache)) pthread_cond_wait(&q->cv, &q->mu);
        s->state = Q_FILL;
    }
    int bad = q->err;
    pthread_mutex_unlock(&q->mu);
    return bad;
}

int soq_finish(soq *q, size_t used)
{
    int bad = soq_submit(q, used);
    pthread_mutex_lock(&q->mu);
    while (q->write < q->fill)   /* help with what is left, then wait for the writes */
        if (!work_one(q, q->own_cache)) pthread_cond_wait(&q->cv, &q->mu);
    q->quit = 1;
    pthread_cond_broadcast(&q->cv);
    pthread_mutex_unlock(&q->mu);
    for (int i = 0; i < q->nthread; i++) pthread_join(q->th[i], NULL);
    q->nthread = 0;
    return bad | q->err;
}

void soq_free(soq *q)
{
    if (!q) return;
    soq_finish(q, 0);
    pthread_mutex_destroy(&q->mu);
    pthread_cond_destroy(&q->cv);
    release(q);
}
