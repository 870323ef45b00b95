/* pupil.c -- first-order pupil data of a prescription by thickness at one wavelength:
 * entrance and exit pupils (the stop's images in object and image space), the
 * marginal and chief rays at every surface (y-nu trace), the paraxial image plane and
 * image height, f-numbers, numerical apertures and the Lagrange invariant.
 *
 * Every paraxial ray is a linear combination of two base rays that start at surface
 * 1: A (height 1, slope 0) and B (height 0, slope 1).  With their heights yA, yB at
 * the stop, the ray through the stop's centre is (a, b) = (yB, -yA): its object-space
 * line crosses the axis at z = -a/b = yB/yA (the entrance pupil), and so on.  Two
 * traces give everything; each quantity is then a ratio formed once. */
#include <float.h>
#include <math.h>
#include <string.h>
#include "paraxial.h"

#define DEG (3.14159265358979323846 / 180)

/* y-nu trace of the ray (y1 at surface 1, slope u0 before it). */
static void trace(const px_pupil *p, const px_csurf *s, double y1, double u0, double *y,
                  double *u)
{
    double yy = y1, uu = u0;
    u[0] = u0;
    for (int k = 0; k < p->nsurf; k++) {
        double c = (s[k].r == 0 || isinf(s[k].r)) ? 0 : 1 / s[k].r;
        double n = p->n[k], n2 = p->n[k + 1];
        y[k] = yy;
        uu = (n * uu - yy * c * (n2 - n)) / n2;
        u[k + 1] = uu;
        if (k + 1 < p->nsurf) yy += s[k].t * uu;
    }
}

static int refuse(px_pupil *out, int code, const char *why)
{
    out->why = why;
    return code;
}

/* Indices, vertices and the focal length; PX_OK or a refusal. */
static int setup(const px_pupil_in *in, px_pupil *out)
{
    px_system sys;
    px_first f;
    int r;
    if (!in->s || in->nsurf < 1 || in->nsurf > PX_PUPIL_MAXSURF)
        return refuse(out, PX_BAD, "a prescription needs 1 to 64 surfaces");
    if (in->stop < 0 || in->stop >= in->nsurf)
        return refuse(out, PX_BAD, "the stop is not one of the surfaces");
    if (!(in->ap_value > 0) || !isfinite(in->ap_value))
        return refuse(out, PX_BAD, "the aperture must be a positive number");
    if (isnan(in->obj_dist) || in->obj_dist == -INFINITY || !isfinite(in->field))
        return refuse(out, PX_BAD, "the object distance or field is not a number");
    if (isinf(in->obj_dist) && !(fabs(in->field) < 90))
        return refuse(out, PX_BAD, "a field angle lies strictly between -90 and 90 degrees");
    out->nsurf = in->nsurf;
    out->stop = in->stop;
    if (px_glass_index(in->obj_glass, in->lambda, &out->n[0]) != PX_OK)
        return refuse(out, PX_BAD, "the object medium has no index at this wavelength");
    px_system_init(&sys, out->n[0]);
    for (int k = 0; k < in->nsurf; k++) {
        const px_csurf *s = &in->s[k];
        if (px_glass_index(s->glass, in->lambda, &out->n[k + 1]) != PX_OK) {
            px_system_free(&sys);
            return refuse(out, PX_BAD, "a glass has no index at this wavelength");
        }
        out->z[k] = k ? out->z[k - 1] + in->s[k - 1].t : 0;
        if ((k && px_system_gap(&sys, in->s[k - 1].t) != PX_OK) || isnan(s->r) ||
            px_system_surface(&sys, s->r == 0 ? INFINITY : s->r, out->n[k + 1]) != PX_OK) {
            px_system_free(&sys);
            return refuse(out, PX_BAD, "a thickness is negative or a radius not a number");
        }
    }
    r = px_first_order(&sys, &f);
    px_system_free(&sys);
    if (r != PX_OK) return refuse(out, PX_BAD, "the system's matrix failed");
    if (f.afocal)
        return refuse(out, PX_AT_INFINITY, "the system is afocal (no power): it has no "
                      "image plane, focal length or f-number; give it a focusing lens");
    out->efl = f.efl.v;
    return PX_OK;
}

