/* ds_int.h -- PRIVATE to src/design: the problem (lens, variables, operands,
 * tolerances) and what its files share. */
#ifndef DS_INT_H
#define DS_INT_H
#include <stdint.h>
#include "design.h"
#include "lens/lens.h"
#include "paraxial/paraxial.h"
#include "trace/trace.h"

#define DS_MAXVAR 64
#define DS_MAXOP 256
#define DS_MAXTOL 256
#define DS_MAXRING 32
#define DS_MAXARM 64
#define DS_MAXSURF PX_PUPIL_MAXSURF
#define DS_MAXGRP 64           /* surfaces and elements that tilt and decentre */
#define DS_MAXRX (DS_MAXSURF + 2 * DS_MAXGRP)   /* the rx with a break pair per group */

enum { DV_C, DV_T, DV_K, DV_A, DV_ND, DV_VD };
enum { DO_EFL, DO_BFD, DO_TOTR, DO_RMS, DO_DIST, DO_AXCL, DO_SPHA, DO_CT, DO_ET,
       DO_GMAP, DO_COMA, DO_ASTI, DO_FCUR, DO_SDIS, DO_LACL, DO_RMSW };
enum { DT_R, DT_T, DT_N, DT_K, DT_TILT, DT_DEC };

typedef struct ds_var {
    int kind, surf, term;      /* term: DV_A's asph index (a4: 1) */
    double scale;              /* internal unknown = value / scale */
    long line;
} ds_var;
typedef struct ds_op {
    int kind;
    int bound;                 /* 0 target, 1 min (counts when below), -1 max */
    double target, weight;
    int field, wave, surf;     /* field, wave 0-based (wave -1: every wavelength) */
    double value;              /* last evaluation */
    long line;
} ds_op;
typedef struct ds_tol {
    int kind, surf;
    int axis;                  /* DT_TILT, DT_DEC: 0 x, 1 y */
    int grp;                   /* DT_TILT, DT_DEC: its group (ds_problem.grp) */
    double delta;              /* absolute (tilts in degrees) */
    long line;
} ds_tol;
/* A surface (s0 == s1) or an element (s0..s1) that tilts and decentres as one: when
 * perturbed, ds_setup puts a coordinate break before s0 (decentre, then tilt about x
 * and y, pivoting on s0's vertex) and its inverse after s1 into the rx. */
typedef struct ds_grp { int s0, s1; } ds_grp;

/* One wavelength's trace set-up for one evaluation. */
typedef struct ds_wl {
    double lambda;
    double n[DS_MAXSURF + 1];  /* n[0] object, n[i+1] right of surface i */
    char names[DS_MAXSURF + 1][32];
    px_csurf cs[DS_MAXSURF];   /* first order: the lens unfolded (ln_unfold) */
    px_pupil p;
    int nu, stop_u;            /* the unfolded lens's surfaces and stop */
    /* the last surface's z folded (zl) and unfolded (zl_u), sig -1 when light leaves
     * it going -z (odd mirrors): an unfolded image-space z u is zl + sig (u - zl_u) */
    double zl, zl_u, sig;
    trace_rx rx;               /* real rays: the lens folded, with the break pairs */
    trace_rx_surface surf[DS_MAXRX];
    double s;                  /* primary stop radius / this wavelength's */
    int index;                 /* which of the lens's wavelengths */
} ds_wl;

struct ds_problem {
    ln_lens lens;              /* the lens as it is now */
    ln_lens base;              /* the nominal (tolerancing restores it) */
    const trace_api *tr;
    char src[256];
    int nvar, nop, ntol;
    ds_var var[DS_MAXVAR];
    ds_op op[DS_MAXOP];
    ds_tol tol[DS_MAXTOL];
    double dn[DS_MAXSURF + 1]; /* index offsets (tolerancing), as ds_wl.n */
    int ngrp;
    ds_grp grp[DS_MAXGRP];
    double gp[DS_MAXGRP][4];   /* each group's decentre x, y and tilt x, y (degrees) now */
    int xsym;                  /* ds_setup: the rx is symmetric under x -> -x */
    int rings, arms, method;   /* method 0 lm, 1 lmaccel */
    int aim_paraxial;          /* 1: rays to the paraxial entrance pupil, no aiming */
    ds_tol_opts topt;
    char *merit_lines;         /* the lens file's own merit lines, verbatim */
    size_t merit_len;
    double ru[DS_MAXRING], rw[DS_MAXRING];   /* ring radii^2 and weights (sum 1) */
    double hull[2 * 1024];     /* glass map: convex hull (vd, nd) of the catalogue */
    int nhull;
    int (*stop)(void *ctx);
    void *stop_ctx;
    long evals;
    int stopped;
    /* Warm starts while optimising: each aimed ray's last solution (2 unknowns) and
     * whether it holds one, per field, wavelength and pupil point (+1: the chief
     * ray).  Off for tolerancing, where lens k must not depend on lens k - 1. */
    int warm;
    double *guess;
    unsigned char *gok;
    size_t nguess;
};

/* ds_read.c */
int ds_read(const char *lens_text, size_t lens_len, const char *lens_src,
            const char *merit_text, size_t merit_len, const char *merit_src,
            const trace_api *tr, ds_problem **out, char *err, size_t cap);
void ds_free(ds_problem *p);
/* ds_merit.c: set up the wavelengths of lens l (with p->dn); 0 or -1 (why). */
int ds_setup(ds_problem *p, const ln_lens *l, ds_wl *w, int nwl, char *why, size_t cap);
/* Every operand's value and the residual vector (f: NULL, or room for ds_nres);
 * 0, or -1 when the lens cannot be evaluated (why), 1 when stopped. */
int ds_eval(ds_problem *p, double *f, char *why, size_t cap);
long ds_nres(const ds_problem *p);
double ds_merit_of(const ds_problem *p, const double *f);
/* The rays of field fi at every wavelength (weights sum 1): image points and
 * directions, for the rms criterion; returns the count, -1 on a failed ray. */
int ds_field_rays(ds_problem *p, ds_wl *w, int nwl, int fi, double z_image, double *pts,
                  double *dirs, double *wt, int cap);
double ds_image_z(const ln_lens *l, const ds_wl *prim);
/* The chief ray of field fi at w on the plane z_image: point (x, y) and slopes
 * (dx/dz, dy/dz).  0, -1 when it fails. */
int ds_chief(ds_problem *p, ds_wl *w, int fi, double z_image, double pt[2], double sl[2]);
/* The wavefront of field fi (waves, piston not removed) at every wavelength of w:
 * count, -1 on a failed ray (or no exit pupil), -2 when stopped. */
int ds_field_wave(ds_problem *p, ds_wl *w, int nwl, int fi, double z_image, double *wv,
                  double *wt, int cap);
/* ds_opt.c */
int ds_optimise(ds_problem *p, int max_iter, int (*progress)(void *, const ds_step *),
                int (*stop)(void *), void *ctx, ds_opt_result *res, char *err, size_t cap);
void ds_set_var(ds_problem *p, int i, double v);
double ds_get_var(const ds_problem *p, int i);
/* ds_tol.c */
int ds_tol_nominal(ds_problem *p, const ds_tol_opts *o, ds_crit *c);
int ds_tol_one(ds_problem *p, const ds_tol_opts *o, int i, double sign, ds_crit *c);
int ds_tol_mc(ds_problem *p, const ds_tol_opts *o, uint64_t seed, long k, ds_crit *c);

#endif
