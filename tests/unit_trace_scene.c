/* unit_trace_scene.c -- the trace front end's readers and geometry, without the
 * engine: scene, triangle, media and OBJ files (good ones parse to the right data,
 * each kind of malformed input is refused with its file, line and reason),
 * tessellations (counts, vertices on the surface, orientation, area converging to
 * the analytic one) and point-source rays.  The readers are plain C, so they are
 * compiled straight in. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "unit.h"
#include "../src/trace/scene_lex.c"
#include "../src/trace/scene_mesh.c"
#include "../src/trace/scene_read.c"
#include "../src/trace/scene_fields.c"
#include "../src/trace/scene_axial.c"
#include "../src/trace/scene_polar.c"
#include "../src/trace/scene_geom.c"

static int parse_scene(const char *text, char *err)
{
    sc_scene sc;
    int rc = sc_parse_scene(text, strlen(text), "t.scene", &sc, err);
    if (!rc) sc_free(&sc);
    return rc;
}

/* The scene `text` is refused with a message holding `want`. */
static void refused(const char *text, const char *want)
{
    char err[SC_ERRMAX];
    int rc = parse_scene(text, err);
    CHECK(rc == -1 && strstr(err, want), "scene refused with '%s' (got: %s)", want,
          rc ? err : "accepted");
}

static void good_scene(void)
{
    static const char text[] =
        "# comment line\n\n"
        "cap refract 1 1.5 vertex 0 0 0 radius 50 aperture 12   # trailing comment\n"
        "asphere refract 1.5 1 vertex 0 0 8 axis 0 0 2 radius -50 conic -1 coef 0 1e-6 "
        "aperture 12\n"
        "plane detect at 0 0 55 normal 0 0 1 rect 10 20 up 0 1 0\n"
        "sphere mirror center 0 0 100 radius 3 tessellate 5 refine\n"
        "source fan from 0 0 -10 dir 0 0 1 angle 5 rays 11\n"
        "source fan from -2 0 1 to .1 .1 0 -.3 -.1 0 rays 5\n"
        "source point from 0 0 -100 toward 0 0 0 radius 5 rings 3 power 2 medium 1.33\n"
        "source gaussian from 0 0 0 dir 0 0 1 waist 1 wavelength 0.0006 rings 4\n"
        "depth 8\ncutoff 1e-4\nthreads 2\nfresnel off\nescape 5\n"
        "output segments p.l\noutput hits h.csv\noutput summary s.txt\n";
    sc_scene sc;
    char err[SC_ERRMAX];
    int rc = sc_parse_scene(text, sizeof text - 1, "good.scene", &sc, err);
    CHECK(rc == 0, "a scene with every kind of directive parses (%s)", rc ? err : "ok");
    if (rc) return;
    CHECK(sc.nsurf == 4 && sc.nsource == 4, "4 surfaces, 4 sources");
    CHECK(sc.surf[1].shape == SC_ASPHERE && sc.surf[1].ncoef == 2 &&
          sc.surf[1].coef[1] == 1e-6 && sc.surf[1].conic == -1, "asphere coefficients");
    CHECK(fabs(sc.surf[1].axis[2] - 1) < 1e-15, "axis normalised");
    CHECK(sc.surf[1].n1 == 1.5 && sc.surf[1].n2 == 1, "refract n1 n2");
    CHECK(sc.surf[2].kind == SC_DETECT && sc.surf[2].rect[1] == 20, "detector rectangle");
    CHECK(sc.surf[3].tessellate == 5 && sc.surf[3].refine, "tessellate and refine");
    CHECK(sc.source[1].has_to && sc.source[1].count == 5, "opticrt's aimed fan");
    CHECK(sc.source[2].power == 2 && sc.source[2].medium == 1.33, "power and medium");
    CHECK(sc.depth == 8 && sc.cutoff == 1e-4 && sc.threads == 2 && !sc.fresnel &&
          sc.reflections && sc.escape == 5, "settings");
    CHECK(sc.out_segments && !strcmp(sc.out_segments, "p.l") && !strcmp(sc.out_hits, "h.csv"),
          "outputs");
    CHECK(sc.surf[0].line == 3 && sc.source[0].line == 7, "definitions remember their line");
    sc_free(&sc);
}

