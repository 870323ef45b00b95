/* trace.h -- public face of the ray-tracing engine (the document's opticrt, on Embree 3).
 * STATUS: ready (API v1) -- callers may build on it; later changes only add at the end
 * of struct trace_api and bump nothing for additions.
 *
 * The engine lives in the module build/lib/lensmat-trace.so; a caller never links
 * Embree: it gets the one exported function with
 *     trace_get_api_fn get = (trace_get_api_fn)lm_engine_symbol("trace", TRACE_API_SYMBOL);
 *     const trace_api *tr = get ? get(TRACE_ABI) : NULL;
 * and calls everything through that table.  The engine never prints and never exits:
 * functions return an id >= 0 or TRACE_OK on success, a negative TRACE_E* code on
 * failure with a message from tr->error(scene) (or the err buffer passed in).
 *
 * Geometry is in double everywhere.  Embree (single precision) only proposes the
 * nearest candidate; every hit is re-intersected in double with the analytic surface
 * or the triangle's plane, and refraction, Fresnel and bookkeeping are in double.
 *
 * Sides and indices (n_front, n_back):
 *   - plane and axial surfaces (conic, asphere, spherical cap): "front" is the side
 *     light travelling along +axis comes from (the -axis side), "back" the +axis side;
 *   - full spheres: front = outside, back = inside;
 *   - triangles: front = the side the triangle normal (v1-v0)x(v2-v0) points to, as
 *     opticrt's p.n ("medium 1 is pointed to by the surface normal").
 *
 * Polarisation: each ray carries the 2x2 coherency matrix of its field in a local
 * transverse basis (e, d x e) -- the s and p powers and their coherence -- and it is
 * re-decomposed into the s/p basis of every interface it meets, so s and p are never
 * averaged.  Hits report the powers along the basis of the last interface (s, p).
 *
 * Results are bit-identical for any thread count: rays are numbered in the order the
 * sources were added and cut into batches; threads (created once per run) take whole
 * batches in order, and the sinks are called from the calling thread batch by batch in
 * batch order (within a batch: its segments, then its hits, each in ray order; within
 * a ray: depth-first, refracted before reflected).  Powers are summed ray by ray in ray
 * order, so the summary does not depend on the thread count or the batch size. */
#ifndef TRACE_H
#define TRACE_H
#include <stddef.h>
#include <stdint.h>

#define TRACE_ABI 4     /* 2: trace_rx_surface's mirror and coordinate-break fields;
                           3: trace_source's Jones vector (TRACE_ELLIPTIC);
                           4: its Stokes vector (TRACE_PARTIAL) */
#define TRACE_API_SYMBOL "trace_get_api"

enum {
    TRACE_OK = 0,
    TRACE_EINVAL = -1,     /* bad parameter (message says which) */
    TRACE_ENOMEM = -2,
    TRACE_EEMBREE = -3,    /* Embree device or build failed */
    TRACE_ECANCEL = -4,    /* a sink asked to stop */
    TRACE_EABI = -5
};

/* What a surface does to light. */
enum trace_kind {
    TRACE_REFRACT,   /* interface between n_front and n_back: Fresnel split (or TIR) */
    TRACE_MIRROR,    /* perfect mirror: everything reflected, no refracted ray */
    TRACE_ABSORB,    /* ends the ray; its power counts as absorbed */
    TRACE_DETECT     /* ends the ray and records a hit; its power counts as detected */
};

typedef struct trace_material {
    int kind;              /* enum trace_kind */
    double n_front, n_back;
} trace_material;

/* Analytic surfaces. */
enum trace_shape {
    TRACE_PLANE,     /* point `at`, normal `axis`; aperture disc/annulus or rectangle */
    TRACE_AXIAL,     /* vertex `at`, axis `axis`: conic + even asphere sag (below) */
    TRACE_SPHERE     /* closed sphere: centre `at`, radius `radius` */
};
enum trace_aperture { TRACE_AP_DISC, TRACE_AP_RECT };

