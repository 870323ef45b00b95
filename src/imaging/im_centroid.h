/* im_centroid.h -- internal seam between detection (im_centroid.c) and locating one
 * spot (im_fit.c: moments, the Gaussian fit, flags and uncertainties). */
#ifndef IM_CENTROID_H
#define IM_CENTROID_H
#include "im_int.h"

/* A GSL workspace kept between spots of the same window size. */
typedef struct im_fit_ws {
    void *w;                   /* gsl_multifit_nlinear_workspace * */
    size_t n, p;               /* its numbers of residuals and parameters */
    void *covar;               /* gsl_matrix * (p x p) */
    void *data;                /* the window's pixels (im_fit.c's fitdata, ~100 kB) */
} im_fit_ws;
void im_fit_ws_free(im_fit_ws *ws);

typedef struct im_spot_in {
    const im_frame *f;
    const int *list;           /* the spot's connected pixels above threshold */
    int npix, peak_i;
    double peak, bg, thr, noise, gain, sat, window;
    int method, edge, plane;
    double w_hint, a_hint;     /* the matched filter's width and amplitude estimate:
                                  the start for a spot too faint for its pixels above
                                  the threshold to say (npix < 3) */
    double x_hint, y_hint;     /* and where its response peaks */
    double snr_mf;             /* the detection statistic */
} im_spot_in;

void im_spot_locate(im_fit_ws *ws, const im_spot_in *in, im_spot *out);

#endif
