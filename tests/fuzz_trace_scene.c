/* fuzz_trace_scene.c -- libFuzzer target for the trace front end's readers
 * (src/trace/scene_lex.c, scene_mesh.c, scene_read.c, scene_fields.c, scene_axial.c)
 * and tessellation (scene_geom.c).  The first byte picks
 * the reader: 's' scene file, 't' triangle file, 'n' media file (for as many
 * triangles as the second byte says), 'o' OBJ; anything else: all of them.  Every
 * input must give 0 or -1 with a "NAME:LINE: ..." message, never a crash, a leak or
 * undefined behaviour; parsed surfaces are tessellated (coarsely) and checked. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "trace/scene.h"

static void expect_message(int rc, const char *err)
{
    if (rc && (!err[0] || !strchr(err, ':'))) abort();   /* an error names its place */
    if (!rc && err[0]) abort();
}

static void scene(const char *p, size_t n)
{
    char err[SC_ERRMAX];
    sc_scene sc;
    int rc = sc_parse_scene(p, n, "fuzz.scene", &sc, err);
    expect_message(rc, err);
    if (rc) return;
    for (int i = 0; i < sc.nsurf; i++) {
        double *tri;
        long nt;
        if (sc.surf[i].shape == SC_MESH) continue;
        if (sc_tessellate(&sc.surf[i], 1 + sc.surf[i].tessellate % 6, &tri, &nt, err) == 0) {
            if (nt <= 0 || sc_check_triangles(tri, nt, "t", err)) abort();
            free(tri);
        }
    }
    for (int i = 0; i < sc.nsource; i++)
        if (sc.source[i].type == SC_POINT && sc.source[i].rings < 20) {
            sc_ray *r = malloc((size_t)sc_point_count(&sc.source[i]) * sizeof *r);
            if (!r) abort();
            sc_point_rays(&sc.source[i], r);
            free(r);
        }
    sc_free(&sc);
}

static void triangles(const char *p, size_t n, int obj)
{
    char err[SC_ERRMAX];
    double *tri;
    long nt;
    int rc = obj ? sc_parse_obj(p, n, "fuzz.obj", &tri, &nt, err)
                 : sc_parse_triangles(p, n, "fuzz.t", &tri, &nt, err);
    expect_message(rc, err);
    if (rc) return;
    if (nt <= 0 || sc_check_triangles(tri, nt, "fuzz", err)) abort();
    free(tri);
}

static void media(const char *p, size_t n, long ntri)
{
    char err[SC_ERRMAX];
    double *m;
    int rc = sc_parse_media(p, n, "fuzz.n", ntri, &m, err);
    expect_message(rc, err);
    if (rc) return;
    for (long i = 0; i < 2 * ntri; i++)
        if (!(m[i] > 0)) abort();
    free(m);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *p = (const char *)data + 1;
    size_t n = size ? size - 1 : 0;
    if (!size) return 0;
    switch (data[0]) {
    case 's': scene(p, n); break;
    case 't': triangles(p, n, 0); break;
    case 'o': triangles(p, n, 1); break;
    case 'n': if (n) media(p + 1, n - 1, (long)(unsigned char)p[0]); break;
    default:
        scene(p, n);
        triangles(p, n, 0);
        triangles(p, n, 1);
        media(p, n, 5);
    }
    return 0;
}
