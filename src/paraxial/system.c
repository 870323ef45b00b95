/* system.c -- a lens system built surface by surface: the matrix product twice (in
 * the original listing's order for the classic dialogue's bytes, and in
 * double-double for the accurate results), the elementary steps kept for condition
 * estimates, the sensitivity of any function of the matrix, and the listing-order
 * cardinal points and image planes (--original).  The afocal and focal-plane
 * decisions are made here, from the sensitivities, for both. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "paraxial.h"
#include "dd.h"

void px_system_init(px_system *s, double n_obj)
{
    memset(s, 0, sizeof *s);
    s->m = s->abs = s->hi = px_identity();
    s->n_obj = s->n_img = n_obj;
    s->cap = PX_INLINE_STEPS;
    if (!(n_obj > 0) || !isfinite(n_obj)) s->err = PX_BAD;
}

void px_system_free(px_system *s)
{
    free(s->heap);
    s->heap = NULL;
    s->cap = PX_INLINE_STEPS;
    s->nsteps = 0;
}

static const px_step *steps_of(const px_system *s) { return s->heap ? s->heap : s->inl; }

/* Record a step (before applying it: `pre` is the matrix it acts on). */
static int push_step(px_system *s, int refract, double e, double w)
{
    px_step *st;
    if (s->nsteps == s->cap) {
        int cap = 2 * s->cap;
        px_step *h = malloc((size_t)cap * sizeof *h);
        if (!h) return s->err = PX_NOMEM;
        memcpy(h, steps_of(s), (size_t)s->nsteps * sizeof *h);
        free(s->heap);
        s->heap = h;
        s->cap = cap;
    }
    st = s->heap ? &s->heap[s->nsteps] : &s->inl[s->nsteps];
    st->e = e;
    st->w = w;
    st->pre = s->hi;
    st->refract = refract;
    s->nsteps++;
    return PX_OK;
}

/* x += e*y on double-double matrix entries x, y (index 0..3 = a, b, c, d). */
static void dd_axpy(px_system *s, int x, int y, dd e)
{
    double *hi = &s->hi.a, *lo = &s->lo.a;
    dd r = dd_add((dd){hi[x], lo[x]}, dd_mul(e, (dd){hi[y], lo[y]}));
    hi[x] = r.hi;
    lo[x] = r.lo;
}

/* A translation by the reduced distance e (listing value t_listing). */
static int add_translation(px_system *s, dd e, double w, double t_listing)
{
    px_mat t = px_translation(t_listing);
    if (push_step(s, 0, dd_val(e), w)) return -1;
    s->m = px_mul(t, s->m);
    s->abs = px_mul_abs(t, s->abs);
    dd_axpy(s, 0, 2, e);   /* a += e*c */
    dd_axpy(s, 1, 3, e);   /* b += e*d */
    return PX_OK;
}

int px_system_translate(px_system *s, double z)
{
    dd e;
    if (!isfinite(z)) { s->err = PX_BAD; return -1; }
    if (s->nsurf == 0 && s->nsteps == 0) s->z_first = s->z_last = z;
    if (z < s->z_last) { s->err = PX_BAD; return -1; }
    if (!(z > s->z_last)) return 0;
    e = dd_div_d(dd_two_sum(z, -s->z_last), s->n_img);
    if (add_translation(s, e, (fabs(z) + fabs(s->z_last)) / s->n_img + fabs(e.hi),
                        (z - s->z_last) / s->n_img))
        return -1;
    s->z_last = z;
    return 1;
}

int px_system_gap(px_system *s, double t)
{
    dd e;
    if (!(t >= 0) || !isfinite(t)) return s->err = PX_BAD;
    if (t == 0) return PX_OK;
    e = dd_div_d(dd_of(t), s->n_img);
    if (add_translation(s, e, 2 * fabs(e.hi), t / s->n_img)) return s->err;
    s->z_last += t;
    return PX_OK;
}

int px_system_surface(px_system *s, double r, double n_right)
{
    px_mat refr;
    dd p = {0, 0};
    double w = 0;
    if (!(n_right > 0) || !isfinite(n_right) || isnan(r)) return s->err = PX_BAD;
    if (isfinite(r) && r != 0.0) {
        p = dd_div_d(dd_two_sum(s->n_img, -n_right), r);
        w = (s->n_img + n_right) / fabs(r) + fabs(p.hi);
    }
    if (push_step(s, 1, dd_val(p), w)) return s->err;
    refr = px_refraction(s->n_img, n_right, r);
    s->m = px_mul(refr, s->m);
    s->abs = px_mul_abs(refr, s->abs);
    dd_axpy(s, 2, 0, p);   /* c += p*a */
    dd_axpy(s, 3, 1, p);   /* d += p*b */
    s->n_img = n_right;
    s->nsurf++;
    return PX_OK;
}

px_mat px_system_refract(px_system *s, double r, double n_right)
{
    double n_left = s->n_img;
    if (px_system_surface(s, r, n_right)) return px_identity();
    return px_refraction(n_left, n_right, r);
}

/* dM/de_j = L_j * dE_j * R_j, L_j the steps after j, R_j = pre the ones before; dE_j
 * has one nonzero entry (b for a translation, c for a refraction). */
double px_sensitivity(const px_system *s, double ga, double gb, double gc, double gd)
{
    const px_step *st = steps_of(s);
    px_mat l = px_identity();
    double sum = 0;
    for (int j = s->nsteps - 1; j >= 0; j--) {
        const px_mat *r = &st[j].pre;
        double e = st[j].e, da, db, dc, dd_;
        if (st[j].refract) {
            da = l.b * r->a; db = l.b * r->b; dc = l.d * r->a; dd_ = l.d * r->b;
            l.a += l.b * e; l.c += l.d * e;
        } else {
            da = l.a * r->c; db = l.a * r->d; dc = l.c * r->c; dd_ = l.c * r->d;
            l.b += l.a * e; l.d += l.c * e;
        }
        sum += fabs(ga * da + gb * db + gc * dc + gd * dd_) * st[j].w;
    }
    return sum;
}

/* |C| below what the inputs' rounding (relative DBL_EPSILON/2 each, to first order)
 * can produce, with a factor 4 to spare: no significant digit of C is left. */
int px_is_afocal(const px_system *s)
{
    double c = s->hi.c + s->lo.c;
    return fabs(c) <= 2.0 * DBL_EPSILON * px_sensitivity(s, 0, 0, 1, 0);
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
    px_conj cj;

    out->dz_obj = dz;
    out->obj_t = px_translation(dz);
    if (px_conjugate(s, z_obj, &cj) == PX_AT_INFINITY) return PX_AT_INFINITY;
    out->d2 = -(a.a * dz + a.b) / (a.c * dz + a.d);
    out->z_img = s->z_last + out->d2 * s->n_img;
    out->img_t = px_translation(out->d2);
    out->obj_to_img = px_mul(out->img_t, px_mul(a, out->obj_t));
    out->mag = out->obj_to_img.a;
    return PX_OK;
}