#define TRACE_MAXASPH 8
/* Axial sag along the axis at distance s from it:
 *   z(s) = c s^2 / (1 + sqrt(1 - (1+k) c^2 s^2)) + sum_i asph[i] s^(2i+2)
 * with c = 1/radius (radius 0 or inf: flat), k the conic constant (0 sphere,
 * -1 paraboloid), asph[0] = A2 (s^2), asph[1] = A4 (s^4), ...  Conics without
 * aspheric terms are intersected in closed form (stable quadratic), aspheres by
 * safeguarded Newton from the conic root.  Radius > 0: centre of curvature on the
 * +axis side (the paraxial engine's sign). */
typedef struct trace_surface {
    int shape;                 /* enum trace_shape */
    double at[3];
    double axis[3];            /* need not be unit; normalised on adding */
    double up[3];              /* rectangle: direction of `height` (_|_ axis) */
    double radius;
    double conic;
    double asph[TRACE_MAXASPH];
    int nasph;
    int aperture;              /* enum trace_aperture (PLANE, AXIAL) */
    double r_outer, r_inner;   /* disc: semi-diameter (0: unbounded for PLANE, the
                                  conic's own limit for AXIAL) and inner hole radius */
    double width, height;      /* rectangle */
} trace_surface;

/* Triangle meshes: vertices (3 doubles each) and indices (3 per triangle).
 * Degenerate (zero-area), non-finite or out-of-range triangles are refused with
 * their number.  Optional per-triangle media (2 doubles: n_front n_back) override
 * the material's.  Optional underlying analytic surface: hits are refined to it. */
enum trace_refine {
    TRACE_REFINE_NONE,    /* the triangle's plane (point and flat normal) */
    TRACE_REFINE_NORMAL,  /* the triangle's point, the analytic normal there
                             ("replace the triangle by the tangent plane") */
    TRACE_REFINE_FULL     /* re-intersect the analytic surface near the triangle hit:
                             exact point and normal */
};
typedef struct trace_mesh {
    const double *vertex;      /* nvertex * 3 */
    long nvertex;
    const uint32_t *index;     /* ntri * 3; NULL: vertex holds 3 per triangle */
    long ntri;
    const double *media;       /* ntri * 2 or NULL */
    const trace_surface *underlying;   /* NULL: none (copied on adding) */
    int refine;                /* enum trace_refine (ignored without underlying) */
    int shared;                /* 1: vertex and index (given) outlive the scene and do
                                  not change: the scene uses them in place instead of
                                  copying them (24 bytes a vertex, 12 a triangle) */
} trace_mesh;

/* Sources.  Rays get consecutive numbers in the order sources are added. */
enum trace_source_type {
    TRACE_SRC_RAYS,       /* explicit rays: ray[i] (origin, direction, power) */
    TRACE_SRC_AIMED,      /* point `at`, rays toward count points evenly spaced from
                             to0 to to1 (opticrt's five rays) */
    TRACE_SRC_FAN,        /* point `at`, count rays in the plane of dir and up,
                             angles evenly from -half_angle to +half_angle */
    TRACE_SRC_CONE,       /* point `at`, hexapolar cone about dir: rings rings of
                             6*r rays up to half_angle, plus the axial ray */
    TRACE_SRC_GRID,       /* collimated along dir: square grid of count x count
                             cell centres across the disc of `radius` about `at`
                             (cells outside the disc dropped) */
    TRACE_SRC_GAUSSIAN    /* laser beam, waist `waist` (1/e^2 radius) at `at`,
                             along dir, wavelength: hyperboloid of skew rays with
                             far-field half-angle lambda/(pi w0) (~lambda/D), polar
                             grid of rings x 6r rays to trunc*waist, weighted
                             exp(-2 rho^2/w0^2) */
};
/* TRACE_ELLIPTIC: fully polarized with the Jones vector trace_source.jones in the
 * frame (x', y' = dir x x'), x' = pol_dir (zero: +x) projected perpendicular to the
 * ray -- for rays within 25 degrees of pol_dir, z x pol_dir (+y if that is zero) --
 * the rule of the Stokes frame (trace_api.polarization), so with pol_dir the Stokes
 * reference a ray's state at its source is what the detector's Stokes parameters
 * report: S3 = 2 Im(Jx* Jy) > 0 turns from x' toward y' (fields exp(i(kz - wt))). */
/* TRACE_PARTIAL: partially polarized, the normalized Stokes vector trace_source.stokes
 * (S1/S0, S2/S0, S3/S0, length = the degree of polarization, at most 1) in that same
 * frame: the coherency (S0 + S1, S2 - i S3; S2 + i S3, S0 - S1) / 2. */
