/* topo.h -- public face of the topography pipeline (issue 19): one corneal
 * measurement end to end.  A scan pattern planned by the rig engine, run on the
 * machine (simulated chip) or only planned, each exposure's spot traced through the
 * true eye by the trace engine, made into a full synthetic detector frame by the
 * imaging engine and located by its centroid fit (or, the quick model, the traced hit
 * plus Gaussian noise), then the cornea engine's fit and the check of its analytic
 * model against the tracer.  The engines never see each other: the pipeline hands
 * each one's results to the next, through the API tables the caller puts in tp_run.
 * It serves --cornea-scan (src/dialogue/cornea_scan.c asks and prints), the study
 * script (through --cornea-scan) and the tests.  Lives in build/lib/lensmat-topo.so:
 *     topo_get_api_fn get = (topo_get_api_fn)lm_engine_symbol("topo", TOPO_API_SYMBOL);
 *     const topo_api *tp = get ? get(TOPO_ABI) : NULL;
 * It never prints and never exits; mm and radians. */
#ifndef TOPO_H
#define TOPO_H
#include <stddef.h>
#include <stdint.h>
#include "rig/rig.h"
#include "cornea/cornea.h"

struct trace_api;
struct imaging_api;

enum { TP_SPIRAL, TP_RINGS, TP_GRID };          /* scan patterns */
enum { TP_SRC_FRAMES, TP_SRC_MODEL, TP_SRC_CAMERA };   /* where the spots come from:
                                   synthetic frames, the traced hit plus noise, or
                                   frames read from a camera, video or files */

/* The detector frames (the imaging benchmark's spot and noise by default). */
typedef struct tp_camera {
    int width, height;          /* pixels */
    double pitch;               /* mm */
    double spot_w;              /* the spot's 1/e^2 radius, pixels (3) */
    double peak;                /* its peak above the background, counts (1000) */
    double bias;                /* background level, counts (100) */
    double read_noise;          /* counts rms (50) */
} tp_camera;

typedef struct tp_shot { double s11, s12, s22, s1y, s2y; int n;
                         double q[5]; } tp_shot;   /* photon transfer: the normal
                                   equations' sums and the 4th moments of the
                                   regressors (the estimate's error) */

typedef struct tp_point {
    rg_target t;
    int planned;                /* 1: solved and quantised (else why[] says) */
    rg_pose pose;               /* commanded; after a machine scan: where the motors
                                   stood during the exposure */
    cn_spot spot;               /* the measurement (status CN_S_*) */
    double hit_u, hit_v;        /* the traced hit (mm, detector plane; NAN: none) */
    double x, y, snr;           /* frame: centroid (pixels) and SNR */
    double amp, w, bg, noise;   /* frame: the spot's fitted peak, 1/e^2 radius and
                                   background (counts, pixels), the frame's noise */
    int nspots;                 /* frame: spots detected */
    int seq;                    /* frame number (1, 2, ...: the planned points in scan
                                   order; 0: none) */
    char why[96];               /* why the point gave no spot */
    int measured;               /* 1: its spot was made (traced, framed, located) */
    int saved;                  /* 1: its frame was written (r->save) */
    /* the scan on the machine (tp_order.c): when it was exposed and how it moved */
    double t_s;                 /* the exposure's middle on the machine's clock, s from
                                   the scan's first move (NaN: not exposed) */
    rg_pose path[8];            /* the poses the motors held at evenly spaced control
                                   steps of the exposure (on the fly: the smear) */
    int npath;                  /* poses in path (1 at rest, 0: not exposed) */
    double blur_det, blur_cornea;   /* the smear's extent on the detector plane and on
                                   the cornea, nominal eye (mm): the counted steps'
                                   poses and the smooth path's over the exposure */
} tp_point;

/* The clinical zone (issue 19 item 4): the adaptive passes and the coverage of the
 * final one by zone, diameters 0-3, 3-6, 6-9 and 9-10 mm about the reference's axis. */
