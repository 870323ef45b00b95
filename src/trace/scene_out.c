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
 * CSV hits and .npy tables go through an ordered chunk queue (scene_outq.c): the
 * trace's thread packs each record into a binary row (a memcpy into a 512 KiB chunk);
 * CSV chunks are formatted by as many threads as the trace has, in parallel, and
 * written in order, one fwrite a chunk; .npy chunks are written as they are, off the
 * trace's thread (measured: scripts/bench_trace_out.sh).  A CSV line is made column by
 * column from the table below: a column added there (and packed in so_hit) is in
 * every format. */
#if defined(__has_include) && !__has_include(<hdf5.h>)
#include <hdf5/serial/hdf5.h>   /* Debian's serial build, without its -I */
#else
#include <hdf5.h>
#endif
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "scene_out.h"

int sc_dtoa(double v, char *buf);   /* scene_dtoa.cpp: buf has room for 40 bytes */

/* ---- the tables' columns ---------------------------------------------------------- */

/* One row of a binary table: every column at its natural alignment, no padding (the
 * offsets below are what NumPy and HDF5 are told).  C_NM: the wavelength, a double in
 * nm in the binary tables (as "%.10g" prints it); the CSV's rows carry the um value
 * and print it so. */
enum { C_U64, C_I32, C_I64, C_F64, C_NM };
typedef struct { const char *name; int type; } column;

static const column hit_cols[] = {
    {"ray", C_U64}, {"depth", C_I32}, {"surface", C_I32}, {"triangle", C_I64},
    {"x", C_F64}, {"y", C_F64}, {"z", C_F64}, {"dx", C_F64}, {"dy", C_F64}, {"dz", C_F64},
    {"power_s", C_F64}, {"power_p", C_F64}, {"power", C_F64}, {"length", C_F64},
    {"opl", C_F64}, {"lambda_nm", C_NM}, {"S0", C_F64}, {"S1", C_F64}, {"S2", C_F64},
    {"S3", C_F64}};
static const column seg_cols[] = {
    {"x0", C_F64}, {"y0", C_F64}, {"z0", C_F64}, {"x1", C_F64}, {"y1", C_F64},
    {"z1", C_F64}, {"lambda_nm", C_NM}};
#define NHIT (int)(sizeof hit_cols / sizeof hit_cols[0])
#define NSEG (int)(sizeof seg_cols / sizeof seg_cols[0])
#define HIT_WL 15            /* hit_cols[15]: lambda_nm, then the Stokes parameters */

static size_t col_size(int type) { return type == C_I32 ? 4 : 8; }

struct so_table {
    sc_out_format fmt;
    int hits;                  /* 1: hits, 0: segments */
    int ncol;                  /* columns of this table: ... */
    int wl, st;                /* ... with the wavelength, with the Stokes parameters */
    column col[NHIT];          /* (the hits' lambda_nm, S0..S3 only when asked for) */
    size_t row;                /* bytes a binary row */
    uint64_t nrows;
    long header;               /* .npy: bytes of the header (rewritten at the end) */
    unsigned char *buf;        /* rows being filled (queue: its chunk; HDF5: all) */
    size_t used, cap;
    soq *q;                    /* CSV hits, .npy: the chunk queue (it owns f's writes) */
    double nm_of, nm;          /* the last wavelength (um) and its "%.10g" nm value */
    char nm_text[40];          /* and that text */
};

static const column *cols(const so_table *t) { return t->col; }

/* lambda um in nm as "%.10g" prints it, into text; the value that reads back. */
static double nm_text(double lambda, char *text, size_t cap)
{
    snprintf(text, cap, "%.10g", lambda * 1e3);
    return strtod(text, NULL);
}

/* The wavelength column's value: lambda um in nm, as the CSV's "%.10g" reads back (the
 * binary tables and the CSV agree to the bit); one conversion per wavelength. */
static double nm_of(so_table *t, double lambda)
{
    if (lambda != t->nm_of || !t->nm_text[0]) {
        t->nm_of = lambda;
        t->nm = nm_text(lambda, t->nm_text, sizeof t->nm_text);
    }
    return t->nm;
}

/* ---- .npy ------------------------------------------------------------------------- */

