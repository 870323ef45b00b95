/* cornea.h -- public face of the cornea analysis engine (issue 12): fit a cornea model
 * (sphere, conic, biconic/toric, even asphere) and the eye's pose to laser-spot
 * positions on the rig's detector, report what clinicians read (apex radius, Q, Sim K
 * at the apex and over the 3 mm zone, cylinder, power) with uncertainties, say which
 * parameters a scan does not determine (SVD of the weighted Jacobian) and when the
 * residuals are systematic (a cone), predict the accuracy of a rig and scan before
 * building it; and give what maps and reports need (map grids, CSV and JSON).
 * Lives in build/lib/lensmat-cornea.so:
 *     cornea_get_api_fn get = (cornea_get_api_fn)lm_engine_symbol("cornea",
 *                                                                 CORNEA_API_SYMBOL);
 *     const cornea_api *cn = get ? get(CORNEA_ABI) : NULL;
 * The rig is reached only through the rig_api table the caller passes in (rig.h's
 * public types and functions).  The engine never prints and never exits; functions
 * return 0 (CN_OK) or a negative CN_E* code with a message in err.  mm and radians.
 *
 * The fit's forward model is analytic: the incoming beam of each commanded pose
 * (where it leaves m2 and its direction, from rig_api.forward: it does not depend on
 * the cornea) meets the cornea of the parameters, reflects, and crosses the fixed
 * detector plane (through the detector point, normal along nominal apex -> detector,
 * the apex being the rig file's eye_at).  Detector coordinates (u, v) are mm in that
 * plane along cn_plane.e1, e2. */
#ifndef CORNEA_H
#define CORNEA_H
#include <stddef.h>
#include "rig/rig.h"

#define CORNEA_ABI 5            /* 4: cn_zfit grew (order 26, the slopes' departure zsl[]);
                                   5: kc_model_in */
#define CORNEA_API_SYMBOL "cornea_get_api"

enum { CN_OK = 0, CN_EINVAL = -1, CN_ENOMEM = -2, CN_EFIT = -3, CN_ESTOP = -4,
       CN_EABI = -10 };

/* Fit parameters.  The toric part is fitted as power-vector components of the apex
 * curvature, c(phi) = 1/R + C0 cos 2phi + C45 sin 2phi (1/mm), well conditioned at
 * zero cylinder; R_flat, R_steep and the axis are derived from them. */
enum cn_param { CN_R, CN_C0, CN_C45, CN_QF, CN_QS, CN_DX, CN_DY, CN_DZ, CN_TX, CN_TY,
                CN_A4, CN_A6,      /* even asphere (section 33): + A4 s^4 + A6 s^6, mm^-3
                                      and mm^-5, about the conic of R and Q_flat */
                CN_NPARAM };
/* CN_ASPHERE: rotational conic (R, Q_flat) plus A4 s^4 + A6 s^6 and the pose.  Q and
 * A4 change the same s^4 term (a conic's s^4 coefficient is (1+Q)/(8R^3)), so Q is
 * held at its start value (the rig file's cornea_Q) unless cn_fit_opts.free_q. */
enum cn_model { CN_SPHERE, CN_CONIC, CN_BICONIC, CN_ASPHERE };

typedef struct cn_plane {          /* the detector plane */
    double at[3], w[3];            /* detector point; unit normal */
    double e1[3], e2[3];           /* in-plane unit axes of (u, v) */
} cn_plane;

typedef struct cn_ray { double o[3], d[3]; } cn_ray;   /* the beam leaving m2 */

/* One exposure.  status: CN_S_OK, or why the frame gave no usable spot. */
enum cn_spot_status { CN_S_OK, CN_S_NONE, CN_S_SEVERAL, CN_S_OUTLIER, CN_S_MISS };
typedef struct cn_spot {
    cn_ray ray;                    /* incoming beam of the commanded pose */
    double u, v;                   /* measured centroid on the detector (mm) */
    double sigma;                  /* its standard uncertainty per axis (mm) */
    int status;                    /* enum cn_spot_status (input: OK, NONE, SEVERAL) */
    double nres;                   /* output: normalised residual |r| / sigma */
} cn_spot;

/* Parameter vector: p[CN_*] in the units above (tilts: rad, about rig x then y). */
typedef struct cn_params { double p[CN_NPARAM]; } cn_params;

