/* scene.h -- the trace front end's public face: a scene as plain data (surfaces,
 * meshes, sources, settings, outputs), its readers (scene files, the document's
 * triangle and media files, OBJ), and running a scene through the trace engine with
 * its outputs (segments in the seed's p.l form, detector hits as CSV, a summary).
 * The readers need nothing but libc and libm (they are fuzzed alone); running needs
 * the engine, so the dialogue reaches all of this through the table returned by the
 * module's exported function lm_scene_api() (see lm_engine_symbol in engine.h). */
#ifndef SCENE_H
#define SCENE_H
#include <stddef.h>
#include <stdint.h>
#include "trace.h"

enum sc_shape { SC_PLANE, SC_SPHERE, SC_CAP, SC_CONIC, SC_ASPHERE, SC_MESH };
enum sc_kind { SC_REFRACT, SC_MIRROR, SC_ABSORB, SC_DETECT, SC_MEDIA };
enum sc_source_type { SC_RAY, SC_FAN, SC_POINT, SC_CONE, SC_COLLIMATED, SC_GAUSSIAN };

#define SC_MAXCOEF 8
#define SC_ERRMAX 1024
#define SC_GLASSMAX 32     /* longest glass name + 1 */
#define SC_MAXWL 8         /* wavelengths of one source */
#define SC_MAXWLS 64       /* distinct wavelengths of one scene */

/* One surface.  Axial shapes (cap, conic, asphere) have a vertex, a unit axis and a
 * signed radius of curvature (centre at vertex + radius*axis; 0 = flat); their sag
 * along the axis is z(s) = c s^2 / (1 + sqrt(1 - (1+k) c^2 s^2)) + sum coef[i] s^(2i+2)
 * with c = 1/radius (the trace engine's conventions, trace.h).  Sides: planes and
 * axial shapes: n1 is where light travelling along the axis (plane: the normal)
 * comes from, n2 the other side.  Spheres: n1 outside, n2 inside.  Mesh triangles,
 * as opticrt's p.n: n1 is the side their normal (v1-v0)x(v2-v0) points to.
 * SC_MEDIA: per-triangle n1 n2 from a media file. */
typedef struct sc_surface {
    int shape, kind;
    double n1, n2;        /* refract: the indices (a glass's at the d line) */
    char glass[2][SC_GLASSMAX];   /* refract: the glass each side names ("": n1/n2 is
                                     a plain number), indices and absorption taken
                                     from the catalogue at each traced wavelength */
    double at[3];         /* plane point, sphere centre, axial vertex */
    double axis[3];       /* plane normal, axial direction (unit) */
    double up[3];         /* rectangle orientation (plane only; unit, _|_ axis) */
    double radius;        /* sphere radius, radius of curvature (0: flat) */
    double conic;
    double coef[SC_MAXCOEF];
    int ncoef;
    double aperture;      /* disc / semi-diameter; 0 with rect[] set: a rectangle */
    double hole;          /* plane disc: radius of a central hole (an annulus), or 0 */
    double rect[2];       /* rectangle width (along up x axis) and height (along up) */
    int tessellate;       /* >0: replace the analytic surface by a mesh of that level */
    int refine;           /* mesh: refine hits to the underlying analytic surface */
    /* meshes (SC_MESH, or tessellated analytic surfaces after sc_tessellate) */
    long ntri;
    double *tri;          /* 9 doubles per triangle */
    double *media;        /* 2 per triangle (n1 n2), or NULL */
    /* an OBJ mesh keeps its shared vertices (tri is NULL): nvtx vertices of 3
     * doubles, 3 indices a triangle (only the vertices its faces use, in order) */
    double *vtx;
    long nvtx;
    uint32_t *idx;
    double sphere[4];     /* file mesh: underlying sphere cx cy cz r, r = 0: none */
    char *mesh_file, *media_file;
    const char *src;      /* defined at src:line (for messages) */
    long line;
    /* polarization (scene_polar.c): refract only.  pol_el: enum trace_polel, on the
     * light it transmits (polarizer AX AY AZ, retarder FX FY FZ DEG, qwp/hwp F...) */
    int pol_el;
    double pol_axis[3], pol_ret;   /* unit axis; retardance, radians */
    int coat;                 /* 1 + its coating in sc_scene.coating (0: bare) */
    char coat_name[SC_GLASSMAX];
} sc_surface;

/* A thin-film coating: `coating NAME layer N D [layer N D ...]` (D in nm; the layers
 * from the side of the first index of the surface that names it). */
#define SC_MAXLAYER 32
typedef struct sc_coating {
    char name[SC_GLASSMAX];
    int nlayer;
    double n[SC_MAXLAYER], d_nm[SC_MAXLAYER];
    const char *src;
    long line;
} sc_coating;

