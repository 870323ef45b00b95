/* beam.c -- Gaussian beams through the engine's system matrices (section 46): the
 * reduced complex beam parameter qhat = q/n, its ABCD transform and the beam's
 * radius, wavefront radius, waist and Rayleigh range at a plane.  See paraxial.h.
 *
 * Numerical care: Im(qhat') is formed as Im(qhat) / |C qhat + D|^2 (det = 1), never
 * as the difference a complex division would take, so the Rayleigh range stays
 * accurate to a few ulp through any chain of matrices; Re(qhat') uses fma for its
 * two products. */
#include <math.h>
#include "paraxial.h"

static const double PI = 3.14159265358979323846;

static int finite_pos(double v) { return isfinite(v) && v > 0; }

int px_beam_waist(double w0, double z_past, double lambda, double m2, double n,
                  px_beam *b)
{
    if (!finite_pos(w0) || !finite_pos(lambda) || !finite_pos(n) || !isfinite(z_past) ||
        !isfinite(m2) || m2 < 1)
        return PX_BAD;
    b->qre = z_past / n;
    b->qim = PI * w0 * w0 / (m2 * lambda);
    b->lambda = lambda;
    b->m2 = m2;
    b->n = n;
    return finite_pos(b->qim) ? PX_OK : PX_BAD;
}

int px_beam_local(double w, double r, double lambda, double m2, double n, px_beam *b)
{
    if (!finite_pos(w) || !finite_pos(lambda) || !finite_pos(n) || isnan(r) ||
        r == 0 || !isfinite(m2) || m2 < 1)
        return PX_BAD;
    /* 1/qhat = n/r - i M^2 lambda / (pi w^2) = u - i v;  qhat = (u + i v)/(u^2 + v^2) */
    double u = isinf(r) ? 0 : n / r;
    double v = m2 * lambda / (PI * w * w);
    double h = hypot(u, v);
    b->qre = (u / h) / h;
    b->qim = (v / h) / h;
    b->lambda = lambda;
    b->m2 = m2;
    b->n = n;
    return finite_pos(b->qim) && isfinite(b->qre) ? PX_OK : PX_BAD;
}

int px_beam_apply(px_beam *b, px_mat m, double n_out)
{
    double a = b->qre, q = b->qim;
    if (!finite_pos(n_out)) return PX_BAD;
    double dr = fma(m.c, a, m.d), di = m.c * q;             /* C qhat + D */
    double nr = fma(m.a, a, m.b), ni = m.a * q;             /* A qhat + B */
    double s = hypot(dr, di);
    if (!(s > 0) || !isfinite(s)) return PX_BAD;
    double det = px_det_accurate(m);
    /* (nr + i ni)(dr - i di) / s^2 */
    double re = (fma(nr, dr, ni * di) / s) / s;
    double im = ((q * det) / s) / s;
    if (!isfinite(re) || !finite_pos(im)) return PX_BAD;
    b->qre = re;
    b->qim = im;
    b->n = n_out;
    return PX_OK;
}

void px_beam_props(const px_beam *b, px_beam_at *at)
{
    double a = b->qre, q = b->qim, n = b->n;
    double h = hypot(a, q);
    /* w^2 = M^2 lambda (a^2 + q^2) / (pi q), in a form that neither overflows nor
     * loses the small term when |a| >> q */
    at->w = sqrt(b->m2 * b->lambda / PI) * h / sqrt(q);
    at->r = a == 0 ? INFINITY : n * (h / a) * h;
    at->z_waist = -n * a;
    at->w0 = sqrt(b->m2 * b->lambda * q / PI);
    at->zr = n * q;
    at->theta = b->m2 * b->lambda / (PI * n * at->w0);
    at->gouy = atan2(a, q);
}
