/* tp_int.h -- the topography pipeline's internal declarations (one file per job:
 * tp_pattern.c, tp_loop.c; the table in tp_api.c). */
#ifndef TP_INT_H
#define TP_INT_H
#include "topo.h"

int tp_pattern(int pattern, int n, double zone, rg_target *t);
int tp_measure(tp_run *r, char *err, size_t cap);
void tp_counts(const tp_run *r, int counts[6]);

/* tp_shot.c: photon transfer over the located spots of a scan (sums a, b over n) */
struct im_frame;
void tp_shot_add(tp_shot *sh, const struct im_frame *f, double x, double y, double amp,
                 double w, double bg, double noise);
double tp_shot_gain(const tp_shot *sh);         /* e-/count; INFINITY: none; NaN: too few */
double tp_shot_gain_se(const tp_shot *sh);      /* its standard error (NaN: none) */
double tp_shot_factor(double amp, double w, double noise, double gain);

/* tp_adapt.c: the clinical zone (issue 19 item 4) */
int tp_measure_zone(tp_run *r, char *err, size_t cap);
int tp_outside_hit(const tp_run *r, const cn_plane *pl, tp_point *q, double hit[3]);
int tp_off_sensor(const tp_run *r, tp_point *q);
/* tp_cover.c: the data's coverage per zone */
void tp_cover_zones(const tp_run *r, tp_cover *c);
/* tp_iso.c: the ISO 19980 report */
int tp_iso_report(const tp_run *r, tp_sag_fn sag, void *ctx, const rg_cornea *place,
                  tp_iso *out);
int tp_truth_sag(void *ctx, double x, double y, double *z);
/* tp_order.c: the scan on the machine in the planner's order, stop and go or on the
 * fly; after(r, k, ...) once per exposure of point k, in scan order (0 or an error) */
typedef int (*tp_exposed_fn)(tp_run *r, int k, void *ctx, char *err, size_t cap);
int tp_scan_machine(tp_run *r, tp_exposed_fn after, void *ctx, char *err, size_t cap);
double tp_blur_tol(const tp_run *r);

/* tp_drift.c: the true eye of point q under the simulated drift (its apex moved by
 * the drift at q->t); and the drift test on the fitted spots (r->drift) */
void tp_drift_eye(const tp_run *r, const tp_point *q, rg_geometry *gt, cn_params *tp);
int tp_drift_test(tp_run *r);
#endif