#define TP_MAXPASS 4
#define TP_NZONE 4
typedef struct tp_pass {
    double zone_h;              /* mm, the targets' largest height */
    int npoints, nplanned, nok; /* targets; planned; spots located */
    double R, Km, cyl;          /* its fit (mm, D; NaN: none; the final pass: NaN) */
    int used;                   /* 1: the next pass was planned on that fit (else on
                                   the plan before) */
} tp_pass;
typedef struct tp_cover {
    int valid;                  /* 1: computed (a surface from the data) */
    double frac[TP_NZONE];      /* fraction of each zone's area within the data */
    int nspots[TP_NZONE];       /* spots fitted in each zone */
    double zone_mm;             /* the largest diameter whose every ring (0.1 mm steps)
                                   is >= 95 % within the data */
} tp_cover;
extern const double tp_zone_edges[TP_NZONE + 1];   /* 0 3 6 9 10 mm diameter */

/* The ISO 19980 report of a test surface (tp_iso.c, issue 19 item 5): the measured
 * surface against the true one on a 0.1 mm grid, the points within the data, area
 * weighted, per zone 0-3, 3-6, 6-9 mm diameter and the central 6 mm: the mean and
 * twice the SD of the height difference (um, measured - true, toward the observer,
 * both from their vertex) and of the axial power difference (D, n 1.3375, both about
 * the measured surface's axis). */
#define TP_ISO_NZONE 4          /* 0-3, 3-6, 6-9, 0-6 */
typedef struct tp_iso_zone {
    int n;                      /* grid points within the data (0: none: NaN below) */
    double frac;                /* of the zone's area */
    double mean_um, sd2_um, mean_D, sd2_D;
} tp_iso_zone;
typedef struct tp_iso { tp_iso_zone z[TP_ISO_NZONE]; } tp_iso;
/* The true surface for the report: its sag z(x, y) in its own eye frame (mm, into the
 * eye; 0, or -1 off the surface), placed in the rig by place->rot and place->trans. */
typedef int (*tp_sag_fn)(void *ctx, double x, double y, double *z);
/* The scan on the machine (tp_order.c, doc/scan-time.md). */
typedef struct tp_scan {
    int on_fly;                 /* 1: exposed on the fly (rig_api.sweep); 0: stop and go */
    int reordered;              /* 1: the planner's order; 0: the pattern's own */
    double sim_s;               /* the machine's clock from the first move to the last
                                   exposure's end (s) */
    double pred_s, pred_own_s;  /* predicted: the order run; the pattern's own order */
    char limit[320];            /* what limits the time, in words */
    double blur_det_max, blur_cornea_max;   /* the largest smear of an exposure (mm) */
    double blur_tol;            /* the smear the centroid tolerates (mm, detector) */
    int blur_over;              /* exposures over it (their spots rejected) */
    double step_det_max;        /* on the fly: the largest distance on the detector
                                   between the beam of the motors' counted steps and
                                   of the smooth path at the pulse (mm): what a shaft
                                   that lags its step count moves the spot */
} tp_scan;

/* Fixation drift (tp_drift.c): the true eye moved during the scan (simulation), and
 * its detection from the fitted spots: the model refitted with the eye's translation
 * per time segment, the translations tested against one fixed pose. */
