/* scene_polout.c -- polarization in a scene's run (inside the module): each surface's
 * polarizer, retarder or coating handed to the engine (tr_polar.c) at the run's
 * wavelength, and the table `output polar FILE [csv|npy]` written from the engine's
 * records, a row per detector hit in the hits' order: the hit's ray, depth, surface
 * and point, the Stokes parameters S0..S3 in the frame (x', dir x x'), the degree of
 * polarization, the Jones matrix's retardance (degrees) and diattenuation, the
 * radiometric gain, x', and Chipman's PRT matrix P (18 columns, re and im, row by
 * row); lambda_nm last when the scene names wavelengths.  CSV numbers are the
 * shortest that read back to the same doubles (scene_dtoa.cpp), as the hits' are. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "scene_pol.h"

int sc_dtoa(double v, char *buf);   /* scene_dtoa.cpp */

#define NDBL 33                      /* doubles a row after ray, depth, surface */
static const char *const names[NDBL + 1] = {
    "x", "y", "z", "S0", "S1", "S2", "S3", "dop", "retardance_deg", "diattenuation",
    "gain", "xref_x", "xref_y", "xref_z",
    "P11_re", "P11_im", "P12_re", "P12_im", "P13_re", "P13_im",
    "P21_re", "P21_im", "P22_re", "P22_im", "P23_re", "P23_im",
    "P31_re", "P31_im", "P32_re", "P32_im", "P33_re", "P33_im", "lambda_nm", NULL};

/* The .npy header for n rows, padded to len bytes (0: as short as any count allows). */
static long npy_header(const sp_out *po, uint64_t n, char *out, long len)
{
    char d[4096];
    int k = snprintf(d, sizeof d, "{'descr': [('ray', '<u8'), ('depth', '<i4'), "
                     "('surface', '<i4')");
    for (int i = 0; i < NDBL - 1 + po->wl; i++)
        k += snprintf(d + k, sizeof d - (size_t)k, ", ('%s', '<f8')", names[i]);
    k += snprintf(d + k, sizeof d - (size_t)k, "], 'fortran_order': False, 'shape': (%llu,), }",
                  (unsigned long long)n);
    long total = len ? len : (10 + k + 20 + 1 + 63) / 64 * 64;
    if (10 + k + 1 > total) return -1;
    memcpy(out, "\x93NUMPY\x01\x00", 8);
    out[8] = (char)((total - 10) & 0xff);
    out[9] = (char)((total - 10) >> 8);
    memcpy(out + 10, d, (size_t)k);
    memset(out + 10 + k, ' ', (size_t)(total - 10 - k - 1));
    out[total - 1] = '\n';
    return total;
}

int sp_open(const sc_scene *sc, sp_out *po, char *err)
{
    po->wl = sc->named_wl != 0;
    po->fmt = sc->out_polar_format;
    if (lm_out_open(&po->o, sc->out_polar, 0, err, SC_ERRMAX)) return -1;
    po->open = 1;
    FILE *f = po->o.f;
    if (po->fmt == SC_OUT_NPY) {
        char h[4096];
        po->header = npy_header(po, 0, h, 0);
        if (po->header < 0 || fwrite(h, 1, (size_t)po->header, f) != (size_t)po->header)
            po->bad = 1;
        return 0;
    }
    fputs("ray,depth,surface", f);
    for (int i = 0; i < NDBL - 1 + po->wl; i++) fprintf(f, ",%s", names[i]);
    fputc('\n', f);
    return 0;
}

/* The engine's record: the hit's Stokes parameters kept for its row of the hits, and
 * one row of the table when there is one. */