enum trace_pol { TRACE_UNPOLARISED, TRACE_LINEAR, TRACE_ELLIPTIC, TRACE_PARTIAL };

typedef struct trace_ray {
    double o[3], d[3];
    double power;              /* <= 0: source power / count */
} trace_ray;

typedef struct trace_source {
    int type;                  /* enum trace_source_type */
    double at[3], dir[3], up[3];
    double to0[3], to1[3];
    double half_angle;         /* radians */
    double radius;
    double waist, wavelength, trunc;   /* trunc 0: 2 */
    long count;
    int rings;
    double power;              /* total; 0: 1 */
    double n_medium;           /* index where the rays start; 0: 1 */
    int pol;                   /* enum trace_pol */
    double pol_dir[3];         /* TRACE_LINEAR: E direction (projected _|_ ray);
                                  TRACE_ELLIPTIC: the Jones frame's x' reference */
    const trace_ray *ray;      /* TRACE_SRC_RAYS: count rays (copied on adding) */
    double alpha_medium;       /* absorption where the rays start (set_absorption) */
    double lambda;             /* the rays' vacuum wavelength, um (0: none named), carried
                                  by every ray into its segments and hits; the indices
                                  are the materials' (a caller tracing several
                                  wavelengths gives each its own run with the indices at
                                  that wavelength, as the scene front end does) */
    double jones[2][2];        /* TRACE_ELLIPTIC: (re, im) of Jx and Jy (any nonzero
                                  length: the power is the source's) */
    double stokes[3];          /* TRACE_PARTIAL: S1/S0, S2/S0, S3/S0 (frame: pol_dir) */
} trace_source;

typedef struct trace_options {
    int max_depth;         /* interactions per path before it is cut off (default 16) */
    double cutoff;         /* a ray under cutoff * its source ray's power is cut off
                              (default 1e-6) */
    int fresnel;           /* 1: Fresnel s/p powers (default); 0: refracted ray keeps
                              its power (pure geometry, reflections only at TIR) */
    int reflections;       /* 1: follow Fresnel-reflected rays (default); 0: their
                              power is cut off (sequential lens work) */
    int threads;           /* 0: all cores */
    double escape_length;  /* length of the segment drawn for an escaping ray (1) */
    long batch;            /* rays per batch (0: 8192 with sinks, 65536 without,
                              halved down to 1024 with several threads until each
                              has 8 batches) */
    int float_hits;        /* 1: take hits as a single-precision tracer computes them
                              (no double refinement) -- only to measure what double
                              buys; never for real work (default 0) */
    int sequential;        /* 1: in a scene made by add_lens alone, a ray refracted
                              forward goes to the next surface without the BVH when
                              the surfaces' z ranges are disjoint -- the same hits,
                              bit for bit, faster (default); 0: always ask Embree */
} trace_options;

/* Records handed to sinks. */
enum trace_end {
    TRACE_END_NONE,        /* segment to the next interface */
    TRACE_END_DETECT, TRACE_END_ABSORB, TRACE_END_ESCAPE, TRACE_END_CUTOFF
};
typedef struct trace_segment {
    uint64_t ray;          /* source-ray number */
    int depth;             /* interactions before this segment */
    int end;               /* enum trace_end: what happened at p1 */
    int surface;           /* surface id at p1 (-1: escaped) */
    double p0[3], p1[3];
    double power;          /* s + p power along the segment (where it starts) */
    double lambda;         /* the ray's wavelength (trace_source.lambda) */
} trace_segment;

typedef struct trace_hit {
    uint64_t ray;
    int depth;             /* interactions before reaching the detector */
    uint32_t history;      /* bit i set: interaction i was a reflection (i < 32) */
    int surface;
    long prim;             /* triangle number (meshes), else -1 */
    double pos[3], dir[3], normal[3];
    double s_dir[3];       /* the s unit vector of the basis (s, dir x s) */
    double power_s, power_p;   /* along s_dir and dir x s_dir */
    double length;         /* geometric path length from the source */
    double opl;            /* optical path length (sum n * length) */
    double lambda;         /* the ray's wavelength (trace_source.lambda) */
} trace_hit;

