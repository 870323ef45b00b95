/* scene_mesh.c -- the trace front end's mesh readers: the document's triangle files
 * (three lines "x y z" per triangle, as opticrt reads sphercap.t), media files ("n1 n2"
 * per triangle, as opticrt's p.n) and OBJ meshes (v and f lines), with the check that
 * refuses degenerate triangles.  Buffers in, arrays out, errors as "FILE:LINE: what";
 * fuzzed alone (tests/fuzz_trace_scene.c). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "scene_int.h"

#define MAXTRI 50000000L   /* triangles in one mesh (1.8 GB of doubles) */

/* ---- triangles ---------------------------------------------------------------- */

/* Why triangle t is unusable, or NULL. */
static const char *bad_triangle(const double *t)
{
    double e1[3], e2[3], e3[3], c[3], l2;
    for (int i = 0; i < 9; i++)
        if (!isfinite(t[i])) return "has a non-finite coordinate";
    sub3(t + 3, t, e1);
    sub3(t + 6, t, e2);
    sub3(t + 6, t + 3, e3);
    cross3(e1, e2, c);
    l2 = fmax(dot3(e1, e1), fmax(dot3(e2, e2), dot3(e3, e3)));
    if (l2 == 0) return "is degenerate (its vertices coincide, or its edges are too short "
                        "to measure)";
    /* twice the area against the longest edge squared: ~ the smallest angle */
    if (sqrt(dot3(c, c)) <= 1e-12 * l2) return "has zero area (collinear vertices)";
    return NULL;
}

int sc_check_triangles(const double *tri, long ntri, const char *name, char *err)
{
    for (long i = 0; i < ntri; i++) {
        const char *why = bad_triangle(tri + 9 * i);
        if (why) {
            snprintf(err, SC_ERRMAX, "%s: triangle %ld %s", name, i + 1, why);
            return -1;
        }
    }
    return 0;
}

int sc_parse_triangles(const char *text, size_t len, const char *name, double **tri,
                       long *ntri, char *err)
{
    reader r;
    dvec a = {0};
    double v[9];
    long first = 0;
    int k = 0, st;

    sl_reader_init(&r, text, len, name, err);
    *tri = NULL;
    *ntri = 0;
    while ((st = sl_next_line(&r)) > 0) {
        const char *why;
        if (k == 0) first = r.line;
        if (sl_line_nums(&r, 3, "a vertex: x y z", v + 3 * k)) goto bad;
        if (++k < 3) continue;
        k = 0;
        if ((why = bad_triangle(v))) {
            r.line = first;
            sl_fail(&r, "triangle %ld (lines %ld-%ld) %s", (long)(a.n / 9) + 1, first,
                 first + 2, why);
            goto bad;
        }
        if (a.n / 9 >= (size_t)MAXTRI) { sl_fail(&r, "more than %ld triangles", MAXTRI); goto bad; }
        if (sl_dvec_push(&a, v, 9)) { sl_fail(&r, "out of memory"); goto bad; }
    }
    if (st < 0) goto bad;
    if (k) {
        sl_fail(&r, "the file ends inside triangle %ld (%d of its 3 vertex lines; "
             "each triangle is three lines x y z)", (long)(a.n / 9) + 1, k);
        goto bad;
    }
    if (!a.n) { sl_fail(&r, "no triangles (each triangle is three lines x y z)"); goto bad; }
    *tri = a.v;
    *ntri = (long)(a.n / 9);
    return 0;
bad:
    free(a.v);
    return -1;
}

