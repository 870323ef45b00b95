/* lex.h -- the answer lexer: splitting answer lines into tokens and parsing numbers
 * and yes/no answers.  Pure functions (no I/O), so they can be fuzzed directly. */
#ifndef LEX_H
#define LEX_H
#include <stddef.h>

#define LM_TOKEN_MAX 256

/* Skip a leading "input:" (what `grep input: rec` leaves) and blanks. */
const char *lm_line_start(const char *line);

/* Copy the next blank-separated token at *cur into tok and advance *cur.
 * Returns the token length, 0 at end of line, -1 if the token is too long
 * (it is then skipped). */
int lm_next_token(const char **cur, char *tok, size_t cap);

enum lm_num_status {
    LM_NUM_OK = 0,      /* a finite decimal number */
    LM_NUM_PLANE,       /* "inf", "infinity" or "plane": *v = +inf */
    LM_NUM_SYNTAX,      /* not a decimal number (abc, 1.2.3, 1,5, 0x10, ...) */
    LM_NUM_NAN,         /* nan */
    LM_NUM_RANGE        /* overflows a double, or beyond +-1e30 */
};
#define LM_NUM_LIMIT 1e30

enum lm_num_status lm_parse_number(const char *tok, double *v);
const char *lm_num_status_text(enum lm_num_status st);

/* y, n, yes, no (any case).  Returns 'y', 'n', or 0 for anything else. */
int lm_parse_yn(const char *tok);

/* The record's echo of a number: %g when that reads back as the same double (the
 * original's bytes), else %.17g so that a replay is exact. */
void lm_format_echo(double v, char *buf, size_t cap);

#endif