typedef struct sc_source {
    int type;                 /* enum sc_source_type */
    double from[3], dir[3];   /* dir: unit */
    double up[3];             /* fan: the plane of dir and up (unit, _|_ dir) */
    double to[2][3];          /* fan toward count points on the segment to[0]-to[1] */
    int has_to;
    double angle;             /* half angle, degrees (fan, cone) */
    double radius;            /* point: pupil radius at `toward`; collimated: beam */
    double toward[3];
    double waist, wavelength, trunc;   /* gaussian (trunc: rings reach trunc*waist) */
    long count;               /* fan: rays; collimated: grid N (N x N cells) */
    int rings;                /* point, cone, gaussian: hexapolar rings */
    double power;             /* total power of the source (default 1) */
    double medium;            /* index where its rays start (default 1) */
    char glass[SC_GLASSMAX];  /* ... a glass named for it ("": none) */
    double lambda[SC_MAXWL];  /* its wavelengths, um (`lambda`: nm, um or F d C e g
                                 hene), in the order given */
    int nlambda;              /* 0: none named (the d line where a glass needs one) */
    int polarised;            /* 1: linear along pol[] (unit), 2: the Jones vector
                                 jones (re, im of Jx, Jy; unit length) in the Stokes
                                 frame (polarization ref), 3: partially polarized,
                                 the normalized Stokes vector stokes (S1..S3 / S0)
                                 in that frame, 0: unpolarised */
    double pol[3];
    double jones[2][2];
    double stokes[3];
    const char *src;          /* defined at src:line */
    long line;
} sc_source;

typedef struct sc_scene {
    sc_surface *surf;
    int nsurf;
    sc_source *source;
    int nsource;
    int depth;                /* recursion depth limit (default 10) */
    double cutoff;            /* intensity cutoff, relative (default 1e-6) */
    int threads;              /* 0: all cores */
    int fresnel, reflections; /* on (1, default) or off */
    double escape;            /* length drawn for an escaping ray (default 1) */
    char *out_segments, *out_hits, *out_summary;
    char *name;               /* the scene file, for messages */
    char *dir;                /* its folder: mesh files are relative to it */
    /* Set by the caller before run(): polled between batches and every few thousand
     * records (a few ms of work); non-zero stops the trace (sc_result.stopped). */
    int (*stop)(void *ctx);
    void *stop_ctx;
    int mismatch_error;       /* `mismatch error`: rays meeting a surface whose index
                                 on their side differs from theirs fail the trace */
    int nmismatch;            /* media that disagree, found when the scene is read */
    int named_wl;             /* some source names its wavelengths: outputs carry a
                                 wavelength column, the trace runs once per wavelength */
    char mismatch_where[256]; /* the first such pair: "FILE:LINE and FILE:LINE" ... */
    int out_format[3];        /* segments, hits, summary: sc_out_format (never
                                 SC_OUT_AUTO once read); HDF5 outputs that name one
                                 file are tables of that one file */
    /* polarization ray tracing (scene_polar.c): `polarization on [ref X Y Z]`, or any
     * element or coating; `output polar FILE [csv|npy]`, a row per hit */
    int polar;
    double polar_ref[3];      /* Stokes frame reference (0 0 0: the engine's, +x) */
    sc_coating *coating;
    int ncoating;
    char *out_polar;
    int out_polar_format;
} sc_scene;

/* An output's format: `output KIND FILE [csv|csv17|npy|h5]`, else from FILE's name. */
typedef enum {
    SC_OUT_AUTO,     /* from the file name: .npy, .h5/.hdf5, else text */
    SC_OUT_TEXT,     /* hits: CSV, shortest round-trip numbers; segments: the p.l text */
    SC_OUT_CSV17,    /* hits: the CSV of before ("%.17g"), byte for byte */
    SC_OUT_NPY,      /* NumPy .npy structured array */
    SC_OUT_H5        /* HDF5: /hits, /segments, /summary */
} sc_out_format;

/* One ray as the sources emit it. */
typedef struct sc_ray {
    double o[3], d[3];
    double power;
} sc_ray;

/* Readers.  Each parses a buffer (name: for messages), returns 0 or -1 with
 * "NAME:LINE: what is wrong" in err (SC_ERRMAX bytes).  They never print. */
int  sc_parse_scene(const char *text, size_t len, const char *name, sc_scene *sc,
                    char *err);
int  sc_parse_triangles(const char *text, size_t len, const char *name, double **tri,
                        long *ntri, char *err);
int  sc_parse_media(const char *text, size_t len, const char *name, long ntri,
                    double **media, char *err);