typedef struct cn_fit_opts {
    int model;                     /* enum cn_model */
    int fix_tilt;                  /* 1: tilt held at the start value (sphere: always) */
    double reject_k;               /* outlier: |r|/sigma > k * robust scale (0: 5) */
    int reject_rounds;             /* refits after rejection, until none is new
                                      (0: at most 12; -1: none) */
    double rcond;                  /* singular value / largest below it: not
                                      determined (0: 1e-9) */
    int max_iter;                  /* trust-region iterations per solve (0: 1000) */
    int (*stop)(void *ctx); void *stop_ctx;   /* polled each iteration */
    int free_q;                    /* asphere: fit Q too (its s^4 term is A4's) */
    int threads;                   /* residuals and Jacobian on this many threads
                                      (0, 1: the caller's; the same bits for any) */
} cn_fit_opts;

/* What the clinician reads, each with its standard uncertainty (sd_*; INFINITY when
 * the scan does not determine it). */
typedef struct cn_clinical {
    double R, sd_R;                /* apex radius, mean of the meridians (mm) */
    double Q, sd_Q;                /* conic constant, flat meridian */
    double R_flat, sd_R_flat, R_steep, sd_R_steep;
    double Q_flat, sd_Q_flat, Q_steep, sd_Q_steep;
    double K1, sd_K1, K1_axis;     /* flat K (D, n 1.3375) and its meridian (deg 0-180) */
    double K2, sd_K2, K2_axis;     /* steep K */
    double sd_axis;                /* of K1_axis (deg) */
    double Km, sd_Km;              /* mean K (D) */
    double cyl, sd_cyl;            /* corneal cylinder K2 - K1 (D, at K2_axis) */
    double P, sd_P;                /* mean corneal power with n = 1.376 (D) */
    double dx, dy, dz, sd_dx, sd_dy, sd_dz;   /* eye pose: apex shift (mm) */
    double tx, ty, sd_tx, sd_ty;   /* tilt (deg) */
    /* Sim K over the standard 3 mm zone, as keratometers and topographers report it:
     * the axial (sagittal) curvature of the fitted surface on the ring of height
     * zone_h = 1.5 mm about its axis, 72 meridians, its mean and second harmonic
     * (K(phi) = zKm + A cos 2(phi - zK2_axis)); the apex values above are the
     * limit zone_h -> 0.  D, n 1.3375; axes deg 0-180. */
    double zone_h;
    double zK1, sd_zK1, zK1_axis, zK2, sd_zK2, zK2_axis, sd_zaxis;
    double zKm, sd_zKm, zcyl, sd_zcyl;
} cn_clinical;

#define CN_KERATO_N 1.3375
#define CN_CORNEA_N 1.376

typedef struct cn_result {
    int model;
    int nused, nrejected;          /* spots fitted; spots left out (status says why) */
    int iterations;
    double rms;                    /* residual RMS on the detector (mm) */
    double chi2_dof;               /* chi^2 / degrees of freedom */
    cn_params par;                 /* fitted values (fixed ones: the start) */
    int free[CN_NPARAM];           /* 1: fitted */
    double cov[CN_NPARAM * CN_NPARAM];   /* covariance (fixed rows/cols 0; INFINITY on
                                            the diagonal of undetermined ones) */
    /* SVD of the weighted Jacobian with columns scaled to unit norm: */
    int nfree;
    int idx[CN_NPARAM];            /* free parameter of each column */
    double sv[CN_NPARAM];          /* singular values, largest first */
    double vt[CN_NPARAM * CN_NPARAM];   /* right singular vectors, row k: direction of
                                           sv[k] over the free columns (row length
                                           nfree), in column-scaled units */
    double cond;                   /* sv[0] / sv[nfree-1] */
    unsigned undetermined;         /* bit CN_*: parameter not determined (a singular
                                      direction below rcond, or sd over its limit) */
    char why[1024];                /* one line per undetermined parameter / direction */
    int poor;                      /* 1: chi^2 more than 4 sd above its dof (the
                                      weakest direction's parameters then marked) */
    double chi2_z;                 /* (chi^2 - dof) / sqrt(2 dof) */
    cn_clinical k;
    double hmax;                   /* largest height of a fitted spot from the fitted
                                      surface's axis (mm): the data's zone */
    double resid_corr;             /* residual map test: mean correlation of each
                                      spot's residual with its nearest neighbour's
                                      (noise ~0; a shape the model lacks ~1) */
    /* --- ABI 3 --- */
    int converged;                 /* 1: the final solve met a stopping test; 0: it
                                      ran into max_iter (the numbers are where it
                                      stopped, not a minimum: callers fail the run) */
    int max_solve_iter;            /* most iterations of one solve (iterations counts
                                      every solve: rejection rounds, restarts) */
    int rejected_model;            /* 1: poor and systematic residuals: the model
                                      lacks the surface's shape; every sd INFINITY,
                                      the report gives none of its numbers */
    double inflation;              /* poor, residuals uncorrelated: the sd are the
                                      covariance's times this, sqrt(chi2/dof) (else 1) */
} cn_result;

