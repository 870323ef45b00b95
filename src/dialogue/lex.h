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

/* A word answer (a file name) at *cur: a blank-free word as lm_next_token reads it,
 * or a quoted one, "..." or '...', which may hold blanks; inside quotes \\, \",
 * \' and \xHH (a byte in hex) are escapes, any other backslash is itself.  Quotes
 * count only at the start of a word (a"b is the three bytes a"b).  Returns 1 (a word
 * in tok, possibly empty: ""), 0 at end of line, -1 too long for cap (skipped), -2
 * an unterminated quote, -3 a \x00 escape (no name holds a NUL byte; the rest of the
 * line is skipped). */
int lm_next_word(const char **cur, char *tok, size_t cap);
/* The form of `word` that lm_next_word reads back as it: the word itself when it has
 * no blank, control byte or leading quote and is not empty (so plain names keep
 * their bytes), else "..." with \\, \" and \xHH escapes.  cap >= 4 * strlen + 3
 * always suffices; returns the length written, or -1 if cap is too small. */
int lm_quote_word(const char *word, char *out, size_t cap);
/* `s` for a message: control bytes, DEL, C1 controls and bytes that are not UTF-8
 * written as \xHH, so no answer can put escape sequences on a terminal; always
 * NUL-terminated (cut if cap is too small). */
void lm_escape(const char *s, char *out, size_t cap);

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
