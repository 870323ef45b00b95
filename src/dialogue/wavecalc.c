/* wavecalc.c -- the --wave dialogue's work for one field: per wavelength the
 * wavefront of rays aimed at the stop (the trace module's rx_opd, in chunks so a
 * SIGINT stops it promptly), the PSF, Strehl ratio, OTF cuts and energy curve (the
 * wave module); then the Zernike fit at the primary wavelength and the polychromatic
 * sums: MTF (each wavelength's OTF carried by its chief ray's offset from the
 * primary's, lateral colour kept; the cuts toward the field's image point and across
 * it), Strehl (weights / lambda^2: the aberration-free
 * peak of equal power goes as 1/(lambda F)^2), encircled energy (each about its own
 * chief ray), resolving power and the through-focus MTF. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "dialogues.h"
#include "wavedlg.h"
#include "prompts_wave.h"

#define P(k) wave_prompts[WAVE_##k]
#define CHUNK 1024
#define DEG (3.14159265358979323846 / 180)
#define PI_ 3.14159265358979323846
#define NF 11

static double unit_mm(const char *u)
{
    return !strcmp(u, "cm") ? 10 : !strcmp(u, "m") ? 1000 : !strcmp(u, "in") ? 25.4 : 1;
}

/* The wavefront of field f at wavelength w into pu (amp 0 where vignetted). */
static int wavefront(wd *d, wave_pupil *pu, const lr_wl *w, const ln_field *f, double lam_lens, double *R,
                     trace_aim_ray *chief, int *nvig, char *why, size_t cap)
{
    trace_aim_req rq[CHUNK + 1];
    double ww[CHUNK + 1];
    int st[CHUNK + 1];
    double t0 = wd_now_ms();
    size_t n2 = (size_t)d->n * d->n;
    for (size_t i = 0; i < n2; i++) { pu->w[i] = 0; pu->amp[i] = 0; }
    *nvig = 0;
    lr_request(&d->L, w, f, 0, 0, &rq[0]);
    for (int k0 = 0; k0 < d->ncell; k0 += CHUNK) {
        int nk = d->ncell - k0 < CHUNK ? d->ncell - k0 : CHUNK;
        if (lm_stop_requested()) return LM_FAIL;
        for (int k = 0; k < nk; k++)
            lr_request(&d->L, w, f, d->cx[k0 + k], d->cy[k0 + k], &rq[k + 1]);
        if (d->tr->rx_opd(&w->rx, rq, nk + 1, w->p.z_xp, lam_lens, ww, st, chief, R, why,
                          cap) != TRACE_OK)
            return -1;
        for (int k = 0; k < nk; k++) {
            int at = d->cidx[k0 + k];
            if (isfinite(ww[k + 1])) { pu->w[at] = ww[k + 1]; pu->amp[at] = 1; }
            else (*nvig)++;
        }
    }
    d->trace_ms += wd_now_ms() - t0;
    return 0;
}

/* Linear interpolation of a cut sampled at k = 0..n (k/n of the cutoff). */
static void otf_at(const wd *d, const wd_wl *r, int sag, double nu, double *re, double *im)
{
    double k = nu / r->cut * d->n;
    const double *a = r->otf + (size_t)(sag ? 2 : 0) * (d->n + 1);
    const double *b = a + (d->n + 1);
    *re = *im = 0;
    if (!(k < d->n) || k < 0) return;
    int i = (int)k;
    double t = k - i;
    *re = a[i] * (1 - t) + a[i + 1] * t;
    *im = b[i] * (1 - t) + b[i + 1] * t;
}

/* The polychromatic MTF at nu: sum of weighted OTFs, each shifted by its chief ray's
 * offset from the primary's (an image displaced by s multiplies the OTF by
 * exp(-2 pi i nu s)). */
static double poly_mtf(const wd *d, int sag, double nu)
{
    double sr = 0, si = 0, sw = 0;
    for (int k = 0; k < d->nwl; k++) {
        const wd_wl *r = &d->wl[k];
        double re, im;
        if (!r->ok) continue;
        otf_at(d, r, sag, nu, &re, &im);
        double dx = r->chief[0] - d->wl[0].chief[0], dy = r->chief[1] - d->wl[0].chief[1];
        double ca = cos(d->az), sa = sin(d->az);
        double s = sag ? -dx * sa + dy * ca : dx * ca + dy * sa;   /* along the cut */
        double ph = -2 * PI_ * nu * s, c = cos(ph), sn = sin(ph);
        sr += r->weight * (re * c - im * sn);
        si += r->weight * (re * sn + im * c);
        sw += r->weight;
    }
    return sw > 0 ? hypot(sr, si) / sw : NAN;
}

