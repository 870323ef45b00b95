/* cornea_loop.h -- the measurement loop of --cornea-scan (cornea_loop.c): a scan
 * pattern planned by the rig engine, run on the machine (simulated chip) or only
 * planned, each exposure's spot traced through the true eye by the trace engine, made
 * into a full synthetic detector frame by the imaging engine and located by its
 * centroid fit (or, the quick model, the traced hit plus Gaussian noise), then the
 * cornea engine's fit and the check of its analytic model against the tracer.  The
 * engines never see each other: this file hands each one's results to the next. */
#ifndef LM_CORNEA_LOOP_H
#define LM_CORNEA_LOOP_H
#include <stddef.h>
#include <stdint.h>
#include "../rig/rig.h"
#include "../cornea/cornea.h"

struct trace_api;
struct imaging_api;

enum { CL_SPIRAL, CL_RINGS, CL_GRID };          /* scan patterns */
enum { CL_SRC_FRAMES, CL_SRC_MODEL, CL_SRC_CAMERA };   /* where the spots come from:
                                   synthetic frames, the traced hit plus noise, or
                                   frames read from a camera, video or files */

/* The detector frames (the imaging benchmark's spot and noise by default). */
typedef struct cl_camera {
    int width, height;          /* pixels */
    double pitch;               /* mm */
    double spot_w;              /* the spot's 1/e^2 radius, pixels (3) */
    double peak;                /* its peak above the background, counts (1000) */
    double bias;                /* background level, counts (100) */
    double read_noise;          /* counts rms (50) */
} cl_camera;

typedef struct cl_point {
    rg_target t;
    int planned;                /* 1: solved and quantised (else why[] says) */
    rg_pose pose;               /* commanded; after a machine scan: where the motors
                                   stood during the exposure */
    cn_spot spot;               /* the measurement (status CN_S_*) */
    double hit_u, hit_v;        /* the traced hit (mm, detector plane; NAN: none) */
    double x, y, snr;           /* frame: centroid (pixels) and SNR */
    int nspots;                 /* frame: spots detected */
    int seq;                    /* frame number (1, 2, ...: the planned points in scan
                                   order; 0: none) */
    char why[96];               /* why the point gave no spot */
    int measured;               /* 1: its spot was made (traced, framed, located) */
    int saved;                  /* 1: its frame was written (r->save) */
} cl_point;

typedef struct cl_times {       /* seconds of wall clock, per part */
    double plan, machine, trace, frames, fit, check, total;
    double cpu;                 /* the process's CPU seconds over the whole loop */
} cl_times;

typedef struct cl_run {
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
    int source;                 /* CL_SRC_* */
    double sigma;               /* model: centroid noise (mm) */
    cl_camera cam;
    const char *camera;         /* CL_SRC_CAMERA: the source (imaging.h source_open) */
    const char *save;           /* CL_SRC_FRAMES: write frame N to this %d pattern
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
    double check_tol;           /* mm: largest tracer/model difference accepted */
    /* results */
    cl_point *pt;               /* npoints */
    int nplanned, nexposed;
    cn_result res;
    int fitted;                 /* 1: res holds a fit */
    double check_max;           /* mm, largest |traced - model| over the fitted spots */
    int check_n;                /* spots traced in the check */
    cl_times tm;
    const char *phase;          /* the part of the loop running (or where it stopped):
                                   "planning", "the scan on the machine", ... */
} cl_run;

/* Scan pattern: n targets (theta, phi) within zone; returns the count written. */
int cl_pattern(int pattern, int n, double zone, rg_target *t);
/* The whole loop.  0; CN_ESTOP when stopped; CN_EFIT (fit failed, err) or CN_EINVAL
 * (bad setup, a machine error: err).  The final check failing is not an error here:
 * the caller compares check_max with check_tol. */
int cl_measure(cl_run *r, char *err, size_t cap);
/* Counts of the points by status (OK, NONE, SEVERAL, OUTLIER, MISS) and unplanned. */
void cl_counts(const cl_run *r, int counts[6]);
#endif
