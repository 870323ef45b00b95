/* tr_wt.c -- meshes decided in double where single precision cannot: the vertex-to-
 * triangle adjacency built with the scene (vertices welded where their coordinates are
 * equal, so an OBJ's triangle soup shares them too), and the watertight ray/triangle
 * test of Woop, Benthin and Wald ("Watertight Ray/Triangle Intersection", JCGT 2(1),
 * 2013) in double, with a long double fallback on the edge functions.  Embree sees
 * every triangle grown by more than a float ray can stray (tr_scene.c), so it never
 * misses one the double ray meets; where its hit lies within that margin of an edge
 * or vertex, tr_hit.c asks the triangles around it here. */
#include <math.h>
#include "tr_eng.h"

/* The triangles around each welded vertex, compressed (f->vt_start, f->vt_tri): the
 * triangles of welded vertex w are vt_tri[vt_start[w] .. vt_start[w + 1]).  f->weld[i]
 * is the first vertex with vertex i's coordinates.  Built once Embree's BVH is (see
 * tr_build: not at the peak of Embree's build).  0, or -1: out of memory. */
int tr_wt_adjacency(tr_surf *f)
{
    const uint32_t *weld = f->weld;
    size_t nv = (size_t)f->nv, n3 = (size_t)f->ntri * 3;
    uint32_t *start = calloc(nv + 1, sizeof *start), *tri = malloc(n3 * sizeof *tri);
    if (!start || !tri) { free(start); free(tri); return -1; }
    for (size_t i = 0; i < n3; i++) start[weld[f->idx[i]] + 1]++;
    for (size_t i = 0; i < nv; i++) start[i + 1] += start[i];
    for (size_t i = 0; i < n3; i++) {                 /* fill, then shift back */
        uint32_t w = weld[f->idx[i]];
        tri[start[w]++] = (uint32_t)(i / 3);
    }
    for (size_t i = nv; i > 0; i--) start[i] = start[i - 1];
    start[0] = 0;
    f->vt_start = start;
    f->vt_tri = tri;
    return 0;
}

/* Woop, Benthin and Wald's test of the ray (o, d) against triangle prim, in double:
 * the ray's dominant axis kz, the vertices translated to o, sheared and scaled so the
 * ray runs along +z, then the three 2D edge functions.  A shared edge's function is
 * computed from the same transformed vertices in both triangles, so its sign is
 * exactly opposite there: no ray passes between them.  Zero edge functions (a ray on
 * an edge or vertex) are recomputed in long double; still zero counts as inside, so a
 * ray on an edge meets both triangles (the nearest is taken once).  Both sides count.
 * 1 and the distance *t along d, or 0. */
int tr_wt_hit(const tr_surf *f, long prim, const double o[3], const double d[3],
              double *t)
{
    int kz = fabs(d[0]) > fabs(d[1]) ? (fabs(d[0]) > fabs(d[2]) ? 0 : 2)
                                     : (fabs(d[1]) > fabs(d[2]) ? 1 : 2);
    int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
    if (d[kz] < 0) { int s = kx; kx = ky; ky = s; }   /* keep the winding */
    double sx = d[kx] / d[kz], sy = d[ky] / d[kz], sz = 1.0 / d[kz];
    const uint32_t *ix = f->idx + 3 * prim;
    const double *pa = f->vtx + 3 * ix[0], *pb = f->vtx + 3 * ix[1],
                 *pc = f->vtx + 3 * ix[2];
    double a[3], b[3], c[3];
    for (int j = 0; j < 3; j++) { a[j] = pa[j] - o[j]; b[j] = pb[j] - o[j]; c[j] = pc[j] - o[j]; }
    double ax = a[kx] - sx * a[kz], ay = a[ky] - sy * a[kz];
    double bx = b[kx] - sx * b[kz], by = b[ky] - sy * b[kz];
    double cx = c[kx] - sx * c[kz], cy = c[ky] - sy * c[kz];
    double u = cx * by - cy * bx, v = ax * cy - ay * cx, w = bx * ay - by * ax;
    if (u == 0 || v == 0 || w == 0) {
        long double lu = (long double)cx * by - (long double)cy * bx;
        long double lv = (long double)ax * cy - (long double)ay * cx;
        long double lw = (long double)bx * ay - (long double)by * ax;
        u = (double)lu; v = (double)lv; w = (double)lw;
        /* the sign survives the rounding back to double (|x| >= LDBL tiny) */
        if (lu != 0 && u == 0) u = lu > 0 ? 0x1p-1074 : -0x1p-1074;
        if (lv != 0 && v == 0) v = lv > 0 ? 0x1p-1074 : -0x1p-1074;
        if (lw != 0 && w == 0) w = lw > 0 ? 0x1p-1074 : -0x1p-1074;
    }
    if ((u < 0 || v < 0 || w < 0) && (u > 0 || v > 0 || w > 0)) return 0;
    double det = u + v + w;
    if (det == 0) return 0;
    double tt = (u * a[kz] + v * b[kz] + w * c[kz]) * sz / det;
    if (!isfinite(tt)) return 0;
    *t = tt;
    return 1;
}

