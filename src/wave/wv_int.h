/* wv_int.h -- private to the wave engine's files: the context (FFTW plan and buffers,
 * the last PSF) and the functions the table in wv_api.c exports. */
#ifndef WV_INT_H
#define WV_INT_H
#include <fftw3.h>
#include "wave.h"

#pragma GCC visibility push(hidden)

struct wave_ctx {
    int m;                     /* the plan's size (0: none yet) */
    fftw_complex *buf;         /* m*m, the plan works in place on it */
    fftw_plan plan;            /* forward, in place */
    double *psf;               /* m*m, the last PSF (normalised, centred) */
    int n;                     /* its pupil's grid */
    double total;              /* its total energy in PSF units (sum of psf) */
    int have;                  /* psf holds a PSF */
    double cx, cy;             /* its centroid, samples from the centre */
};

/* Cell centre j of an n-cell axis across [-1, 1]. */
#define WV_PI 3.14159265358979323846

static inline double wv_cell(int n, int j) { return -1 + (2.0 * j + 1) / n; }

int wv_zernike_nm(int order, int j, int *n, int *m);
double wv_zernike(int order, int j, double rho, double theta);
const char *wv_zernike_name(int order, int j);
int wv_pupil_add_zernike(wave_pupil *p, int order, int j, double c);
int wv_zernike_fit(const wave_pupil *p, int order, int nterm, wave_zfit *out);
int wv_pupil_mask(wave_pupil *p, double obsc, double apod);

wave_ctx *wv_ctx_new(void);
void wv_ctx_free(wave_ctx *c);
int wv_plan(wave_ctx *c, int m);
int wv_psf(wave_ctx *c, const wave_pupil *p, int m, double defocus, double *psf,
           wave_quality *q);
int wv_energy(wave_ctx *c, const double *r, int nr, int square, double *frac);
int wv_mtf(wave_ctx *c, int nk, double *tan, double *sag);
int wv_otf(wave_ctx *c, int nk, double *tr, double *ti, double *sr, double *si);
int wv_otf_dir(wave_ctx *c, double angle, int nk, double *re, double *im);
double wv_mtf_diffraction(double v);
int wv_resolution(wave_ctx *c, int tan, double *rayleigh, double *sparrow);

int wv_kirchhoff(const wave_pupil *p, double a, double R, double lambda, const double *x,
                 const double *y, int npt, double *out);
int wv_fraunhofer(int order, const double *zc, int nz, int nr, int nt, const double *u,
                  const double *v, int npt, double *out);
int wv_fraunhofer_ee(int nr, int nt, const double *r_ee, int nee, double *ee);

int wv_jones(int kind, double angle, double ret, wave_c m[4]);
int wv_fresnel(double n1, double n2, double th, wave_c out[4]);
int wv_film(double n0, const double *n, const double *d, int nl, double ns, double lambda,
            double th, double *Rs, double *Rp);

#pragma GCC visibility pop
#endif