typedef struct cn_predict {        /* accuracy of a rig and scan before building it */
    int nfree, idx[CN_NPARAM];
    double sv[CN_NPARAM], vt[CN_NPARAM * CN_NPARAM], cond;
    double sd[CN_NPARAM];          /* predicted parameter uncertainty */
    double J[2 * CN_NPARAM];       /* not used by callers: scratch */
    unsigned undetermined;
    char why[512];
    cn_clinical k;                 /* predicted clinical uncertainties (sd_*) */
} cn_predict;

/* A simulated scan (synthetic data, tests and benchmarks). */
typedef struct cn_scan_opts {
    int npoints;                   /* number of targets (rings of a sunflower pattern) */
    double theta_max;              /* zone: largest polar angle (rad) about the apex
                                      centre of curvature */
    int one_meridian;              /* 1: all points on the meridian phi = meridian */
    double meridian;
    double sigma;                  /* centroid noise (mm, Gaussian; 0: none) */
    unsigned long long seed;
    int quantise;                  /* 1: commanded poses on the step grid */
} cn_scan_opts;

/* A keratoconus-like local steepening (a model of the truth for simulations, never
 * fitted): a Gaussian protrusion of the surface toward the observer added to the
 * sag in the eye frame,
 *     z(x, y) -= h exp(-((x - x0)^2 + (y - y0)^2) / (2 w^2)),
 * which steepens the apex curvature at (x0, y0) by h / w^2 (1/mm), i.e.
 * 337.5 h / w^2 D: h 10 um over w 0.8 mm is 5.3 D, a mild cone.  mm. */
typedef struct cn_bump { double h, w, x0, y0; } cn_bump;

/* Maps of a fitted surface, in its eye frame (apex at the origin, x, y in mm as the
 * rig's eye frame), on an n x n grid over [-hmax, hmax]^2, row 0 at y = +hmax,
 * column 0 at x = -hmax; NaN outside the disc of radius hmax or off the surface. */
enum cn_map_kind {
    CN_MAP_ELEVATION,    /* height above the best-fit sphere (um, + toward the
                            observer); the sphere's radius in *aux */
    CN_MAP_AXIAL,        /* axial (sagittal) curvature, D (n 1.3375) */
    CN_MAP_TANGENTIAL    /* tangential (meridional) curvature, D */
};

/* The surface from the data (cn_zern.c): Zernike polynomials (unnormalised,
 * R_n^|m|(rho) cos m theta for m >= 0, sin |m| theta for m < 0, j = 0 piston,
 * ordered n = 0.., m = -n, -n+2 .. n) over the disc of radius rho (the spots' largest
 * distance from the reference's axis) in the eye frame of a reference sphere fit,
 * fitted to the slopes the spots give (deflectometry), the radial order the lowest
 * BIC's, for the departure from a base sphere (z below; mm, into the eye, as cn_sag). */
#define CN_ZORDER 26
#define CN_ZTERMS 378                  /* (CN_ZORDER + 1)(CN_ZORDER + 2) / 2 */
#define CN_ZPTS 10000
typedef struct cn_zfit {
    cn_params ref;                 /* the reference fit's parameters: the eye frame */
    int order, nterms;             /* chosen radial order; terms incl. piston */
    double rho;                    /* the data's disc (mm) */
    double c[CN_ZTERMS];           /* coefficients (mm) */
    double cov[CN_ZTERMS * CN_ZTERMS];   /* their covariance (row, col j; piston 0) */
    double bic[CN_ZORDER + 1];     /* BIC of each order tried (0: not tried) */
    double chi2_dof;               /* of the chosen order's slope fit */
    double det_chi2;               /* the spots' chi^2 on the detector for the surface */
    int nused, npts;
    double gap;                    /* a map point within gap (mm) of a spot is data */
    double xy[2 * CN_ZPTS];        /* where the spots met the surface (eye frame) */
    double sl[2 * CN_ZPTS];        /* the slopes each spot gives there (fx, fy) */
    double wt[CN_ZPTS];            /* their weight, 1 / sigma_slope^2 */
    double zsl[2 * CN_ZPTS];       /* the Zernike surface's own slopes there: the
                                      trend the local curvature fits take out */
    double kr;                     /* the curvatures' local fit: kernel radius (mm) */
    double l0x, l0y;               /* the local fit's slope at the origin (vertex) */
    double R0;                     /* the base sphere (the reference's radius, mm): z =
                                      R0 - sqrt(R0^2 - r^2) + sum c_j Z_j */
    double g0x, g0y;               /* the slope at the frame's origin: curvatures are
                                      taken about the normal there (the vertex) */
    int iterations;                /* Levenberg-Marquardt steps of the joint fit of
                                      heights and slopes to the detector (cn_recon.c) */
} cn_zfit;

