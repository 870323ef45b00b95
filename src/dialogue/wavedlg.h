/* wavedlg.h -- what the --wave dialogue's files share (wave.c asks, wavecalc.c
 * computes and prints per field, waveplot.c draws): the session and one wavelength's
 * results. */
#ifndef WAVEDLG_H
#define WAVEDLG_H
#include "lensrx.h"
#include "../imaging/imaging.h"
#include "../wave/wave.h"

#define WD_WORD 4096
#define WD_NR 240                  /* radii of the encircled-energy curve */

typedef struct wd_wl {
    int ok;
    double lambda, weight;         /* um, the file's weight */
    double F, lam_mm, pitch_um;    /* working F-number, lambda in the image medium */
    double cut;                    /* cutoff, cycles/mm */
    double strehl, strehl_c, rms, pv;
    double chief[2];               /* the chief ray at the image plane, mm */
    double defocus_per_mm;         /* W020 in waves per mm of focus shift */
    double *otf;                   /* 4 (n+1): tan re, im, sag re, im */
    wave_pupil pu;                 /* this field's pupil at this wavelength */
    double ee[WD_NR + 1], es[WD_NR + 1];   /* at the session's radii; [WD_NR]: the Airy radius */
    int nvig, ncell;
} wd_wl;

typedef struct wd {
    lm_io *io;
    calc c;
    lr_lens L;
    lr_texts t;
    const trace_api *tr;
    const wave_api *wv;
    const im_draw_api *im;
    wave_ctx *ctx;
    int n, m, Q, order, nterm, steps, ncell;
    double fmax, focus, ffreq;
    double az;                     /* this field's tangential direction (radians from
                                      +x toward +y; 90 degrees on the axis) */
    char pic[WD_WORD];             /* picture name base, "" for none */
    double *cx, *cy;               /* the pupil cells' centres (ncell) */
    int *cidx;                     /* ... their index in the n x n grid */
    double *psf;                   /* its PSF (m*m) */
    double dr_um;                  /* the energy curve's radius step */
    double trace_ms, wave_ms;
    int nwl;
    wd_wl wl[LN_WL_MAX];
} wd;

int wd_field(wd *d, int fi);       /* wavecalc.c: one field, LM_GO or LM_FAIL */
/* waveplot.c: the field's pictures; 0, or -1 after saying why */
int wd_pictures(wd *d, int fi, const wave_zfit *z, const double *fq, const double *mt,
                const double *ms, const double *md, int nf, const double *shift,
                const double *ft, const double *fs, int nshift);
double wd_now_ms(void);

#endif
