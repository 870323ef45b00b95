/* scene_out.h -- the record tables' formats (scene_out.c): CSV/text, .npy, HDF5.
 * Internal to the scene front end (scene_run.c); the files themselves are opened,
 * renamed and closed there. */
#ifndef SCENE_OUT_H
#define SCENE_OUT_H
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include "scene.h"


typedef struct so_table so_table;
/* A hits (hits=1) or segments table in format fmt written to f (its header now;
 * nothing written to f for SC_OUT_H5: the rows are kept for so_h5_write); wl: with the
 * wavelength column; stokes (hits): with S0..S3 last; threads: the trace's (0: all
 * cores), as many formatter threads for a CSV.  NULL with a message on failure. */
so_table *so_open(FILE *f, sc_out_format fmt, int hits, int wl, int stokes, int threads,
                  char *err, size_t errmax);
/* One row (stokes: the hit's S0..S3 for a table with them, NULL: NaN); 0, or non-zero
 * on a write error (or out of memory). */
int so_hit(so_table *t, FILE *f, const trace_hit *h, uint64_t ray, const double stokes[4]);
/* n hits at once, each numbered h[i].ray + ray0 (the Stokes columns, if any, NaN): the
 * bytes so_hit would write for each; 0 or non-zero as so_hit. */
int so_hits(so_table *t, FILE *f, const trace_hit *h, size_t n, uint64_t ray0);
int so_segment(so_table *t, FILE *f, const trace_segment *s);
/* The table's end (.npy: the rest of the rows, the header's row count); 0 or -1. */
int so_finish(so_table *t, FILE *f, char *err, size_t errmax);
void so_free(so_table *t);

/* What /summary holds. */
typedef struct {
    const char *scene;
    const trace_summary *sum;
    int nwl;                     /* per-wavelength rows (0: no wavelengths named) */
    const double *wl;            /* um */
    const trace_summary *per;
} so_summary;
/* One HDF5 file with whichever of /hits, /segments, /summary are not NULL, written
 * to f; 0 or -1 with a message. */
int so_h5_write(FILE *f, const so_table *hits, const so_table *segs, const so_summary *sum,
                char *err, size_t errmax);

/* The ordered chunk queue (scene_outq.c).  fmt turns n bytes of rows into text at
 * `text` (returning its length) with a per-thread cache of cache_size bytes (zeroed
 * at the start); NULL: the rows are written as they are.  nthread formatter threads
 * (0: the filling thread does everything). */
typedef struct soq soq;
typedef size_t (*soq_format)(void *ctx, void *cache, const unsigned char *rows, size_t n,
                             char *text);
soq *soq_new(FILE *f, int nthread, size_t chunk, size_t text_cap, soq_format fmt,
             void *ctx, size_t cache_size);
unsigned char *soq_rows(soq *q);          /* the chunk to fill */
int soq_submit(soq *q, size_t used);      /* hand it over; 0, or 1 after a write error */
int soq_finish(soq *q, size_t used);      /* the last one, every chunk written */
void soq_free(soq *q);
#endif
