/* scene_lex.c -- the line and token reader the trace front end's readers share: lines
 * with '#' comments, items split on blanks, numbers checked to one range, every error
 * as "FILE:LINE: what" (scene_int.h).  Plain C on a buffer: fuzzed with the readers. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "scene_int.h"

/* ---- lines and tokens --------------------------------------------------------- */



int sl_fail(reader *r, const char *fmt, ...)
{
    va_list ap;
    int k = snprintf(r->err, SC_ERRMAX, "%s:%ld: ", r->name, r->line);
    if (k < 0 || k >= SC_ERRMAX) k = 0;
    va_start(ap, fmt);
    vsnprintf(r->err + k, SC_ERRMAX - k, fmt, ap);
    va_end(ap);
    return -1;
}

static int is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/* Next line with at least one item (comments and blank lines skipped).  1 with the
 * items in r->t, 0 at the end, -1 on an error. */
int sl_next_line(reader *r)
{
    while (r->p < r->end) {
        const char *nl = memchr(r->p, '\n', (size_t)(r->end - r->p));
        const char *e = nl ? nl : r->end, *q = r->p;
        r->line++;
        r->p = nl ? nl + 1 : r->end;
        r->nt = 0;
        if (memchr(q, '\0', (size_t)(e - q)))
            return sl_fail(r, "a NUL byte: this is not a text file");
        while (q < e) {
            const char *b;
            while (q < e && is_blank(*q)) q++;
            if (q == e || *q == '#') break;
            b = q;
            while (q < e && !is_blank(*q) && *q != '#') q++;
            if (r->nt == MAXTOK) return sl_fail(r, "more than %d items on one line", MAXTOK);
            r->t[r->nt].s = b;
            r->t[r->nt].n = (size_t)(q - b);
            r->nt++;
        }
        if (r->nt) return 1;
    }
    return 0;
}

int sl_tok_is(const tok *t, const char *w) { return strlen(w) == t->n && !memcmp(t->s, w, t->n); }

/* A finite decimal number (no hex, inf or nan).  0 or -1 (error reported). */
int sl_tok_num(reader *r, const tok *t, const char *what, double *v)
{
    char buf[NUMLEN], *end;
    size_t i;
    if (t->n >= NUMLEN) return sl_fail(r, "%s: '%.20s...' is too long for a number", what, t->s);
    memcpy(buf, t->s, t->n);
    buf[t->n] = '\0';
    for (i = 0; i < t->n; i++)
        if (!strchr("0123456789+-.eE", buf[i])) break;
    if (i < t->n || !t->n) {
        if (!strncmp(buf, "nan", 3) || !strncmp(buf, "NaN", 3) || !strncmp(buf, "-nan", 4))
            return sl_fail(r, "%s: '%s': NaN is not a number", what, buf);
        if (strstr(buf, "inf") || strstr(buf, "Inf"))
            return sl_fail(r, "%s: '%s': infinite values are not allowed", what, buf);
        return sl_fail(r, "%s: '%s' is not a number", what, buf);
    }
    errno = 0;
    *v = strtod(buf, &end);
    if (end != buf + t->n) return sl_fail(r, "%s: '%s' is not a number", what, buf);
    if (errno == ERANGE && fabs(*v) > 1) return sl_fail(r, "%s: '%s' is out of range", what, buf);
    if (!isfinite(*v) || fabs(*v) > 1e30)
        return sl_fail(r, "%s: '%s' is out of range (|x| <= 1e30)", what, buf);
    /* one range for every number: 0, or 1e-30 <= |x| <= 1e30 (squares and products
     * of lengths then neither underflow nor overflow; see README, Conventions) */
    if ((*v != 0 && fabs(*v) < 1e-30) || (*v == 0 && errno == ERANGE))
        return sl_fail(r, "%s: '%s' is out of range (0, or 1e-30 <= |x| <= 1e30)", what, buf);
    return 0;
}

/* Read the whole line as exactly n numbers. */
int sl_line_nums(reader *r, int n, const char *what, double *v)
{
    if (r->nt != n)
        return sl_fail(r, "expected %d numbers (%s), found %d item%s", n, what, r->nt,
                    r->nt == 1 ? "" : "s");
    for (int i = 0; i < n; i++)
        if (sl_tok_num(r, &r->t[i], what, &v[i])) return -1;
    return 0;
}

void sl_reader_init(reader *r, const char *text, size_t len, const char *name,
                        char *err)
{
    memset(r, 0, sizeof *r);
    r->p = text;
    r->end = text + len;
    r->name = name;
    r->err = err;
    err[0] = '\0';
}


int sl_dvec_push(dvec *a, const double *x, size_t k)
{
    if (a->n + k > a->cap) {
        size_t cap = a->cap ? a->cap * 2 : 256;
        double *v;
        while (cap < a->n + k) cap *= 2;
        v = realloc(a->v, cap * sizeof *v);
        if (!v) return -1;
        a->v = v;
        a->cap = cap;
    }
    memcpy(a->v + a->n, x, k * sizeof *x);
    a->n += k;
    return 0;
}
