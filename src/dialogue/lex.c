/* lex.c -- answer tokens, numbers and yes/no, without any I/O.  The original read
 * answers with cin >>, which loops forever on a typo; here every token is either a
 * well-formed answer or a named error. */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "lex.h"

const char *lm_line_start(const char *line)
{
    while (*line == ' ' || *line == '\t') line++;
    if (strncmp(line, "input:", 6) == 0) line += 6;
    return line;
}

static int is_blank(int c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' ||
                                    c == '\v' || c == '\f'; }

int lm_next_token(const char **cur, char *tok, size_t cap)
{
    const char *p = *cur, *start;
    size_t len;

    while (*p && is_blank((unsigned char)*p)) p++;
    start = p;
    while (*p && !is_blank((unsigned char)*p)) p++;
    *cur = p;
    len = (size_t)(p - start);
    if (len >= cap) return -1;
    memcpy(tok, start, len);
    tok[len] = '\0';
    return (int)len;
}

/* [+-] digits [. digits] [(e|E) [+-] digits], with at least one mantissa digit. */
static int is_decimal(const char *s)
{
    int digits = 0;
    if (*s == '+' || *s == '-') s++;
    while (isdigit((unsigned char)*s)) { s++; digits++; }
    if (*s == '.') {
        s++;
        while (isdigit((unsigned char)*s)) { s++; digits++; }
    }
    if (!digits) return 0;
    if (*s == 'e' || *s == 'E') {
        s++;
        if (*s == '+' || *s == '-') s++;
        if (!isdigit((unsigned char)*s)) return 0;
        while (isdigit((unsigned char)*s)) s++;
    }
    return *s == '\0';
}

enum lm_num_status lm_parse_number(const char *tok, double *v)
{
    const char *word = (*tok == '+' || *tok == '-') ? tok + 1 : tok;

    if (!strcasecmp(word, "inf") || !strcasecmp(word, "infinity") ||
        !strcasecmp(word, "plane")) {
        *v = *tok == '-' ? -INFINITY : INFINITY;
        return LM_NUM_PLANE;
    }
    if (!strcasecmp(word, "nan")) return LM_NUM_NAN;
    if (!is_decimal(tok)) return LM_NUM_SYNTAX;
    *v = strtod(tok, NULL);
    if (!isfinite(*v) || fabs(*v) > LM_NUM_LIMIT) return LM_NUM_RANGE;
    return LM_NUM_OK;
}

const char *lm_num_status_text(enum lm_num_status st)
{
    switch (st) {
    case LM_NUM_OK: return "a number";
    case LM_NUM_PLANE: return "infinity (allowed only for a radius: a plane surface)";
    case LM_NUM_SYNTAX: return "not a number";
    case LM_NUM_NAN: return "nan is not a number";
    case LM_NUM_RANGE: return "number out of range (|x| <= 1e30)";
    }
    return "?";
}

int lm_parse_yn(const char *tok)
{
    if (!strcasecmp(tok, "y") || !strcasecmp(tok, "yes")) return 'y';
    if (!strcasecmp(tok, "n") || !strcasecmp(tok, "no")) return 'n';
    return 0;
}

void lm_format_echo(double v, char *buf, size_t cap)
{
    snprintf(buf, cap, "%g", v);
    if (strtod(buf, NULL) != v)
        snprintf(buf, cap, "%.17g", v);
}

static int hexval(int c)
{
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

int lm_next_word(const char **cur, char *tok, size_t cap)
{
    const char *p = *cur;
    size_t len = 0;
    int q, too_long = 0;

    while (*p && is_blank((unsigned char)*p)) p++;
    if (*p != '"' && *p != '\'') {
        int n = lm_next_token(cur, tok, cap);
        return n > 0 ? 1 : n;
    }
    q = *p++;
    for (;;) {
        int c = (unsigned char)*p;
        if (!c) { *cur = p; return -2; }
        p++;
        if (c == q) break;
        if (c == '\\' && (*p == '\\' || *p == '"' || *p == '\'')) c = (unsigned char)*p++;
        else if (c == '\\' && *p == 'x' && hexval((unsigned char)p[1]) >= 0 &&
                 hexval((unsigned char)p[2]) >= 0) {
            c = hexval((unsigned char)p[1]) * 16 + hexval((unsigned char)p[2]);
            p += 3;
            if (!c) { *cur = p + strlen(p); return -3; }   /* a C string holds no NUL */
        }
        if (len + 1 >= cap) too_long = 1;
        else tok[len++] = (char)c;
    }
    *cur = p;
    if (too_long) return -1;
    tok[len] = '\0';
    return 1;
}

int lm_quote_word(const char *word, char *out, size_t cap)
{
    const unsigned char *s = (const unsigned char *)word;
    size_t n = 0;
    int plain = *s && *s != '"' && *s != '\'';
    for (const unsigned char *t = s; *t && plain; t++)
        if (is_blank(*t) || *t < 0x20 || *t == 0x7f) plain = 0;
    if (plain) {
        n = strlen(word);
        if (n + 1 > cap) return -1;
        memcpy(out, word, n + 1);
        return (int)n;
    }
    if (cap < 3) return -1;
    out[n++] = '"';
    for (; *s; s++) {
        if (n + 5 > cap) return -1;
        if (*s == '"' || *s == '\\') { out[n++] = '\\'; out[n++] = (char)*s; }
        else if (*s < 0x20 || *s == 0x7f) n += (size_t)snprintf(out + n, 5, "\\x%02x", *s);
        else out[n++] = (char)*s;
    }
    out[n++] = '"';
    out[n] = '\0';
    return (int)n;
}

/* Length of the UTF-8 sequence at s that is printable (not C1), or 0. */
static int utf8_ok(const unsigned char *s)
{
    int n, i;
    unsigned cp;
    if (*s >= 0xc2 && *s <= 0xdf) { n = 2; cp = *s & 0x1f; }
    else if (*s >= 0xe0 && *s <= 0xef) { n = 3; cp = *s & 0x0f; }
    else if (*s >= 0xf0 && *s <= 0xf4) { n = 4; cp = *s & 0x07; }
    else return 0;
    for (i = 1; i < n; i++) {
        if ((s[i] & 0xc0) != 0x80) return 0;
        cp = cp << 6 | (s[i] & 0x3f);
    }
    if ((n == 3 && cp < 0x800) || (n == 4 && (cp < 0x10000 || cp > 0x10ffff)) ||
        (cp >= 0xd800 && cp <= 0xdfff) || (cp >= 0x80 && cp <= 0x9f))
        return 0;
    return n;
}

void lm_escape(const char *str, char *out, size_t cap)
{
    const unsigned char *s = (const unsigned char *)str;
    size_t n = 0;
    if (!cap) return;
    while (*s) {
        int k = *s >= 0x80 ? utf8_ok(s) : (*s >= 0x20 && *s != 0x7f);
        if (k) {
            if (n + (size_t)k >= cap) break;
            memcpy(out + n, s, (size_t)k);
            n += (size_t)k;
            s += k;
        } else {
            if (n + 4 >= cap) break;
            n += (size_t)snprintf(out + n, 5, "\\x%02x", *s);
            s++;
        }
    }
    out[n] = '\0';
}
