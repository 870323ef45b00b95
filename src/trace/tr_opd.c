/* tr_opd.c -- the wave aberration of rays aimed at the stop (the table's rx_opd): the
 * optical path of each aimed ray (tr_aim.c) carried from the image plane back or on
 * to the reference sphere, against the chief ray's.  The same construction as the
 * --pupil dialogue's RMS and peak-to-valley, here once for every engine that needs a
 * pupil's OPD (the wave engine's PSF and MTF). */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "tr_int.h"

typedef struct ref_sphere {
    int inf;
    double c[3], R, sign, n0, ni;
} ref_sphere;

/* The ray's optical path from its start (the object point, or the incoming plane
 * wavefront through the origin: rx_aim's paths start on the plane z = z_ref, the
 * ray's o . d added) to where it meets the sphere; NaN if it misses. */
static double path_to_sphere(const ref_sphere *s, const trace_aim_ray *r)
{
    double o = r->opl, pc[3], b, cc, disc;
    if (s->inf) o += s->n0 * (r->o[0] * r->d[0] + r->o[1] * r->d[1] + r->o[2] * r->d[2]);
    for (int k = 0; k < 3; k++) pc[k] = r->img[k] - s->c[k];
    b = r->img_dir[0] * pc[0] + r->img_dir[1] * pc[1] + r->img_dir[2] * pc[2];
    cc = pc[0] * pc[0] + pc[1] * pc[1] + pc[2] * pc[2] - s->R * s->R;
    disc = b * b - cc;
    if (disc < 0) return NAN;
    return o - s->ni * (b + s->sign * sqrt(disc));
}

int tr_rx_opd(const trace_rx *rx, const trace_aim_req *rq, int n, double z_xp, double lambda,
              double *w, int *st, trace_aim_ray *chief, double *R_ref, char *err,
              size_t errcap)
{
    trace_aim_ray c, r;
    ref_sphere s;
    double w0, t;
    int rc;
    if (!rx || !rq || n < 1 || !w || !(lambda > 0) || !isfinite(z_xp) || rx->nsurf < 1) {
        snprintf(err, errcap, "rx_opd: bad request (n %d, lambda %g, exit pupil at %g)", n,
                 lambda, z_xp);
        return TRACE_EINVAL;
    }
    if ((rc = tr_rx_aim(rx, &rq[0], &c, err, errcap)) != TRACE_OK) return rc;
    if (chief) *chief = c;
    if (c.status != TRACE_AIM_OK) {
        snprintf(err, errcap, "the chief ray does not pass (surface %d)", c.surface + 1);
        return TRACE_EINVAL;
    }
    /* after an odd number of mirrors the light runs -z (img_dir[2] < 0): the sphere's
     * construction holds either way, only a ray parallel to the image plane has none */
    if (c.img_dir[2] == 0 || !isfinite(c.img[2])) {
        snprintf(err, errcap, "the chief ray does not reach the image plane");
        return TRACE_EINVAL;
    }
    t = (z_xp - c.img[2]) / c.img_dir[2];
    if (!(fabs(t) > 0)) {
        snprintf(err, errcap, "the exit pupil lies on the image plane: no reference sphere");
        return TRACE_EINVAL;
    }
    memset(&s, 0, sizeof s);
    s.inf = rq[0].infinite;
    memcpy(s.c, c.img, sizeof s.c);
    s.R = fabs(t);
    s.sign = t < 0 ? 1 : -1;
    s.n0 = rx->n_object;
    s.ni = rx->surf[rx->nsurf - 1].n_right;
    if (R_ref) *R_ref = s.R;
    w0 = path_to_sphere(&s, &c);
    if (!isfinite(w0)) {
        snprintf(err, errcap, "the chief ray misses its own reference sphere");
        return TRACE_EINVAL;
    }
    w[0] = 0;
    if (st) st[0] = c.status;
    for (int i = 1; i < n; i++) {
        if ((rc = tr_rx_aim(rx, &rq[i], &r, err, errcap)) != TRACE_OK) return rc;
        if (st) st[i] = r.status;
        w[i] = r.status == TRACE_AIM_OK ? (w0 - path_to_sphere(&s, &r)) / lambda : NAN;
    }
    return TRACE_OK;
}