/* Every callback returns 0 to go on, non-zero to cancel the trace (TRACE_ECANCEL).
 * All are called from the thread that called run(), in ray order.  NULL: not wanted
 * (nothing is kept for it). */
typedef struct trace_sink {
    void *ctx;
    int (*segment)(void *ctx, const trace_segment *seg);
    int (*hit)(void *ctx, const trace_hit *hit);
    int (*progress)(void *ctx, uint64_t done, uint64_t total);   /* per batch */
} trace_sink;

/* The same records a batch at a time (trace_api.run_batches, added after
 * prt_interface): segments() gets a batch's segments, hits() its hits, as arrays of n
 * records (n >= 1) in the order trace_sink's callbacks would get them one by one, from
 * the same thread; the array is the engine's and holds until the call returns.  One
 * call per callback and batch -- except with polarization on, whose record for each hit
 * comes just before the call holding that hit: such hits come one per call.  Cuts a
 * call per record (and lets the caller copy a batch in one loop).  Each returns 0 to
 * go on, non-zero to cancel (TRACE_ECANCEL); NULL: not wanted. */
typedef struct trace_batch_sink {
    void *ctx;
    int (*segments)(void *ctx, const trace_segment *seg, size_t n);
    int (*hits)(void *ctx, const trace_hit *hit, size_t n);
    int (*progress)(void *ctx, uint64_t done, uint64_t total);   /* per batch */
} trace_batch_sink;

typedef struct trace_summary {
    uint64_t rays;             /* source rays */
    uint64_t segments;
    uint64_t interactions;     /* interface events (refraction, reflection, TIR) */
    uint64_t tir;              /* total internal reflections */
    uint64_t hits;             /* detector hits */
    uint64_t cut_depth, cut_power, cut_reflection;  /* how rays were cut off */
    uint64_t medium_mismatch;  /* rays whose carried index differed from the side
                                  of the surface they hit (inconsistent scene) */
    uint64_t failures;         /* numerical failures (non-finite); counted as cut */
    int max_depth_seen;
    /* Power: emitted = detected + absorbed + escaped + cutoff (to ~1e-15 relative) */
    double emitted, detected, absorbed, escaped, cutoff;
    double build_ms, trace_ms;
    int lens_surfaces;         /* surfaces of the sequential lens the run took the lens
                                  shortcut through (add_lens's, or one found inside the
                                  scene: tr_seqscan.c); 0: every segment by Embree */
    char lens_kernel[12];      /* with lens_surfaces: the packet kernel that ran it
                                  (trace_isa_active(); "scalar": rays one by one, as
                                  with an absorbing medium) */
} trace_summary;

/* A sequential lens as the classic dialogue enters it: surfaces left to right with
 * radius (0 or inf: plane; > 0: centre to the right), vertex z on the axis (the z
 * axis) and the index to the right; spheres become analytic TRACE_AXIAL surfaces. */
typedef struct trace_lens_surface {
    double radius, z, n_right;
    double semi_diameter;      /* 0: unbounded (up to the sphere's own limit) */
} trace_lens_surface;
typedef struct trace_lens {
    double n_object;           /* index left of the first surface */
    int nsurf;
    const trace_lens_surface *surf;
    int mounts;                /* 1: absorbing annulus outside each semi-diameter */
    double z_detector;         /* NaN: none; else a detector plane there */
} trace_lens;

/* One meridional ray of a fan (object on the axis or in the y-z plane). */
typedef struct trace_fan_ray {
    double h;                  /* in: the height aimed at on the first surface (the
                                  ray meets surface 1 there); out: the height where it
                                  met it (to rounding the same), or h if it missed */
    double z_cross;            /* where it crosses the axis after the last surface */
    double lsa;                /* z_cross - z_paraxial (longitudinal aberration) */
    double y_image;            /* height at z_paraxial (transverse aberration) */
    double opl;                /* optical path from the object (or the first vertex
                                  plane when the object is at infinity) to z_paraxial */
    int status;                /* 0 ok; 1 vignetted/missed; 2 TIR; 3 parallel exit */
} trace_fan_ray;

/* Result of the Fresnel formulas (section 51, Born & Wolf): amplitude coefficients
 * (real: no TIR; at TIR the reflection phases are in r*_phase) and power
 * coefficients; T includes the n2 cos t / (n1 cos i) factor. */