int sc_parse_media(const char *text, size_t len, const char *name, long ntri,
                   double **media, char *err)
{
    reader r;
    double *m = NULL;
    long n = 0;
    int st;

    sl_reader_init(&r, text, len, name, err);
    *media = NULL;
    if (ntri <= 0 || !(m = malloc((size_t)ntri * 2 * sizeof *m))) {
        if (ntri > 0) sl_fail(&r, "out of memory");
        else sl_fail(&r, "no triangles to give media to");
        return -1;
    }
    while ((st = sl_next_line(&r)) > 0) {
        double v[2];
        if (n == ntri) {
            sl_fail(&r, "more media lines than the mesh has triangles (%ld)", ntri);
            goto bad;
        }
        if (sl_line_nums(&r, 2, "indices of refraction: n1 n2", v)) goto bad;
        for (int i = 0; i < 2; i++)
            if (!(v[i] > 0)) {
                sl_fail(&r, "index of refraction n%d = %g must be positive", i + 1, v[i]);
                goto bad;
            }
        m[2 * n] = v[0];
        m[2 * n + 1] = v[1];
        n++;
    }
    if (st < 0) goto bad;
    if (n != ntri) {
        sl_fail(&r, "%ld media lines for %ld triangles (one line n1 n2 per triangle)", n,
             ntri);
        goto bad;
    }
    *media = m;
    return 0;
bad:
    free(m);
    return -1;
}

/* An OBJ vertex reference "i", "i/t", "i//n", "i/t/n"; negative counts back. */
static int obj_index(reader *r, const tok *t, long nv, long *idx)
{
    tok head = *t;
    const char *slash = memchr(t->s, '/', t->n);
    double v;
    if (slash) head.n = (size_t)(slash - t->s);
    if (!head.n) return sl_fail(r, "face: a vertex reference without a number");
    if (sl_tok_num(r, &head, "face vertex index", &v)) return -1;
    double given = v;
    if (v != floor(v)) return sl_fail(r, "face: vertex index %g is not an integer", v);
    if (v < 0) v += (double)nv + 1;
    if (v < 1 || v > (double)nv)
        return sl_fail(r, "face: vertex %.0f does not exist (%ld vertices so far)", given, nv);
    *idx = (long)v - 1;
    return 0;
}

/* Growable array of vertex indices. */
typedef struct ivec { uint32_t *v; size_t n, cap; } ivec;
static int ivec_push(ivec *a, const uint32_t *x, size_t k)
{
    if (a->n + k > a->cap) {
        size_t cap = a->cap ? a->cap * 2 : 256;
        while (cap < a->n + k) cap *= 2;
        uint32_t *p = realloc(a->v, cap * sizeof *p);
        if (!p) return -1;
        a->v = p;
        a->cap = cap;
    }
    memcpy(a->v + a->n, x, k * sizeof *x);
    a->n += k;
    return 0;
}

