/* rg_geom.h -- inside the rig module: what the geometry files (rg_cornea.c,
 * rg_gimbal.c, rg_forward.c, rg_solve.c, rg_quant.c, rg_verify.c, rg_geomdef.c) share.
 * The public face is rig.h; nothing here is exported. */
#ifndef RG_GEOM_H
#define RG_GEOM_H
#include <stddef.h>
#include "rig/rg_int.h"

/* ---- rg_cornea.c: the surface in the eye frame, and placed in the rig ---- */
/* Sag z = f(x, y) and its slopes in the eye frame: 0, or -1 outside the surface's
 * domain (past the conic's edge or where its slope is infinite). */
RG_HIDDEN int rg_sag(const rg_cornea *c, double x, double y, double *z, double *fx,
                     double *fy);
/* Outward unit normal at an eye-frame point of the surface. */
RG_HIDDEN void rg_normal_eye(const rg_cornea *c, const double p[3], double n[3]);
/* First hit of the rig-frame ray o + t d (d unit, t > tmin) with the cornea: 0 with
 * the point and outward normal (rig frame) and t, or -1 (miss). */
RG_HIDDEN int rg_cornea_hit(const rg_cornea *c, const double o[3], const double d[3],
                            double q[3], double n[3], double *t);
/* Height of a rig-frame point from the eye's axis. */
RG_HIDDEN double rg_cornea_height(const rg_cornea *c, const double p[3]);
RG_HIDDEN int rg_cornea_point(const rg_cornea *c, const rg_target *t, double p[3],
                              double n[3], char *err, size_t errcap);
/* rig_api.cornea_curvature: the second fundamental form on two tangent vectors. */
RG_HIDDEN int rg_cornea_curvature(const rg_cornea *c, const double p[3], const double e1[3],
                                  const double e2[3], double K[3]);
RG_HIDDEN void rg_eye_pose(rg_cornea *c, double rx, double ry, double rz,
                           const double at[3]);

/* ---- rg_gimbal.c ---- */
RG_HIDDEN void rg_gimbal_normal(const rg_gimbal *m, double a, double b, double n[3]);
RG_HIDDEN int rg_gimbal_angles(const rg_gimbal *m, const double n[3], double *a,
                               double *b);

/* ---- rg_forward.c ---- */
/* The beam through the two mirrors only: hit points, directions and the diagnostics
 * of the mirrors (miss, grazing).  0 or -1 (beam lost: b->diag says where). */
RG_HIDDEN int rg_mirrors(const rg_geometry *g, const rg_pose *p, rg_beam *b);
/* The same with ap 0: mirrors unbounded (the model's equations past the rims). */
RG_HIDDEN int rg_mirrors_ap(const rg_geometry *g, const rg_pose *p, rg_beam *b, int ap);
/* The same with the mirrors' normals given (NULL: from the pose): derivatives move one
 * joint, so the other mirror's normal need not be turned again. */
RG_HIDDEN int rg_mirrors_nn(const rg_geometry *g, const rg_pose *p, rg_beam *b, int ap,
                            double n1[3], double n2[3]);
/* The whole path, plus blocking tests: 0 or -1. */
RG_HIDDEN int rg_forward_beam(const rg_geometry *g, const rg_pose *p, rg_beam *b);
/* The same; checks 0: no blocking or travel tests (derivatives, landing errors). */
RG_HIDDEN int rg_forward_path(const rg_geometry *g, const rg_pose *p, rg_beam *b,
                              int checks);
RG_HIDDEN int rg_forward_nn(const rg_geometry *g, const rg_pose *p, rg_beam *b,
                            int checks, double n1[3], double n2[3]);
RG_HIDDEN int rg_forward(const rg_geometry *g, const rg_pose *p, rg_beam *b, char *err,
                         size_t errcap);
/* m2's gimbal centre for a stage position. */
RG_HIDDEN void rg_m2_center(const rg_geometry *g, double u, double v, double c[3]);
/* Unit normal of the detector plane (from the eye's apex toward the detector). */
RG_HIDDEN void rg_detector_normal(const rg_geometry *g, double w[3]);
/* Does the segment a-b pass through the mirror's body (disc + mount cylinder)? */
RG_HIDDEN int rg_blocks(const rg_gimbal *m, const double c[3], const double n[3],
                        const double a[3], const double b[3]);
RG_HIDDEN unsigned rg_travel_check(const rg_geometry *g, const rg_pose *p);

/* ---- rg_aim.c: the construction repeated for mirror offsets (passes or -1) ---- */
RG_HIDDEN int rg_aim_full(const rg_geometry *g, const double P[3], const double back[3],
                          double n1[3], double n2[3], double c2[3]);
RG_HIDDEN int rg_aim_stage(const rg_geometry *g, const double P[3], const double back[3],
                           const double c2[3], double n1[3], double n2[3]);
RG_HIDDEN int rg_aim_m1_beam(const rg_geometry *g, const double n1[3], double h1[3],
                             double d1[3]);
RG_HIDDEN int rg_aim_m2(const rg_geometry *g, const double P[3], const double h1[3],
                        const double d1[3], const double c2[3], double n2[3]);

/* ---- rg_solve.c ---- */
RG_HIDDEN void rg_opts_fill(const rg_solve_opts *in, rg_solve_opts *o);
RG_HIDDEN int rg_solve(const rg_geometry *g, const rg_target *t,
                       const rg_solve_opts *opts, rg_solution *s, char *err,
                       size_t errcap);
RG_HIDDEN int rg_jacobian(const rg_geometry *g, const rg_pose *p, double *J,
                          double *cond, char *err, size_t errcap);
/* Newton on the exact model: move the joints flagged in `free` (bit k: joint k) so
 * that the beam leaving m2 runs along the line through `target` with direction
 * `dir` (4 equations) and, with 6 free joints, lands on m2's centre (2 more); with 2
 * free joints only the target is hit (2 equations).  Returns the iterations
 * (>= 0) or -1 (no convergence); *res: the largest residual (mm). */
RG_HIDDEN int rg_newton(const rg_geometry *g, rg_pose *p, unsigned free,
                        const double target[3], const double dir[3], double tol,
                        int max_iter, double *res);
RG_HIDDEN const char *rg_diag_text(unsigned diag, char *buf, size_t cap);

/* ---- rg_quant.c ---- */
RG_HIDDEN int rg_quantise(const rg_geometry *g, const rg_target *t,
                          const rg_solution *s, rg_quantised *q, char *err,
                          size_t errcap);

/* ---- rg_verify.c ---- */
RG_HIDDEN int rg_verify_pose(const struct trace_api *tr, const rg_geometry *g,
                        const rg_pose *p, const double target[3], rg_verify *v,
                        char *err, size_t errcap);

/* ---- rg_geomdef.c ---- */
RG_HIDDEN void rg_geometry_default(rg_geometry *g);
RG_HIDDEN int rg_geometry_key(rg_geometry *g, int argc, const char *const *argv,
                              char *err, size_t errcap);
RG_HIDDEN int rg_geometry_check(rg_geometry *g, char *err, size_t errcap);
RG_HIDDEN const char *rg_joint_name(int joint);

#define RG_PI 3.14159265358979323846
#endif