/* Keratoconus indices from the reconstructed surface (cn_kc.c), each with its sd
 * from the coefficients' covariance (Monte Carlo, 16 draws).  Axial (sagittal) power
 * 337.5 kappa_axial D (n 1.3375); +y superior, so inferior is -y.  Definitions and
 * thresholds: doc/topography.md (Rabinowitz-McDonnell, Rabinowitz-Rasheed). */
enum { CN_KC_NORMAL, CN_KC_SUSPECT, CN_KC_KERATOCONUS };
typedef struct cn_kc {
    double zone_r;                 /* the data's radius (mm) */
    double kmax, sd_kmax, kmax_x, kmax_y, sd_kmax_loc;   /* steepest axial power and
                                      where (within 0.9 zone_r; x, y about the rig's
                                      nominal apex: the instrument's axis) */
    double ck, sd_ck;              /* central K: mean axial power on the rings of 2, 3
                                      and 4 mm diameter the data cover */
    int ck_rings;                  /* of those 3 rings, how many were covered */
    double is, sd_is, is_r;        /* I-S: inferior - superior mean of 5 points each,
                                      30 deg apart, at radius is_r (3 mm when the data
                                      reach it, else 0.9 zone_r) */
    double simk1, simk2, sd_simk, simk_axis;   /* the 3 mm ring: K1, K2 (D), steep
                                      axis deg */
    double ast, sd_ast;            /* K2 - K1 */
    double srax, sd_srax;          /* skew of the steepest radial axes (deg) */
    double kisa, sd_kisa;          /* K x I-S x AST x SRAX x 100 / 300 (%) */
    int screen;                    /* CN_KC_*: the worst of the thresholds */
    char why[512];
} cn_kc;

enum cn_zmap_kind { CN_ZMAP_ELEVATION, CN_ZMAP_AXIAL, CN_ZMAP_TANGENTIAL };

