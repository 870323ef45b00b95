/* mesh.h -- meshes for the trace engine's tests and bench: indexed octahedron and
 * geodesic spheres (outward normals, shared vertices), and a cornea-like cap. */
#ifndef MESH_H
#define MESH_H
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

typedef struct tmesh { double *v; uint32_t *t; long nv, nt, capv, capt; } tmesh;

static long tm_vertex(tmesh *m, double x, double y, double z)
{
    if (m->nv == m->capv) {
        m->capv = m->capv ? 2 * m->capv : 64;
        m->v = realloc(m->v, (size_t)m->capv * 3 * sizeof(double));
    }
    m->v[3 * m->nv] = x; m->v[3 * m->nv + 1] = y; m->v[3 * m->nv + 2] = z;
    return m->nv++;
}
static void tm_tri(tmesh *m, long a, long b, long c)
{
    if (m->nt == m->capt) {
        m->capt = m->capt ? 2 * m->capt : 64;
        m->t = realloc(m->t, (size_t)m->capt * 3 * sizeof(uint32_t));
    }
    m->t[3 * m->nt] = (uint32_t)a; m->t[3 * m->nt + 1] = (uint32_t)b;
    m->t[3 * m->nt + 2] = (uint32_t)c;
    m->nt++;
}

static void tm_octahedron(tmesh *m, double r)
{
    long px = tm_vertex(m, r, 0, 0), nx = tm_vertex(m, -r, 0, 0);
    long py = tm_vertex(m, 0, r, 0), ny = tm_vertex(m, 0, -r, 0);
    long pz = tm_vertex(m, 0, 0, r), nz = tm_vertex(m, 0, 0, -r);
    tm_tri(m, px, py, pz); tm_tri(m, py, nx, pz); tm_tri(m, nx, ny, pz);
    tm_tri(m, ny, px, pz); tm_tri(m, py, px, nz); tm_tri(m, nx, py, nz);
    tm_tri(m, ny, nx, nz); tm_tri(m, px, ny, nz);
}

static long tm_lattice(tmesh *m, long *map, long n, long i, long j, long k, double r)
{
    long dim = 2 * n + 1, key = (((i + n) * dim + (j + n)) * 2) + (k > 0);
    if (map[key] < 0) {
        double l = sqrt((double)(i * i + j * j + k * k));
        map[key] = tm_vertex(m, r * i / l, r * j / l, r * k / l);
    }
    return map[key];
}

/* Geodesic sphere of radius r: the octahedron's faces split n x n (8 n^2
 * triangles), vertices shared exactly, outward normals. */
static void tm_sphere(tmesh *m, double r, long n)
{
    long dim = 2 * n + 1;
    long *map = malloc((size_t)(dim * dim * 2) * sizeof(long));
    for (long q = 0; q < dim * dim * 2; q++) map[q] = -1;
    for (int sx = -1; sx <= 1; sx += 2)
        for (int sy = -1; sy <= 1; sy += 2)
            for (int sz = -1; sz <= 1; sz += 2)
                for (long i = 0; i < n; i++)
                    for (long j = 0; j < n - i; j++) {
                        long k = n - i - j, flip = sx * sy * sz < 0;
                        long a = tm_lattice(m, map, n, sx * i, sy * j, sz * k, r);
                        long b = tm_lattice(m, map, n, sx * (i + 1), sy * j, sz * (k - 1), r);
                        long c = tm_lattice(m, map, n, sx * i, sy * (j + 1), sz * (k - 1), r);
                        if (flip) tm_tri(m, a, c, b); else tm_tri(m, a, b, c);
                        if (k >= 2) {
                            long d = tm_lattice(m, map, n, sx * (i + 1), sy * (j + 1),
                                                sz * (k - 2), r);
                            if (flip) tm_tri(m, b, c, d); else tm_tri(m, b, d, c);
                        }
                    }
    free(map);
}

#endif