typedef struct trace_fresnel_coef {
    double rs, rp, ts, tp;         /* amplitudes (rs, rp magnitude at TIR) */
    double rs_phase, rp_phase;     /* radians: 0 or pi outside TIR */
    double Rs, Rp, Ts, Tp;         /* powers: Rs + Ts = Rp + Tp = 1 */
    double cos_t;                  /* 0 at TIR */
    int tir;
} trace_fresnel_coef;

/* ---- real rays aimed at the stop (tr_aim.c) ----------------------------------
 * A sequential prescription with conics and aspheres: surfaces left to right, each
 * an axial surface of the z axis (vertex z, radius: 0 or inf plane, > 0 centre to
 * the right; conic and even-asphere terms as trace_surface), the index to its right
 * (one wavelength: the caller's), its clear semi-diameter (0: none).  No Embree: a
 * ray meets the surfaces in order, in double, with the engine's own intersections
 * and Snell law.  Clear apertures do not bound the surfaces while a ray is aimed; a
 * converged ray that passes outside one is reported vignetted there. */
typedef struct trace_rx_surface {
    double z, radius, conic;
    double asph[TRACE_MAXASPH];
    int nasph;
    double n_right;
    double semi_diameter;
    /* ABI 2 (tr_aim.c's head comment has the conventions).  mirror 1: the surface
     * reflects (n_right: the medium the light goes back into; z may then run
     * backwards).  coordbrk 1: not a surface but a coordinate break at z (only
     * decenter, tilt and order count): the surfaces after it are in the new frame,
     * whose origin is (decenter x, y) off the old axis at z, rotated by tilt[0..2]
     * degrees about x, y, z (order 0: decentre, then tilt x, y, z; order 1: tilt z,
     * y, x, then decentre -- OpticStudio's COORDBRK PARM 1-6). */
    int mirror, coordbrk, order;
    double decenter[2], tilt[3];
} trace_rx_surface;
typedef struct trace_rx {
    double n_object;
    int nsurf;
    const trace_rx_surface *surf;
    int stop;                  /* the aperture stop, 0-based */
    double stop_radius;        /* what px, py = 1 means at the stop */
    double z_image;            /* the image plane rays are carried to (NaN: none) */
} trace_rx;
enum trace_aim_status {
    TRACE_AIM_OK,              /* crosses the stop at its target */
    TRACE_AIM_VIGNETTED,       /* aimed, but outside a clear semi-diameter (surface) */
    TRACE_AIM_MISSED,          /* misses a surface (surface) */
    TRACE_AIM_TIR,             /* totally reflected at a surface (surface) */
    TRACE_AIM_NOCONV           /* Newton did not bring it to the target */
};
/* What to aim: from the object point obj (finite: z left of surface 1), or a beam
 * from infinity along dir; to the stop point (px, py) * stop_radius (local x, y of
 * the stop's vertex).  The unknowns start at the caller's paraxial guess: for a
 * finite object the ray's slopes dx/dz, dy/dz; for infinity the point (x, y) where it
 * crosses the plane z = z_ref.  tol: stop residual accepted (0: 1e-10 * max(1,
 * stop_radius)); max_iter 0: 40. */
typedef struct trace_aim_req {
    int infinite;
    double obj[3], dir[3];
    double px, py;
    double guess[2];
    double z_ref;
    double tol;
    int max_iter;
} trace_aim_req;
typedef struct trace_aim_ray {
    int status;                /* enum trace_aim_status */
    int surface;               /* where it failed (0-based), or -1 */
    int iterations;            /* Newton steps taken (0: the guess was on target) */
    int traces;                /* rays traced to get there */
    double residual;           /* |stop crossing - target| */
    double v[2];               /* the unknowns found (slopes, or x, y at z_ref) */
    double o[3], d[3];         /* the ray in object space (o: the object point, or
                                  its crossing of z_ref) */
    double stop[3];            /* its stop crossing */
    double img[3], img_dir[3]; /* at z_image (NaN if none) */
    double opl;                /* optical path from o to the image plane */
} trace_aim_ray;

