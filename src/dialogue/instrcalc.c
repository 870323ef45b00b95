/* instrcalc.c -- the instrument and eye dialogues: --magnifier (31.7-31.8),
 * --microscope (31.9-31.10, 58), --telescope (31.11-31.13), --vision (41, 57) and
 * --cornea (37).  Texts in prompts/NAME.txt; arithmetic in calc_instr.c/calc_lens.c. */
#include <math.h>
#include "calcio.h"
#include "dialogues.h"
#include "prompts_magnifier.h"
#include "prompts_microscope.h"
#include "prompts_telescope.h"
#include "prompts_vision.h"
#include "prompts_cornea.h"

#define MG(k) magnifier_prompts[MAGNIFIER_##k]
#define MS(k) microscope_prompts[MICROSCOPE_##k]
#define TS(k) telescope_prompts[TELESCOPE_##k]
#define VS(k) vision_prompts[VISION_##k]
#define CO(k) cornea_prompts[CORNEA_##k]
#define CL(v) lm_clean(c->io, (v))

int lm_magnifier(lm_io *io)
{
    calc cc = {io, PX_CM, "cm"}, *c = &cc;
    double f, b, d_o;
    px_magnifier m;
    int rc, more = 1;
    if ((rc = calc_unit(c)) ||
        (rc = calc_num(c, MG(F), MG(F_WHAT), LM_POSITIVE, &f)) ||
        (rc = calc_num(c, MG(B), MG(B_WHAT), LM_POSITIVE, &b)))
        return rc;
    while (more) {
        if ((rc = calc_num(c, MG(DO), MG(DO_WHAT), LM_POSITIVE, &d_o))) return rc;
        if (px_magnify(f, b, d_o, &m) == PX_AT_INFINITY) calc_say(c, MG(IMAGE_INF));
        else calc_say(c, MG(IMAGE), CL(m.d_i), CL(m.lateral));
        if (d_o > f) calc_say(c, MG(REAL));
        else calc_say(c, MG(ANGULAR), CL(m.angular));
        calc_say(c, MG(LIMIT), CL(m.angular_limit));
        calc_say(c, MG(BEST), CL(m.best_alpha), CL(m.best_d_o), CL(m.best_angular));
        if ((rc = calc_yn(c, MG(ANOTHER), MG(ANOTHER_WHAT), &more))) return rc;
    }
    return calc_done(c);
}
const char *lm_magnifier_example(void) { return MG(EXAMPLE); }

static int single_lens(calc *c)
{
    double r1, r2, t, n, b;
    px_lens l;
    int rc;
    if ((rc = calc_num(c, MS(R1), MS(R1_WHAT), LM_ALLOW_PLANE, &r1)) ||
        (rc = calc_num(c, MS(R2), MS(R2_WHAT), LM_ALLOW_PLANE, &r2)) ||
        (rc = calc_num(c, MS(T), MS(T_WHAT), LM_NONNEG, &t)) ||
        (rc = calc_index(c, MS(N), MS(N_WHAT), &n)) ||
        (rc = calc_num(c, MS(B), MS(B_WHAT), LM_POSITIVE, &b)))
        return rc;
    rc = px_thick_lens(1, r1, t, n, r2, 1, &l);
    if (rc != PX_OK && rc != PX_AT_INFINITY) return LM_FAIL;
    calc_power(c, MS(POWER), l.first.power.v);
    if (l.first.afocal) calc_say(c, MS(AFOCAL));
    else calc_say(c, MS(SINGLE), CL(l.first.efl.v), CL(b / l.first.efl.v));
    px_system_free(&l.sys);
    return LM_GO;
}

static int compound(calc *c)
{
    double fo, fe, tube, b;
    px_compound m;
    int rc;
    if ((rc = calc_num(c, MS(FO), MS(FO_WHAT), LM_POSITIVE, &fo)) ||
        (rc = calc_num(c, MS(FE), MS(FE_WHAT), LM_POSITIVE, &fe)) ||
        (rc = calc_num(c, MS(TUBE), MS(TUBE_WHAT), LM_POSITIVE, &tube)) ||
        (rc = calc_num(c, MS(B), MS(B_WHAT), LM_POSITIVE, &b)))
        return rc;
    px_compound_microscope(fo, fe, tube, b, &m);
    calc_say(c, MS(COMPOUND), CL(m.d_o), CL(m.m_objective), CL(m.m_eyepiece));
    calc_say(c, MS(TOTAL), CL(fabs(m.total)), MS(INVERTED), CL(m.length));
    return LM_GO;
}

int lm_microscope(lm_io *io)
{
    static const char *const kinds[] = {"single", "compound", NULL};
    calc cc = {io, PX_CM, "cm"}, *c = &cc;
    int rc, k;
    if ((rc = calc_unit(c)) || (rc = calc_choice(c, MS(KIND), MS(KIND_WHAT), kinds, &k)) ||
        (rc = k == 0 ? single_lens(c) : compound(c)))
        return rc;
    return calc_done(c);
}
const char *lm_microscope_example(void) { return MS(EXAMPLE); }

/* fo, then the group fe, d: Galileo's (negative) eyepiece must be weaker than the
 * objective (else the length fo + fe is not positive), and the erector lens is
 * offered for the astronomical telescope only (Galileo's is erect without one);
 * either is fixed by the eyepiece or the erector distance, so those are asked
 * again. */
