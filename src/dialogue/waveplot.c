/* waveplot.c -- the --wave dialogue's pictures of one field, through the imaging
 * module's map and plot calls: the wavefront map and the PSF (linear and log10) at
 * the primary wavelength (PNG), the polychromatic MTF against frequency with the
 * diffraction limit, the through-focus MTF and the Zernike coefficients (PNG and SVG).
 * Each file is checked first (lm_check_output: never an input of this session). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "dialogues.h"
#include "wavedlg.h"
#include "prompts_wave.h"

#define P(k) wave_prompts[WAVE_##k]

static int stop_asked(void *ctx) { (void)ctx; return lm_stop_requested(); }

static int failed(wd *d, const char *err)
{
    lm_say(d->io, LM_BOTH, P(PICTURE_FAILED), err);
    return -1;
}

/* Names BASE-fN-WHAT.png (and .svg): checked; 0 or -1 after saying why. */
static int names(wd *d, int fi, const char *what, int svg, char *png, char *sv, size_t cap)
{
    char msg[512];
    snprintf(png, cap, "%s-f%d-%s.png", d->pic, fi + 1, what);
    snprintf(sv, cap, "%s-f%d-%s.svg", d->pic, fi + 1, what);
    if (lm_check_output(d->io, png, msg, sizeof msg) ||
        (svg && lm_check_output(d->io, sv, msg, sizeof msg)))
        return failed(d, msg);
    return 0;
}

static int map(wd *d, int fi, const char *what, const char *title, const char *unit,
               const double *v, int nx, double half, const char *xl, const char *yl,
               double disc, int sym, char *list, size_t lcap)
{
    char png[WD_WORD + 64], sv[WD_WORD + 64], err[512];
    im_map m;
    memset(&m, 0, sizeof m);
    if (names(d, fi, what, 0, png, sv, sizeof png)) return -1;
    m.title = title;
    m.unit = unit;
    m.xlabel = xl;
    m.ylabel = yl;
    m.nx = m.ny = nx;
    m.v = v;
    m.xmin = m.ymin = -half;
    m.xmax = m.ymax = half;
    m.disc = disc;
    m.symmetric = sym;
    im_out out = {png, NULL, 0, 0, stop_asked, NULL};
    if (d->im->map(&m, &out, NULL, err, sizeof err)) return failed(d, err);
    size_t u = strlen(list);
    snprintf(list + u, lcap - u, "%s%s", u ? ", " : "", png);
    return 0;
}

static int plot(wd *d, int fi, const char *what, const im_plot *p, char *list, size_t lcap)
{
    char png[WD_WORD + 64], sv[WD_WORD + 64], err[512];
    if (names(d, fi, what, 1, png, sv, sizeof png)) return -1;
    im_out out = {png, sv, 0, 0, stop_asked, NULL};
    if (d->im->plot(p, &out, NULL, err, sizeof err)) return failed(d, err);
    size_t u = strlen(list);
    snprintf(list + u, lcap - u, "%s%s", u ? ", " : "", png);
    return 0;
}

