/* scene_out.c -- how the trace front end formats its record tables (scene_run.c opens,
 * renames and closes the files; this file only says what goes into them):
 *   hits      CSV with the shortest numbers that read back to the same doubles
 *             (scene_dtoa.cpp), or the CSV of before ("%.17g", keyword csv17), or a
 *             NumPy .npy structured array (the same columns, one field each);
 *   segments  the seed's p.l text (two "x y z" lines, "%.10g") or .npy (x0 .. z1);
 *   HDF5      (.h5/.hdf5, or `output all FILE`): one file holding the tables /hits and
 *             /segments (the .npy layouts as compound datasets) and /summary (its
 *             counts and powers as attributes, per-wavelength rows as a table).
 * The .npy header is written per the NPY 1.0 format (numpy.org/neps/nep-0001) with room
 * for any row count and rewritten with the real one when the table ends (the file must
 * be seekable).  HDF5 is assembled in memory (the core driver) and its image written
 * through the same stream, so where the bytes go stays scene_run.c's business.
 * CSV hits and .npy tables are written by a thread of their own: the trace's thread
 * packs each record into a binary row (a memcpy); the writer formats the rows (CSV:
 * the digits are most of the cost) and writes them, one 1 MiB chunk while the trace
 * fills the next, so the formatting and the kernel's copy into the page cache run
 * beside the trace instead of inside it (measured: scripts/bench_trace_out.sh). */
#if defined(__has_include) && !__has_include(<hdf5.h>)
#include <hdf5/serial/hdf5.h>   /* Debian's serial build, without its -I */
#else
#include <hdf5.h>
#endif
#include <pthread.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "scene_out.h"

int sc_dtoa(double v, char *buf);   /* scene_dtoa.cpp */

/* ---- the tables' columns ---------------------------------------------------------- */

/* One row of a binary table: every column at its natural alignment, no padding (the
 * offsets below are what NumPy and HDF5 are told). */
enum { C_U64, C_I32, C_I64, C_F64 };
typedef struct { const char *name; int type; } column;

static const column hit_cols[] = {
    {"ray", C_U64}, {"depth", C_I32}, {"surface", C_I32}, {"triangle", C_I64},
    {"x", C_F64}, {"y", C_F64}, {"z", C_F64}, {"dx", C_F64}, {"dy", C_F64}, {"dz", C_F64},
    {"power_s", C_F64}, {"power_p", C_F64}, {"power", C_F64}, {"length", C_F64},
    {"opl", C_F64}, {"lambda_nm", C_F64}};
static const column seg_cols[] = {
    {"x0", C_F64}, {"y0", C_F64}, {"z0", C_F64}, {"x1", C_F64}, {"y1", C_F64},
    {"z1", C_F64}, {"lambda_nm", C_F64}};
#define NHIT (int)(sizeof hit_cols / sizeof hit_cols[0])
#define NSEG (int)(sizeof seg_cols / sizeof seg_cols[0])

static size_t col_size(int type) { return type == C_I32 ? 4 : 8; }

struct so_table {
    sc_out_format fmt;
    int hits;                  /* 1: hits, 0: segments */
    int ncol;                  /* the wavelength column is the last one, when named */
    size_t row;                /* bytes a binary row */
    uint64_t nrows;
    long header;               /* .npy: bytes of the header (rewritten at the end) */
    unsigned char *buf;        /* rows being filled (.npy, CSV: a chunk; HDF5: all) */
    size_t used, cap;
    /* the writer thread (CSV hits, .npy): it owns f between so_open and so_finish */
    int async;
    FILE *f;
    pthread_t th;
    pthread_mutex_t mu;
    pthread_cond_t cv;
    unsigned char *wbuf;       /* the chunk handed to the writer (NULL: none pending) */
    size_t wused;
    unsigned char *spare;      /* the chunk it gave back */
    int quit, werr;
    char *text;                /* the writer's CSV text (a chunk of lines) */
    so_table *wt;              /* the writer's own caches: the wavelength, and ... */
    uint64_t last[11];         /* ... each column's last value (a detector plane's z,
                                  a constant length: the digits are made once) */
    char last_text[11][32];
    unsigned char last_len[11];
    double nm_of, nm;          /* the last wavelength (um) and its "%.10g" nm value */
    char nm_text[40];          /* and that text, for the CSV */
};

static const column *cols(const so_table *t) { return t->hits ? hit_cols : seg_cols; }

/* The wavelength column's value: lambda um in nm, as the CSV's "%.10g" reads back (the
 * binary tables and the CSV agree to the bit); one conversion per wavelength. */