static double poly_diff(const wd *d, double nu)
{
    double s = 0, sw = 0;
    for (int k = 0; k < d->nwl; k++)
        if (d->wl[k].ok) {
            s += d->wl[k].weight * d->wv->mtf_diffraction(nu / d->wl[k].cut);
            sw += d->wl[k].weight;
        }
    return sw > 0 ? s / sw : NAN;
}

static double poly_strehl(const wd *d, int centre)
{
    double s = 0, sw = 0;
    for (int k = 0; k < d->nwl; k++) {
        const wd_wl *r = &d->wl[k];
        if (!r->ok) continue;
        double p0 = r->weight / (r->lam_mm * r->F * r->lam_mm * r->F);
        s += p0 * (centre ? r->strehl_c : r->strehl);
        sw += p0;
    }
    return sw > 0 ? s / sw : NAN;
}

/* The radius (um) at which the polychromatic curve e reaches frac, as text. */
static const char *radius_at(const wd *d, int square, double frac, char *buf, size_t cap)
{
    double prev = 0;
    for (int i = 0; i < WD_NR; i++) {
        double s = 0, sw = 0;
        for (int k = 0; k < d->nwl; k++)
            if (d->wl[k].ok) {
                s += d->wl[k].weight * (square ? d->wl[k].es[i] : d->wl[k].ee[i]);
                sw += d->wl[k].weight;
            }
        double v = s / sw;
        if (v >= frac) {
            double r0 = i * d->dr_um, r1 = (i + 1) * d->dr_um;
            double r = i == 0 ? r1 : r0 + (frac - prev) / (v - prev) * (r1 - r0);
            snprintf(buf, cap, "%.4g", r);
            return buf;
        }
        prev = v;
    }
    snprintf(buf, cap, "> %.4g", WD_NR * d->dr_um);
    return buf;
}

/* PSF and its figures for wavelength r (its pupil r->pu): 0, 1 (the PSF reaches the
 * field's edge), -1. */
static int psf_figures(wd *d, wd_wl *r, double defocus, double *psf)
{
    wave_quality q;
    double t0 = wd_now_ms();
    int n = d->n;
    if (d->wv->psf(d->ctx, &r->pu, d->m, defocus, psf, &q) != WAVE_OK) return -1;
    r->strehl = q.strehl;
    r->strehl_c = q.strehl_centre;
    if (!r->otf && !(r->otf = malloc(sizeof(double) * 4 * (size_t)(n + 1)))) return -1;
    double *o = r->otf, h = 3.14159265358979323846 / 2;
    if (d->wv->otf_dir(d->ctx, d->az, n + 1, o, o + (n + 1)) != WAVE_OK ||
        d->wv->otf_dir(d->ctx, d->az + h, n + 1, o + 2 * (n + 1), o + 3 * (n + 1)) != WAVE_OK)
        return -1;
    d->wave_ms += wd_now_ms() - t0;
    /* the aberration-free PSF's rings alone put about 2/(pi^2 r) of the energy beyond
     * r (lambda F); the band starts at 7n/16: three times that is a PSF too wide */
    return q.edge > 3 * 2 / (PI_ * PI_ * (7.0 * d->n / 16));
}