int wd_pictures(wd *d, int fi, const wave_zfit *z, const double *fq, const double *mt,
                const double *ms, const double *md, int nf, const double *shift,
                const double *ft, const double *fs, int nshift)
{
    char maps[4 * WD_WORD], plots[4 * WD_WORD], title[160];
    int n = d->n, m = d->m, h = m / 2, rc = 0;
    const wd_wl *r = &d->wl[0];
    maps[0] = plots[0] = '\0';
    /* the wavefront: W where the pupil passes light, NaN elsewhere */
    double *v = malloc(sizeof(double) * (size_t)(n > 129 ? n : 129) * (n > 129 ? n : 129));
    if (!v) return failed(d, "out of memory");
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            size_t at = (size_t)i * n + j, row = (size_t)(n - 1 - i) * n + j;   /* top: +y */
            v[row] = r->pu.amp[at] > 0 ? r->pu.w[at] : NAN;
        }
    snprintf(title, sizeof title, "Wavefront, field %d, %g nm: RMS %.4f, PV %.4f waves", fi + 1,
             r->lambda * 1000, r->rms, r->pv);
    rc = map(d, fi, "wavefront", title, "waves", v, n, 1, "pupil x", "pupil y", 1, 1, maps,
             sizeof maps);
    /* the PSF's centre: +-16 lambda F (Q samples each), at most the field */
    int c = 16 * d->Q < h - 1 ? 16 * d->Q : h - 1, w = 2 * c + 1;
    if (w > 129) { c = 64; w = 129; }
    double half = (c + 0.5) * r->pitch_um;
    for (int log = 0; log < 2 && !rc; log++) {
        for (int i = 0; i < w; i++)
            for (int j = 0; j < w; j++) {
                double p = d->psf[(size_t)(h + c - i) * m + (h - c + j)];
                v[(size_t)i * w + j] = log ? log10(p > 1e-6 ? p : 1e-6) : p;
            }
        snprintf(title, sizeof title, "PSF%s, field %d, %g nm: Strehl %.4f", log ? " (log10)" : "",
                 fi + 1, r->lambda * 1000, r->strehl);
        rc = map(d, fi, log ? "psf-log" : "psf", title, log ? "log10 of peak 1" : "of the "
                 "aberration-free peak", v, w, half, "x (um)", "y (um)", 0, 0, maps, sizeof maps);
    }
    free(v);
    if (!rc) {
        im_series s[3] = {{"tangential", nf, fq, mt, IM_LINES | IM_MARKERS},
                          {"sagittal", nf, fq, ms, IM_LINES | IM_MARKERS},
                          {"diffraction limit", nf, fq, md, IM_LINES}};
        snprintf(title, sizeof title, "MTF, field %d (polychromatic)", fi + 1);
        im_plot p = {title, "cycles/mm", "modulation", 0, 0, 0, 3, s, NULL};
        rc = plot(d, fi, "mtf", &p, plots, sizeof plots);
    }
    if (!rc && nshift > 1) {
        char xl[64];
        im_series s[2] = {{"tangential", nshift, shift, ft, IM_LINES | IM_MARKERS},
                          {"sagittal", nshift, shift, fs, IM_LINES | IM_MARKERS}};
        snprintf(title, sizeof title, "Through-focus MTF at %g cycles/mm, field %d", d->ffreq, fi + 1);
        snprintf(xl, sizeof xl, "focus shift (%s)", d->c.uname);
        im_plot p = {title, xl, "modulation", 0, 0, 0, 2, s, NULL};
        rc = plot(d, fi, "focus", &p, plots, sizeof plots);
    }
    if (!rc) {
        /* bars as stems: one line out of the zero line to each coefficient and back
         * (the plot joins a series' points, so the stems share the baseline) */
        double x[3 * WAVE_MAXZ], y[3 * WAVE_MAXZ];
        int j0 = z->order == WAVE_Z_ANSI ? 0 : 1;
        for (int t = 0; t < z->nterm; t++) {
            x[3 * t] = x[3 * t + 1] = x[3 * t + 2] = j0 + t;
            y[3 * t] = y[3 * t + 2] = 0;
            y[3 * t + 1] = z->c[t];
        }
        im_series s[1] = {{"coefficient", 3 * z->nterm, x, y, IM_LINES}};
        snprintf(title, sizeof title, "Zernike coefficients (%s), field %d, %g nm",
                 z->order == WAVE_Z_FRINGE ? "Fringe" : z->order == WAVE_Z_NOLL ? "Noll" : "ANSI",
                 fi + 1, r->lambda * 1000);
        im_plot p = {title, "term j", "waves", 0, 0, 1, 1, s, NULL};
        rc = plot(d, fi, "zernike", &p, plots, sizeof plots);
    }
    if (lm_stop_requested()) return -1;
    if (!rc) lm_say(d->io, LM_BOTH, P(WRITTEN), maps, plots);
    return rc;
}
