/* tr_meshbvh.c -- a mesh's Embree geometry.  Every triangle goes to Embree grown about
 * its centroid until each edge has moved out by 2 pad (what a float ray may stray from
 * the double one, and more than the vertices' own rounding), by a tenth at most:
 * Embree then never misses a triangle the double ray meets, at a shared edge or
 * vertex or a mesh's boundary, and tr_hit.c decides the hits within that margin of an
 * edge in double (tr_wt_margin).  So each triangle has its own three float vertices.
 *
 * A mesh of up to sc->chunk triangles is one geometry of the scene (one BVH).  A
 * bigger one is cut into chunks of that many triangles in Morton order of their
 * centroids, each chunk its own scene (BVH) under an instance of the scene: its grown
 * triangles exist only while its BVH is built and are unmapped after it (Embree's
 * robust BVH holds its triangles' vertices in its leaves, Triangle4v, and reads no
 * buffer when it traverses: any read would fault), and the build's temporaries are
 * one chunk's, not the whole mesh's.  That is what brings a big mesh's peak from
 * about 174 bytes a triangle to about 110 (doc/trace.md, Meshes); the price is a
 * second level of traversal. */
#define _DEFAULT_SOURCE 1       /* MAP_ANONYMOUS */
#include <sys/mman.h>
#include "tr_eng.h"

/* The grown triangles of f's triangles tri[0..n) (or 0..n when tri is NULL) in
 * Embree's frame, into v (9 floats each). */
static void grown(const trace_scene *sc, const tr_surf *f, const uint32_t *tri, long n,
                  float *v, unsigned *ix)
{
    for (long i = 0; i < n; i++) {
        long t = tri ? (long)tri[i] : i;
        double c[3] = {0, 0, 0}, k = tr_wt_margin(f, t, 2 * f->pad);
        for (int q = 0; q < 3; q++)
            for (int j = 0; j < 3; j++) c[j] += (f->vtx[3 * f->idx[3 * t + q] + j] - sc->eoff[j]) / 3;
        for (int q = 0; q < 3; q++) {
            const double *p = f->vtx + 3 * f->idx[3 * t + q];
            for (int j = 0; j < 3; j++)
                v[9 * i + 3 * q + j] = (float)(c[j] + (p[j] - sc->eoff[j] - c[j]) * (1 + k));
            ix[3 * i + q] = (unsigned)(3 * i + q);
        }
    }
}

static int one_bvh(trace_scene *sc, tr_surf *f)
{
    RTCGeometry g = rtcNewGeometry(sc->dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!g) return -1;
    float *v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                       3 * sizeof(float), (size_t)f->ntri * 3);
    unsigned *ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                           3 * sizeof(unsigned), (size_t)f->ntri);
    if (!v || !ix) { rtcReleaseGeometry(g); return -1; }
    grown(sc, f, NULL, f->ntri, v, ix);
    rtcSetGeometryUserData(g, f);
    rtcSetGeometryIntersectFilterFunction(g, tr_mesh_filter);
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(sc->scn, g, (unsigned)f->id);
    rtcReleaseGeometry(g);
    return 0;
}

