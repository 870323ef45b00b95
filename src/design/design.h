/* design.h -- public face of the lens-design pipeline (build/lib/lensmat-design.so):
 * a lens (src/lens) with the designer's variables, merit operands and tolerances,
 * damped least squares over the variables (GSL gsl_multifit_nlinear), sensitivities
 * and Monte Carlo tolerancing.  Real rays are the trace engine's (rx_aim, reached
 * only through the trace_api table the caller hands in); first order is the paraxial
 * engine's.  No user I/O: results come back in structs, refusals as "FILE:LINE: why".
 *
 * The merit and tolerance lines (doc/design.md "Writing a merit function") live in a
 * thickness prescription or in a file of their own:
 *     vary c 1             curvature of surface 1 (also: r, t, k, a4..a16, glass)
 *     target efl 50 weight 1
 *     target rms 0 field 2 wave 0
 *     min ct 2 surface 1   (a bound: counts only when violated)
 *     tol r all 0.1%       tolerances (r t n k; tx ty in degrees, dx dy, of a surface
 *                          or an element 2-3); tolopt dist uniform, tolopt limit 25 ...
 *     design rings 3 arms 6 method lm
 * Get the table with
 *     ds_get_api_fn get = (ds_get_api_fn)lm_engine_symbol("design", DS_API_SYMBOL);
 *     const ds_api *ds = get ? get(DS_ABI) : NULL;                                  */
#ifndef DESIGN_H
#define DESIGN_H
#include <stddef.h>
#include <stdint.h>

#define DS_ABI 2     /* 2: ds_crit.bore, tilt and decentre tolerances, folded lenses */
#define DS_API_SYMBOL "ds_get_api"
#define DS_ERR_MAX 1024

enum { DS_OK = 0, DS_BAD = 2, DS_NOMEM = 3, DS_STOPPED = 4 };

struct trace_api;
typedef struct ds_problem ds_problem;

/* What a variable or operand is, for printing (the dialogue's table). */
typedef struct ds_var_info {
    char name[32];             /* "c 1", "t 6", "nd 2" ... */
    double value;
    long line;
} ds_var_info;
typedef struct ds_op_info {
    char name[96];             /* "efl", "rms field 2 wave 0", "min ct surface 1" */
    double target, weight, value;
    double contribution;       /* its share of the merit (percent of MF^2) */
    long line;
} ds_op_info;

/* One step of an optimisation, as the progress callback gets it. */
typedef struct ds_step {
    int iter;                  /* 0: the start */
    double merit;              /* sqrt(sum w (v - t)^2 / sum w) */
    double seconds;            /* since the start */
    long evaluations;          /* merit evaluations so far (Jacobian columns count) */
} ds_step;
typedef struct ds_opt_result {
    int iterations;
    double merit0, merit;
    double seconds;
    long evaluations;
    int reason;                /* 1 small step, 2 small gradient, 3 iterations, 4 no
                                  progress, 0 stopped */
    char method[192];           /* the method's name as GSL and we run it */
} ds_opt_result;

/* Tolerancing. */
typedef struct ds_tol_info {
    char name[32];             /* "r 1", "t 2", "n 3", "k 5", "tx 2", "dy 1-2" (an element) */
    int angle;                 /* 1: delta is in degrees (tx, ty) */
    double delta;              /* the tolerance (absolute, in the parameter's unit) */
    long line;
} ds_tol_info;
/* The criteria of one built (or perturbed) lens. */
typedef struct ds_crit {
    double rms;                /* RMS spot radius (lens units): field-weighted quadratic
                                  mean of every field's polychromatic RMS about its
                                  centroid, after the back-focus compensator */
    double efl, bfd;           /* paraxial, primary wavelength */
    double focus;              /* the compensator's image-plane shift, along the light
                                  (the last thickness's change, sign as if unfolded) */
    double wave;               /* with ds_tol_opts.wave: RMS wavefront (waves, piston
                                  removed; field-weighted quadratic mean, every
                                  wavelength) on the compensated image plane; else NaN */
    int ok;                    /* 0: a ray failed (missed, TIR): rms is NaN */
    double bore[2];            /* field 1's chief ray (primary wavelength) on the
                                  compensated image plane, x and y (lens units): for an
                                  on-axis field 1 the boresight error times the efl */
} ds_crit;
typedef struct ds_tol_opts {
    int dist;                  /* 0 uniform in [-d, d], 1 Gaussian sigma d/2 cut at +-d */
    int compensate;            /* 1: back focus refocused for the least rms */
    double limit;              /* yield: rms <= limit (lens units); 0: none */
    int wave;                  /* 1: also the RMS wavefront (ds_crit.wave) */
} ds_tol_opts;

typedef struct ds_api {
    int abi;
    /* A lens file's text (thickness prescription or .zmx) and, optionally, a merit
     * file's (NULL: the merit lines are the lens file's own).  tr: the trace engine's
     * table (kept; must outlive the problem).  DS_OK or DS_BAD/DS_NOMEM, err says why
     * as "FILE:LINE: why". */
    int (*read)(const char *lens_text, size_t lens_len, const char *lens_src,
                const char *merit_text, size_t merit_len, const char *merit_src,
                const struct trace_api *tr, ds_problem **out, char *err, size_t cap);
    void (*free)(ds_problem *p);
    int (*nvar)(const ds_problem *p);
    int (*nop)(const ds_problem *p);
    int (*ntol)(const ds_problem *p);
    void (*var_info)(const ds_problem *p, int i, ds_var_info *out);
    void (*tol_info)(const ds_problem *p, int i, ds_tol_info *out);
    /* The merit of the current lens: DS_OK and *merit, every operand's info updated
     * (op_info after it). */
    int (*merit)(ds_problem *p, double *merit, char *err, size_t cap);
    void (*op_info)(const ds_problem *p, int i, ds_op_info *out);
    /* The pupil sampling of the ray operands and the method, as a sentence. */
    void (*describe)(const ds_problem *p, char *buf, size_t cap);
    /* Damped least squares.  max_iter iterations at most; progress (may be NULL) is
     * called at the start and after each iteration (non-zero: stop); stop (may be
     * NULL) is polled during evaluations (non-zero: stop now).  DS_OK, DS_STOPPED
     * (the lens is left at the best point reached) or DS_BAD. */
    int (*optimise)(ds_problem *p, int max_iter, int (*progress)(void *ctx, const ds_step *s),
                    int (*stop)(void *ctx), void *ctx, ds_opt_result *res, char *err,
                    size_t cap);
    /* The current lens as a thickness prescription with the lens file's own merit
     * lines after it (malloc'd text, NULL: out of memory). */
    char *(*write)(const ds_problem *p);
    /* Tolerancing: the nominal lens's criteria; tolerance i applied at sign*delta. */
    int (*tol_nominal)(ds_problem *p, const ds_tol_opts *o, ds_crit *c);
    int (*tol_one)(ds_problem *p, const ds_tol_opts *o, int i, double sign, ds_crit *c);
    /* Monte Carlo lens number k (1-based) of the seed: every tolerance drawn from its
     * own SplitMix64 stream of (seed, k), so lens k is the same in any split of the
     * run.  The problem's lens is restored after. */
    int (*tol_mc)(ds_problem *p, const ds_tol_opts *o, uint64_t seed, long k, ds_crit *c);
    void (*tol_defaults)(const ds_problem *p, ds_tol_opts *o);   /* the file's tolopt */
    const char *(*unit)(const ds_problem *p);    /* the lens's length unit ("mm") */
} ds_api;

typedef const ds_api *(*ds_get_api_fn)(int abi);
const ds_api *ds_get_api(int abi);

#endif