int  sc_parse_obj(const char *text, size_t len, const char *name, double **tri,
                  long *ntri, char *err);
/* The same OBJ as shared vertices and indices (what scenes keep: 24 bytes a
 * vertex and 12 a triangle instead of 72 a triangle). */
int  sc_parse_obj_ix(const char *text, size_t len, const char *name, double **vtx,
                     long *nvtx, uint32_t **idx, long *ntri, char *err);
/* Validate triangles (finite, non-degenerate): 0 or -1 with the triangle's number. */
int  sc_check_triangles(const double *tri, long ntri, const char *name, char *err);
/* A whole scene file with its mesh and media files (scene_load.c): 0 or -1 (err
 * set). */
int  sc_load(const char *path, sc_scene *sc, char *err);
void sc_free(sc_scene *sc);
void sc_scene_defaults(sc_scene *sc);   /* an empty scene with the default settings */
/* The rays of a point source (hexapolar rings filling the disc of `radius` about
 * `toward`, perpendicular to from->toward): 1 + 3 rings (rings + 1) of them. */
long sc_point_count(const sc_source *s);
void sc_point_rays(const sc_source *s, sc_ray *out);

/* Tessellate an analytic surface: axial shapes and discs into 6 level^2 triangles
 * (hexapolar rings, vertices on the surface), rectangles into 2 level^2, spheres
 * into 4 level (level - 1) (level >= 2).  Oriented as the surface's normal. */
int  sc_tessellate(const sc_surface *s, int level, double **tri, long *ntri, char *err);
/* Coincident surfaces: 0, or -1 with both FILE:LINEs in err (scene_geom.c). */
int  sc_check_coincident(const sc_scene *sc, char *err);

/* ---- running (inside the module: needs the engine) ----------------------------- */

/* What a run did.  Outputs named in the scene are written as FILE.part and renamed
 * when complete; after a failure they stay .part and err says so. */
typedef struct sc_result {
    trace_summary sum;
    int progress_shown;       /* a progress line was drawn on stderr */
    int stopped;              /* the stop callback stopped it (outputs left as .part) */
    int mismatch_failed;      /* `mismatch error` and rays met disagreeing media */
    char note[SC_ERRMAX];     /* "FILE:LINE: what" lines ('\n' between) for glasses
                                 traced outside their transmittance data ("" if none) */
} sc_result;

/* The error-against-run-time table: a spherical singlet modelled analytically and as
 * meshes of increasing tessellation, with and without analytic refinement, the same
 * collimated bundle traced to a detector plane, one row per model. */
typedef struct sc_tess_spec {
    double r1, r2, thickness, n, aperture;   /* the lens, first vertex at z = 0 */
    double z_detector;                       /* detector plane (the paraxial focus) */
    double beam_radius;                      /* collimated along +z from z = -1 */
    long grid;                               /* grid x grid rays */
    int nlevels;
    const int *levels;                       /* tessellation levels (rings per cap) */
    int threads;
    int (*stop)(void *ctx);                  /* polled during the traces (may be NULL) */
    void *stop_ctx;
} sc_tess_spec;

enum sc_model { SC_MODEL_ANALYTIC, SC_MODEL_MESH, SC_MODEL_MESH_NORMAL, SC_MODEL_MESH_FULL };
typedef struct sc_tess_row {
    int model, level;
    long triangles;
    double build_ms, trace_ms, rays_per_s;
    double err_max, err_rms;                 /* detector position error (lens units) */
    long rays, lost;                         /* rays compared; rays that missed one
                                                trace but not the other */
} sc_tess_row;

/* Fill rows[0 .. 1 + 3 nlevels): the analytic model, then per level the mesh
 * without refinement, with analytic normals, with full re-intersection. */
int sc_tess_table(const sc_tess_spec *spec, sc_tess_row *rows, char *err);

#define SC_API_ABI 4   /* 4: sc_source's Stokes vector (pol stokes) */
#define SC_API_SYMBOL "lm_scene_api"
typedef struct scene_api {
    int abi;
    int  (*load)(const char *path, sc_scene *sc, char *err);
    void (*free)(sc_scene *sc);
    /* Trace the scene, write its outputs; progress on stderr when it is a terminal
     * and the trace runs over a second.  0 or -1 (err set). */
    int  (*run)(const sc_scene *sc, sc_result *res, char *err);
    int  (*tess_table)(const sc_tess_spec *spec, sc_tess_row *rows, char *err);
    const trace_api *engine;
} scene_api;
typedef const scene_api *(*scene_api_fn)(int abi);
const scene_api *lm_scene_api(int abi);

#endif
