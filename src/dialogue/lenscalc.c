/* lenscalc.c -- the lens calculation dialogues: --thick (sections 8-10, 21, 23),
 * --thin (57), --gauss (4), --pair (56).  Texts in prompts/{thick,thin,gauss,pair}.txt;
 * arithmetic in the paraxial engine (calc_lens.c). */
#include <math.h>
#include "calcio.h"
#include "dialogues.h"
#include "prompts_thick.h"
#include "prompts_thin.h"
#include "prompts_gauss.h"
#include "prompts_pair.h"

#define TK(k) thick_prompts[THICK_##k]
#define TN(k) thin_prompts[THIN_##k]
#define GS(k) gauss_prompts[GAUSS_##k]
#define PR(k) pair_prompts[PAIR_##k]
#define CL(v) lm_clean(c->io, (v))

/* ---- --thick ---- */
/* Object planes: z may be -inf (a collimated beam: the image is in the second focal
 * plane and there is no height to ask); +inf is refused and asked again. */
static int thick_objects(calc *c, px_lens *l)
{
    int rc, more;
    if ((rc = calc_yn(c, TK(OBJECT_Q), TK(OBJECT_Q_WHAT), &more))) return rc;
    while (more) {
        double z, h;
        px_conj cj;
        lm_mark m;
        calc_mark(c, &m);
        if ((rc = calc_num(c, TK(OBJECT), TK(OBJECT_WHAT), LM_ALLOW_INF, &z))) return rc;
        if (z > 0 && isinf(z)) {
            if ((rc = calc_reject(c, &m, TK(OBJECT_WHAT), TK(OBJECT), TK(AGAIN_OBJECT), "%s",
                                  TK(PLUS_INF))))
                return rc;
            continue;
        }
        if (isinf(z)) {
            double zf2 = l->first.z_f2.v;
            calc_say(c, TK(IMAGE_AT_INF), CL(zf2),
                     zf2 >= l->sys.z_last ? TK(REAL) : TK(VIRTUAL));
        } else {
            if ((rc = calc_num(c, TK(HEIGHT), TK(HEIGHT_WHAT), 0, &h))) return rc;
            if (px_conjugate(&l->sys, z, &cj) == PX_OK)
                calc_say(c, TK(IMAGE), CL(cj.z_img.v),
                         cj.z_img.v >= l->sys.z_last ? TK(REAL) : TK(VIRTUAL),
                         CL(cj.lateral.v), CL(h * cj.lateral.v));
            else
                calc_say(c, TK(IMAGE_INF));
        }
        if ((rc = calc_yn(c, TK(ANOTHER), TK(OBJECT_Q_WHAT), &more))) return rc;
    }
    return LM_GO;
}

int lm_thick(lm_io *io)
{
    calc cc = {io, PX_CM, "cm"}, *c = &cc;
    double n1, r1, t, n, r2, n3;
    px_lens l;
    int rc;
    if ((rc = calc_unit(c)) ||
        (rc = calc_index(c, TK(N1), TK(N1_WHAT), &n1)) ||
        (rc = calc_num(c, TK(R1), TK(R1_WHAT), LM_ALLOW_PLANE, &r1)) ||
        (rc = calc_num(c, TK(T), TK(T_WHAT), LM_NONNEG, &t)) ||
        (rc = calc_index(c, TK(N), TK(N_WHAT), &n)) ||
        (rc = calc_num(c, TK(R2), TK(R2_WHAT), LM_ALLOW_PLANE, &r2)) ||
        (rc = calc_index(c, TK(N3), TK(N3_WHAT), &n3)))
        return rc;
    rc = px_thick_lens(n1, r1, t, n, r2, n3, &l);
    if (rc != PX_OK && rc != PX_AT_INFINITY) return LM_FAIL;
    rc = LM_GO;     /* PX_AT_INFINITY (afocal) is no dialogue outcome (found by the fuzzer) */
    calc_say(c, TK(SURFACES), t);
    calc_say(c, TK(MATRIX));
    calc_matrix(c, l.first.m);
    calc_power(c, TK(POWER), l.first.power.v);
    calc_power(c, TK(MAKER), l.maker_power);
    calc_power(c, TK(THIN), l.thin_power);
    if (l.first.afocal) {
        calc_say(c, TK(AFOCAL), CL(l.first.angular.v));
    } else {
        px_first *f = &l.first;
        calc_say(c, TK(FOCAL), CL(f->f_front.v), CL(f->f_back.v));
        calc_say(c, TK(DIST), CL(f->ffd.v), CL(f->bfd.v));
        calc_say(c, TK(POINTS), CL(f->z_f1.v), CL(f->z_h1.v), CL(f->z_n1.v), CL(f->z_h2.v),
                 CL(f->z_n2.v), CL(f->z_f2.v));
        rc = thick_objects(c, &l);
    }
    px_system_free(&l.sys);
    return rc ? rc : calc_done(c);
}
const char *lm_thick_example(void) { return TK(EXAMPLE); }