static double nm_of(so_table *t, double lambda)
{
    if (lambda != t->nm_of || !t->nm_text[0]) {
        t->nm_of = lambda;
        snprintf(t->nm_text, sizeof t->nm_text, "%.10g", lambda * 1e3);
        t->nm = strtod(t->nm_text, NULL);
    }
    return t->nm;
}

/* ---- .npy ------------------------------------------------------------------------- */

/* The NPY 1.0 header for n rows, padded with blanks to `len` bytes (0: as short as any
 * row count allows, a multiple of 64); its length, or -1 if it does not fit. */
static long npy_header(const so_table *t, uint64_t n, char *out, long len)
{
    const column *c = cols(t);
    static const char *const descr[] = {"u8", "i4", "i8", "f8"};
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__
    const char end = '>';
#else
    const char end = '<';
#endif
    char d[1024];
    int k = snprintf(d, sizeof d, "{'descr': [");
    for (int i = 0; i < t->ncol; i++)
        k += snprintf(d + k, sizeof d - (size_t)k, "%s('%s', '%c%s')", i ? ", " : "",
                      c[i].name, end, descr[c[i].type]);
    /* the row count's field is as wide as the largest one: the header keeps its size */
    k += snprintf(d + k, sizeof d - (size_t)k, "], 'fortran_order': False, 'shape': (%llu,), }",
                  (unsigned long long)n);
    long need = 10 + k + 1, total = len ? len : (10 + k + 20 + 1 + 63) / 64 * 64;
    if (need > total || total - 10 > 65535) return -1;
    memcpy(out, "\x93NUMPY\x01\x00", 8);
    out[8] = (char)((total - 10) & 0xff);
    out[9] = (char)((total - 10) >> 8);
    memcpy(out + 10, d, (size_t)k);
    memset(out + 10 + k, ' ', (size_t)(total - 10 - k - 1));
    out[total - 1] = '\n';
    return total;
}

/* ---- opening, rows, closing ------------------------------------------------------- */

enum { CHUNK = 1 << 20, TEXTBUF = 1 << 18 };   /* rows a hand-over, CSV text a write */
static void *writer(void *arg);

so_table *so_open(FILE *f, sc_out_format fmt, int hits, int wl, char *err, size_t errmax)
{
    so_table *t = calloc(1, sizeof *t);
    if (!t) return snprintf(err, errmax, "out of memory"), NULL;
    t->fmt = fmt;
    t->hits = hits;
    t->ncol = (hits ? NHIT : NSEG) - (wl ? 0 : 1);
    for (int i = 0; i < t->ncol; i++) t->row += col_size(cols(t)[i].type);
    t->f = f;
    if (fmt == SC_OUT_TEXT || fmt == SC_OUT_CSV17) {
        if (hits)
            fputs(wl ? "ray,depth,surface,triangle,x,y,z,dx,dy,dz,power_s,power_p,power,"
                  "length,opl,lambda_nm\n" : "ray,depth,surface,triangle,x,y,z,dx,dy,dz,"
                  "power_s,power_p,power,length,opl\n", f);
        if (fmt == SC_OUT_CSV17 || !hits) return t;   /* written as they come */
    }
    if (fmt == SC_OUT_NPY) {
        char h[2048];
        t->header = npy_header(t, 0, h, 0);
        if (t->header < 0 || fwrite(h, 1, (size_t)t->header, f) != (size_t)t->header) {
            snprintf(err, errmax, "cannot write the .npy header");
            free(t);
            return NULL;
        }
    }
    if (fmt == SC_OUT_TEXT || fmt == SC_OUT_NPY) {   /* the writer thread */
        t->buf = malloc(CHUNK);
        t->spare = malloc(CHUNK);
        t->text = fmt == SC_OUT_TEXT ? malloc(TEXTBUF) : NULL;
        t->wt = calloc(1, sizeof *t->wt);
        t->cap = CHUNK;
        if (!t->buf || !t->spare || !t->wt || (fmt == SC_OUT_TEXT && !t->text)) goto oom;
        pthread_mutex_init(&t->mu, NULL);
        pthread_cond_init(&t->cv, NULL);
        if (pthread_create(&t->th, NULL, writer, t) == 0) {
            t->async = 1;
        } else {   /* no thread: the rows are written as the chunks fill */
            pthread_mutex_destroy(&t->mu);
            pthread_cond_destroy(&t->cv);
        }
    }
    return t;
oom:
    snprintf(err, errmax, "out of memory");
    so_free(t);
    return NULL;
}


