/* calcio.h -- what the calculation dialogues (thick, thin, gauss, pair, magnifier,
 * microscope, telescope, fit, vision, cornea) share: the length unit, asking with
 * the question echoed to stdout and the record, and printing powers in diopters. */
#ifndef CALCIO_H
#define CALCIO_H
#include "ask.h"
#include "../paraxial/paraxial.h"

typedef struct calc {
    lm_io *io;
    px_unit unit;
    const char *uname;          /* "mm", "cm", "m" */
} calc;

int  calc_unit(calc *c);                                  /* asks mm, cm or m */
int  calc_num(calc *c, const char *q, const char *what, unsigned flags, double *v);
/* An index of refraction: a number > 0 or a medium's name (lm_ask_index). */
int  calc_index(calc *c, const char *q, const char *what, double *v);
/* Answers checked together (see lm_mark_set in ask.h): calc_mark before the first
 * question of the group; calc_reject when they do not go together: msg says why,
 * again which answers are asked again, first_q is the group's first question,
 * what names the answer(s) in messages (NULL: "these answers do not go together").
 * LM_GO on a terminal (ask the group again), LM_FAIL in a replay. */
void calc_mark(calc *c, lm_mark *m);
int  calc_reject(calc *c, const lm_mark *m, const char *what, const char *first_q,
                 const char *again, const char *fmt, ...);
int  calc_yn(calc *c, const char *q, const char *what, int *yes);
int  calc_choice(calc *c, const char *q, const char *what, const char *const *choices,
                 int *idx);
void calc_say(calc *c, const char *fmt, ...);             /* stdout and record */
void calc_power(calc *c, const char *label, double power); /* power in 1/unit */
void calc_matrix(calc *c, px_mat m);                      /* and its determinant */
int  calc_fail(calc *c, const char *msg);   /* inconsistent answers: say why, LM_FAIL */
int  calc_done(calc *c);                                  /* end of a dialogue */

#endif
