/* wave.h -- public face of the wave-optics engine (build/lib/lensmat-wave.so, FFTW 3
 * and GSL): the pupil function of a lens on an n x n grid (optical path difference
 * from the trace engine's rx_opd, an amplitude mask, apodisation), its Zernike fit
 * (Fringe and ANSI/Noll orderings), the PSF by FFT and by direct Huygens-Fresnel /
 * Kirchhoff integration (seed section 43), Strehl ratio, encircled and ensquared
 * energy, MTF and resolving power (section 44), and the small closed-form
 * calculators of sections 40 and 67-69 (Jones calculus, thin
 * films and Fresnel coefficients).  Loaded on first use:
 *     wave_get_api_fn get = (wave_get_api_fn)lm_engine_symbol("wave", WAVE_API_SYMBOL);
 *     const wave_api *wv = get ? get(WAVE_ABI) : NULL;
 *
 * Conventions.  The pupil grid covers the normalised exit pupil [-1, 1]^2 with cell
 * centres x_j = -1 + (2 j + 1) / n (column j, x), y_i likewise (row i, y), row-major;
 * a cell belongs to the pupil when its centre lies inside the unit circle (and outside
 * the central obscuration).  W is in waves at the wavelength in use, positive where
 * the wavefront leads the reference sphere.  The FFT runs on an m x m array (m >= 2n
 * for an unaliased MTF): Q = m / n, the PSF's sample pitch in the image is
 * lambda * F / Q (F: the working F-number of the image-space cone) and its centre
 * (the chief ray's image point, the reference sphere's centre) is sample (m/2, m/2).
 * The PSF is normalised to the peak of the aberration-free PSF of the same amplitude
 * (so its maximum is the Strehl ratio); the MTF's frequency k/n of the cutoff
 * 1/(lambda F) is sample k (k = 0..n). */
#ifndef WAVE_H
#define WAVE_H
#include <stddef.h>

#define WAVE_ABI 1
#define WAVE_API_SYMBOL "wave_get_api"
#define WAVE_OK 0
#define WAVE_EINVAL (-1)
#define WAVE_ENOMEM (-2)
#define WAVE_ESTOP (-3)           /* the stop flag was raised (SIGINT) */
#define WAVE_MAXZ 64              /* Zernike terms fitted at most */

/* Zernike orderings: Fringe (University of Arizona, Z1 piston .. Z37, terms 1-based)
 * and ANSI Z80.28 / Noll single indices (Noll: 1-based, cos terms even j). */
enum wave_zorder { WAVE_Z_FRINGE, WAVE_Z_NOLL, WAVE_Z_ANSI };

typedef struct wave_ctx wave_ctx;      /* FFTW plans and buffers, reused */

typedef struct wave_pupil {
    int n;
    double *w;                 /* n*n waves (undefined where amp is 0) */
    double *amp;               /* n*n amplitude >= 0 (0: outside, vignetted) */
} wave_pupil;

typedef struct wave_zfit {
    int order, nterm;          /* enum wave_zorder; terms 1..nterm (ANSI: 0..nterm-1) */
    double c[WAVE_MAXZ];       /* coefficients, waves (unit-RMS normalised for Noll/ANSI,
                                  Fringe: peak-normalised, 1 at the rim) */
    int nn[WAVE_MAXZ], mm[WAVE_MAXZ];   /* radial degree, signed azimuthal order */
    double rms, pv;            /* of W over the pupil (piston removed from the RMS) */
    double resid_rms, resid_pv;/* W minus the fit */
    int npoint;
} wave_zfit;

typedef struct wave_quality {
    double strehl;             /* PSF maximum (normalised as above) */
    double strehl_centre;      /* PSF at the reference point */
    double peak_x, peak_y;     /* where the maximum is, in samples from the centre */
    double cx, cy;             /* the PSF centroid, in samples from the centre */
    double edge;               /* the fraction of the energy in the field's outer
                                  sixteenth (each side): above ~1e-3 the field is too
                                  small for the PSF and its energy wraps round */
} wave_quality;

typedef struct { double re, im; } wave_c;     /* a complex number (Jones calculus) */