int px_pupil_run(const px_pupil_in *in, px_pupil *out)
{
    double yA[PX_PUPIL_MAXSURF], uA[PX_PUPIL_MAXSURF + 1];
    double yB[PX_PUPIL_MAXSURF], uB[PX_PUPIL_MAXSURF + 1];
    double L = in->obj_dist, scale, ya, yb, ma, mb, ca, cb, g = 0;
    int N, S, inf = isinf(in->obj_dist), r;

    memset(out, 0, sizeof *out);
    out->why = "";
    if ((r = setup(in, out)) != PX_OK) return r;
    N = out->nsurf - 1;
    S = out->stop;
    trace(out, in->s, 1, 0, yA, uA);
    trace(out, in->s, 0, 1, yB, uB);
    ya = yA[S];
    yb = yB[S];
    /* the system's length scale, for deciding when a pupil is at infinity */
    scale = fmax(fabs(out->z[N]), fabs(out->efl));
    if (!inf) scale = fmax(scale, fabs(L));

    /* entrance pupil: where the ray through the stop's centre (yB, -yA) crosses the
     * axis in object space */
    if (fabs(ya) * 1e12 * scale <= fabs(yb)) out->z_ep = INFINITY;
    else out->z_ep = yb / ya;

    /* the marginal ray (ma at surface 1, slope mb) */
    if (inf) {
        if (isinf(out->z_ep))
            return refuse(out, PX_NO_PUPIL, "the stop lies in the focal plane of the "
                          "lenses before it: an object at infinity is imaged onto it, "
                          "so no marginal ray reaches its rim (move the stop or give a "
                          "finite object)");
        mb = 0;
        switch (in->aperture) {
        case PX_AP_EPD: ma = in->ap_value / 2; break;
        case PX_AP_FNUM: ma = fabs(out->efl) / (2 * in->ap_value); break;
        case PX_AP_STOP: ma = in->ap_value / fabs(ya); break;
        default:
            return refuse(out, PX_BAD, "an object-space NA needs a finite object");
        }
    } else {
        double epd = in->aperture == PX_AP_FNUM ? fabs(out->efl) / in->ap_value
                                                 : in->ap_value;
        g = L * ya + yb;     /* the stop height of the ray from the axial object point */
        if (fabs(g) <= 1e-12 * (fabs(L * ya) + fabs(yb)) || g == 0)
            return refuse(out, PX_NO_PUPIL, "the stop is conjugate to the object (the "
                          "marginal ray's height at the stop is zero): move the stop or "
                          "the object");
        switch (in->aperture) {
        case PX_AP_EPD:
        case PX_AP_FNUM:
            if (isinf(out->z_ep))
                return refuse(out, PX_NO_PUPIL, "the entrance pupil is at infinity "
                              "(telecentric in object space): give the aperture as an "
                              "NA or the stop's size, not a pupil diameter or f-number");
            mb = epd / 2 / (out->z_ep + L);
            break;
        case PX_AP_NA:
            if (!(in->ap_value < out->n[0]))
                return refuse(out, PX_BAD, "an NA must be smaller than the object "
                              "medium's index");
            mb = in->ap_value / out->n[0];
            break;
        case PX_AP_STOP: mb = in->ap_value / g; break;
        default: return refuse(out, PX_BAD, "unknown aperture type");
        }
        mb = fabs(mb);
        ma = mb * L;
    }

    /* the chief ray: through the stop's centre and the edge of the field */
    if (inf) {
        cb = tan(in->field * DEG);
        ca = -out->z_ep * cb;
    } else {
        cb = -in->field * ya / g;
        ca = in->field + cb * L;
    }
    for (int k = 0; k <= N; k++) {
        out->y[k] = ma * yA[k] + mb * yB[k];
        out->yb[k] = ca * yA[k] + cb * yB[k];
    }
    for (int k = 0; k <= N + 1; k++) {
        out->u[k] = ma * uA[k] + mb * uB[k];
        out->ub[k] = ca * uA[k] + cb * uB[k];
    }
    out->r_stop = fabs(out->y[S]);
    out->r_ep = isinf(out->z_ep) ? INFINITY : fabs(ma + mb * out->z_ep);

    /* exit pupil: the ray through the stop's centre in image space */
    {
        double py = yb * yA[N] - ya * yB[N], pu = yb * uA[N + 1] - ya * uB[N + 1];
        if (fabs(pu) * 1e12 * scale <= fabs(py) || pu == 0) {
            out->z_xp = INFINITY;
            out->r_xp = INFINITY;
        } else {
            out->z_xp = out->z[N] - py / pu;
            out->r_xp = fabs(out->y[N] + out->u[N + 1] * (out->z_xp - out->z[N]));
        }
    }

    /* image plane: where the marginal ray meets the axis */
    {
        double y = out->y[N], u = out->u[N + 1], ni = out->n[N + 1];
        out->na_obj = inf ? 0 : out->n[0] * fabs(mb);
        out->na_img = ni * fabs(u);
        if (fabs(u) * 1e12 * scale <= fabs(y) || u == 0) {
            out->z_img = INFINITY;
            out->h_img = NAN;
            out->work_fnum = INFINITY;
            out->mag = INFINITY;
        } else {
            out->z_img = out->z[N] - y / u;
            out->h_img = out->yb[N] + out->ub[N + 1] * (out->z_img - out->z[N]);
            out->work_fnum = 1 / (2 * ni * fabs(u));
            out->mag = inf ? 0 : out->n[0] * mb / (ni * u);
        }
    }
    out->fnum = isinf(out->r_ep) ? NAN : fabs(out->efl) / (2 * out->r_ep);
    out->lagrange = out->n[0] * (out->ub[0] * out->y[0] - out->u[0] * out->yb[0]);
    return PX_OK;
}