/* ---- polarization ray tracing (tr_polar.c) -------------------------------------
 * With trace_api.polarization on, every ray carries Chipman's 3x3 polarization
 * ray-tracing matrix P (Chipman, Lam & Young, "Polarized Light and Optical Systems",
 * ch. 9-10): the field after the path is P E for the source field E (global x y z,
 * fields as exp(i(kz - wt)), rp with Hecht's sign).  At each interface P grows by
 * O_out J O_in^T, O = [s, k x s, k] with s = k_in x n / |k_in x n|, J = diag(rs, rp, 1)
 * on reflection, diag(ts, tp, 1) on refraction (amplitudes; TIR gives rs, rp of unit
 * modulus and their phases), then a surface's element (below) on what it transmits.
 * Powers follow P: a ray's power is gain * |P E|^2 summed over the source's
 * coherency, gain the product of n2 cos t / (n1 cos i) over its refractions (and the
 * Beer-Lambert factors), so polarizers absorb and coatings set R and T.  Such runs go
 * ray by ray (never on the packet path). */
enum trace_polel { TRACE_POL_NONE, TRACE_POL_POLARIZER, TRACE_POL_RETARDER };
#define TRACE_MAXLAYER 32
typedef struct trace_polar_surface {
    int element;               /* enum trace_polel: applied to the transmitted light */
    double axis[3];            /* polarizer: transmission axis; retarder: fast axis
                                  (projected perpendicular to each ray) */
    double retardance;         /* retarder: radians (slow axis delayed) */
    int nlayer;                /* coating: layers from the front side (n_front) */
    double layer_n[TRACE_MAXLAYER];
    double layer_d[TRACE_MAXLAYER];   /* thickness, um (as trace_source.lambda) */
} trace_polar_surface;
typedef struct trace_polar_hit {
    uint64_t ray;              /* the hit's ray, depth, surface and point (trace_hit) */
    int depth, surface;
    double pos[3];
    double prt[3][3][2];       /* P (re, im), row-major, global coordinates */
    double gain;               /* the radiometric factor (above) */
    double stokes[4];          /* S0..S3 (power units) in the frame x', y' = dir x x',
                                  x' the reference projected perpendicular to dir;
                                  S3 = 2 Im(Ex* Ey) > 0: E turning from x' toward y' */
    double xref[3];            /* x' */
    double retardance;         /* the path's proper retardance (radians, 0..pi; NaN
                                  where a polarizer leaves it undefined): of the Jones
                                  matrix from the frame x', y' at the source to that
                                  frame carried along the path by parallel transport
                                  (Q, Chipman ch. 11), so frame turns are not in it;
                                  an ideal mirror counts as a half-wave (Hecht's rp) */
    double diattenuation;      /* (smax^2 - smin^2) / (smax^2 + smin^2) of it */
} trace_polar_hit;

typedef struct trace_scene trace_scene;

