/* tp_iso.c -- the test report ISO 19980 asks of a corneal topographer (issue 19 item
 * 5): on a test surface whose shape is known, the measured surface (the Zernike
 * surface from the data, cornea_api.zsag) against the true one, per zone of 0-3, 3-6
 * and 6-9 mm diameter and over the central 6 mm: the area-weighted mean difference and
 * twice its standard deviation, as height (um) and as axial power (D).
 * Conventions (doc/topography.md "Zone and the ISO 19980 report"): a 0.1 mm grid in the
 * measured surface's eye frame, the points the maps count as data (zcovered), each the
 * same area; height: the true surface met along the measured axis through the
 * measured point, difference measured - true toward the observer, both taken from
 * their vertex (the instrument's absolute distance is not the surface's shape); power:
 * the axial (sagittal) power 337.5 f_r / (r sqrt(1 + f_r^2)) of both surfaces about the
 * measured axis (the true one's heights along it, slopes by central differences). */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "tp_int.h"

typedef struct frame {
    double R[9], T[3];          /* measured eye frame -> rig */
    const rg_cornea *place;     /* the true surface's frame */
    tp_sag_fn sag;
    void *ctx;
    const tp_run *r;
} frame;

/* The true surface met along the measured axis from measured point (x, y, zm): the
 * distance s (mm, + into the eye) from the measured point; 0 or -1. */
static int along(const frame *f, double x, double y, double zm, double *s)
{
    const double *R = f->R, *Rt = f->place->rot, *Tt = f->place->trans;
    double P[3], a[3], p[3], d[3], rel[3];
    for (int i = 0; i < 3; i++) {
        P[i] = R[3 * i] * x + R[3 * i + 1] * y + R[3 * i + 2] * zm + f->T[i];
        a[i] = R[3 * i + 2];
        rel[i] = P[i] - Tt[i];
    }
    for (int i = 0; i < 3; i++) {           /* into the true eye frame: Rt^T */
        p[i] = Rt[i] * rel[0] + Rt[3 + i] * rel[1] + Rt[6 + i] * rel[2];
        d[i] = Rt[i] * a[0] + Rt[3 + i] * a[1] + Rt[6 + i] * a[2];
    }
    double t = 0;
    for (int it = 0; it < 40; it++) {      /* Newton on g(t) = z(t) - sag(x(t), y(t)) */
        const double h = 1e-5;
        double xx = p[0] + t * d[0], yy = p[1] + t * d[1], z0, zx1, zx0, zy1, zy0;
        if (f->sag(f->ctx, xx, yy, &z0) || f->sag(f->ctx, xx + h, yy, &zx1) ||
            f->sag(f->ctx, xx - h, yy, &zx0) || f->sag(f->ctx, xx, yy + h, &zy1) ||
            f->sag(f->ctx, xx, yy - h, &zy0))
            return -1;
        double g = p[2] + t * d[2] - z0;
        double dg = d[2] - (zx1 - zx0) / (2 * h) * d[0] - (zy1 - zy0) / (2 * h) * d[1];
        if (!(fabs(dg) > 1e-6)) return -1;
        double step = g / dg;
        t -= step;
        if (fabs(step) < 1e-13) break;
    }
    *s = t;
    return isfinite(t) ? 0 : -1;
}

/* The measured surface's sag and the true one's along the measured axis at (x, y). */
static int heights(const frame *f, double x, double y, double *zm, double *zt)
{
    double fx, fy, s;
    if (f->r->cn->zsag(f->r->zf, x, y, zm, &fx, &fy) || along(f, x, y, *zm, &s)) return -1;
    *zt = *zm + s;
    return 0;
}

static double axial_D(double x, double y, double fx, double fy)
{
    double r = hypot(x, y), fr = (x * fx + y * fy) / r;
    return (CN_KERATO_N - 1) * 1e3 * fr / (r * sqrt(1 + fr * fr));
}