typedef struct cornea_api {
    int abi;
    const char *(*version)(void);
    const char *(*param_name)(int param);          /* "R" "C0" ... NULL past the end */
    /* Detector plane of a rig geometry (normal along nominal apex -> detector). */
    void (*plane)(const rg_geometry *g, cn_plane *pl);
    /* Model (true) cornea parameters from an rg_cornea placed by eye_pose(rx, ry, 0)
     * relative to nominal apex `apex0`; and back (biconic or conic). */
    void (*params_from_cornea)(const rg_cornea *c, const double apex0[3], double rx,
                               double ry, cn_params *p);
    /* And back: the rg_cornea (zone 0) of parameters, for the rig and the tracer. */
    void (*cornea_from_params)(const rig_api *rg, int model, const cn_params *p,
                               const double apex0[3], rg_cornea *c);
    /* The analytic forward model: the ray off the cornea of p onto the plane.
     * 0 (u, v filled; spot/normal optional) or CN_EFIT (misses the cornea). */
    int (*forward)(int model, const cn_params *p, const double apex0[3],
                   const cn_plane *pl, const cn_ray *r, double *u, double *v,
                   double spot[3], double normal[3]);
    /* The incoming ray of a commanded pose, through rig_api.forward. */
    int (*ray_of_pose)(const rig_api *rg, const rg_geometry *g, const rg_pose *pose,
                       cn_ray *r, char *err, size_t errcap);
    /* Simulate a scan: targets on the rig's nominal cornea (g->cornea), solved and
     * (optionally) quantised by the rig, traced by rig_api.forward through the TRUE
     * cornea `truth` (placed), detector hits on the plane of g plus noise.  spots[]
     * holds cap entries; returns the number written (>= 0) or CN_E*. */
    int (*simulate)(const rig_api *rg, const rg_geometry *g, const rg_cornea *truth,
                    const cn_scan_opts *o, cn_spot *spots, int cap, char *err,
                    size_t errcap);
    /* Fit.  start: initial parameters (NULL: the nominal cornea of g, pose 0). */
    int (*fit)(const rg_geometry *g, cn_spot *spots, int n, const cn_params *start,
               const cn_fit_opts *o, cn_result *res, char *err, size_t errcap);
    /* Predicted accuracy of the scan's rays at parameters p for centroid sigma
     * (each spot's own sigma when sigma <= 0). */
    int (*predict)(const rg_geometry *g, const cn_spot *spots, int n, int model,
                   int fix_tilt, const cn_params *p, double sigma, cn_predict *pr,
                   char *err, size_t errcap);
    /* Plain-text report of a result into buf; returns buf. */
    const char *(*report)(const cn_result *r, char *buf, size_t cap);
    /* --- ABI 2 --- */
    /* Re-image a planned scan through a truth of `model` and p plus an optional
     * bump (NULL: none), by the analytic model (equal to rig_api.forward to 1e-12
     * mm): each spot's (u, v) from its ray, plus Gaussian noise sigma (mm) from
     * seed (drawn for every spot, as simulate).  Status CN_S_NONE where the beam
     * misses.  Returns the number of spots on the detector. */
    int (*reimage)(const rg_geometry *g, int model, const cn_params *p,
                   const cn_bump *bump, double sigma, unsigned long long seed,
                   cn_spot *spots, int n);
    /* A map (enum cn_map_kind) of model and p (bump: NULL, or the truth's) into
     * grid[n * n]; aux: the best-fit sphere's radius (elevation).  CN_OK or
     * CN_EINVAL. */
    int (*map)(int kind, int model, const cn_params *p, const cn_bump *bump,
               double hmax, int n, double *grid, double *aux);
    /* Where each fitted spot met the fitted surface, in its eye frame (x, y mm):
     * spot i -> xy[2i], xy[2i+1] (NaN when it missed). */
    void (*spot_xy)(const rg_geometry *g, const cn_result *r, const cn_spot *spots,
                    int n, double *xy);
    /* The report as CSV (one `quantity,value,sd,unit` row per number; documented in
     * README "Cornea measurement") or as one JSON object; returns bytes written
     * (snprintf's rule: >= cap means truncated). */
    size_t (*report_csv)(const cn_result *r, const cn_spot *spots, int n, char *buf,
                         size_t cap);
    size_t (*report_json)(const cn_result *r, const cn_spot *spots, int n, char *buf,
                          size_t cap);
    /* --- ABI 3 --- */
    /* The surface from the spots' slopes (statuses OK and OUTLIER used: an outlier
     * of a global model is data here) in the frame of `ref`, a fit of ref_model
     * (where each beam first meets the cornea; its mean R is the base sphere);
     * max_order 0: CN_ZORDER.  z: caller's (large: allocate it). */
    int (*zfit)(const rg_geometry *g, const cn_spot *spots, int n, const cn_params *ref,
                int ref_model, int max_order, cn_zfit *z, char *err, size_t errcap);
    /* Its sag and slopes; axial and tangential curvature (1/mm) at (x, y) mm. */
    int (*zsag)(const cn_zfit *z, double x, double y, double *f, double *fx, double *fy);
    int (*zcurv)(const cn_zfit *z, double x, double y, double *axial, double *tang);
    /* 1 when (x, y) lies within the data (a spot within z->gap), else 0. */
    int (*zcovered)(const cn_zfit *z, double x, double y);
    /* A map (enum cn_zmap_kind) on n x n over [-hmax, hmax]^2 as cornea_api.map
     * (row 0 at +y), NaN where there are no data; elevation against the surface's
     * best-fit sphere (um, radius in *aux), curvatures in D (n 1.3375). */
    int (*zmap)(int kind, const cn_zfit *z, double hmax, int n, double *grid, double *aux);
    /* The keratoconus indices and screen. */
    int (*kc)(const cn_zfit *z, cn_kc *k);
    /* The same indices of an analytic surface (model, p, bump; the truth in tests and
     * benchmarks), without sd, in the eye frame of p. */
    int (*kc_model)(int model, const cn_params *p, const cn_bump *bump, double zone_r,
                    cn_kc *k);
    /* ... in a given frame (a pose; the measurement's is its reconstruction's z->ref:
     * the reference model's eye frame when that fits, else the instrument's axes):
     * the surface met along the frame's z lines, axial power about its normal at the
     * frame's origin, x, y as cn_kc_of reports them.  kc_model is this with frame p. */
    int (*kc_model_in)(int model, const cn_params *p, const cn_bump *bump,
                       const cn_params *frame, double zone_r, cn_kc *k);
} cornea_api;

typedef const cornea_api *(*cornea_get_api_fn)(int abi);
const cornea_api *cornea_get_api(int abi);

#endif