enum { TP_DRIFT_NONE, TP_DRIFT_LINEAR, TP_DRIFT_SACCADE };
#define TP_DRIFT_SEGMENTS 32
typedef struct tp_drift {
    int kind;                   /* TP_DRIFT_*: slow (linear over the scan) or a saccade
                                   (a jump at the scan's middle) */
    double amp;                 /* the apex's total lateral displacement (mm) */
    double dir;                 /* its direction in the rig's x-y plane (rad from x) */
    /* detection (after the fit) */
    int segments;               /* time segments used (0: not tested) */
    double d[TP_DRIFT_SEGMENTS][3];     /* each segment's eye translation (mm) */
    double sd[TP_DRIFT_SEGMENTS][3];    /* and its standard deviation */
    double t0[TP_DRIFT_SEGMENTS], t1[TP_DRIFT_SEGMENTS];  /* the segment's times (s) */
    double chi2;                /* of the segments against one pose */
    int dof;
    double p;                   /* its probability */
    double range;               /* the largest lateral distance between segments (mm) */
    int flagged;                /* 1: the eye moved (p < 0.001, range over 2 um, and
                                   a pose per segment explains the misfit: the joint
                                   fit's chi2/dof under TP_DRIFT_CHI2_MAX or under a
                                   twentieth of the one-pose fit's) */
    double joint_chi2_dof;      /* the joint fit's (a pose per segment) */
    double single_chi2_dof;     /* the model's own fit's (one pose) */
    int joint_fitted;           /* 1: joint holds the model refitted with a pose per
                                   segment (the drift corrected) */
    cn_result joint;
} tp_drift;
#define TP_DRIFT_CHI2_MAX 2.0

typedef struct tp_times {       /* seconds of wall clock, per part */
    double plan, machine, trace, frames, fit, check, total;
    double cpu;                 /* the process's CPU seconds over the whole loop */
} tp_times;

typedef struct tp_run {
    /* engines (the imaging engine only for frames; the tracer may be NULL: then the
       rig's forward model gives the hit and the final check is not made) */
    const rig_api *rg;
    const cornea_api *cn;
    const struct trace_api *tr;
    const struct imaging_api *im;
    const rg_geometry *g;       /* the rig's nominal geometry (planning) */
    rg_cornea truth;            /* the synthetic eye, placed */
    /* scan */
    int pattern, npoints;
    double zone;                /* largest theta (rad) */
    int source;                 /* TP_SRC_* */
    double sigma;               /* model: centroid noise (mm) */
    tp_camera cam;
    const char *camera;         /* TP_SRC_CAMERA: the source (imaging.h source_open) */
    const char *save;           /* TP_SRC_FRAMES: write frame N to this %d pattern
                                   (NULL: not saved) */
    int have_truth;             /* 0: a real eye (camera): nothing to trace */
    const cn_bump *bump;        /* a keratoconus-like cone on the true eye (NULL:
                                   none): the tracer has no such surface, so each
                                   spot's hit comes from the cornea engine's analytic
                                   model of the true eye with it (cornea_api.reimage) */
    cn_params truth_p;          /* with bump: the true eye as a biconic's parameters */
    uint64_t seed;
    int threads;                /* workers for the per-point work (>= 1) */
    /* machine (NULL: planned only) and its rig file (step sizes) */
    rg_machine *m;
    const rg_rig *rig;
    double expose_ms;
    int (*stop)(void *ctx);
    void *stop_ctx;
    /* fit */
    int model;
    int max_iter;               /* per solve (0: the engine's 1000) */
    double check_tol;           /* mm: largest tracer/model difference accepted */
    /* results */
    tp_point *pt;               /* npoints */
    int nplanned, nexposed;
    cn_result res;
    int fitted;                 /* 1: res holds a fit */
    double check_max;           /* mm, largest |traced - model| over the fitted spots */
    int check_n;                /* spots traced in the check */
    /* camera frames: their gain measured from the spots (photon transfer, tp_shot.c)
       and the centroid sigmas widened for the shot noise it implies */
    tp_shot shot;
    /* the surface from the data (when zf is set: the caller's, large): a reference
       sphere, the Zernike slope fit, the keratoconus indices */
    cn_zfit *zf;
    int have_z;                 /* 1: zf and kc hold a surface (else zwhy says why) */
    char zwhy[256];
    double zref_R;              /* the reference sphere's radius (mm) */
    cn_kc kc;
    double gain;                /* e-/count (NaN: not measured; INFINITY: no shot
                                   noise seen) */
    double shot_factor;         /* mean factor applied to the centroid sigmas (1) */
    tp_times tm;
    rg_dose dose;               /* the scan's dose at the cornea against the MPE, checked
                                   before the first pulse (have_dose: on a machine) */
    int have_dose;
    const char *phase;          /* the part of the loop running (or where it stopped):
                                   "planning", "the scan on the machine", ... */
    /* --- the clinical zone (tp_adapt.c, tp_cover.c; issue 19 item 4) --- */
    double zone_h;              /* > 0: targets by height (mm from the axis) out to
                                   zone_h on the planning cornea; zone is then unused */
    const rg_geometry *plan_g;  /* the geometry poses are planned on (NULL: g) */
    int (*hit)(void *ctx, const cn_ray *ray, double *u, double *v);   /* an outside
                                   forward model of the eye (tests): the detector hit
                                   of the beam, 0, or -1 when it misses (NULL: traced) */
    void *hit_ctx;
    const cn_params *fit_start; /* the fit's start (NULL: the nominal cornea, pose 0) */
    int sensor_cut;             /* 1: the quick model loses the spots whose traced hit
                                   lands off the camera's sensor, as frames do */
    int npass;                  /* measure_zone: the passes made, the last the scan */
    tp_pass pass[TP_MAXPASS];
    rg_geometry zone_g;         /* measure_zone: the last pass's planning geometry */
    tp_cover cover;             /* measure_zone: the data's coverage per zone */
    tp_scan sc;                 /* the scan's order, machine time and smear (tp_order.c) */
    tp_drift drift;             /* fixation drift: simulated and detected (tp_drift.c) */
} tp_run;