int tp_iso_report(const tp_run *r, tp_sag_fn sag, void *ctx, const rg_cornea *place,
                  tp_iso *out)
{
    static const double lo[TP_ISO_NZONE] = {0, 3, 6, 0}, hi[TP_ISO_NZONE] = {3, 6, 9, 6};
    memset(out, 0, sizeof *out);
    for (int k = 0; k < TP_ISO_NZONE; k++)
        out->z[k].mean_um = out->z[k].sd2_um = out->z[k].mean_D = out->z[k].sd2_D = NAN;
    if (!r->have_z || !r->zf || !sag || !place) return -1;
    const cn_zfit *z = r->zf;
    frame f = {.place = place, .sag = sag, .ctx = ctx, .r = r};
    rg_cornea mc;
    r->cn->cornea_from_params(r->rg, CN_BICONIC, &z->ref, r->g->cornea.trans, &mc);
    memcpy(f.R, mc.rot, sizeof f.R);
    memcpy(f.T, mc.trans, sizeof f.T);
    double zm0, zt0;
    if (heights(&f, 0, 0, &zm0, &zt0)) return -1;
    double s1[TP_ISO_NZONE] = {0}, s2[TP_ISO_NZONE] = {0}, p1[TP_ISO_NZONE] = {0},
           p2[TP_ISO_NZONE] = {0};
    int np[TP_ISO_NZONE] = {0}, all[TP_ISO_NZONE] = {0};
    const double step = 0.1, dd = 0.01;
    const int half = 45;
    for (int i = -half; i < half; i++)
        for (int j = -half; j < half; j++) {
            double x = (i + 0.5) * step, y = (j + 0.5) * step, d = 2 * hypot(x, y);
            if (d >= 9) continue;
            for (int k = 0; k < TP_ISO_NZONE; k++) all[k] += d >= lo[k] && d < hi[k];
            if (!r->cn->zcovered(z, x, y)) continue;
            double zm, zt, a[4], b[4];
            if (heights(&f, x, y, &zm, &zt) || heights(&f, x + dd, y, &a[0], &b[0]) ||
                heights(&f, x - dd, y, &a[1], &b[1]) || heights(&f, x, y + dd, &a[2], &b[2]) ||
                heights(&f, x, y - dd, &a[3], &b[3]))
                continue;
            /* toward the observer: height = -sag */
            double dh = ((zt - zt0) - (zm - zm0)) * 1e3;
            double mx, my, fm;
            r->cn->zsag(z, x, y, &fm, &mx, &my);
            double tx = (b[0] - b[1]) / (2 * dd), ty = (b[2] - b[3]) / (2 * dd);
            double dp = axial_D(x, y, mx, my) - axial_D(x, y, tx, ty);
            for (int k = 0; k < TP_ISO_NZONE; k++)
                if (d >= lo[k] && d < hi[k]) {
                    np[k]++;
                    s1[k] += dh;
                    s2[k] += dh * dh;
                    p1[k] += dp;
                    p2[k] += dp * dp;
                }
        }
    for (int k = 0; k < TP_ISO_NZONE; k++) {
        tp_iso_zone *q = &out->z[k];
        q->n = np[k];
        q->frac = all[k] ? (double)np[k] / all[k] : 0;
        if (!np[k]) continue;
        q->mean_um = s1[k] / np[k];
        q->sd2_um = 2 * sqrt(fmax(0, s2[k] / np[k] - q->mean_um * q->mean_um));
        q->mean_D = p1[k] / np[k];
        q->sd2_D = 2 * sqrt(fmax(0, p2[k] / np[k] - q->mean_D * q->mean_D));
    }
    return 0;
}

/* The sag of a rig cornea (its eye frame) with the cornea engine's cone, for the
 * report on a synthetic eye. */
int tp_truth_sag(void *ctx, double x, double y, double *z)
{
    const tp_truth *t = ctx;
    const rg_cornea *c = t->c;
    rg_target tg = {RG_T_HEIGHT, hypot(x, y), atan2(y, x)};
    double p[3], n[3], rel[3];
    char e[RG_ERRMAX];
    if (t->rg->cornea_point(c, &tg, p, n, e, sizeof e)) return -1;
    for (int i = 0; i < 3; i++) rel[i] = p[i] - c->trans[i];
    *z = c->rot[2] * rel[0] + c->rot[5] * rel[1] + c->rot[8] * rel[2];
    if (t->bump && t->bump->h > 0) {
        const cn_bump *b = t->bump;
        double bx = x - b->x0, by = y - b->y0;
        *z -= b->h * exp(-(bx * bx + by * by) / (2 * b->w * b->w));
    }
    return 0;
}
