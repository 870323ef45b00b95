/* beam.c -- the --beam dialogue: a Gaussian beam (waist, wavelength, M^2) carried
 * through thin lenses, refracting surfaces and planes placed along the axis, its
 * radius, wavefront radius and new waist printed at each (section 46); mirrors are
 * unfolded (the cornea of the rig is a convex mirror).  Texts in
 * prompts/beam.txt; arithmetic in the paraxial engine (src/paraxial/beam.c). */
#include <math.h>
#include "calcio.h"
#include "dialogues.h"
#include "prompts_beam.h"

#define BM(k) beam_prompts[BEAM_##k]
#define CL(v) lm_clean(c->io, (v))

/* %g of a value, "inf" for an infinite one (a flat wavefront) */
static const char *num(calc *c, double v, char *buf, size_t n)
{
    if (isinf(v)) return BM(PLANE_R);
    snprintf(buf, n, "%g", CL(v));
    return buf;
}

static void say_at(calc *c, double z, const px_beam *b)
{
    px_beam_at at;
    char s1[40], s2[40], s3[40], s4[40];
    px_beam_props(b, &at);
    calc_say(c, BM(AT), num(c, z, s1, sizeof s1), num(c, at.w, s2, sizeof s2),
             num(c, at.r, s3, sizeof s3), num(c, at.gouy, s4, sizeof s4));
}

static void say_after(calc *c, double z, const px_beam *b)
{
    px_beam_at at;
    char s1[40], s2[40], s3[40], s4[40], s5[40];
    px_beam_props(b, &at);
    calc_say(c, BM(AFTER), num(c, b->n, s1, sizeof s1), num(c, at.w0, s2, sizeof s2),
             num(c, z + at.z_waist, s3, sizeof s3), num(c, at.zr, s4, sizeof s4),
             num(c, at.theta, s5, sizeof s5));
}

int lm_beam(lm_io *io)
{
    static const char *const kinds[] = {"lens", "surface", "mirror", "plane", "end", NULL};
    calc cc = {io, PX_MM, "mm"}, *c = &cc;
    double lnm, m2, n0, w0, zw, zprev;
    px_beam b;
    px_beam_at at;
    lm_mark mk;
    int rc;
    lm_say(io, LM_BOTH, "%s", BM(INTRO));
    if ((rc = calc_unit(c)) ||
        (rc = calc_num(c, BM(LAMBDA), BM(LAMBDA_WHAT), LM_POSITIVE, &lnm)))
        return rc;
    for (;;) {
        calc_mark(c, &mk);
        if ((rc = calc_num(c, BM(M2), BM(M2_WHAT), LM_POSITIVE, &m2))) return rc;
        if (m2 >= 1) break;
        if ((rc = calc_reject(c, &mk, BM(M2_WHAT), BM(M2), BM(AGAIN_M2), "%s", BM(M2_LOW))))
            return rc;
    }
    if ((rc = calc_index(c, BM(N0), BM(N0_WHAT), &n0)) ||
        (rc = calc_num(c, BM(W0), BM(W0_WHAT), LM_POSITIVE, &w0)) ||
        (rc = calc_num(c, BM(ZW), BM(ZW_WHAT), 0, &zw)))
        return rc;
    /* the wavelength in the answers' length unit: nm -> m -> unit */
    double lambda = lnm * 1e-9 / px_unit_meters(c->unit);
    if (px_beam_waist(w0, 0, lambda, m2, n0, &b) != PX_OK) return calc_fail(c, BM(NOT_BEAM));
    px_beam_props(&b, &at);
    {
        char s1[40], s2[40], s3[40];
        calc_say(c, BM(START), num(c, at.zr, s1, sizeof s1), num(c, at.theta, s2, sizeof s2),
                 num(c, 2 * at.zr, s3, sizeof s3));
    }
    zprev = zw;     /* the beam is known at its waist */
    int first = 1;
    for (;;) {
        int kind;
        double z, f = 0, r = 0, n2 = b.n;
        if ((rc = calc_choice(c, BM(ELEMENT), BM(ELEMENT_WHAT), kinds, &kind))) return rc;
        if (kind == 4) break;
        calc_mark(c, &mk);
        if ((rc = calc_num(c, BM(Z), BM(Z_WHAT), 0, &z))) return rc;
        if (kind == 0 && (rc = calc_num(c, BM(F), BM(F_WHAT), LM_ALLOW_INF, &f))) return rc;
        if (kind == 1 && ((rc = calc_num(c, BM(R), BM(R_WHAT), LM_ALLOW_PLANE, &r)) ||
                          (rc = calc_index(c, BM(N), BM(N_WHAT), &n2))))
            return rc;
        if (kind == 2 && (rc = calc_num(c, BM(RM), BM(R_WHAT), LM_ALLOW_PLANE, &r))) return rc;
        /* the first element may stand before the waist; later ones go left to right */
        const char *why = !first && z < zprev ? BM(Z_BACK) : kind == 0 && f == 0 ? BM(F_ZERO) : NULL;
        if (why) {
            if ((rc = calc_reject(c, &mk, BM(Z_WHAT), BM(Z), BM(AGAIN_Z), "%s", why))) return rc;
            continue;
        }
        px_beam nb = b;
        px_mat m = px_translation((z - zprev) / b.n);
        if (px_beam_apply(&nb, m, b.n) != PX_OK) return calc_fail(c, BM(NOT_BEAM));
        say_at(c, z, &nb);
        if (kind == 0) m = (px_mat){1, 0, isinf(f) ? 0 : -nb.n / f, 1};
        else if (kind == 1) m = px_refraction(nb.n, n2, r);
        else if (kind == 2) {
            /* unfolded: a mirror of radius r is a lens of power -2n/r (diverging when
               convex); the reflected beam stays in the same medium */
            m = (px_mat){1, 0, isinf(r) ? 0 : 2 * nb.n / r, 1};
            lm_say(c->io, LM_BOTH, "%s", BM(MIRROR_NOTE));
        } else m = px_identity();
        if (px_beam_apply(&nb, m, n2) != PX_OK) return calc_fail(c, BM(NOT_BEAM));
        if (kind != 3) say_after(c, z, &nb);
        b = nb;
        zprev = z;
        first = 0;
    }
    /* the seed's trade-off: the beam small on two planes L apart at once is smallest
       with its waist midway and zR = L/2 (w = sqrt 2 w0 on both); any other waist
       is larger on one of them */
    double span;
    if ((rc = calc_num(c, BM(SPAN), BM(SPAN_WHAT), LM_NONNEG, &span))) return rc;
    if (span > 0) {
        double n = b.n, wb = sqrt(m2 * lambda * span / (2 * 3.14159265358979323846 * n));
        double w_half, w_two;
        px_beam t;
        px_beam_at a;
        px_beam_waist(wb / 2, span / 2, lambda, m2, n, &t);
        px_beam_props(&t, &a);
        w_half = a.w;
        px_beam_waist(2 * wb, span / 2, lambda, m2, n, &t);
        px_beam_props(&t, &a);
        w_two = a.w;
        char s1[40], s2[40], s3[40], s4[40], s5[40], s6[40];
        calc_say(c, BM(BALANCE), num(c, span, s1, sizeof s1), num(c, n, s2, sizeof s2),
                 num(c, wb, s3, sizeof s3), num(c, sqrt(2) * wb, s4, sizeof s4),
                 num(c, w_half, s5, sizeof s5), num(c, w_two, s6, sizeof s6));
    }
    return calc_done(c);
}

const char *lm_beam_example(void) { return BM(EXAMPLE); }