static int write_rows(so_table *t, const unsigned char *b, size_t n);

/* The writer thread: takes each chunk handed over, writes it (CSV: formats it first),
 * gives the buffer back. */
static void *writer(void *arg)
{
    so_table *t = arg;
    pthread_mutex_lock(&t->mu);
    for (;;) {
        while (!t->wbuf && !t->quit) pthread_cond_wait(&t->cv, &t->mu);
        if (!t->wbuf) break;
        unsigned char *b = t->wbuf;
        size_t n = t->wused;
        int bad = t->werr;
        pthread_mutex_unlock(&t->mu);
        if (!bad) bad = write_rows(t, b, n);
        pthread_mutex_lock(&t->mu);
        t->werr |= bad;
        t->spare = b;
        t->wbuf = NULL;
        pthread_cond_broadcast(&t->cv);
    }
    pthread_mutex_unlock(&t->mu);
    return NULL;
}

/* Hand the filled chunk to the writer (waiting for it to finish the one before); the
 * chunk it gave back becomes the one to fill.  0, or non-zero after a write error. */
static int hand_over(so_table *t)
{
    pthread_mutex_lock(&t->mu);
    while (t->wbuf) pthread_cond_wait(&t->cv, &t->mu);
    int bad = t->werr;
    if (t->used) {
        t->wbuf = t->buf;
        t->wused = t->used;
        t->buf = t->spare;
        t->spare = NULL;
        t->used = 0;
        pthread_cond_broadcast(&t->cv);
    }
    pthread_mutex_unlock(&t->mu);
    return bad || !t->buf;
}

/* Room for one more binary row: a full chunk goes to the writer (or, without one, to
 * f); HDF5 keeps growing. */
static unsigned char *row_slot(so_table *t, FILE *f)
{
    if (t->fmt != SC_OUT_H5 && t->used + t->row > CHUNK) {
        if (t->async ? hand_over(t) : write_rows(t, t->buf, t->used)) return NULL;
        if (!t->async) t->used = 0;
    }
    (void)f;
    if (t->used + t->row > t->cap) {
        size_t cap = t->cap ? t->cap * 2 : 65536;
        unsigned char *b = realloc(t->buf, cap);
        if (!b) return NULL;
        t->buf = b;
        t->cap = cap;
    }
    unsigned char *p = t->buf + t->used;
    t->used += t->row;
    t->nrows++;
    return p;
}

#define PUT(p, v) (memcpy((p), &(v), sizeof (v)), (p) += sizeof (v))

/* Decimal digits of v at p; returns the end. */
static char *put_u64(char *p, uint64_t v)
{
    char tmp[24];
    int n = 0;
    do tmp[n++] = (char)('0' + v % 10); while (v /= 10);
    while (n) *p++ = tmp[--n];
    return p;
}

static char *put_i64(char *p, long long v)
{
    if (v < 0) { *p++ = '-'; return put_u64(p, 0 - (uint64_t)v); }
    return put_u64(p, (uint64_t)v);
}

int so_hit(so_table *t, FILE *f, const trace_hit *h, uint64_t ray)
{
    const double v[11] = {h->pos[0], h->pos[1], h->pos[2], h->dir[0], h->dir[1], h->dir[2],
                          h->power_s, h->power_p, h->power_s + h->power_p, h->length,
                          h->opl};
    if (t->fmt == SC_OUT_CSV17) {   /* the bytes of before, number for number */
        if (fprintf(f, "%llu,%d,%d,%ld,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,"
                    "%.17g,%.17g,%.17g,%.17g", (unsigned long long)ray, h->depth,
                    h->surface, h->prim, v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7],
                    v[8], v[9], v[10]) < 0)
            return 1;
        return (t->ncol == NHIT ? fprintf(f, ",%.10g\n", h->lambda * 1e3)
                                : fputs("\n", f)) < 0;
    }
    unsigned char *p = row_slot(t, f);
    if (!p) return 1;
    int32_t depth = h->depth, surf = h->surface;
    int64_t prim = h->prim;
    PUT(p, ray);
    PUT(p, depth);
    PUT(p, surf);
    PUT(p, prim);
    memcpy(p, v, sizeof v);
    p += sizeof v;
    if (t->ncol == NHIT) {   /* CSV: the wavelength as it came (the writer prints it) */
        double nm = t->fmt == SC_OUT_TEXT ? h->lambda : nm_of(t, h->lambda);
        PUT(p, nm);
    }
    return 0;
}

