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
