/* lens_text.c -- the readers' and writers' shared helpers: a growing text buffer,
 * notes, line splitting and strict number parsing. */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "lens_text.h"

int ln_vfail(char *err, size_t cap, const char *src, long line, const char *fmt,
             va_list ap)
{
    char why[LN_ERR_MAX];
    vsnprintf(why, sizeof why, fmt, ap);
    snprintf(err, cap, "%s:%ld: %s", src, line, why);
    return LN_BAD;
}

static void vput(char **s, size_t *len, size_t *cap, int *err, const char *fmt, va_list ap)
{
    va_list aq;
    int n;
    if (*err) return;
    va_copy(aq, ap);
    n = vsnprintf(NULL, 0, fmt, aq);
    va_end(aq);
    if (n < 0) { *err = 1; return; }
    if (*len + (size_t)n + 1 > *cap) {
        size_t c = (*cap + (size_t)n + 1) * 2;
        char *t = realloc(*s, c);
        if (!t) { *err = 1; return; }
        *s = t;
        *cap = c;
    }
    vsnprintf(*s + *len, *cap - *len, fmt, ap);
    *len += (size_t)n;
}

void ln_buf_printf(ln_buf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vput(&b->s, &b->len, &b->cap, &b->err, fmt, ap);
    va_end(ap);
}

char *ln_buf_done(ln_buf *b)
{
    if (b->err) { free(b->s); b->s = NULL; return NULL; }
    if (!b->s) { b->s = malloc(1); if (b->s) b->s[0] = '\0'; }
    return b->s;
}

void ln_note(ln_notes *n, const char *src, long line, const char *fmt, ...)
{
    va_list ap;
    char msg[LN_ERR_MAX], head[LN_ERR_MAX + 300];
    size_t k;
    if (!n) return;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (line > 0) snprintf(head, sizeof head, "%s:%ld: %s\n", src, line, msg);
    else snprintf(head, sizeof head, "%s: %s\n", src, msg);
    k = strlen(head);
    if (n->len + k + 1 > n->cap) {
        size_t c = (n->cap + k + 1) * 2;
        char *t = realloc(n->s, c);
        if (!t) return;                     /* a note lost to memory, not the lens */
        n->s = t;
        n->cap = c;
    }
    memcpy(n->s + n->len, head, k + 1);
    n->len += k;
    n->n++;
}

int ln_parse_number(const char *tok, int allow_inf, double *v)
{
    const char *p = tok, *word = (*tok == '+' || *tok == '-') ? tok + 1 : tok;
    char *end;
    int digits = 0;
    if (!strcasecmp(word, "inf") || !strcasecmp(word, "infinity")) {
        if (!allow_inf) return 0;
        *v = *tok == '-' ? -INFINITY : INFINITY;
        return 1;
    }
    /* [+-] digits [. digits] [e [+-] digits]: what strtod takes, minus hex and words */
    if (*p == '+' || *p == '-') p++;
    while (isdigit((unsigned char)*p)) p++, digits++;
    if (*p == '.') for (p++; isdigit((unsigned char)*p); p++) digits++;
    if (!digits) return 0;
    if (*p == 'e' || *p == 'E') {
        p++;
        if (*p == '+' || *p == '-') p++;
        if (!isdigit((unsigned char)*p)) return 0;
        while (isdigit((unsigned char)*p)) p++;
    }
    if (*p) return 0;
    *v = strtod(tok, &end);
    if (isinf(*v) && !allow_inf) return 0;               /* 1e999 */
    return 1;
}

int ln_split(char *line, int hash, char **tok, int max)
{
    int n = 0;
    char *p = line;
    for (;;) {
        while (*p == ' ' || *p == '\t' || *p == '\r' || *p == '\f' || *p == '\v') *p++ = '\0';
        if (!*p || (hash && *p == '#')) { *p = '\0'; return n; }
        if (n == max) return -1;
        tok[n++] = p;
        while (*p && *p != ' ' && *p != '\t' && *p != '\r' && *p != '\f' && *p != '\v' &&
               !(hash && *p == '#')) p++;
        if (p - tok[n - 1] >= LN_TOK_MAX) return -1;
        if (hash && *p == '#') { *p = '\0'; return n; }
    }
}

void ln_title(char *dst, const char *src, size_t n)
{
    size_t k = 0;
    while (n && (*src == ' ' || (unsigned char)*src < 0x20 || *src == 0x7f)) src++, n--;
    for (size_t i = 0; i < n && k < LN_TITLE_MAX - 1; i++) {
        unsigned char c = (unsigned char)src[i];
        dst[k++] = c < 0x20 || c == 0x7f ? ' ' : (char)c;
    }
    if (k == LN_TITLE_MAX - 1 && k < n) {     /* cut short: not inside a UTF-8 letter */
        size_t j = k;
        while (j && ((unsigned char)dst[j - 1] & 0xc0) == 0x80) j--;
        if (j && (unsigned char)dst[j - 1] >= 0xc0) {
            unsigned char lead = (unsigned char)dst[j - 1];
            size_t want = lead >= 0xf0 ? 4 : lead >= 0xe0 ? 3 : 2;
            if (k - (j - 1) < want) k = j - 1;
        }
    }
    while (k && dst[k - 1] == ' ') k--;
    dst[k] = '\0';
}

void ln_glass_spelling(char *g)
{
    char a[26], b[26], *slash = strchr(g, '/');
    double v, w;
    if (ln_parse_number(g, 0, &v)) { ln_format(v, g, LN_NAME_MAX); return; }
    if (!slash) return;
    *slash = '\0';
    if (ln_parse_number(g, 0, &v) && ln_parse_number(slash + 1, 0, &w)) {
        ln_format(v, a, sizeof a);
        ln_format(w, b, sizeof b);
        snprintf(g, LN_NAME_MAX, "%s/%s", a, b);
    } else *slash = '/';
}