/* One binary hit row as a CSV line at p; returns the end. */
static char *csv_line(so_table *t, const unsigned char *r, char *p)
{
    uint64_t ray;
    int32_t depth, surf;
    int64_t prim;
    double v[12];
    memcpy(&ray, r, 8);
    memcpy(&depth, r + 8, 4);
    memcpy(&surf, r + 12, 4);
    memcpy(&prim, r + 16, 8);
    memcpy(v, r + 24, t->row - 24);
    p = put_u64(p, ray);
    *p++ = ',';
    p = put_i64(p, depth);
    *p++ = ',';
    p = put_i64(p, surf);
    *p++ = ',';
    p = put_i64(p, prim);
    so_table *c = t->wt;
    for (int i = 0; i < 11; i++) {
        uint64_t bits;
        memcpy(&bits, &v[i], 8);
        *p++ = ',';
        if (!c->last_len[i] || bits != c->last[i]) {
            c->last[i] = bits;
            c->last_len[i] = (unsigned char)sc_dtoa(v[i], c->last_text[i]);
        }
        memcpy(p, c->last_text[i], c->last_len[i]);
        p += c->last_len[i];
    }
    if (t->ncol == NHIT) {
        nm_of(t->wt, v[11]);
        *p++ = ',';
        size_t n = strlen(t->wt->nm_text);
        memcpy(p, t->wt->nm_text, n);
        p += n;
    }
    *p++ = '\n';
    return p;
}

/* n bytes of rows into t's file: as they are (.npy) or as CSV lines.  0 or 1. */
static int write_rows(so_table *t, const unsigned char *b, size_t n)
{
    if (t->fmt != SC_OUT_TEXT) return fwrite(b, 1, n, t->f) != n;
    char *p = t->text;
    for (size_t k = 0; k < n; k += t->row) {
        if (p - t->text > TEXTBUF - 512) {
            if (fwrite(t->text, 1, (size_t)(p - t->text), t->f) != (size_t)(p - t->text))
                return 1;
            p = t->text;
        }
        p = csv_line(t, b + k, p);
    }
    return fwrite(t->text, 1, (size_t)(p - t->text), t->f) != (size_t)(p - t->text);
}

int so_segment(so_table *t, FILE *f, const trace_segment *s)
{
    if (t->fmt == SC_OUT_TEXT || t->fmt == SC_OUT_CSV17) {   /* the seed's p.l form */
        if (t->ncol == NSEG) {
            double nm = s->lambda * 1e3;
            return fprintf(f, "%.10g %.10g %.10g %.10g\n%.10g %.10g %.10g %.10g\n",
                           s->p0[0], s->p0[1], s->p0[2], nm, s->p1[0], s->p1[1],
                           s->p1[2], nm) < 0;
        }
        return fprintf(f, "%.10g %.10g %.10g\n%.10g %.10g %.10g\n", s->p0[0], s->p0[1],
                       s->p0[2], s->p1[0], s->p1[1], s->p1[2]) < 0;
    }
    unsigned char *p = row_slot(t, f);
    if (!p) return 1;
    memcpy(p, s->p0, sizeof s->p0);
    memcpy(p + 24, s->p1, sizeof s->p1);
    if (t->ncol == NSEG) {
        double nm = nm_of(t, s->lambda);
        memcpy(p + 48, &nm, sizeof nm);
    }
    return 0;
}

/* The writer's last chunk and its end (joined): 0, or 1 after a write error. */
static int stop_writer(so_table *t)
{
    int bad;
    if (!t->async) return 0;
    bad = hand_over(t);
    pthread_mutex_lock(&t->mu);
    t->quit = 1;
    pthread_cond_broadcast(&t->cv);
    pthread_mutex_unlock(&t->mu);
    pthread_join(t->th, NULL);
    pthread_mutex_destroy(&t->mu);
    pthread_cond_destroy(&t->cv);
    t->async = 0;
    return bad | t->werr;
}

int so_finish(so_table *t, FILE *f, char *err, size_t errmax)
{
    int bad = stop_writer(t);
    if (!bad && t->fmt != SC_OUT_H5 && t->used && t->buf)   /* rows of a thread-less table */
        bad = write_rows(t, t->buf, t->used);
    t->used = 0;
    if (bad) return snprintf(err, errmax, "write error"), -1;
    if (t->fmt == SC_OUT_NPY) {
        char h[2048];
        /* the real row count into the header (same length: the field was sized for
         * the largest count) */
        if (npy_header(t, t->nrows, h, t->header) != t->header || fflush(f) ||
            fseek(f, 0, SEEK_SET) || fwrite(h, 1, (size_t)t->header, f) != (size_t)t->header ||
            fseek(f, 0, SEEK_END))
            return snprintf(err, errmax, "a .npy output must be a file it can go back "
                            "into (its header gets the row count at the end)"), -1;
    }
    return 0;
}