/* Spread the low 10 bits of x to every third bit. */
static uint64_t spread3(uint64_t x)
{
    x &= 0x3ff;
    x = (x | x << 16) & 0x30000ff;
    x = (x | x << 8) & 0x300f00f;
    x = (x | x << 4) & 0x30c30c3;
    x = (x | x << 2) & 0x9249249;
    return x;
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* f->perm: the triangles in Morton order of their centroids (ties by number), so a
 * chunk is a compact piece of the mesh and the chunks' boxes barely overlap (in file
 * order a shuffled mesh's chunks would each span all of it: 6.7 times slower). */
static int sort_triangles(tr_surf *f)
{
    if (f->perm) return 0;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (long v = 0; v < f->nv; v++)
        for (int j = 0; j < 3; j++) {
            lo[j] = fmin(lo[j], f->vtx[3 * v + j]);
            hi[j] = fmax(hi[j], f->vtx[3 * v + j]);
        }
    uint64_t *key = malloc((size_t)f->ntri * sizeof *key);
    f->perm = malloc((size_t)f->ntri * sizeof *f->perm);
    if (!key || !f->perm) { free(key); free(f->perm); f->perm = NULL; return -1; }
    for (long t = 0; t < f->ntri; t++) {
        uint64_t m = 0;
        for (int j = 0; j < 3; j++) {
            double c = 0, w = hi[j] - lo[j];
            for (int q = 0; q < 3; q++) c += f->vtx[3 * f->idx[3 * t + q] + j] / 3;
            double u = w > 0 ? (c - lo[j]) / w * 1023 : 0;
            m |= spread3((uint64_t)(u < 0 ? 0 : u > 1023 ? 1023 : u)) << j;
        }
        key[t] = m << 32 | (uint64_t)t;     /* ntri < 2^32 (tr_add_mesh) */
    }
    qsort(key, (size_t)f->ntri, sizeof *key, cmp_u64);
    for (long t = 0; t < f->ntri; t++) f->perm[t] = (uint32_t)key[t];
    free(key);
    return 0;
}

static int chunk_bvh(trace_scene *sc, tr_surf *f, long s0, long n)
{
    int k = sc->nch, rc = -1;
    int *cs = realloc(sc->ch_surf, (size_t)(k + 1) * sizeof *cs);
    if (!cs) return -1;
    sc->ch_surf = cs;
    /* mapped, not malloc'd: unmapped after the build, so a read by Embree after it
     * would fault instead of reading freed memory (+16: Embree's vector loads) */
    size_t vb = (size_t)n * 9 * sizeof(float) + 16, ib = (size_t)n * 3 * sizeof(unsigned);
    float *v = mmap(NULL, vb, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    unsigned *ix = mmap(NULL, ib, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    RTCScene s = NULL;
    RTCGeometry g = NULL, in = NULL;
    if (v == MAP_FAILED || ix == MAP_FAILED) goto out;
    grown(sc, f, f->perm + s0, n, v, ix);
    if (!(s = rtcNewScene(sc->dev)) || !(g = rtcNewGeometry(sc->dev, RTC_GEOMETRY_TYPE_TRIANGLE)))
        goto out;
    rtcSetSceneFlags(s, RTC_SCENE_FLAG_ROBUST);     /* robust: Triangle4v leaves */
    rtcSetSceneBuildQuality(s, RTC_BUILD_QUALITY_MEDIUM);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, v, 0,
                               3 * sizeof(float), (size_t)n * 3);
    rtcSetSharedGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, ix, 0,
                               3 * sizeof(unsigned), (size_t)n);
    rtcSetGeometryUserData(g, f);
    rtcSetGeometryIntersectFilterFunction(g, tr_mesh_filter);
    rtcCommitGeometry(g);
    rtcAttachGeometry(s, g);
    rtcCommitScene(s);
    if (rtcGetDeviceError(sc->dev) != RTC_ERROR_NONE) goto out;
    if (!(in = rtcNewGeometry(sc->dev, RTC_GEOMETRY_TYPE_INSTANCE))) goto out;
    static const float id[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
    rtcSetGeometryInstancedScene(in, s);
    rtcSetGeometryTransform(in, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, id);
    rtcCommitGeometry(in);
    rtcAttachGeometryByID(sc->scn, in, (unsigned)(sc->ch_base + k));
    sc->ch_surf[k] = f->id;
    sc->nch++;
    rc = 0;
out:
    if (in) rtcReleaseGeometry(in);
    if (g) rtcReleaseGeometry(g);
    if (s) rtcReleaseScene(s);          /* the instance holds it */
    if (v != MAP_FAILED) munmap(v, vb);
    if (ix != MAP_FAILED) munmap(ix, ib);
    return rc;
}

int tr_mesh_attach(trace_scene *sc, tr_surf *f)
{
    if (sc->chunk <= 0 || f->ntri <= sc->chunk) return one_bvh(sc, f);
    if (sort_triangles(f)) return -1;
    f->ch0 = sc->ch_base + sc->nch;
    for (long s0 = 0; s0 < f->ntri; s0 += sc->chunk)
        if (chunk_bvh(sc, f, s0, f->ntri - s0 < sc->chunk ? f->ntri - s0 : sc->chunk))
            return -1;
    return 0;
}