/* The NPY 1.0 header for n rows, padded with blanks to `len` bytes (0: as short as any
 * row count allows, a multiple of 64); its length, or -1 if it does not fit. */
static long npy_header(const so_table *t, uint64_t n, char *out, long len)
{
    const column *c = cols(t);
    static const char *const descr[] = {"u8", "i4", "i8", "f8", "f8"};
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


/* ---- CSV lines (in the formatter threads) ----------------------------------------- */

/* A formatter's own memory: the wavelength's text (made once a run of them). */
typedef struct {
    double nm_of;
    char nm_text[40];
    unsigned char nm_len;
} csv_cache;

/* The longest a CSV field can be ("-2.2250738585072014e-308", a 20-digit integer) and
 * its comma; a number's digits are written with 8-byte stores that reach up to 32
 * bytes from where it starts (sc_dtoa), and a repeated field is copied 32 bytes at a
 * time: the slack after the last field. */
enum { FIELD_MAX = 25, LINE_SLACK = 64 };

static char *put_u64(char *p, uint64_t v)
{
    static const char d2[201] =
        "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
        "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
        "8081828384858687888990919293949596979899";
    char tmp[24];
    int n = 24;
    while (v >= 100) {
        n -= 2;
        memcpy(tmp + n, d2 + 2 * (v % 100), 2);
        v /= 100;
    }
    if (v >= 10) { n -= 2; memcpy(tmp + n, d2 + 2 * v, 2); }
    else tmp[--n] = (char)('0' + v);
    memcpy(p, tmp + n, (size_t)(24 - n));
    return p + 24 - n;
}

static char *put_i64(char *p, int64_t v)
{
    if (v < 0) { *p++ = '-'; return put_u64(p, 0 - (uint64_t)v); }
    return put_u64(p, (uint64_t)v);
}

/* n bytes of binary hit rows as CSV lines at `text`; their length.  A field whose value
 * (its bits) is the one before in its column -- a detector plane's z, the depth, the
 * surface -- is copied from where it was written in this text (a row back: long
 * written, so the copy does not wait on the stores) instead of made again. */
static size_t csv_rows(void *ctx, void *cache, const unsigned char *r, size_t n, char *text)
{
    const so_table *t = ctx;
    const column *col = cols(t);
    csv_cache *c = cache;
    const char *at[NHIT] = {0};   /* column i's last text in this chunk, its bits */
    uint64_t last[NHIT];
    unsigned char len[NHIT];
    char *p = text;
    for (const unsigned char *end = r + n; r < end; ) {
        for (int i = 0; i < t->ncol; i++) {
            uint64_t u;
            int32_t i32;
            double v;
            if (i) *p++ = ',';
            if (col[i].type == C_NM) {   /* the um value, printed as "%.10g" of nm */
                memcpy(&v, r, 8);
                r += 8;
                if (!c->nm_len || v != c->nm_of) {
                    c->nm_of = v;
                    nm_text(v, c->nm_text, sizeof c->nm_text);
                    c->nm_len = (unsigned char)strlen(c->nm_text);
                }
                memcpy(p, c->nm_text, c->nm_len);
                p += c->nm_len;
                continue;
            }
            if (col[i].type == C_I32) {
                memcpy(&i32, r, 4);
                u = (uint64_t)(int64_t)i32;
                r += 4;
            } else {
                memcpy(&u, r, 8);
                r += 8;
            }
            if (at[i] && u == last[i]) {   /* 32 bytes (the rest is the next field's
                                              room), loaded before any is stored */
                char b[32];
                memcpy(b, at[i], 32);
                memcpy(p, b, 32);
                p += len[i];
                continue;
            }
            char *q = p;
            switch (col[i].type) {
            case C_U64: p = put_u64(p, u); break;
            case C_F64: memcpy(&v, &u, 8); p += sc_dtoa(v, p); break;
            default: p = put_i64(p, (int64_t)u);   /* C_I32, C_I64 */
            }
            at[i] = q;
            last[i] = u;
            len[i] = (unsigned char)(p - q);
        }
        *p++ = '\n';
    }
    return (size_t)(p - text);
}

/* ---- opening, rows, closing ------------------------------------------------------- */

enum { CHUNK = 1 << 19 };   /* bytes of rows a hand-over (CSV: about 1 MB of text) */

so_table *so_open(FILE *f, sc_out_format fmt, int hits, int wl, int stokes, int threads,
                  char *err, size_t errmax)
{
    so_table *t = calloc(1, sizeof *t);
    if (!t) return snprintf(err, errmax, "out of memory"), NULL;
    t->fmt = fmt;
    t->hits = hits;
    t->wl = wl != 0;
    t->st = hits && stokes;
    for (int i = 0; i < (hits ? NHIT : NSEG); i++) {
        int k = hits ? i - HIT_WL : i - (NSEG - 1);   /* 0: lambda_nm, > 0: S0..S3 */
        if ((k == 0 && !t->wl) || (k > 0 && !t->st)) continue;
        t->col[t->ncol++] = hits ? hit_cols[i] : seg_cols[i];
    }
    for (int i = 0; i < t->ncol; i++) t->row += col_size(cols(t)[i].type);
    if (fmt == SC_OUT_TEXT || fmt == SC_OUT_CSV17) {
        if (hits)
            for (int i = 0; i < t->ncol; i++)
                fprintf(f, "%s%s", t->col[i].name, i + 1 < t->ncol ? "," : "\n");
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
    if (fmt == SC_OUT_TEXT || fmt == SC_OUT_NPY) {
        size_t rows = CHUNK / t->row;
        long cores = sysconf(_SC_NPROCESSORS_ONLN);
        /* formatters: the trace's thread count, at most 8 (each has two chunks in the
         * ring: 4.5 MB with their text) */
        int n = fmt == SC_OUT_NPY ? 1 : threads > 0 ? threads : cores > 0 ? (int)cores : 1;
        t->cap = rows * t->row;
        t->q = soq_new(f, n > 8 ? 8 : n, t->cap, rows * (size_t)t->ncol * FIELD_MAX +
                       LINE_SLACK, fmt == SC_OUT_TEXT ? csv_rows : NULL, t,
                       fmt == SC_OUT_TEXT ? sizeof(csv_cache) : 0);
        if (!t->q) {
            snprintf(err, errmax, "out of memory");
            free(t);
            return NULL;
        }
        t->buf = soq_rows(t->q);
    }
    return t;
}

/* Room for at least one more binary row (a full chunk goes to the queue; HDF5 keeps
 * growing): how many rows fit now, 0 after a write error or out of memory. */
static size_t room(so_table *t)
{
    if (t->used + t->row > t->cap) {
        if (t->q) {
            if (soq_submit(t->q, t->used)) return 0;
            t->buf = soq_rows(t->q);
            t->used = 0;
        } else {
            size_t cap = t->cap ? t->cap * 2 : 65536;
            unsigned char *b = realloc(t->buf, cap);
            if (!b) return 0;
            t->buf = b;
            t->cap = cap;
        }
    }
    return (t->cap - t->used) / t->row;
}

static unsigned char *row_slot(so_table *t)
{
    if (!room(t)) return NULL;
    unsigned char *p = t->buf + t->used;
    t->used += t->row;
    t->nrows++;
    return p;
}

#define PUT(p, v) (memcpy((p), &(v), sizeof (v)), (p) += sizeof (v))

/* Hit h's binary row at p (hit_cols' order; sv: its S0..S3, for a table with them).
 * Field by field from the record to the row: x..dz and the two pairs after the powers
 * lie in the record as in the row (no copy through a stack array, whose 8-byte
 * stores a 16-byte load cannot take: it waits for them). */
static inline void pack_hit(so_table *t, unsigned char *p, const trace_hit *h, uint64_t ray,
                            const double *sv)
{
    int32_t depth = h->depth, surf = h->surface;
    int64_t prim = h->prim;
    double power = h->power_s + h->power_p;
    PUT(p, ray);
    PUT(p, depth);
    PUT(p, surf);
    PUT(p, prim);
    memcpy(p, h->pos, 3 * sizeof(double));
    memcpy(p + 24, h->dir, 3 * sizeof(double));
    memcpy(p + 48, &h->power_s, sizeof(double));
    memcpy(p + 56, &h->power_p, sizeof(double));
    memcpy(p + 64, &power, sizeof(double));
    memcpy(p + 72, &h->length, sizeof(double));
    memcpy(p + 80, &h->opl, sizeof(double));
    p += 88;
    if (t->wl) {   /* CSV: the wavelength as it came (the formatter prints it) */
        double nm = t->fmt == SC_OUT_TEXT ? h->lambda : nm_of(t, h->lambda);
        PUT(p, nm);
    }
    if (t->st) memcpy(p, sv, 4 * sizeof *sv);
}

static const double no_stokes[4] = {NAN, NAN, NAN, NAN};

int so_hit(so_table *t, FILE *f, const trace_hit *h, uint64_t ray, const double stokes[4])
{
    const double *sv = stokes ? stokes : no_stokes;
    if (t->fmt == SC_OUT_CSV17) {   /* the bytes of before, number for number */
        const double *p = h->pos, *d = h->dir;
        if (fprintf(f, "%llu,%d,%d,%ld,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,"
                    "%.17g,%.17g,%.17g,%.17g", (unsigned long long)ray, h->depth,
                    h->surface, h->prim, p[0], p[1], p[2], d[0], d[1], d[2], h->power_s,
                    h->power_p, h->power_s + h->power_p, h->length, h->opl) < 0)
            return 1;
        if (t->wl && fprintf(f, ",%.10g", h->lambda * 1e3) < 0) return 1;
        if (t->st && fprintf(f, ",%.17g,%.17g,%.17g,%.17g", sv[0], sv[1], sv[2], sv[3]) < 0)
            return 1;
        return fputs("\n", f) < 0;
    }
    unsigned char *p = row_slot(t);
    if (!p) return 1;
    pack_hit(t, p, h, ray, sv);
    return 0;
}

int so_hits(so_table *t, FILE *f, const trace_hit *h, size_t n, uint64_t ray0)
{
    if (t->fmt == SC_OUT_CSV17) {
        for (size_t i = 0; i < n; i++)
            if (so_hit(t, f, h + i, h[i].ray + ray0, NULL)) return 1;
        return 0;
    }
    while (n) {   /* as many rows as the chunk holds, in one loop */
        size_t k = room(t);
        if (!k) return 1;
        if (k > n) k = n;
        unsigned char *p = t->buf + t->used;
        for (size_t i = 0; i < k; i++, p += t->row)
            pack_hit(t, p, h + i, h[i].ray + ray0, no_stokes);
        t->used += k * t->row;
        t->nrows += k;
        h += k;
        n -= k;
    }
    return 0;
}

int so_segment(so_table *t, FILE *f, const trace_segment *s)
{
    if (t->fmt == SC_OUT_TEXT || t->fmt == SC_OUT_CSV17) {   /* the seed's p.l form */
        if (t->wl) {
            double nm = s->lambda * 1e3;
            return fprintf(f, "%.10g %.10g %.10g %.10g\n%.10g %.10g %.10g %.10g\n",
                           s->p0[0], s->p0[1], s->p0[2], nm, s->p1[0], s->p1[1],
                           s->p1[2], nm) < 0;
        }
        return fprintf(f, "%.10g %.10g %.10g\n%.10g %.10g %.10g\n", s->p0[0], s->p0[1],
                       s->p0[2], s->p1[0], s->p1[1], s->p1[2]) < 0;
    }
    unsigned char *p = row_slot(t);
    if (!p) return 1;
    memcpy(p, s->p0, sizeof s->p0);
    memcpy(p + 24, s->p1, sizeof s->p1);
    if (t->wl) {
        double nm = nm_of(t, s->lambda);
        memcpy(p + 48, &nm, sizeof nm);
    }
    return 0;
}

int so_finish(so_table *t, FILE *f, char *err, size_t errmax)
{
    int bad = t->q ? soq_finish(t->q, t->used) : 0;
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
    if (t->q) soq_free(t->q);
    else free(t->buf);
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
        /* 1 MB a write: one write(2) of the whole image (120 MB for the triplet's
         * hits) spent 10 times longer in the kernel's copy into the page cache
         * (perf: copy_folio_from_iter_atomic, 0.9-1.1 of the trace's samples, against
         * 0.03-0.08 so) */
        size_t done = 0;
        while (done < (size_t)size) {
            size_t k = (size_t)size - done < (1u << 20) ? (size_t)size - done : 1u << 20;
            if (fwrite((char *)img + done, 1, k, f) != k) break;
            done += k;
        }
        if (done != (size_t)size) {
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