void so_free(so_table *t)
{
    if (!t) return;
    stop_writer(t);
    free(t->buf);
    free(t->spare);
    free(t->text);
    free(t->wt);
    free(t);
}

/* ---- HDF5 ------------------------------------------------------------------------- */

static hid_t h5_native(int type)
{
    return type == C_U64 ? H5T_NATIVE_UINT64 : type == C_I32 ? H5T_NATIVE_INT32 :
           type == C_I64 ? H5T_NATIVE_INT64 : H5T_NATIVE_DOUBLE;
}

static hid_t h5_type(const so_table *t)
{
    hid_t ty = H5Tcreate(H5T_COMPOUND, t->row);
    size_t off = 0;
    for (int i = 0; ty >= 0 && i < t->ncol; i++) {
        const column *c = &cols(t)[i];
        if (H5Tinsert(ty, c->name, off, h5_native(c->type)) < 0) { H5Tclose(ty); return -1; }
        off += col_size(c->type);
    }
    return ty;
}

/* One table as a compound dataset NAME under loc; 0 or -1. */
static int h5_table(hid_t loc, const char *name, const so_table *t)
{
    hsize_t n = t->nrows;
    hid_t ty = h5_type(t), sp = H5Screate_simple(1, &n, NULL), ds = -1;
    int rc = -1;
    if (ty >= 0 && sp >= 0 &&
        (ds = H5Dcreate2(loc, name, ty, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)) >= 0)
        rc = n == 0 || H5Dwrite(ds, ty, H5S_ALL, H5S_ALL, H5P_DEFAULT, t->buf) >= 0 ? 0 : -1;
    if (ds >= 0) H5Dclose(ds);
    if (sp >= 0) H5Sclose(sp);
    if (ty >= 0) H5Tclose(ty);
    return rc;
}

static int h5_attr(hid_t loc, const char *name, hid_t type, const void *v)
{
    hid_t sp = H5Screate(H5S_SCALAR), a = -1;
    int rc = -1;
    if (sp >= 0 && (a = H5Acreate2(loc, name, type, sp, H5P_DEFAULT, H5P_DEFAULT)) >= 0)
        rc = H5Awrite(a, type, v) >= 0 ? 0 : -1;
    if (a >= 0) H5Aclose(a);
    if (sp >= 0) H5Sclose(sp);
    return rc;
}

/* /summary: the text summary's lines as attributes (same names), the scene's name, and
 * with wavelengths named a table of the per-wavelength lines. */