static void bad_scenes(void)
{
    const char *src = "\nsource ray from 0 0 0 dir 0 0 1\n";
    char buf[512];
#define WITH_SOURCE(s) (snprintf(buf, sizeof buf, "%s%s", s, src), buf)
    refused(WITH_SOURCE("plane detect at 0 0 normal 0 0 1 disc 1"),
            "t.scene:1: plane: 'at' needs 3 numbers, found 2");
    refused(WITH_SOURCE("plane detect at 0 0 nan normal 0 0 1 disc 1"), "NaN is not a number");
    refused(WITH_SOURCE("plane detect at 0 0 inf normal 0 0 1 disc 1"), "infinite");
    refused(WITH_SOURCE("plane detect at 0 0 1e999 normal 0 0 1 disc 1"), "out of range");
    refused(WITH_SOURCE("plane detect at 0 0 0x10 normal 0 0 1 disc 1"), "not a number");
    refused(WITH_SOURCE("plane detect at 0 0 0 normal 0 0 0 disc 1"),
            "t.scene:1: plane: 'normal' 0 0 0 is a zero-length direction");
    refused("cap refract 1 1.5 vertex 0 0 0 radius 5 aperture 1\n"
            "source ray from 0 0 -1 dir 0 0 0\n",
            "t.scene:2: source ray: 'dir' 0 0 0 is a zero-length direction");
    refused(WITH_SOURCE("cap refract 1 -1.5 vertex 0 0 0 radius 5 aperture 1"),
            "index of refraction must be positive");
    refused(WITH_SOURCE("cap refract 1 0 vertex 0 0 0 radius 5 aperture 1"),
            "index of refraction must be positive");
    refused(WITH_SOURCE("conic refract 1 1.5 vertex 0 0 0 radius 5 conic 3 aperture 3"),
            "no real surface at the aperture 3");
    refused(WITH_SOURCE("cap refract 1 1.5 vertex 0 0 0 radius 5 aperture 6"),
            "aperture 6 exceeds the radius 5");
    refused(WITH_SOURCE("cap mirror absorb vertex 0 0 0 radius 5 aperture 1"), "exactly one of");
    refused(WITH_SOURCE("cap vertex 0 0 0 radius 5 aperture 1"), "exactly one of");
    refused(WITH_SOURCE("cap mirror vertex 0 0 0 aperture 1"), "'radius' is missing");
    refused(WITH_SOURCE("sphere mirror center 0 0 0 radius 1 radius 2"), "given twice");
    refused(WITH_SOURCE("lens refract 1 1.5"), "unknown directive 'lens'");
    refused(WITH_SOURCE("plane detect at 0 0 0 normal 0 0 1 disc 1 rect 1 1"), "either disc");
    refused(WITH_SOURCE("sphere mirror center 0 0 0 radius 1 refine"), "'refine' applies");
    refused(WITH_SOURCE("depth 2.5"), "depth 2.5");
    refused(WITH_SOURCE("cutoff 1"), "cutoff 1");
    refused(WITH_SOURCE("output picture x.png"), "not segments, hits or summary");
    refused("plane detect at 0 0 0 normal 0 0 1 disc 1\n", "no source of rays");
    refused("source ray from 0 0 0 dir 0 0 1\n", "no surface");
    refused("plane detect at 0 0 1 normal 0 0 1 disc 1\nsource fan from 0 0 0 to 0 0 0 1 1 1 "
            "rays 3\n", "zero-direction ray");
    refused("plane detect at 0 0 1 normal 0 0 1 disc 1\nsource fan from 0 0 0 to -1 0 0 1 0 0 "
            "rays 3\n", "passes through the source point");
    refused("plane detect at 0 0 1 normal 0 0 1 disc 1\nsource point from 0 0 0 toward 0 0 0 "
            "radius 1 rings 2\n", "zero-direction ray");
    refused("plane detect at 0 0 1 normal 0 0 1 disc 1\nsource fan from 0 0 0 dir 0 0 1 "
            "angle 5 rays 0\n", "'rays' 0 must be an integer");
    refused("plane detect at 0 0 1 normal 0 0 1 disc 1\nsource laser from 0 0 0\n",
            "unknown kind 'laser'");
    refused("plane detect at 0 0 1 normal 0 0 1 disc 1\nsource gaussian from 0 0 0 dir 0 0 1 "
            "waist 0.0001 wavelength 1 rings 2\n", "beyond the paraxial Gaussian beam");
    refused("plane detect at 0 0 1 normal 0 0 1 disc 1\nsource ray from 0 0 0 dir 0 0 1 "
            "power -1\n", "power = -1 must be positive");
    refused(WITH_SOURCE("plane detect at\0 0 0 normal 0 0 1 disc 1"), "t.scene:1");
    {
        static const char nul[] = "plane detect at 0 0 0\0 normal 0 0 1 disc 1\n";
        char err[SC_ERRMAX];
        sc_scene sc;
        int rc = sc_parse_scene(nul, sizeof nul - 1, "t.scene", &sc, err);
        CHECK(rc == -1 && strstr(err, "t.scene:1: a NUL byte"), "a NUL byte is refused (%s)", err);
    }
#undef WITH_SOURCE
}