int wd_field(wd *d, int fi)
{
    const ln_lens *l = &d->L.lens;
    const ln_field *f = &l->field[fi];
    const char *un = d->c.uname;
    double umm = unit_mm(un);
    char why[512];
    wave_zfit z, zp;
    int have_z = 0, rc = LM_GO;
    lr_wl *w = malloc(sizeof *w);
    if (!w) return LM_FAIL;
    /* tangential: toward the field's image point (y on the axis); sagittal across */
    d->az = f->x == 0 && f->y == 0 ? PI_ / 2 : atan2(f->y, f->x);
    if (f->x == 0) {
        if (isinf(l->object)) calc_say(&d->c, P(FIELD_HEAD_ANGLE), fi + 1, f->y);
        else calc_say(&d->c, P(FIELD_HEAD_HEIGHT), fi + 1, f->y);
    } else {
        if (isinf(l->object)) calc_say(&d->c, P(FIELD_HEAD_ANGLE_XY), fi + 1, f->x, f->y);
        else calc_say(&d->c, P(FIELD_HEAD_HEIGHT_XY), fi + 1, f->x, f->y);
    }
    for (int k = 0; k < d->nwl && rc == LM_GO; k++) {
        wd_wl *r = &d->wl[k];
        trace_aim_ray chief;
        double R = 0;
        int nvig = 0;
        r->ok = 0;
        if (lr_at(&d->L, r->lambda, w, why, sizeof why)) {
            calc_say(&d->c, P(WL_FAIL), r->lambda * 1000, why);
            continue;
        }
        double ni = w->surf[w->rx.nsurf - 1].n_right;
        double lam_lens = r->lambda * 1e-3 / umm;
        int wr = wavefront(d, &r->pu, w, f, lam_lens, &R, &chief, &nvig, why, sizeof why);
        if (wr == LM_FAIL) { rc = LM_FAIL; break; }
        if (wr) { calc_say(&d->c, P(WL_FAIL), r->lambda * 1000, why); continue; }
        if (nvig == d->ncell) { calc_say(&d->c, P(WL_VIGN), r->lambda * 1000, nvig, d->ncell); continue; }
        double rxp = w->p.r_xp * w->s;
        r->F = R / (2 * fabs(rxp));
        r->lam_mm = r->lambda * 1e-3 / ni;
        r->pitch_um = r->lam_mm * 1e3 * r->F / d->Q;
        r->cut = 1 / (r->lam_mm * r->F);
        r->chief[0] = chief.img[0] * umm;
        r->chief[1] = chief.img[1] * umm;
        /* a focus shift delta moves the sphere's centre: W020 = n' delta (1 - cos u')/lambda */
        r->defocus_per_mm = ni * (1 - cos(atan(1 / (2 * r->F)))) / (r->lambda * 1e-3);
        r->nvig = nvig;
        if (d->wv->zernike_fit(&r->pu, d->order, d->nterm, k == 0 ? &zp : &z) != WAVE_OK) {
            calc_say(&d->c, P(WL_FAIL), r->lambda * 1000, "too few pupil cells for the fit");
            continue;
        }
        if (k == 0) z = zp;
        r->rms = z.rms;
        r->pv = z.pv;
        int edge = psf_figures(d, r, 0, k == 0 ? d->psf : NULL);
        if (edge < 0) { calc_say(&d->c, P(WL_FAIL), r->lambda * 1000, "PSF"); continue; }
        if (k == 0) {
            /* the energy curve's radii: 60 samples of the coarsest wavelength at most */
            double pmin = r->pitch_um;
            for (int j = 1; j < d->nwl; j++) {
                double lj = d->wl[j].lambda / d->wl[0].lambda * pmin;
                if (lj < pmin) pmin = lj;
            }
            d->dr_um = 60 * pmin / WD_NR;
        }
        double rad[WD_NR + 1];
        for (int i = 0; i < WD_NR; i++) rad[i] = (i + 1) * d->dr_um / r->pitch_um;
        rad[WD_NR] = 1.21966989 * d->wl[0].lam_mm * d->wl[0].F * 1e3 / r->pitch_um;
        d->wv->energy(d->ctx, rad, WD_NR + 1, 0, r->ee);
        d->wv->energy(d->ctx, rad, WD_NR, 1, r->es);
        r->ok = 1;
        calc_say(&d->c, P(WL_ROW), r->lambda * 1000, r->rms, r->pv, r->strehl, r->strehl_c, r->F,
                 r->pitch_um, d->n * r->lam_mm * 1e3 * r->F, edge ? P(EDGE_WARN) : "");
        if (nvig) calc_say(&d->c, P(WL_VIGN), r->lambda * 1000, nvig, d->ncell);
        if (k == 0) {
            int small = 0, j0 = d->order == WAVE_Z_ANSI ? 0 : 1;
            const char *on = d->order == WAVE_Z_FRINGE ? "Fringe" : d->order == WAVE_Z_NOLL
                             ? "Noll" : "ANSI";
            have_z = 1;
            calc_say(&d->c, P(ZERN_HEAD), r->lambda * 1000, on, z.resid_rms, z.resid_pv, z.npoint);
            for (int t = 0; t < z.nterm; t++) {
                if (fabs(z.c[t]) < 5e-4) { small++; continue; }
                calc_say(&d->c, P(ZERN_ROW), j0 + t, z.nn[t], z.mm[t], lm_clean(d->io, z.c[t]),
                         d->wv->zernike_name(d->order, j0 + t));
            }
            if (small) calc_say(&d->c, P(ZERN_SMALL), small);
            /* resolving power from the primary's PSF */
            double rt, st, rs, ss;
            if (d->wv->resolution(d->ctx, 1, &rt, &st) == WAVE_OK &&
                d->wv->resolution(d->ctx, 0, &rs, &ss) == WAVE_OK) {
                double p = r->pitch_um;
                calc_say(&d->c, P(RES), r->lambda * 1000, rt * p, rs * p, st * p, ss * p,
                         1000 / (rt * p), 1000 / (rs * p));
            } else {
                calc_say(&d->c, P(RES_NONE), r->lambda * 1000);
            }
        }
    }
    if (rc != LM_GO || !d->wl[0].ok) { free(w); return rc; }
    /* the polychromatic sums */
    char a[32], b[32], e[32];
    double eeA = 0, sw = 0;
    for (int k = 0; k < d->nwl; k++)
        if (d->wl[k].ok) { eeA += d->wl[k].weight * d->wl[k].ee[WD_NR]; sw += d->wl[k].weight; }
    calc_say(&d->c, "%s", P(POLY_HEAD));
    calc_say(&d->c, P(STREHL), poly_strehl(d, 0));
    calc_say(&d->c, P(EE), 100 * eeA / sw, 1.21966989 * d->wl[0].lam_mm * d->wl[0].F * 1e3,
             d->wl[0].lambda * 1000, radius_at(d, 0, 0.5, a, sizeof a),
             radius_at(d, 0, 0.8, b, sizeof b), radius_at(d, 1, 0.8, e, sizeof e));
    double fmax = d->fmax > 0 ? d->fmax : d->wl[0].cut, fq[NF], mt[NF], ms[NF], md[NF];
    calc_say(&d->c, P(MTF_HEAD), d->wl[0].cut, d->wl[0].lambda * 1000);
    for (int i = 0; i < NF; i++) {
        fq[i] = fmax * i / (NF - 1);
        mt[i] = poly_mtf(d, 0, fq[i]);
        ms[i] = poly_mtf(d, 1, fq[i]);
        md[i] = poly_diff(d, fq[i]);
        calc_say(&d->c, P(MTF_ROW), fq[i], mt[i], ms[i], md[i]);
    }
    /* through focus: every wavelength's pupil again with W020 for each shift */
    double shift[21], ft[21], fs[21];
    int nsh = 0;
    if (d->focus > 0) {
        calc_say(&d->c, P(FOCUS_HEAD), d->ffreq, un);
        for (int s = -d->steps; s <= d->steps && rc == LM_GO; s++) {
            double dz = d->focus * s / d->steps;
            for (int k = 0; k < d->nwl && rc == LM_GO; k++) {
                wd_wl *r = &d->wl[k];
                if (!r->ok) continue;
                if (lm_stop_requested()) { rc = LM_FAIL; break; }
                if (psf_figures(d, r, r->defocus_per_mm * dz * umm, NULL) < 0) r->ok = 0;
            }
            if (rc != LM_GO) break;
            shift[nsh] = dz;
            ft[nsh] = poly_mtf(d, 0, d->ffreq);
            fs[nsh] = poly_mtf(d, 1, d->ffreq);
            calc_say(&d->c, P(FOCUS_ROW), lm_clean(d->io, dz), ft[nsh], fs[nsh], poly_strehl(d, 1));
            nsh++;
        }
    }
    free(w);
    if (rc == LM_GO && d->pic[0] && have_z)
        if (wd_pictures(d, fi, &zp, fq, mt, ms, md, NF, shift, ft, fs, nsh)) rc = LM_FAIL;
    return rc;
}