/* ---- --thin ---- */
/* A distance for the result line: %g, or "infinity" (an answer of inf is no number
 * to print: found by the dialogue fuzzer). */
static const char *thin_num(char *buf, size_t cap, double v)
{
    if (isinf(v)) snprintf(buf, cap, "%sinfinity", v < 0 ? "-" : "");
    else snprintf(buf, cap, "%g", v);
    return buf;
}

/* The object at infinity: the image is in the focal plane (di = f) and the lateral
 * magnification -di/do is not defined (it tends to 0); the image at infinity: no
 * magnification either.  Only a finite image of a finite object has a height. */
static int thin_finite(const px_thin *t) { return !isinf(t->d_o) && !isinf(t->d_i); }

static const char *thin_lens_kind(const px_thin *t)
{
    return t->power > 0 ? TN(CONV) : t->power < 0 ? TN(DIV) : TN(NONE);
}

static void thin_report(calc *c, const px_thin *t, int unknown, double h)
{
    char f[32], d_o[32], d_i[32];
    thin_num(f, sizeof f, CL(t->f));
    thin_num(d_o, sizeof d_o, CL(t->d_o));
    thin_num(d_i, sizeof d_i, CL(t->d_i));
    if (unknown == PX_THIN_NONE) calc_say(c, TN(SCRIPT), f, d_o, d_i);
    else calc_say(c, TN(RESULT), f, d_o, d_i);
    calc_power(c, TN(POWER), t->power);
    if (isinf(t->d_i)) { calc_say(c, TN(MAG_INF)); return; }
    if (isinf(t->d_o)) {
        calc_say(c, TN(OBJ_INF), t->d_i > 0 ? TN(REAL) : TN(VIRTUAL), thin_lens_kind(t));
        return;
    }
    calc_say(c, TN(MAG), CL(t->mag), CL(h * t->mag));
    calc_say(c, TN(KIND), t->d_i > 0 ? TN(REAL) : TN(VIRTUAL),
             t->mag < 0 ? TN(INVERTED) : TN(ERECT), thin_lens_kind(t));
}

int lm_thin(lm_io *io)
{
    static const char *const which[] = {"f", "do", "di", "none", NULL};
    calc cc = {io, PX_CM, "cm"}, *c = &cc;
    double f = 0, d_o = 0, d_i = 0, h = 0;
    int rc, u;
    px_thin t;
    if ((rc = calc_unit(c)) ||
        (rc = calc_choice(c, TN(UNKNOWN), TN(UNKNOWN_WHAT), which, &u)) ||
        (u != PX_THIN_F && (rc = calc_num(c, TN(F), TN(F_WHAT), LM_NONZERO | LM_ALLOW_INF, &f))) ||
        (u != PX_THIN_DO && (rc = calc_num(c, TN(DO), TN(DO_WHAT), LM_NONZERO | LM_ALLOW_INF, &d_o))) ||
        (u != PX_THIN_DI && (rc = calc_num(c, TN(DI), TN(DI_WHAT), LM_NONZERO | LM_ALLOW_INF, &d_i))))
        return rc;
    if (px_thin_equation(u, f, d_o, d_i, &t) == PX_BAD) return LM_FAIL;
    /* the height is asked only where it has an image height */
    if (thin_finite(&t) && (rc = calc_num(c, TN(H), TN(H_WHAT), 0, &h))) return rc;
    thin_report(c, &t, u, h);
    return calc_done(c);
}
const char *lm_thin_example(void) { return TN(EXAMPLE); }