static void triangle_files(void)
{
    char err[SC_ERRMAX];
    double *tri, *media;
    long n;
    static const char good[] = "0 0 0\n1 0 0\n0 1 0\n\n# second\n0 0 1\n1 0 1\n0 1 1\n";
    int rc = sc_parse_triangles(good, sizeof good - 1, "g.t", &tri, &n, err);
    CHECK(rc == 0 && n == 2 && tri[9 + 8] == 1, "two triangles read (%s)", rc ? err : "ok");
    if (!rc) free(tri);
#define TRI_BAD(text, want) do {                                                    \
        rc = sc_parse_triangles(text, strlen(text), "b.t", &tri, &n, err);          \
        CHECK(rc == -1 && strstr(err, want) && !tri, "triangle file refused: %s (got: %s)", \
              want, rc ? err : "accepted");                                         \
    } while (0)
    TRI_BAD("0 0 0\n1 0\n0 1 0\n", "b.t:2: expected 3 numbers (a vertex: x y z), found 2");
    TRI_BAD("0 0 0\n1 0 0 5\n0 1 0\n", "b.t:2: expected 3 numbers");
    TRI_BAD("0 0 0\n1 0 0\n0 nan 0\n", "b.t:3: a vertex: x y z: 'nan': NaN");
    TRI_BAD("0 0 0\n1 0 0\n2 0 0\n", "b.t:1: triangle 1 (lines 1-3) has zero area");
    TRI_BAD("0 0 0\n1 0 0\n0 1 0\n5 5 5\n5 5 5\n5 5 5\n", "b.t:4: triangle 2 (lines 4-6) is degenerate");
    TRI_BAD("0 0 0\n1 0 0\n0 1 0\n0 0 1\n", "the file ends inside triangle 2 (1 of its 3");
    TRI_BAD("# nothing\n", "no triangles");
    TRI_BAD("0 0 0\n1e-300 0 0\n0 1e-300 0\n", "'1e-300' is out of range (0, or 1e-30");
    TRI_BAD("0 0 0\n1 0 0\n0 1e-13 0\n", "zero area");

    rc = sc_parse_media("1 1.5\n1.5 1 # glass to air\n", 27, "g.n", 2, &media, err);
    CHECK(rc == 0 && media[0] == 1 && media[3] == 1, "media read (%s)", rc ? err : "ok");
    if (!rc) free(media);
#define MEDIA_BAD(text, ntri, want) do {                                            \
        rc = sc_parse_media(text, strlen(text), "b.n", ntri, &media, err);          \
        CHECK(rc == -1 && strstr(err, want) && !media, "media refused: %s (got: %s)", want, \
              rc ? err : "accepted");                                               \
    } while (0)
    MEDIA_BAD("1 1.5\n", 2, "b.n:1: 1 media lines for 2 triangles");
    MEDIA_BAD("1 1.5\n1 1.5\n1 1.5\n", 2, "b.n:3: more media lines than the mesh has triangles (2)");
    MEDIA_BAD("1 -1.5\n", 1, "b.n:1: index of refraction n2 = -1.5 must be positive");
    MEDIA_BAD("1\n", 1, "b.n:1: expected 2 numbers");
    MEDIA_BAD("1 nan\n", 1, "NaN");
}

static void obj_files(void)
{
    char err[SC_ERRMAX];
    double *tri;
    long n;
    static const char good[] = "# quad and a triangle\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0 1\n"
                               "vn 0 0 1\nvt 0 0\ng side\nf 1/1/1 2/1/1 3//1 4\nf -4 -3 -1\n";
    int rc = sc_parse_obj(good, sizeof good - 1, "g.obj", &tri, &n, err);
    CHECK(rc == 0 && n == 3, "OBJ quad fanned into 2 triangles plus 1 (%s, %ld)",
          rc ? err : "ok", n);
    if (!rc) {
        CHECK(tri[18 + 6] == 0 && tri[18 + 7] == 1, "negative indices count back");
        free(tri);
    }
#define OBJ_BAD(text, want) do {                                                    \
        rc = sc_parse_obj(text, strlen(text), "b.obj", &tri, &n, err);              \
        CHECK(rc == -1 && strstr(err, want), "OBJ refused: %s (got: %s)", want,     \
              rc ? err : "accepted");                                               \
    } while (0)
    OBJ_BAD("v 0 0 0\nv 1 0 0\nf 1 2 3\n", "b.obj:3: face: vertex 3 does not exist (2 vertices");
    OBJ_BAD("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", "b.obj:4: f: triangle 1 has zero area");
    OBJ_BAD("v 0 0\n", "b.obj:1: v: expected x y z [w], found 2 numbers");
    OBJ_BAD("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", "at least 3 vertices");
    OBJ_BAD("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n", "vertex 0 does not exist");
    OBJ_BAD("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2.5\n", "not an integer");
    OBJ_BAD("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 /3\n", "without a number");
    OBJ_BAD("v 0 0 0\n", "no faces");
    OBJ_BAD("curv 0 1 2\n", "'curv': not an OBJ statement");
}