typedef struct topo_api {
    int abi;
    const char *(*version)(void);
    /* Scan pattern (TP_SPIRAL ...): n targets (theta, phi) within zone; returns the
     * count written. */
    int (*pattern)(int pattern, int n, double zone, rg_target *t);
    /* The whole measurement.  0; CN_ESTOP when stopped; CN_EFIT (fit failed, err) or
     * CN_EINVAL (bad setup, a machine error: err).  The final check failing is not
     * an error here: the caller compares check_max with check_tol. */
    int (*measure)(tp_run *r, char *err, size_t cap);
    /* Counts of the points by status (OK, NONE, SEVERAL, OUTLIER, MISS) and
     * unplanned. */
    void (*counts)(const tp_run *r, int counts[6]);
    /* --- the clinical zone and the ISO 19980 report (issue 19 items 4, 5) --- */
    /* The measurement planned adaptively (tp_adapt.c): coarse passes (1.2 mm, then
     * 3 mm from the axis, npoints / 6 each, planned on the nominal cornea, then on
     * each pass's biconic fit), then the scan of npoints out to zone_h planned on the
     * last fit, and its coverage per zone (r->cover, with r->zf).  As measure. */
    int (*measure_zone)(tp_run *r, char *err, size_t cap);
    /* The ISO 19980 statistics of r's surface from the data (r->have_z) against the
     * true surface sag (in the frame of place); 0 or -1 (no surface). */
    int (*iso)(const tp_run *r, tp_sag_fn sag, void *ctx, const rg_cornea *place,
               tp_iso *out);
    /* The true sag of a rig cornea with an optional cone (ctx: a tp_truth). */
    int (*truth_sag)(void *ctx, double x, double y, double *z);
} topo_api;

typedef struct tp_truth { const rig_api *rg; const rg_cornea *c; const cn_bump *bump; } tp_truth;

#define TOPO_ABI 2            /* 2: tp_run grew the zone fields, topo_api measure_zone, iso */
#define TOPO_API_SYMBOL "topo_get_api"
typedef const topo_api *(*topo_get_api_fn)(int abi);
const topo_api *topo_get_api(int abi);
#endif