typedef struct wave_api {
    int abi;                               /* WAVE_ABI */
    const char *(*version)(void);          /* engine, FFTW and GSL versions */

    wave_ctx *(*ctx_new)(void);            /* NULL: out of memory */
    void (*ctx_free)(wave_ctx *c);

    /* ---- the pupil function (wv_pupil.c) ---- */
    /* Fill p->amp for an n x n grid: the unit circle less an obscuration of radius
     * obsc (0: none), times a Gaussian apodisation exp(-(rho/apod)^2) (apod <= 0:
     * none).  Number of pupil cells. */
    int (*pupil_mask)(wave_pupil *p, double obsc, double apod);
    /* Add c waves of Zernike term j (ordering `order`) to p->w (all cells). */
    int (*pupil_add_zernike)(wave_pupil *p, int order, int j, double c);

    /* ---- Zernike polynomials and fit (wv_zernike.c) ---- */
    /* Radial degree n and signed azimuthal order m of term j (m > 0: cos m theta,
     * m < 0: sin |m| theta), 0 or WAVE_EINVAL. */
    int (*zernike_nm)(int order, int j, int *n, int *m);
    /* Z_j(rho, theta) with theta from +x toward +y. */
    double (*zernike)(int order, int j, double rho, double theta);
    /* "defocus", "astigmatism 0", "coma y" ..., or "" */
    const char *(*zernike_name)(int order, int j);
    /* Least-squares fit of terms 1..nterm (ANSI 0..nterm-1) to W over the pupil
     * (cells with amp > 0), GSL's QR.  WAVE_OK, WAVE_EINVAL (fewer cells than terms,
     * nterm outside 1..WAVE_MAXZ) or WAVE_ENOMEM. */
    int (*zernike_fit)(const wave_pupil *p, int order, int nterm, wave_zfit *out);

    /* ---- PSF, energy, MTF (wv_psf.c, wv_mtf.c) ---- */
    /* The PSF of pupil p in an m x m field (m >= n; normalised, centred as above) into
     * psf (m*m, may be NULL to keep it only in the context for mtf and energy),
     * the quality figures into q (may be NULL).  defocus: waves of rho^2 added (W020,
     * for through-focus).  The FFTW plan of size m is made once and reused. */
    int (*psf)(wave_ctx *c, const wave_pupil *p, int m, double defocus, double *psf,
               wave_quality *q);
    /* From the context's last PSF: the fraction of the energy within radius r (in
     * samples, about the centre; encircled) or within the square of half-width r
     * (ensquared) for each of nr radii; each sample counted by the part of it inside
     * (a 4 x 4 sub-sample grid). */
    int (*energy)(wave_ctx *c, const double *r, int nr, int square, double *frac);
    /* From the context's last PSF: the MTF along the tangential (y) and sagittal (x)
     * frequency axes at samples k = 0..nk-1 (k/n of the cutoff; nk <= n + 1), either
     * output may be NULL. */
    int (*mtf)(wave_ctx *c, int nk, double *tan, double *sag);
    /* The same cuts as the complex OTF, referred to the PSF's centre sample (the
     * chief ray's image point): re/im pairs, any output may be NULL.  For summing
     * wavelengths whose chief rays land apart (lateral colour). */
    int (*otf)(wave_ctx *c, int nk, double *tan_re, double *tan_im, double *sag_re,
               double *sag_im);
    /* The complex OTF along any direction `angle` (radians, from +x toward +y) at
     * frequencies k/n of the cutoff, k = 0..nk-1: bilinear between the transform's
     * samples (exact at 0 and 90 degrees, where it equals otf's cuts).  For the
     * tangential and sagittal MTF of a field off both axes. */
    int (*otf_dir)(wave_ctx *c, double angle, int nk, double *re, double *im);
    /* The aberration-free MTF of a circular pupil (2/pi)(phi - cos phi sin phi),
     * phi = acos(nu / cutoff), at normalised frequency v = nu / cutoff. */
    double (*mtf_diffraction)(double v);
    /* Resolving power (section 44) from the context's last PSF cut along y (tan) or
     * x: Rayleigh's separation (the first minimum of the profile from its peak) and
     * Sparrow's (the smallest separation at which two equal incoherent points' sum
     * has no dip between them), in samples; 0 or WAVE_EINVAL (no minimum in the
     * field). */
    int (*resolution)(wave_ctx *c, int tan, double *rayleigh, double *sparrow);

    /* ---- direct integration (wv_direct.c) ---- */
    /* Section 43's Kirchhoff formula over the reference sphere of radius R (lens
     * units) through the exit pupil of radius a, for the converging wave amp *
     * exp(i 2 pi W) of pupil p: the intensity at each of npt image-plane points (x, y)
     * (lens units, about the sphere's centre) with the exact distances and obliquity
     * factor, normalised to the W = 0 intensity at the centre.  lambda in lens units.
     * Costs n^2 per point: for checking the FFT on small grids. */
    int (*kirchhoff)(const wave_pupil *p, double a, double R, double lambda,
                     const double *x, const double *y, int npt, double *out);
    /* The Fraunhofer (Debye) integral of a circular pupil with W(rho, theta) given by
     * Zernike coefficients zc (ordering `order`, nz terms, may be 0), by Gauss-Legendre
     * quadrature in rho (nr nodes) and the trapezoid rule in theta (nt nodes): the
     * PSF at npt points (u, v) in units of lambda F, normalised like psf().
     * fraunhofer_ee: the encircled energy of the aberration-free pupil's PSF so
     * computed within each radius r_ee (lambda F), by a second Gauss-Legendre
     * quadrature over the image plane. */
    int (*fraunhofer)(int order, const double *zc, int nz, int nr, int nt,
                      const double *u, const double *v, int npt, double *out);
    int (*fraunhofer_ee)(int nr, int nt, const double *r_ee, int nee, double *ee);

    /* ---- calculators (wv_calc.c; Gaussian beams are the paraxial engine's) ---- */
    /* Jones matrices: kind 0 linear polarizer (angle of its axis), 1 retarder of
     * retardance `ret` (radians) with its fast axis at `angle` (quarter wave pi/2,
     * half wave pi), 2 rotator by `angle`.  Out: m[4] row-major. */
    int (*jones)(int kind, double angle, double ret, wave_c m[4]);
    /* Fresnel amplitude coefficients at incidence angle th (radians) from n1 into
     * n2 (real indices): rs, rp, ts, tp as complex (TIR: |r| = 1 with its phase). */
    int (*fresnel)(double n1, double n2, double th, wave_c out[4]);
    /* Reflectance R_s, R_p of a stack: ambient n0, nl layers (index n[i] real,
     * physical thickness d[i], lens units), substrate ns, at wavelength lambda and
     * incidence angle th in the ambient (characteristic matrices, Born and Wolf 1.6). */
    int (*film)(double n0, const double *n, const double *d, int nl, double ns,
                double lambda, double th, double *Rs, double *Rp);
} wave_api;

typedef const wave_api *(*wave_get_api_fn)(int abi);
/* Exported by lensmat-wave.so: the table, or NULL if abi != WAVE_ABI. */
const wave_api *wave_get_api(int abi);

#endif
