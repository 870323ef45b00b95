/* lens_text.h -- PRIVATE to src/lens: what the readers and writers share: a growing
 * text buffer, notes, line splitting and number parsing. */
#ifndef LENS_TEXT_H
#define LENS_TEXT_H
#include <stdarg.h>
#include <stddef.h>
#include "lens.h"

typedef struct ln_buf { char *s; size_t len, cap; int err; } ln_buf;
void ln_buf_printf(ln_buf *b, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
/* b's text (malloc'd), or NULL (freed) if a printf ran out of memory. */
char *ln_buf_done(ln_buf *b);
/* "SRC:LINE: " and the message into err (cap bytes); returns LN_BAD (the readers'
 * one way to refuse a line). */
int ln_vfail(char *err, size_t cap, const char *src, long line, const char *fmt,
             va_list ap);
void ln_note(ln_notes *n, const char *src, long line, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* A decimal number filling the whole token (no hex, no nan; "inf", "-inf",
 * "infinity" only with allow_inf).  1 with *v set, else 0. */
int ln_parse_number(const char *tok, int allow_inf, double *v);

/* A title from n bytes of src: control bytes become blanks, blanks trimmed at both
 * ends, at most LN_TITLE_MAX - 1 bytes (so every writer's title reads back). */
void ln_title(char *dst, const char *src, size_t n);

/* A number or a model glass ND/VD in its shortest spelling (1.50 is 1.5, 1.6/40.0
 * is 1.6/40), in place (g holds LN_NAME_MAX), so every writer spells it the same. */
void ln_glass_spelling(char *g);

#define LN_TOK_MAX 256
#define LN_TOKS (LN_FIELD_MAX + 16)   /* a field line: 64 fields, its two words */
/* Split a line (modified in place: blanks become NULs; '#' ends it when hash) into at
 * most max tokens; the count, or -1 if there are more or one is too long. */
int ln_split(char *line, int hash, char **tok, int max);
#endif