static int h5_summary(hid_t file, const so_summary *s)
{
    hid_t g = H5Gcreate2(file, "summary", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    const trace_summary *m = s->sum;
    const struct { const char *n; uint64_t v; } u[] = {
        {"rays", m->rays}, {"segments", m->segments}, {"interactions", m->interactions},
        {"tir", m->tir}, {"hits", m->hits}, {"cut_depth", m->cut_depth},
        {"cut_power", m->cut_power}, {"cut_reflection", m->cut_reflection},
        {"failures", m->failures}, {"medium_mismatch", m->medium_mismatch}};
    const struct { const char *n; double v; } d[] = {
        {"emitted", m->emitted}, {"detected", m->detected}, {"absorbed", m->absorbed},
        {"escaped", m->escaped}, {"cutoff", m->cutoff},
        {"balance_error", m->emitted - (m->detected + m->absorbed + m->escaped + m->cutoff)}};
    int rc = g < 0 ? -1 : 0;
    if (g >= 0) {
        hid_t str = H5Tcopy(H5T_C_S1);   /* variable length, UTF-8: a str in h5py */
        H5Tset_size(str, H5T_VARIABLE);
        H5Tset_cset(str, H5T_CSET_UTF8);
        rc |= h5_attr(g, "scene", str, &s->scene);
        H5Tclose(str);
    }
    for (size_t i = 0; !rc && i < sizeof u / sizeof u[0]; i++)
        rc |= h5_attr(g, u[i].n, H5T_NATIVE_UINT64, &u[i].v);
    for (size_t i = 0; !rc && i < sizeof d / sizeof d[0]; i++)
        rc |= h5_attr(g, d[i].n, H5T_NATIVE_DOUBLE, &d[i].v);
    if (!rc && s->nwl) {   /* wavelength_nm rays hits emitted detected absorbed escaped cutoff */
        typedef struct { double nm; uint64_t rays, hits; double e, d, a, x, c; } wrow;
        wrow *w = calloc((size_t)s->nwl, sizeof *w);
        hid_t ty = H5Tcreate(H5T_COMPOUND, sizeof(wrow));
        hsize_t n = (hsize_t)s->nwl;
        rc = w && ty >= 0 ? 0 : -1;
        for (int k = 0; !rc && k < s->nwl; k++) {
            char txt[40];
            snprintf(txt, sizeof txt, "%.10g", s->wl[k] * 1e3);
            w[k] = (wrow){strtod(txt, NULL), s->per[k].rays, s->per[k].hits,
                          s->per[k].emitted, s->per[k].detected, s->per[k].absorbed,
                          s->per[k].escaped, s->per[k].cutoff};
        }
        if (!rc) {
            H5Tinsert(ty, "wavelength_nm", offsetof(wrow, nm), H5T_NATIVE_DOUBLE);
            H5Tinsert(ty, "rays", offsetof(wrow, rays), H5T_NATIVE_UINT64);
            H5Tinsert(ty, "hits", offsetof(wrow, hits), H5T_NATIVE_UINT64);
            H5Tinsert(ty, "emitted", offsetof(wrow, e), H5T_NATIVE_DOUBLE);
            H5Tinsert(ty, "detected", offsetof(wrow, d), H5T_NATIVE_DOUBLE);
            H5Tinsert(ty, "absorbed", offsetof(wrow, a), H5T_NATIVE_DOUBLE);
            H5Tinsert(ty, "escaped", offsetof(wrow, x), H5T_NATIVE_DOUBLE);
            H5Tinsert(ty, "cutoff", offsetof(wrow, c), H5T_NATIVE_DOUBLE);
            hid_t sp = H5Screate_simple(1, &n, NULL);
            hid_t ds = H5Dcreate2(g, "wavelengths", ty, sp, H5P_DEFAULT, H5P_DEFAULT,
                                  H5P_DEFAULT);
            rc = ds >= 0 && H5Dwrite(ds, ty, H5S_ALL, H5S_ALL, H5P_DEFAULT, w) >= 0 ? 0 : -1;
            if (ds >= 0) H5Dclose(ds);
            H5Sclose(sp);
        }
        if (ty >= 0) H5Tclose(ty);
        free(w);
    }
    if (g >= 0) H5Gclose(g);
    return rc;
}

int so_h5_write(FILE *f, const so_table *hits, const so_table *segs, const so_summary *sum,
                char *err, size_t errmax)
{
    hid_t fapl, file;
    int rc = 0;
    void *img = NULL;
    ssize_t size;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);   /* our message, not HDF5's error stack */
    /* in memory (no backing store): the image goes out through f */
    if ((fapl = H5Pcreate(H5P_FILE_ACCESS)) < 0 || H5Pset_fapl_core(fapl, 1 << 20, 0) < 0)
        return snprintf(err, errmax, "HDF5: cannot set up a file"), -1;
    /* a name no file can have (HDF5 tries to open it even with no backing store:
     * never a user's file) */
    file = H5Fcreate("/dev/null/lensmat-trace-core.h5", H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    H5Pclose(fapl);
    if (file < 0) return snprintf(err, errmax, "HDF5: cannot create a file"), -1;
    if (hits) rc |= h5_table(file, "hits", hits);
    if (segs && !rc) rc |= h5_table(file, "segments", segs);
    if (sum && !rc) rc |= h5_summary(file, sum);
    if (!rc && H5Fflush(file, H5F_SCOPE_GLOBAL) < 0) rc = -1;
    if (!rc && (size = H5Fget_file_image(file, NULL, 0)) > 0 && (img = malloc((size_t)size)) &&
        H5Fget_file_image(file, img, (size_t)size) == size) {
        if (fwrite(img, 1, (size_t)size, f) != (size_t)size) {
            snprintf(err, errmax, "write error");
            rc = -1;
        }
    } else if (!rc) {
        snprintf(err, errmax, "HDF5: cannot make the file's image (out of memory?)");
        rc = -1;
    } else {
        snprintf(err, errmax, "HDF5: cannot write the tables (out of memory?)");
    }
    free(img);
    H5Fclose(file);
    return rc;
}
