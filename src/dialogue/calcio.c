/* calcio.c -- shared asking and printing of the calculation dialogues; see calcio.h.
 * Texts in prompts/calc.txt. */
#include <stdarg.h>
#include <stdio.h>
#include "calcio.h"
#include "prompts_calc.h"

#define P(k) calc_prompts[CALC_##k]

int calc_unit(calc *c)
{
    static const char *const units[] = {"mm", "cm", "m", NULL};
    int i = 0, rc = lm_ask_choice(c->io, P(UNIT), P(UNIT), P(UNIT_WHAT), units, &i);
    if (rc) return rc;
    c->unit = (px_unit)i;
    c->uname = units[i];
    lm_say(c->io, LM_BOTH, P(UNIT_ECHO), c->uname);
    return LM_GO;
}

int calc_num(calc *c, const char *q, const char *what, unsigned flags, double *v)
{
    lm_numspec spec = {what, flags, 0};
    return lm_ask_number(c->io, q, q, &spec, v);
}

int calc_index(calc *c, const char *q, const char *what, double *v)
{
    lm_numspec spec = {what, LM_POSITIVE, 0};
    return lm_ask_index(c->io, q, q, &spec, v);
}

void calc_mark(calc *c, lm_mark *m) { lm_mark_set(c->io, m); }

int calc_reject(calc *c, const lm_mark *m, const char *what, const char *first_q,
                const char *again, const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return lm_mark_reject(c->io, m, what ? what : P(CHECK_WHAT), msg, again, first_q);
}

int calc_yn(calc *c, const char *q, const char *what, int *yes)
{
    return lm_ask_yn(c->io, q, q, what, yes);
}

int calc_choice(calc *c, const char *q, const char *what, const char *const *choices,
                int *idx)
{
    return lm_ask_choice(c->io, q, q, what, choices, idx);
}

void calc_say(calc *c, const char *fmt, ...)
{
    char buf[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    lm_say(c->io, LM_BOTH, "%s", buf);
}

void calc_power(calc *c, const char *label, double power)
{
    calc_say(c, P(POWER), label, lm_clean(c->io, power), c->uname,
             lm_clean(c->io, px_diopters(power, c->unit)));
}

void calc_matrix(calc *c, px_mat m)
{
    lm_matrix(c->io, LM_BOTH, P(MATRIX_ELEM), m.a, m.b, m.c, m.d);
    calc_say(c, P(DET), px_det_accurate(m));
}

int calc_fail(calc *c, const char *msg)
{
    lm_say(c->io, LM_BOTH, "%s", msg);
    fprintf(stderr, "lensmat: %s:%ld: %s", c->io->src, c->io->line, msg);
    return LM_FAIL;
}

int calc_done(calc *c)
{
    lm_check_leftover(c->io);
    lm_say(c->io, LM_OUT, P(WRITTEN_OUT), c->io->rec_shown);
    return LM_GO;
}
