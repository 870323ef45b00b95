/* fit.c -- the fit module: GSL's straight-line least squares for the --fit dialogue
 * (section 14).  Built as build/lib/lensmat-fit.so, loaded on first use. */
#include <math.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_fit.h>
#include "fit.h"

int lm_fit_line(const double *x, const double *y, int n, double *c0, double *c1,
                double *sumsq)
{
    double cov00, cov01, cov11;
    int distinct = 0;
    if (n < 2) return -1;
    for (int i = 1; i < n; i++) distinct |= x[i] != x[0];
    if (!distinct) return -1;
    gsl_set_error_handler_off();
    if (gsl_fit_linear(x, 1, y, 1, (size_t)n, c0, c1, &cov00, &cov01, &cov11, sumsq))
        return -1;
    return isfinite(*c0) && isfinite(*c1) ? 0 : -1;
}
