/* fitcalc.c -- the --fit dialogue: a lens matrix from measured object/image distances
 * and magnifications by least squares (section 14; GSL, loaded from the fit module
 * only here), from the cardinal points (24), or from the nodal points and focal
 * lengths (26).  Texts in prompts/fit.txt. */
#include <math.h>
#include "calcio.h"
#include "dialogues.h"
#include "engine.h"
#include "prompts_fit.h"

#define FT(k) fit_prompts[FIT_##k]
#define CL(v) lm_clean(c->io, (v))

typedef struct fitdata { double x[PX_FIT_MAX], y[PX_FIT_MAX], m[PX_FIT_MAX]; int n; } fitdata;

static int measurement(calc *c, fitdata *d)
{
    int rc, i = d->n;
    if ((rc = calc_num(c, FT(X), FT(X_WHAT), 0, &d->x[i])) ||
        (rc = calc_num(c, FT(Y), FT(Y_WHAT), 0, &d->y[i])) ||
        (rc = calc_num(c, FT(M), FT(M_WHAT), LM_NONZERO, &d->m[i])))
        return rc;
    d->n++;
    return LM_GO;
}

/* Is some object distance different from the first?  A line through the points
 * (x, 1/m) needs two different x. */
static int distinct_x(const fitdata *d)
{
    for (int i = 1; i < d->n; i++)
        if (d->x[i] != d->x[0]) return 1;
    return 0;
}

static int least_squares(calc *c)
{
    static fitdata d;       /* 24 kB: too big for the stack of a sanitised build */
    px_linfit line;
    px_fit f;
    lm_mark m;
    int rc, more = 1;
    d.n = 0;
    /* a module that cannot be loaded is said before the first measurement */
    *(void **)&line = lm_engine_symbol("fit", "lm_fit_line");
    if (!line) return LM_FAIL;
    if ((rc = measurement(c, &d)) || (rc = measurement(c, &d))) return rc;
    while (d.n < PX_FIT_MAX) {
        /* "no more" with all object distances equal is refused: the answer that can
         * fix it is another measurement */
        calc_mark(c, &m);
        if ((rc = calc_yn(c, FT(MORE), FT(MORE_WHAT), &more))) return rc;
        if (!more && !distinct_x(&d)) {
            if ((rc = calc_reject(c, &m, NULL, FT(MORE), FT(AGAIN_MORE), FT(SAME_X), d.n,
                                  d.x[0])))
                return rc;
            continue;
        }
        if (!more) break;
        if ((rc = measurement(c, &d))) return rc;
    }
    if (more) calc_say(c, FT(TOO_MANY));
    if (px_fit_matrix(d.x, d.y, d.m, d.n, line, &f) != PX_OK) return calc_fail(c, FT(BAD));
    calc_say(c, FT(FITTED), d.n);
    calc_matrix(c, f.m);
    calc_say(c, FT(RESID), f.rss_cd, f.rss_ab);
    calc_say(c, FT(COND), f.max_condition);
    calc_power(c, FT(POWER), -f.m.c);
    return LM_GO;
}

static int ask_frame(calc *c, double *n1, double *n2, double *z1, double *z2)
{
    int rc;
    if ((rc = calc_index(c, FT(N1), FT(N1_WHAT), n1)) ||
        (rc = calc_index(c, FT(N2), FT(N2_WHAT), n2)) ||
        (rc = calc_num(c, FT(Z1), FT(Z1_WHAT), 0, z1)) ||
        (rc = calc_num(c, FT(Z2), FT(Z2_WHAT), 0, z2)))
        return rc;
    return LM_GO;
}

static int report(calc *c, int rc, px_mat m, double mismatch)
{
    if (rc != PX_OK) return calc_fail(c, FT(BAD));
    calc_say(c, FT(MATRIX));
    calc_matrix(c, m);
    calc_power(c, FT(POWER), -m.c);
    calc_say(c, FT(MISMATCH), mismatch);
    return LM_GO;
}

/* The four points are a group: a focal point on its principal point (a focal
 * length 0) is refused and the four asked again. */
static int from_cardinal(calc *c)
{
    double n1, n2, z1, z2, f1, f2, h1, h2, mis = 0;
    px_mat m;
    lm_mark mk;
    int rc;
    if ((rc = ask_frame(c, &n1, &n2, &z1, &z2))) return rc;
    for (;;) {
        calc_mark(c, &mk);
        if ((rc = calc_num(c, FT(ZF1), FT(ZF1_WHAT), 0, &f1)) ||
            (rc = calc_num(c, FT(ZF2), FT(ZF2_WHAT), 0, &f2)) ||
            (rc = calc_num(c, FT(ZH1), FT(ZH1_WHAT), 0, &h1)) ||
            (rc = calc_num(c, FT(ZH2), FT(ZH2_WHAT), 0, &h2)))
            return rc;
        if (f1 != h1 && f2 != h2) break;
        if ((rc = calc_reject(c, &mk, NULL, FT(ZF1), FT(AGAIN_CARDINAL), FT(SAME_POINT),
                              f1 == h1 ? FT(FIRST) : FT(SECOND), f1 == h1 ? f1 : f2)))
            return rc;
    }
    rc = px_matrix_from_cardinal(n1, n2, z1, z2, f1, f2, h1, h2, &m, &mis);
    return report(c, rc, m, mis);
}

/* Likewise a focal point (z1 - ffl, z2 + bfl) on its nodal point. */
static int from_nodal(calc *c)
{
    double n1, n2, z1, z2, zn1, zn2, ffl, bfl, h1 = 0, h2 = 0, mis = 0;
    px_mat m;
    lm_mark mk;
    int rc;
    if ((rc = ask_frame(c, &n1, &n2, &z1, &z2))) return rc;
    for (;;) {
        calc_mark(c, &mk);
        if ((rc = calc_num(c, FT(ZN1), FT(ZN1_WHAT), 0, &zn1)) ||
            (rc = calc_num(c, FT(ZN2), FT(ZN2_WHAT), 0, &zn2)) ||
            (rc = calc_num(c, FT(FFL), FT(FFL_WHAT), 0, &ffl)) ||
            (rc = calc_num(c, FT(BFL), FT(BFL_WHAT), 0, &bfl)))
            return rc;
        if (zn1 != z1 - ffl && zn2 != z2 + bfl) break;
        if ((rc = calc_reject(c, &mk, NULL, FT(ZN1), FT(AGAIN_NODAL), FT(SAME_NODAL),
                              zn1 == z1 - ffl ? FT(FIRST) : FT(SECOND),
                              zn1 == z1 - ffl ? zn1 : zn2)))
            return rc;
    }
    rc = px_matrix_from_nodal(n1, n2, z1, z2, zn1, zn2, ffl, bfl, &m, &h1, &h2, &mis);
    if ((rc = report(c, rc, m, mis))) return rc;
    calc_say(c, FT(PRINCIPAL), CL(h1), CL(h2));
    return LM_GO;
}

int lm_fit(lm_io *io)
{
    static const char *const kinds[] = {"lsq", "cardinal", "nodal", NULL};
    calc cc = {io, PX_CM, "cm"}, *c = &cc;
    int rc, k;
    if ((rc = calc_unit(c)) || (rc = calc_choice(c, FT(KIND), FT(KIND_WHAT), kinds, &k)) ||
        (rc = k == 0 ? least_squares(c) : k == 1 ? from_cardinal(c) : from_nodal(c)))
        return rc;
    return calc_done(c);
}
const char *lm_fit_example(void) { return FT(EXAMPLE); }