/* Triangles' total area; all normals against want(): count of agreeing ones. */
static double area(const double *t, long n, const double *axis, const double *centre,
                   long *agree)
{
    double a = 0;
    *agree = 0;
    for (long i = 0; i < n; i++) {
        const double *p = t + 9 * i;
        double e1[3], e2[3], c[3], m[3];
        for (int k = 0; k < 3; k++) {
            e1[k] = p[3 + k] - p[k];
            e2[k] = p[6 + k] - p[k];
            m[k] = (p[k] + p[3 + k] + p[6 + k]) / 3 - (centre ? centre[k] : 0);
        }
        cross3(e1, e2, c);
        a += sqrt(dot3(c, c)) / 2;
        *agree += centre ? dot3(c, m) > 0 : -dot3(c, axis) > 0;
    }
    return a;
}

static void tessellation(void)
{
    char err[SC_ERRMAX];
    double *t, prev_err = INFINITY;
    long n, agree;
    sc_surface cap = {0}, sph = {0};
    const double R = 10, A = 8, h = R - sqrt(R * R - A * A);
    cap.shape = SC_CAP;
    cap.at[0] = 1; cap.at[1] = 2; cap.at[2] = 3;
    cap.axis[0] = 0.6; cap.axis[2] = 0.8;
    cap.radius = R;
    cap.aperture = A;
    for (int level = 2; level <= 64; level *= 2) {
        double e, worst = 0;
        if (sc_tessellate(&cap, level, &t, &n, err)) { CHECK(0, "cap tessellation: %s", err); return; }
        e = fabs(area(t, n, cap.axis, NULL, &agree) - 2 * PI * R * h) / (2 * PI * R * h);
        for (long i = 0; i < 3 * n; i++) {   /* every vertex on the sphere */
            double c[3], d[3];
            for (int k = 0; k < 3; k++) c[k] = cap.at[k] + R * cap.axis[k];
            for (int k = 0; k < 3; k++) d[k] = t[3 * i + k] - c[k];
            worst = fmax(worst, fabs(sqrt(dot3(d, d)) - R));
        }
        CHECK(n == 6L * level * level && agree == n && worst < 1e-12 && e < prev_err,
              "cap level %d: %ld triangles, %ld facing -axis, vertices on the sphere to %.1e, "
              "area error %.2e shrinking", level, n, agree, worst, e);
        prev_err = e;
        free(t);
    }
    CHECK(prev_err < 1e-3, "cap area converges (level 64: %.2e)", prev_err);
    sph.shape = SC_SPHERE;
    sph.radius = 2;
    sph.at[2] = 5;
    for (int level = 2; level <= 16; level *= 4) {
        if (sc_tessellate(&sph, level, &t, &n, err)) { CHECK(0, "sphere: %s", err); return; }
        area(t, n, NULL, sph.at, &agree);
        CHECK(n == 4L * level * (level - 1) && agree == n && !sc_check_triangles(t, n, "s", err),
              "sphere level %d: %ld triangles, all facing out", level, n);
        free(t);
    }
    CHECK(sc_tessellate(&sph, 1, &t, &n, err) == -1, "a sphere needs level 2 at least");
}

