/* beam.c -- the --beam dialogue (seed section 46, the rig's laser): a Gaussian beam's
 * waist, wavelength and M^2, then free-space gaps and thin lenses; at each plane the
 * beam radius, wavefront radius, the next waist and its Rayleigh range, from the q
 * parameter carried by the system matrix (the paraxial engine's matrices, in air) and
 * the wave module's beam_abcd; then the seed's trade-off, a beam small on two planes
 * at once (the cornea and the detector): the waist that balances them.  Texts in
 * prompts/beam.txt. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "calcio.h"
#include "dialogues.h"
#include "engine.h"
#include "../wave/wave.h"
#include "prompts_beam.h"

#define P(k) beam_prompts[BEAM_##k]
#define MAXEL 20

typedef struct count_ctx { int lo, hi, value; } count_ctx;
static int check_count(void *ctx, const char *w, char *msg, size_t cap)
{
    count_ctx *k = ctx;
    char *end;
    long v = strtol(w, &end, 10);
    if (end == w || *end || v < k->lo || v > k->hi) {
        snprintf(msg, cap, P(COUNT_BAD), w, k->lo, k->hi);
        return 1;
    }
    k->value = (int)v;
    return 0;
}

int lm_beam(lm_io *io)
{
    calc c = {io, PX_MM, "mm"};
    double nm, w0, m2, val[MAXEL];
    int kind[MAXEL], rc;
    count_ctx k = {0, MAXEL, 0};
    char buf[32], q[128];
    if ((rc = calc_unit(&c)) || (rc = calc_num(&c, P(LAMBDA), P(LAMBDA_WHAT), LM_POSITIVE, &nm)) ||
        (rc = calc_num(&c, P(WAIST), P(WAIST_WHAT), LM_POSITIVE, &w0)))
        return rc;
    for (;;) {
        lm_mark m;
        calc_mark(&c, &m);
        if ((rc = calc_num(&c, P(M2), P(M2_WHAT), LM_POSITIVE, &m2))) return rc;
        if (m2 >= 1) break;
        if ((rc = calc_reject(&c, &m, P(M2_WHAT), P(M2), P(AGAIN_M2), "%s", P(M2_BAD)))) return rc;
    }
    if ((rc = lm_ask_word(io, P(NEL), P(NEL), P(COUNT_WHAT), check_count, &k, buf, sizeof buf)))
        return rc;
    for (int i = 0; i < k.value; i++) {
        static const char *const kinds[] = {"d", "f", NULL};
        snprintf(q, sizeof q, P(KIND), i + 1);
        if ((rc = calc_choice(&c, q, P(KIND_WHAT), kinds, &kind[i]))) return rc;
        if (kind[i] == 0) {
            if ((rc = calc_num(&c, P(DIST), P(DIST_WHAT), LM_NONNEG, &val[i]))) return rc;
            continue;
        }
        for (;;) {
            lm_mark m;
            calc_mark(&c, &m);
            if ((rc = calc_num(&c, P(FOCAL), P(FOCAL_WHAT), 0, &val[i]))) return rc;
            if (val[i] != 0) break;
            if ((rc = calc_reject(&c, &m, P(FOCAL_WHAT), P(FOCAL), P(AGAIN_FOCAL), "%s",
                                  P(FOCAL_BAD))))
                return rc;
        }
    }
    double span;
    if ((rc = calc_num(&c, P(SPAN), P(SPAN_WHAT), LM_NONNEG, &span))) return rc;
    wave_get_api_fn get = (wave_get_api_fn)lm_engine_symbol("wave", WAVE_API_SYMBOL);
    const wave_api *wv = get ? get(WAVE_ABI) : NULL;
    if (!wv) return LM_FAIL;
    const char *u = c.uname;
    double lam = nm * 1e-9 / px_unit_meters(c.unit);      /* in the length unit */
    wave_beam b, o;
    if (wv->beam_at(w0, lam, m2, 0, &b) != WAVE_OK) return calc_fail(&c, P(WAIST_WHAT));
    calc_say(&c, P(HEAD), nm, m2);
    calc_say(&c, P(START), w0, u, b.zR, u, m2 * lam / (3.14159265358979323846 * w0) * 1e3);
    px_mat sys = px_identity();
    for (int i = 0; i < k.value; i++) {
        px_mat e = kind[i] == 0 ? px_translation(val[i]) : (px_mat){1, 0, -1 / val[i], 1};
        char el[64], rs[32];
        sys = px_mul(e, sys);
        double abcd[4] = {sys.a, sys.b, sys.c, sys.d};
        if (wv->beam_abcd(&b, lam, m2, abcd, &o) != WAVE_OK) return calc_fail(&c, "beam");
        if (kind[i] == 0) snprintf(el, sizeof el, P(EL_D), val[i], u);
        else snprintf(el, sizeof el, P(EL_F), val[i], u);
        if (isinf(o.R) || fabs(o.R) > 1e15) snprintf(rs, sizeof rs, "%s", P(FLAT));
        else snprintf(rs, sizeof rs, "%.6g %s", lm_clean(io, o.R), u);
        calc_say(&c, P(PLANE), i + 1, el, o.w, u, rs, o.w0, u, lm_clean(io, fabs(o.z_waist)), u,
                 o.z_waist >= 0 ? P(AFTER) : P(BEFORE), o.zR, u, lm_clean(io, sys.a),
                 lm_clean(io, sys.b), lm_clean(io, sys.c), lm_clean(io, sys.d));
    }
    if (span > 0) {
        /* w(L/2) for a waist midway is w0 sqrt(1 + (L / 2 zR)^2): smallest, d/dw0 = 0, at
         * zR = L/2, where it is sqrt 2 w0; the beam_at calls give the figures */
        double best = sqrt(m2 * lam * span / (2 * 3.14159265358979323846));
        wave_beam e, e1, e2;
        if (wv->beam_at(best, lam, m2, span / 2, &e) != WAVE_OK ||
            wv->beam_at(best / 2, lam, m2, span / 2, &e1) != WAVE_OK ||
            wv->beam_at(best * 2, lam, m2, span / 2, &e2) != WAVE_OK)
            return calc_fail(&c, P(SPAN_WHAT));
        calc_say(&c, P(BALANCE), span, u, best, u, e.w, u, e1.w, e2.w, u);
    }
    return calc_done(&c);
}
const char *lm_beam_example(void) { return P(EXAMPLE); }