/* ---- --gauss ---- */
int lm_gauss(lm_io *io)
{
    calc cc = {io, PX_CM, "cm"}, *c = &cc;
    double n1, n2, r, z1;
    px_gauss g;
    int rc, more = 1, first = 1;
    if ((rc = calc_unit(c)) ||
        (rc = calc_index(c, GS(N1), GS(N1_WHAT), &n1)) ||
        (rc = calc_index(c, GS(N2), GS(N2_WHAT), &n2)) ||
        (rc = calc_num(c, GS(R), GS(R_WHAT), LM_ALLOW_PLANE, &r)))
        return rc;
    while (more) {
        lm_mark m;
        calc_mark(c, &m);
        if ((rc = calc_num(c, GS(Z1), GS(Z1_WHAT), LM_NONZERO | LM_ALLOW_INF, &z1))) return rc;
        if (z1 > 0 && isinf(z1)) {
            if ((rc = calc_reject(c, &m, GS(Z1_WHAT), GS(Z1), GS(AGAIN_Z1), "%s", GS(PLUS_INF))))
                return rc;
            continue;
        }
        rc = px_gauss_surface(n1, n2, r, z1, &g);
        if (first) {
            calc_power(c, GS(POWER), g.power);
            if (isfinite(g.focal_obj) && isfinite(g.focal_img))
                calc_say(c, GS(FOCAL), CL(g.focal_obj), CL(g.focal_img));
            else    /* no power (a plane, or n1 = n2): found by the dialogue fuzzer */
                calc_say(c, GS(NO_FOCUS));
            first = 0;
        }
        if (rc == PX_OK && isinf(z1))     /* a collimated beam: no magnification */
            calc_say(c, GS(IMAGE_OBJ_INF), CL(g.z2), (g.z2 > 0) ? GS(REAL) : GS(VIRTUAL));
        else if (rc == PX_OK)
            calc_say(c, GS(IMAGE), CL(g.z2), (g.z2 > 0) ? GS(REAL) : GS(VIRTUAL), CL(g.mag));
        else
            calc_say(c, GS(IMAGE_INF));
        if ((rc = calc_yn(c, GS(ANOTHER), GS(ANOTHER_WHAT), &more))) return rc;
    }
    return calc_done(c);
}
const char *lm_gauss_example(void) { return GS(EXAMPLE); }

/* ---- --pair ---- */
int lm_pair(lm_io *io)
{
    calc cc = {io, PX_CM, "cm"}, *c = &cc;
    double f1, f2, t;
    px_pair p;
    int rc;
    if ((rc = calc_unit(c)) ||
        (rc = calc_num(c, PR(F1), PR(F1_WHAT), LM_NONZERO | LM_ALLOW_INF, &f1)) ||
        (rc = calc_num(c, PR(F2), PR(F2_WHAT), LM_NONZERO | LM_ALLOW_INF, &f2)) ||
        (rc = calc_num(c, PR(T), PR(T_WHAT), LM_NONNEG, &t)))
        return rc;
    rc = px_thin_pair(f1, f2, t, &p);
    if (rc == PX_BAD) return LM_FAIL;
    calc_say(c, PR(MATRIX));
    calc_matrix(c, p.m);
    calc_power(c, PR(POWER), p.power);
    calc_power(c, PR(SUM), (isinf(f1) ? 0 : 1 / f1) + (isinf(f2) ? 0 : 1 / f2));
    if (rc == PX_AT_INFINITY) {
        calc_say(c, PR(AFOCAL), CL(p.m.d));
    } else {
        calc_say(c, PR(F), CL(p.f));
        calc_say(c, PR(DIST), CL(p.ffd), CL(p.bfd));
        calc_say(c, PR(PLANES), CL(p.z_h1), CL(p.z_h2));
    }
    return calc_done(c);
}
const char *lm_pair_example(void) { return PR(EXAMPLE); }