typedef struct trace_api {
    int abi;                                   /* TRACE_ABI */
    const char *(*version)(void);              /* engine and Embree versions */

    trace_scene *(*scene_new)(void);           /* NULL: out of memory; no Embree yet */
    void (*scene_free)(trace_scene *sc);
    const char *(*error)(const trace_scene *sc);    /* last error message */

    /* Each returns the new surface id (>= 0) or a TRACE_E* code. */
    int (*add_surface)(trace_scene *sc, const trace_surface *s, const trace_material *m);
    int (*add_mesh)(trace_scene *sc, const trace_mesh *mesh, const trace_material *m);
    /* TRACE_OK (number of its first ray in *first, may be NULL) or an error. */
    int (*add_source)(trace_scene *sc, const trace_source *src, uint64_t *first);

    void (*options_default)(trace_options *o);
    /* Build the acceleration structure now (else run() does it, creating the Embree
     * device on first use).  Returns TRACE_OK or an error; build_ms in *ms. */
    int (*build)(trace_scene *sc, double *ms);
    /* Trace every source.  sink may be NULL; sum may be NULL. */
    int (*run)(trace_scene *sc, const trace_options *o, const trace_sink *sink,
               trace_summary *sum);

    /* Physics helpers (pure functions, also what run() uses). */
    /* Refract unit direction d at unit normal nrm (either orientation) from index
     * n1 into n2: 1 and out = refracted unit direction, or 0 at TIR (out =
     * reflected direction).  Exact vector Snell law at every angle. */
    int (*refract)(const double d[3], const double nrm[3], double n1, double n2,
                   double out[3]);
    void (*fresnel)(double n1, double n2, double cos_i, trace_fresnel_coef *out);

    /* Sequential lenses. */
    int (*add_lens)(trace_scene *sc, const trace_lens *lens);   /* id of surface 1 */
    /* Trace nrays meridional rays that meet the first surface at heights h[i] from the
     * object point (0, y_obj, z_obj) (z_obj = -INFINITY: a collimated beam parallel
     * to the axis) through the lens, geometry only, and compare with the paraxial
     * image z_paraxial supplied by the caller.  TRACE_OK or error (message in err). */
    int (*lens_fan)(const trace_lens *lens, double z_obj, double y_obj,
                    double z_paraxial, int nrays, const double *h,
                    trace_fan_ray *out, char *err, size_t errcap);

    /* Absorption (added after v1): the absorption coefficients (per unit of the scene's
     * length, >= 0; 0: transparent) of the media on either side of surface `id`
     * (front/back as n_front/n_back).  Inside a medium with alpha > 0 a ray's power
     * falls as exp(-alpha L) along every segment (Beer-Lambert), the loss counted as
     * absorbed; a source starts in alpha_medium.  A scene with any absorbing medium is
     * traced ray by ray, never on the packet path (which does not apply it; see
     * tr_pool.c).  Per-triangle media (trace_mesh.media) stay transparent.  TRACE_OK
     * or TRACE_EINVAL. */
    int (*set_absorption)(trace_scene *sc, int id, double alpha_front, double alpha_back);

    /* Real rays aimed at the stop (ABI 1 additions).  rx_trace: the ray o, d (unit,
     * in the object medium) through rx in order to z_image; out->status and
     * out->surface as above (clear apertures checked), pts (NULL or 3*nsurf
     * doubles): the surface crossings.  rx_aim: Newton on the stop crossing from the
     * guess (a damped step when a trial ray fails), then the converged ray traced to
     * z_image.  Both: TRACE_OK with the ray's status in out, or TRACE_EINVAL (bad
     * rx or request: err says why). */
    int (*rx_trace)(const trace_rx *rx, const double o[3], const double d[3],
                    double *pts, trace_aim_ray *out, char *err, size_t errcap);
    int (*rx_aim)(const trace_rx *rx, const trace_aim_req *rq, trace_aim_ray *out,
                  char *err, size_t errcap);

    /* The wave aberration of aimed rays (tr_opd.c; added after rx_aim): rq[0] the chief
     * ray, rq[1..n-1] pupil rays, each aimed as rx_aim does.  w[i] (waves of lambda,
     * lambda in the lens's unit) is Welford's W: the chief ray's optical path to the
     * reference sphere minus ray i's, positive where the wavefront leads the sphere;
     * the sphere is centred on the chief ray's image point and passes through the
     * chief ray's crossing of the plane z = z_xp (the exit pupil's).  Paths count from
     * the object point, or (rq->infinite) from the plane wavefront through the origin.
     * w[i] is NaN where ray i is not TRACE_AIM_OK or misses the sphere; st (may be
     * NULL) gets each status; chief (may be NULL) the chief ray; *R_ref (may be NULL)
     * the sphere's radius.  TRACE_OK, or TRACE_EINVAL (bad rx or request, the chief
     * ray does not pass, no sphere: err says why). */
    int (*rx_opd)(const trace_rx *rx, const trace_aim_req *rq, int n, double z_xp,
                  double lambda, double *w, int *st, trace_aim_ray *chief, double *R_ref,
                  char *err, size_t errcap);

    /* Polarization ray tracing (tr_polar.c; added after rx_opd).  polarization: on 1
     * makes run() trace P per ray and hand each hit's trace_polar_hit to cb (may be
     * NULL) with ctx, from run()'s thread just before the sink's hit() for that hit
     * (when the sink takes hits); xref (NULL: +x) is the Stokes frame's reference
     * (for rays within 25 degrees of it: z x xref, +y for the default).  set_polar:
     * surface id's element and coating (refracting surfaces only; it turns
     * polarization on).  TRACE_OK or TRACE_EINVAL. */
    int (*polarization)(trace_scene *sc, int on, const double xref[3],
                        int (*cb)(void *ctx, const trace_polar_hit *ph), void *ctx);
    int (*set_polar)(trace_scene *sc, int id, const trace_polar_surface *ps);
    /* The PRT matrix of one interface (pure function): unit k_in, unit normal nrm (either
     * orientation), media n1 -> n2, ps (NULL: bare), lambda um (for a coating),
     * reflect 1: the reflected ray.  P (re/im) and the direction out; returns 0, or 1 at
     * TIR when refraction was asked (P then 0). */
    int (*prt_interface)(const double k_in[3], const double nrm[3], double n1, double n2,
                         const trace_polar_surface *ps, double lambda, int reflect,
                         double P[3][3][2], double k_out[3]);

    /* run() with a sink that takes each batch's records at once (trace_batch_sink,
     * above; added after prt_interface): the same records in the same order, the same
     * summary, the same return codes.  sink may be NULL; sum may be NULL. */
    int (*run_batches)(trace_scene *sc, const trace_options *o,
                       const trace_batch_sink *sink, trace_summary *sum);
} trace_api;

