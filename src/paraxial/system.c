/* system.c -- a lens system built surface by surface, its cardinal points and the
 * image of an object plane.  Formulas are written in the original listing's order
 * (so the classic dialogue keeps its bytes); where the listing is wrong (nodal planes
 * for unequal media) or undefined (afocal systems, objects in the focal plane) this
 * file decides it, not the dialogue. */
#include <float.h>
#include <math.h>
#include "paraxial.h"

void px_system_init(px_system *s, double n_obj)
{
    s->m = px_identity();
    s->abs = px_identity();
    s->z_first = s->z_last = 0.0;
    s->n_obj = s->n_img = n_obj;
    s->nsurf = 0;
}

int px_system_translate(px_system *s, double z)
{
    px_mat t;
    if (s->nsurf == 0) s->z_first = s->z_last = z;
    if (!(z > s->z_last)) return 0;
    t = px_translation((z - s->z_last) / s->n_img);
    s->m = px_mul(t, s->m);
    s->abs = px_mul_abs(t, s->abs);
    s->z_last = z;
    return 1;
}

px_mat px_system_refract(px_system *s, double r, double n_right)
{
    px_mat refr = px_refraction(s->n_img, n_right, r);
    s->m = px_mul(refr, s->m);
    s->abs = px_mul_abs(refr, s->abs);
    s->n_img = n_right;
    s->nsurf++;
    return refr;
}

/* C is the sum of products whose magnitudes add up to abs.c; each of the nsurf
 * steps can add a rounding error of a few ulps of that sum.  A C below that bound
 * has no significant digit left: the system is afocal as far as double can tell. */
int px_is_afocal(const px_system *s)
{
    double bound = 4.0 * (s->nsurf + 1) * DBL_EPSILON * s->abs.c;
    return fabs(s->m.c) <= bound;
}

void px_cardinal_points(const px_system *s, int original, px_cardinal *out)
{
    const px_mat a = s->m;
    double z1 = s->z_first, z2 = s->z_last, n1 = s->n_obj, n2 = s->n_img;
    double x, y;

    y = (1. - a.a) / a.c;
    x = -(a.b + y * a.d) / (a.a + y * a.c);
    out->principal1 = z1 - x * n1;
    out->principal2 = z2 + y * n2;

    if (original || n1 == n2) {
        x = (1. - a.d) / a.c;
        y = -(a.a * x + a.b) / (a.c * x + a.d);
    } else {
        /* ray through N1 leaves N2 at the same angle: C*d1 + D = n2/n1 */
        x = (n2 / n1 - a.d) / a.c;
        y = -(a.a * x + a.b) * n1 / n2;
    }
    out->nodal1 = z1 - x * n1;
    out->nodal2 = z2 + y * n2;

    out->focal1 = z1 + (a.d / a.c) * n1;
    out->focal_dist1 = fabs(out->principal1 - out->focal1);
    out->focal2 = z2 - (a.a / a.c) * n2;
    out->focal_dist2 = fabs(out->principal2 - out->focal2);
}

int px_image_plane(const px_system *s, double z_obj, px_image *out)
{
    const px_mat a = s->m;
    double dz = (s->z_first - z_obj) / s->n_obj;
    double den = a.c * dz + a.d;
    /* den is zero within rounding: the object is in the first focal plane */
    double scale = fabs(s->abs.c * dz) + s->abs.d;

    out->dz_obj = dz;
    out->obj_t = px_translation(dz);
    if (fabs(den) <= 4.0 * (s->nsurf + 2) * DBL_EPSILON * scale)
        return PX_AT_INFINITY;
    out->d2 = -(a.a * dz + a.b) / den;
    out->z_img = s->z_last + out->d2 * s->n_img;
    out->img_t = px_translation(out->d2);
    out->obj_to_img = px_mul(out->img_t, px_mul(a, out->obj_t));
    out->mag = out->obj_to_img.a;
    return PX_OK;
}