int sc_parse_obj_ix(const char *text, size_t len, const char *name, double **vtx,
                    long *nvtx, uint32_t **idx_out, long *ntri, char *err)
{
    static const char *const ignored[] = {"vt", "vn", "vp", "o", "g", "s", "usemtl",
                                          "mtllib", NULL};
    reader r;
    dvec v = {0};
    ivec a = {0};
    uint32_t *map = NULL;
    int st;

    sl_reader_init(&r, text, len, name, err);
    *vtx = NULL;
    *idx_out = NULL;
    *nvtx = *ntri = 0;
    while ((st = sl_next_line(&r)) > 0) {
        int skip = 0;
        for (int i = 0; ignored[i]; i++) skip |= sl_tok_is(&r.t[0], ignored[i]);
        if (skip) continue;
        if (sl_tok_is(&r.t[0], "v")) {
            double x[3];
            if (r.nt != 4 && r.nt != 5) {
                sl_fail(&r, "v: expected x y z [w], found %d numbers", r.nt - 1);
                goto bad;
            }
            for (int i = 0; i < 3; i++)
                if (sl_tok_num(&r, &r.t[i + 1], "v", &x[i])) goto bad;
            if ((long)(v.n / 3) >= 3 * MAXTRI) { sl_fail(&r, "too many vertices"); goto bad; }
            if (sl_dvec_push(&v, x, 3)) { sl_fail(&r, "out of memory"); goto bad; }
        } else if (sl_tok_is(&r.t[0], "f")) {
            long idx[MAXTOK], nv = (long)(v.n / 3);
            if (r.nt < 4) { sl_fail(&r, "f: a face needs at least 3 vertices"); goto bad; }
            for (int i = 1; i < r.nt; i++)
                if (obj_index(&r, &r.t[i], nv, &idx[i - 1])) goto bad;
            for (int i = 1; i + 1 < r.nt - 1; i++) {   /* fan: 0, i, i+1 */
                double t[9];
                const char *why;
                uint32_t k[3] = {(uint32_t)idx[0], (uint32_t)idx[i], (uint32_t)idx[i + 1]};
                memcpy(t, v.v + 3 * idx[0], 3 * sizeof *t);
                memcpy(t + 3, v.v + 3 * idx[i], 3 * sizeof *t);
                memcpy(t + 6, v.v + 3 * idx[i + 1], 3 * sizeof *t);
                if ((why = bad_triangle(t))) {
                    sl_fail(&r, "f: triangle %ld %s", (long)(a.n / 3) + 1, why);
                    goto bad;
                }
                if (a.n / 3 >= (size_t)MAXTRI) { sl_fail(&r, "too many triangles"); goto bad; }
                if (ivec_push(&a, k, 3)) { sl_fail(&r, "out of memory"); goto bad; }
            }
        } else {
            char w[32];
            snprintf(w, sizeof w, "%.*s", (int)(r.t[0].n < 24 ? r.t[0].n : 24), r.t[0].s);
            sl_fail(&r, "'%s': not an OBJ statement this reader knows (v, f; vt, vn, o, g, "
                 "s, usemtl, mtllib are ignored)", w);
            goto bad;
        }
    }
    if (st < 0) goto bad;
    if (!a.n) { sl_fail(&r, "no faces (f lines)"); goto bad; }
    /* keep only the vertices the faces use, in their order in the file (the engine's
     * bounds and tolerances come from the vertices it is given) */
    size_t nv = v.n / 3, m = 0;
    if (!(map = malloc(nv * sizeof *map))) { sl_fail(&r, "out of memory"); goto bad; }
    for (size_t i = 0; i < nv; i++) map[i] = UINT32_MAX;
    for (size_t i = 0; i < a.n; i++) map[a.v[i]] = 0;
    for (size_t i = 0; i < nv; i++)
        if (map[i] == 0) {
            memmove(v.v + 3 * m, v.v + 3 * i, 3 * sizeof *v.v);
            map[i] = (uint32_t)m++;
        }
    for (size_t i = 0; i < a.n; i++) a.v[i] = map[a.v[i]];
    free(map);
    /* no growth slack kept: a mesh's arrays live as long as its scene */
    double *vv = realloc(v.v, 3 * m * sizeof *vv);
    uint32_t *aa = realloc(a.v, a.n * sizeof *aa);
    *vtx = vv ? vv : v.v;
    *idx_out = aa ? aa : a.v;
    *nvtx = (long)m;
    *ntri = (long)(a.n / 3);
    return 0;
bad:
    free(v.v);
    free(a.v);
    return -1;
}

/* The soup form, for readers of the triangles themselves (9 doubles each). */
int sc_parse_obj(const char *text, size_t len, const char *name, double **tri,
                 long *ntri, char *err)
{
    double *v;
    uint32_t *ix;
    long nv;
    *tri = NULL;
    if (sc_parse_obj_ix(text, len, name, &v, &nv, &ix, ntri, err)) return -1;
    if (!(*tri = malloc((size_t)*ntri * 9 * sizeof **tri))) {
        snprintf(err, SC_ERRMAX, "%s: out of memory", name);
        *ntri = 0;
    } else {
        for (long i = 0; i < 3 * *ntri; i++) memcpy(*tri + 3 * i, v + 3 * ix[i], 3 * sizeof *v);
    }
    free(v);
    free(ix);
    return *tri ? 0 : -1;
}