static int telescope_answers(calc *c, double *fo, double *fe, double *d)
{
    int rc;
    lm_mark m;
    if ((rc = calc_num(c, TS(FO), TS(FO_WHAT), LM_POSITIVE, fo))) return rc;
    for (;;) {
        calc_mark(c, &m);
        if ((rc = calc_num(c, TS(FE), TS(FE_WHAT), LM_NONZERO, fe))) return rc;
        if (*fe < 0 && -*fe >= *fo) {
            if ((rc = calc_reject(c, &m, NULL, TS(FE), TS(AGAIN_FE), TS(BAD_GALILEO), -*fe, *fo)))
                return rc;
            continue;
        }
        if ((rc = calc_num(c, TS(D), TS(D_WHAT), LM_NONNEG, d))) return rc;
        if (*d > 0 && *fe < 0) {
            if ((rc = calc_reject(c, &m, NULL, TS(FE), TS(AGAIN_FE_D), TS(BAD_ERECTOR), *d, *fe)))
                return rc;
            continue;
        }
        return LM_GO;
    }
}

int lm_telescope(lm_io *io)
{
    calc cc = {io, PX_CM, "cm"}, *c = &cc;
    double fo, fe, d;
    px_telescope t;
    int rc;
    if ((rc = calc_unit(c)) || (rc = telescope_answers(c, &fo, &fe, &d))) return rc;
    if (px_telescope_make(fo, fe, d, &t) == PX_BAD) return LM_FAIL;   /* checked above */
    if (d > 0) calc_say(c, TS(TERR), t.erector_f);
    else calc_say(c, fe > 0 ? TS(ASTRO) : TS(GALILEO));
    calc_power(c, TS(OBJECTIVE), 1 / fo);
    calc_power(c, TS(EYEPIECE), 1 / fe);
    calc_say(c, TS(LENGTH), CL(t.length));
    calc_say(c, TS(MATRIX));
    /* C is zero within its rounding (that is what afocal means): print it as 0, not
     * as the 1e-17 of round-off the product leaves */
    calc_matrix(c, t.afocal ? (px_mat){t.m.a, t.m.b, 0.0, t.m.d} : t.m);
    if (t.afocal)
        calc_say(c, TS(AFOCAL), CL(t.angular), t.angular > 0 ? TS(ERECT) : TS(INVERTED),
                 CL(fo / fe));
    else calc_say(c, TS(NOT_AFOCAL), t.m.c);
    return calc_done(c);
}
const char *lm_telescope_example(void) { return TS(EXAMPLE); }

int lm_vision(lm_io *io)
{
    static const char *const kinds[] = {"near", "far", NULL};
    calc cc = {io, PX_CM, "cm"}, *c = &cc;
    double p, near, target, far;
    int rc, k;
    if ((rc = calc_unit(c)) || (rc = calc_choice(c, VS(KIND), VS(KIND_WHAT), kinds, &k)))
        return rc;
    if (k == 0) {
        if ((rc = calc_num(c, VS(NEAR), VS(NEAR_WHAT), LM_POSITIVE, &near)) ||
            (rc = calc_num(c, VS(TARGET), VS(TARGET_WHAT), LM_POSITIVE, &target)))
            return rc;
        p = px_vision_near(near, target);
    } else {
        if ((rc = calc_num(c, VS(FAR), VS(FAR_WHAT), LM_POSITIVE | LM_ALLOW_INF, &far)))
            return rc;
        p = px_vision_far(far);
    }
    calc_power(c, VS(POWER), p);
    calc_say(c, VS(F), p == 0 ? INFINITY : CL(1 / p),
             p > 0 ? VS(CONV) : p < 0 ? VS(DIV) : VS(NONE));
    return calc_done(c);
}
const char *lm_vision_example(void) { return VS(EXAMPLE); }

int lm_cornea(lm_io *io)
{
    static const char *const kinds[] = {"radius", "power", NULL};
    static const double n[2] = {PX_N_CORNEA, PX_N_KERATOMETRIC};
    calc cc = {io, PX_MM, "mm"}, *c = &cc;
    double v, dp, p[2], pdoc;
    int rc, k;
    if ((rc = calc_unit(c)) || (rc = calc_choice(c, CO(KIND), CO(KIND_WHAT), kinds, &k)) ||
        (rc = calc_num(c, k == 0 ? CO(R) : CO(P), k == 0 ? CO(R_WHAT) : CO(P_WHAT),
                       LM_POSITIVE, &v)) ||
        (rc = calc_num(c, CO(DP), CO(DP_WHAT), LM_NONNEG, &dp)))
        return rc;
    for (int i = 0; i < 2; i++) {
        if (k == 0) {
            p[i] = px_diopters(px_cornea_power(v, n[i]), c->unit);
            calc_say(c, CO(FROM_R), n[i], p[i]);
        } else {
            p[i] = v;
            calc_say(c, CO(FROM_P), n[i],
                     px_cornea_radius(px_power_of_diopters(v, c->unit), n[i]), c->uname);
        }
    }
    pdoc = k == 0 ? px_diopters(1 / (PX_N_CORNEA / (PX_N_CORNEA - 1) * v), c->unit) : v;
    if (k == 0) calc_say(c, CO(DOC_R), pdoc);
    else calc_say(c, CO(DOC_P),
                  px_cornea_doc_radius(px_power_of_diopters(v, c->unit), PX_N_CORNEA), c->uname);
    for (int i = 0; i < 2; i++)
        calc_say(c, CO(DR), n[i], dp,
                 px_cornea_dradius(px_power_of_diopters(p[i], c->unit),
                                   px_power_of_diopters(dp, c->unit), n[i]), c->uname);
    calc_say(c, CO(DOC_DR), px_cornea_doc_dradius(px_power_of_diopters(pdoc, c->unit),
                                                  px_power_of_diopters(dp, c->unit),
                                                  PX_N_CORNEA), c->uname);
    return calc_done(c);
}
const char *lm_cornea_example(void) { return CO(EXAMPLE); }
