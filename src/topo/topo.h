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

typedef struct tp_shot { double s11, s12, s22, s1y, s2y; int n; } tp_shot;   /* photon
                                   transfer: the normal equations' sums */

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
} topo_api;

#define TOPO_ABI 1
#define TOPO_API_SYMBOL "topo_get_api"
typedef const topo_api *(*topo_get_api_fn)(int abi);
const topo_api *topo_get_api(int abi);
#endif