static void point_source(void)
{
    sc_source s = {0};
    sc_ray r[1 + 3 * 4 * 5];
    double worst = 0, far = 0;
    s.type = SC_POINT;
    s.from[2] = -100;
    s.toward[0] = 1;
    s.radius = 5;
    s.rings = 4;
    s.power = 2;
    CHECK(sc_point_count(&s) == 61, "4 hexapolar rings: 61 rays");
    sc_point_rays(&s, r);
    for (int i = 0; i < 61; i++) {
        /* where the ray crosses the plane through `toward` perpendicular to the axis */
        double ax[3] = {1, 0, 100}, m = sqrt(dot3(ax, ax)), t, p[3], d[3];
        for (int k = 0; k < 3; k++) ax[k] /= m;
        t = m / dot3(r[i].d, ax);
        for (int k = 0; k < 3; k++) p[k] = r[i].o[k] + t * r[i].d[k] - s.toward[k];
        d[0] = sqrt(dot3(p, p));
        far = fmax(far, d[0]);
        worst = fmax(worst, fabs(dot3(r[i].d, r[i].d) - 1));
    }
    CHECK(fabs(far - 5) < 1e-9 && worst < 1e-15 && fabs(r[0].power - 2.0 / 61) < 1e-17,
          "point rays fill the disc of radius 5 (outermost %.12g), unit, equal power", far);
}

/* Glasses for indices and wavelengths for sources (issue 14). */
static void glasses_and_wavelengths(void)
{
    static const char text[] =
        "cap refract 1 n-bk7 vertex 0 0 0 radius 50 aperture 10\n"
        "cap refract glass N-BK7 1.5168/64.17 vertex 0 0 5 radius -50 aperture 10\n"
        "plane detect at 0 0 60 normal 0 0 1 disc 30\n"
        "source ray from 0 0 -5 dir 0 0 1 lambda F d C 632.8 0.5 medium water\n"
        "source ray from 0 0 -5 dir 0 0 1\n";
    char err[SC_ERRMAX];
    sc_scene sc;
    int rc = sc_parse_scene(text, sizeof text - 1, "wl.scene", &sc, err);
    CHECK(rc == 0, "a scene with glasses and wavelengths reads (%s)", rc ? err : "ok");
    if (rc) return;
    CHECK(!strcmp(sc.surf[0].glass[0], "") && !strcmp(sc.surf[0].glass[1], "N-BK7") &&
          sc.surf[0].n1 == 1 && fabs(sc.surf[0].n2 - 1.5168) < 1e-5,
          "refract 1 n-bk7: a number and the catalogue's N-BK7 (n at d %.6f)", sc.surf[0].n2);
    CHECK(!strcmp(sc.surf[1].glass[0], "N-BK7") && !strcmp(sc.surf[1].glass[1], "1.5168/64.17"),
          "refract glass N-BK7 1.5168/64.17: a glass after the word glass, a model glass");
    CHECK(sc.source[0].nlambda == 5 && sc.source[0].lambda[0] == PX_LAMBDA_F &&
          sc.source[0].lambda[2] == PX_LAMBDA_C && fabs(sc.source[0].lambda[3] - 0.6328) < 1e-15 &&
          sc.source[0].lambda[4] == 0.5 && !strcmp(sc.source[0].glass, "WATER"),
          "lambda F d C 632.8 0.5: five wavelengths in um; medium water is the catalogue's");
    CHECK(sc.named_wl == 1 && sc.source[1].nlambda == 0, "the scene names wavelengths");
    CHECK(sc.nmismatch == 0, "N-BK7 after surface 1 and N-BK7 before surface 2 agree");
    sc_free(&sc);
    refused("plane refract 1 N-BK8 at 0 0 0 normal 0 0 1 disc 9\n"
            "source ray from 0 0 -1 dir 0 0 1\n", "'N-BK8' is neither a number nor a glass");
    refused("plane refract 1 glass at 0 0 0 normal 0 0 1 disc 9\n"
            "source ray from 0 0 -1 dir 0 0 1\n", "'glass' needs a glass name");
    refused("plane refract 1 1.5 at 0 0 0 normal 0 0 1 disc 9\n"
            "source ray from 0 0 -1 dir 0 0 1 lambda\n", "needs at least one wavelength");
    refused("plane refract 1 1.5 at 0 0 0 normal 0 0 1 disc 9\n"
            "source ray from 0 0 -1 dir 0 0 1 lambda 0.05\n", "'0.05' is not a wavelength");
    refused("plane refract 1 1.5 at 0 0 0 normal 0 0 1 disc 9\n"
            "source ray from 0 0 -1 dir 0 0 1 lambda 1 2 3 4 5 6 7 8 9\n",
            "more than 8 wavelengths");
    refused("plane refract 1 1.5 at 0 0 0 normal 0 0 1 disc 9\n"
            "source ray from 0 0 -1 dir 0 0 1 medium 1.6/2\n", "neither a number nor a glass");
}

int main(void)
{
    good_scene();
    bad_scenes();
    triangle_files();
    obj_files();
    tessellation();
    point_source();
    glasses_and_wavelengths();
    return unit_failed();
}
