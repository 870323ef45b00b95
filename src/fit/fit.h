/* fit.h -- public face of the fit module (build/lib/lensmat-fit.so): least squares
 * with GSL, kept out of the core so that only a session that fits loads libgsl.
 * Load with lm_engine_symbol("fit", "lm_fit_line"); its type is px_linfit. */
#ifndef FIT_H
#define FIT_H

/* Least-squares line y = c0 + c1 x through n >= 2 points (gsl_fit_linear); *sumsq is
 * the residual sum of squares.  Returns 0, or -1 (fewer than two distinct x, or a
 * non-finite result). */
int lm_fit_line(const double *x, const double *y, int n, double *c0, double *c1,
                double *sumsq);

#endif