static int row(void *ctx, const trace_polar_hit *p)
{
    sp_out *po = ctx;
    memcpy(po->stokes, p->stokes, sizeof po->stokes);
    if (!po->open) return 0;
    double v[NDBL], S0 = p->stokes[0];
    uint64_t ray = p->ray + po->ray0;
    int32_t dep = p->depth, surf = p->surface;
    memcpy(v, p->pos, 3 * sizeof *v);
    memcpy(v + 3, p->stokes, 4 * sizeof *v);
    v[7] = S0 > 0 ? sqrt(p->stokes[1] * p->stokes[1] + p->stokes[2] * p->stokes[2] +
                         p->stokes[3] * p->stokes[3]) / S0 : NAN;
    v[8] = p->retardance * 57.29577951308232;
    v[9] = p->diattenuation;
    v[10] = p->gain;
    memcpy(v + 11, p->xref, 3 * sizeof *v);
    memcpy(v + 14, p->prt, 18 * sizeof *v);
    v[32] = po->nm;
    int n = NDBL - 1 + po->wl;
    FILE *f = po->o.f;
    po->rows++;
    if (po->fmt == SC_OUT_NPY) {
        if (fwrite(&ray, 8, 1, f) != 1 || fwrite(&dep, 4, 1, f) != 1 ||
            fwrite(&surf, 4, 1, f) != 1 || fwrite(v, 8, (size_t)n, f) != (size_t)n)
            po->bad = 1;
        return po->bad;
    }
    char line[64 * NDBL], *q = line;
    q += sprintf(q, "%llu,%d,%d", (unsigned long long)ray, dep, surf);
    for (int i = 0; i < n; i++) {
        *q++ = ',';
        q += sc_dtoa(v[i], q);
    }
    *q++ = '\n';
    if (fwrite(line, 1, (size_t)(q - line), f) != (size_t)(q - line)) po->bad = 1;
    return po->bad;
}

int sp_engine(const trace_api *tr, trace_scene *ts, const sc_scene *sc, double l,
              uint64_t ray0, sp_out *po, char *err)
{
    const double *ref = dot3(sc->polar_ref, sc->polar_ref) > 0 ? sc->polar_ref : NULL;
    char nm[40];
    po->ray0 = ray0;
    snprintf(nm, sizeof nm, "%.10g", l * 1e3);   /* as the hits' lambda_nm */
    po->nm = strtod(nm, NULL);
    for (int i = 0; i < 4; i++) po->stokes[i] = NAN;
    if (tr->polarization(ts, 1, ref, row, po) != TRACE_OK)
        return snprintf(err, SC_ERRMAX, "%s: %s", sc->name, tr->error(ts)), -1;
    for (int i = 0; i < sc->nsurf; i++) {
        const sc_surface *s = &sc->surf[i];
        if (!s->pol_el && !s->coat) continue;
        trace_polar_surface ps;
        memset(&ps, 0, sizeof ps);
        ps.element = s->pol_el;
        memcpy(ps.axis, s->pol_axis, sizeof ps.axis);
        ps.retardance = s->pol_ret;
        if (s->coat) {
            const sc_coating *c = &sc->coating[s->coat - 1];
            ps.nlayer = c->nlayer;
            for (int k = 0; k < c->nlayer; k++) {
                ps.layer_n[k] = c->n[k];
                ps.layer_d[k] = c->d_nm[k] * 1e-3;   /* um, as the wavelength */
            }
        }
        if (tr->set_polar(ts, i, &ps) != TRACE_OK)
            return snprintf(err, SC_ERRMAX, "%s:%ld: %s", s->src, s->line, tr->error(ts)), -1;
    }
    return 0;
}

int sp_finish(sp_out *po, int ok, char *err)
{
    char why[SC_ERRMAX];
    if (!po->open) return 0;
    po->open = 0;
    if (ok && po->fmt == SC_OUT_NPY && !po->bad) {
        char h[4096];
        if (npy_header(po, po->rows, h, po->header) != po->header ||
            fseek(po->o.f, 0, SEEK_SET) || fwrite(h, 1, (size_t)po->header, po->o.f) !=
            (size_t)po->header)
            po->bad = 1;
    }
    if (ok && po->bad && !err[0])
        snprintf(err, SC_ERRMAX, "%s: cannot write the polar table", po->o.name);
    if (!ok || po->bad) { lm_out_abort(&po->o, 1); return -1; }
    if (lm_out_commit(&po->o, why, sizeof why)) {
        if (!err[0]) snprintf(err, SC_ERRMAX, "%s", why);
        return -1;
    }
    return 0;
}