/* How far (in barycentric units) Embree's hit on triangle prim may lie from the true
 * triangle's edges: the triangle was grown about its centroid by k (tr_wt_grow), so
 * its true edges sit at barycentric k/(3(1+k)) of the grown one, and Embree's own
 * rounding adds at most as much again; below k the hit is decided here.  k is held
 * to TR_WT_KMAX: the grown triangle then stays inside the triangles around its
 * vertices, which are the ones asked. */
double tr_wt_margin(const tr_surf *f, long prim, double pad)
{
    const uint32_t *ix = f->idx + 3 * prim;
    const double *p[3] = {f->vtx + 3 * ix[0], f->vtx + 3 * ix[1], f->vtx + 3 * ix[2]};
    double e1[3], e2[3], e3[3], n[3];
    for (int j = 0; j < 3; j++) {
        e1[j] = p[1][j] - p[0][j];
        e2[j] = p[2][j] - p[0][j];
        e3[j] = p[2][j] - p[1][j];
    }
    v_cross(e1, e2, n);
    double lmax = sqrt(fmax(v_dot(e1, e1), fmax(v_dot(e2, e2), v_dot(e3, e3))));
    double hmin = v_norm(n) / lmax;             /* the smallest altitude */
    double k = 3 * pad / hmin;
    return k < TR_WT_KMAX ? k : TR_WT_KMAX;
}

/* The nearest of the triangles around triangle prim's three vertices that the ray
 * (o, d) meets at t > tmin in double (never `skip`); triangles in ex[0..nex) are not
 * asked.  Each one asked is appended to ex (up to cap).  1 with *best, *t; or 0. */
int tr_wt_ring(const tr_surf *f, long prim, const double o[3], const double d[3],
               long skip, double tmin, long *best, double *t, uint32_t *ex, int *nex,
               int cap)
{
    double bt = INFINITY;
    long bp = -1;
    for (int k = 0; k < 3; k++) {
        uint32_t w = f->weld[f->idx[3 * prim + k]];
        for (uint32_t q = f->vt_start[w]; q < f->vt_start[w + 1]; q++) {
            uint32_t tri = f->vt_tri[q];
            int seen = 0;
            for (int i = 0; i < *nex && !seen; i++) seen = ex[i] == tri;
            if (seen || (long)tri == skip) continue;
            if (*nex < cap) ex[(*nex)++] = tri;
            double tt;
            if (tr_wt_hit(f, tri, o, d, &tt) && tt > tmin &&
                (tt < bt || (tt == bt && (long)tri < bp))) {
                bt = tt;
                bp = tri;
            }
        }
    }
    if (bp < 0) return 0;
    *best = bp;
    *t = bt;
    return 1;
}
