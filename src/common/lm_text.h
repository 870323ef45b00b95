/* lm_text.h -- one copy of the text decoding that the file readers of several engines
 * share (the lens model's .zmx reader, the paraxial engine's AGF glass catalogues):
 * a file as Zemax OpticStudio and the glass makers write them -- UTF-16LE/BE with or
 * without a byte-order mark, UTF-8 with or without one, or Latin-1 (Windows code page
 * 1252's printable range) -- into NUL-terminated UTF-8.  Header-only (static
 * functions) so that no engine reaches into another's objects. */
#ifndef LM_TEXT_H
#define LM_TEXT_H
#include <stdlib.h>
#include <string.h>

static size_t lm_put_utf8(char *o, unsigned cp)
{
    if (cp < 0x80) { o[0] = (char)cp; return 1; }
    if (cp < 0x800) { o[0] = (char)(0xc0 | cp >> 6); o[1] = (char)(0x80 | (cp & 63)); return 2; }
    if (cp < 0x10000) {
        o[0] = (char)(0xe0 | cp >> 12); o[1] = (char)(0x80 | ((cp >> 6) & 63));
        o[2] = (char)(0x80 | (cp & 63));
        return 3;
    }
    o[0] = (char)(0xf0 | cp >> 18); o[1] = (char)(0x80 | ((cp >> 12) & 63));
    o[2] = (char)(0x80 | ((cp >> 6) & 63)); o[3] = (char)(0x80 | (cp & 63));
    return 4;
}

/* The length (2-4) of the well-formed UTF-8 sequence at u (n bytes left), or 0:
 * overlong forms, surrogates and code points above U+10FFFF are not well formed. */
static size_t lm_utf8_seq(const unsigned char *u, size_t n)
{
    unsigned cp;
    size_t k, i;
    if (u[0] >= 0xc2 && u[0] <= 0xdf) { k = 2; cp = u[0] & 0x1f; }
    else if (u[0] >= 0xe0 && u[0] <= 0xef) { k = 3; cp = u[0] & 0x0f; }
    else if (u[0] >= 0xf0 && u[0] <= 0xf4) { k = 4; cp = u[0] & 0x07; }
    else return 0;
    if (n < k) return 0;
    for (i = 1; i < k; i++) {
        if ((u[i] & 0xc0) != 0x80) return 0;
        cp = cp << 6 | (u[i] & 0x3f);
    }
    if ((k == 3 && cp < 0x800) || (k == 4 && cp < 0x10000) || cp > 0x10ffff ||
        (cp >= 0xd800 && cp < 0xe000)) return 0;
    return k;
}

/* 8-bit text as NUL-terminated UTF-8 (malloc'd; *n its length): well-formed UTF-8
 * is kept, every other byte above 0x7f taken as Latin-1, a NUL made a blank.  NULL:
 * out of memory. */
static char *lm_utf8_fix(const char *text, size_t len, size_t *n)
{
    const unsigned char *u = (const unsigned char *)text;
    size_t i = 0, k = 0;
    char *o = malloc(2 * len + 1);                  /* Latin-1: 2 bytes a byte */
    if (!o) return NULL;
    while (i < len) {
        size_t q;
        if (u[i] < 0x80) { o[k++] = u[i] ? (char)u[i] : ' '; i++; continue; }
        if ((q = lm_utf8_seq(u + i, len - i))) { memcpy(o + k, u + i, q); k += q; i += q; }
        else { k += lm_put_utf8(o + k, u[i]); i++; }
    }
    o[k] = '\0';
    *n = k;
    return o;
}

/* The text as NUL-terminated UTF-8 (malloc'd; *n its length): UTF-16LE/BE by their
 * byte-order mark, or without one when the first bytes are ASCII with NULs beside
 * them; otherwise 8-bit text, where well-formed UTF-8 is kept and every other byte
 * above 0x7f is taken as Latin-1 (so a name typed on a Western Windows machine is
 * written back as the same letter, in UTF-8).  A UTF-8 byte-order mark is dropped;
 * a NUL in the decoded text becomes a blank (the line still reads).  NULL: out of
 * memory. */
static char *lm_text_utf8(const char *text, size_t len, size_t *n)
{
    const unsigned char *u = (const unsigned char *)text;
    int be = -1;
    size_t i = 0, k = 0;
    char *o;
    if (len >= 2 && u[0] == 0xff && u[1] == 0xfe) { be = 0; i = 2; }
    else if (len >= 2 && u[0] == 0xfe && u[1] == 0xff) { be = 1; i = 2; }
    else if (len >= 4 && u[0] && !u[1] && u[2] && !u[3]) be = 0;
    else if (len >= 4 && !u[0] && u[1] && !u[2] && u[3]) be = 1;
    if (be < 0) {
        if (len >= 3 && !memcmp(text, "\xef\xbb\xbf", 3)) i = 3;
        return lm_utf8_fix(text + i, len - i, n);
    }
    if (!(o = malloc((len / 2) * 3 + 4))) return NULL;   /* a unit is at most 3 bytes */
    for (; i + 1 < len; i += 2) {
        unsigned cp = be ? (unsigned)(u[i] << 8 | u[i + 1]) : (unsigned)(u[i + 1] << 8 | u[i]);
        if (cp >= 0xd800 && cp < 0xdc00 && i + 3 < len) {          /* a surrogate pair */
            unsigned lo = be ? (unsigned)(u[i + 2] << 8 | u[i + 3]) : (unsigned)(u[i + 3] << 8 | u[i + 2]);
            if (lo >= 0xdc00 && lo < 0xe000) {
                cp = 0x10000 + ((cp - 0xd800) << 10) + (lo - 0xdc00);
                i += 2;
            } else cp = '?';
        } else if (cp >= 0xd800 && cp < 0xe000) cp = '?';
        if (cp == 0) cp = ' ';
        k += lm_put_utf8(o + k, cp);
    }
    o[k] = '\0';
    *n = k;
    return o;
}
#endif