typedef const trace_api *(*trace_get_api_fn)(int abi);
/* Exported by lensmat-trace.so: the table, or NULL if abi != TRACE_ABI. */
const trace_api *trace_get_api(int abi);

/* Also exported: the instruction sets the lens packets can run on in this build, best
 * first (x86-64: "avx512", "avx2", "sse2"; arm64: "neon"; then "scalar", rays one by
 * one): name i, or NULL past the last, *usable (may be NULL) 1 if this processor runs
 * it.  trace_isa_active(): the one this process uses, chosen when the module loads:
 * the best usable, or the one the environment variable LENSMAT_ISA names (if this
 * processor cannot run that one, the best below it).  All give the same bits. */
const char *trace_isa_name(int i, int *usable);
const char *trace_isa_active(void);

/* ---- a lens's geometry, checked without the module -------------------------------
 * Inline so that the dialogue can refuse an answer at its question without loading
 * the engine; tr_lens.c refuses the same lenses in add_lens and lens_fan.
 * trace_lens_sag: the sag of a sphere of this radius (0 or inf: a plane) at height
 * s <= |radius|.
 * trace_lens_cross: do consecutive surfaces a, b (a left of b) cross within their
 * semi-diameters?  The edge thickness t(s) = (b.z + sag_b(s)) - (a.z + sag_a(s)) of
 * two spheres is monotone in s (t' = s (g(c_b) - g(c_a)) with g(c) = c / sqrt(1 - c^2
 * s^2) increasing in the curvature c), so from t(0) = b.z - a.z >= 0 they cross iff t
 * is negative at the rim: the smaller of the semi-diameters given (0 is none; when
 * neither is given nothing is checked).  Returns 1 if they cross, with *h the height
 * where t = 0 (0: they touch on the axis), *rim the rim height and *edge = t(rim) < 0;
 * else 0. */
static inline double trace_lens_sag(double radius, double s)
{
    if (!(radius != 0) || radius > 1e300 || radius < -1e300) return 0;
    double c = 1 / radius, q = 1 - c * c * s * s;
    return c * s * s / (1 + __builtin_sqrt(q > 0 ? q : 0));
}
static inline int trace_lens_cross(const trace_lens_surface *a, const trace_lens_surface *b,
                                   double *h, double *rim, double *edge)
{
    double sa = a->semi_diameter, sb = b->semi_diameter;
    double s = sa > 0 && sb > 0 ? (sa < sb ? sa : sb) : sa > 0 ? sa : sb;
    if (!(s > 0)) return 0;
    double za = a->z + trace_lens_sag(a->radius, s), zb = b->z + trace_lens_sag(b->radius, s);
    double t = zb - za, scale = __builtin_fabs(za) + __builtin_fabs(zb) + s;
    if (!(t < -1e-14 * scale)) return 0;
    double lo = 0, hi = s;            /* t(lo) >= 0 > t(hi): bisection to the last bit */
    if (b->z > a->z)
        for (int i = 0; i < 200; i++) {
            double mid = 0.5 * (lo + hi);
            if (!(mid > lo && mid < hi)) break;
            double tm = (b->z + trace_lens_sag(b->radius, mid)) -
                        (a->z + trace_lens_sag(a->radius, mid));
            if (tm >= 0) lo = mid; else hi = mid;
        }
    *h = lo;
    *rim = s;
    *edge = t;
    return 1;
}

#endif
