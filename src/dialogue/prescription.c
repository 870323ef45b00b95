/* prescription.c -- prescription files: a plain text lens description (nearpoint,
 * object-side index, one surface per line, object planes; format in README
 * "Calculations") as an alternative to typing the classic dialogue's answers, and
 * the converse.  --prescription reads the file, checks every line (FILE:LINE
 * messages), turns it into the classic dialogue's answers and runs lm_classic, so
 * its record is an ordinary classic record (grep input: replays it).
 * --to-prescription reads a classic record or answer file and writes the
 * prescription file.  Texts in prompts/prescription.txt. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "ask.h"
#include "dialogues.h"
#include "lex.h"
#include "prompts_prescription.h"

#define PS(k) prescription_prompts[PRESCRIPTION_##k]

typedef struct text { char *s; size_t len, cap; int err; } text;

static void put(text *t, const char *a, const char *b)
{
    size_t n = strlen(a) + strlen(b) + 1;
    if (t->err) return;
    if (t->len + n + 1 > t->cap) {
        size_t cap = (t->cap + n) * 2;
        char *s = realloc(t->s, cap);
        if (!s) { t->err = 1; return; }
        t->s = s; t->cap = cap;
    }
    t->len += (size_t)sprintf(t->s + t->len, "%s%s\n", a, b);
}

static int bad(const lm_io *io, long line, const char *fmt, const char *arg)
{
    char msg[512];
    snprintf(msg, sizeof msg, fmt, arg);
    fprintf(stderr, PS(BAD_LINE), io->src, line, msg);
    return LM_FAIL;
}

/* A number token (plane words only where `plane`); 0 or LM_FAIL. */
static int number(const lm_io *io, long line, const char *tok, int plane, double *v)
{
    enum lm_num_status st = lm_parse_number(tok, v);
    if (st == LM_NUM_OK || (plane && st == LM_NUM_PLANE)) return 0;
    return bad(io, line, plane ? PS(BAD_RADIUS) : PS(BAD_NUMBER), tok);
}

typedef struct rx {
    text ans;                 /* the classic dialogue's answers */
    int have_near, have_index, nsurf, nobj;
    double z_last;
    char near[LM_TOKEN_MAX], index[LM_TOKEN_MAX];
} rx;

static int keyword(const lm_io *io, long line, rx *r, const char *key, const char *val)
{
    double v;
    int near = !strcmp(key, "nearpoint");
    if (near ? r->have_near : r->have_index) return bad(io, line, PS(TWICE), key);
    if (number(io, line, val, 0, &v)) return LM_FAIL;
    if (near && v < 0) return bad(io, line, "%s", PS(NEGATIVE));
    if (!near && !(v > 0)) return bad(io, line, "%s", PS(NOT_POSITIVE));
    strcpy(near ? r->near : r->index, val);
    *(near ? &r->have_near : &r->have_index) = 1;
    return LM_GO;
}

static int surface(const lm_io *io, long line, rx *r, char tok[3][LM_TOKEN_MAX])
{
    double rad, z, n;
    if (r->nobj) return bad(io, line, "%s", PS(AFTER_OBJECT));
    if (number(io, line, tok[0], 1, &rad) || number(io, line, tok[1], 0, &z) ||
        number(io, line, tok[2], 0, &n))
        return LM_FAIL;
    if (r->nsurf && z < r->z_last) return bad(io, line, "%s", PS(DECREASING));
    if (!(n > 0)) return bad(io, line, "%s", PS(NOT_POSITIVE));
    if (r->nsurf) put(&r->ans, "y", "");
    put(&r->ans, tok[0], ""); put(&r->ans, tok[1], ""); put(&r->ans, tok[2], "");
    r->z_last = z;
    r->nsurf++;
    return LM_GO;
}

static int one_line(const lm_io *io, long line, const char *buf, rx *r)
{
    char tok[4][LM_TOKEN_MAX];
    const char *cur = buf;
    int n = 0, len;
    char *hash = strchr(buf, '#');
    if (hash) *hash = '\0';
    while (n < 4 && (len = lm_next_token(&cur, tok[n], LM_TOKEN_MAX)) != 0) {
        if (len < 0) return bad(io, line, "%s", PS(TOO_LONG));
        n++;
    }
    if (n == 0) return LM_GO;
    if (n == 2 && (!strcmp(tok[0], "nearpoint") || !strcmp(tok[0], "index"))) {
        if (r->nsurf) return bad(io, line, "%s", "nearpoint and index come before the surfaces");
        return keyword(io, line, r, tok[0], tok[1]);
    }
    if (n == 2 && !strcmp(tok[0], "object")) {
        double z;
        if (!r->nsurf) return bad(io, line, "%s", PS(NEED_THREE));
        if (number(io, line, tok[1], 0, &z)) return LM_FAIL;
        put(&r->ans, r->nobj ? "y" : "n", "");
        put(&r->ans, tok[1], "");
        r->nobj++;
        return LM_GO;
    }
    if (n != 3) return bad(io, line, "%s", PS(NEED_THREE));
    return surface(io, line, r, tok);
}

static int read_prescription(lm_io *io, rx *r)
{
    char *buf = NULL;
    size_t cap = 0;
    long line = 0;
    int rc = LM_GO;
    text head = {0};
    while (rc == LM_GO && getline(&buf, &cap, io->in) >= 0)
        rc = one_line(io, ++line, buf, r);
    free(buf);
    if (rc) return rc;
    if (!r->nsurf) { fprintf(stderr, PS(NO_SURFACE), io->src); return LM_FAIL; }
    if (!r->nobj) { fprintf(stderr, PS(NO_OBJECT), io->src); return LM_FAIL; }
    put(&r->ans, "n", "");
    put(&head, r->have_near ? r->near : "25", "");
    put(&head, r->have_index ? r->index : "1", "");
    put(&head, r->ans.s ? r->ans.s : "", "");
    if (head.err || r->ans.err) { free(head.s); return LM_FAIL; }
    free(r->ans.s);
    r->ans = head;
    return LM_GO;
}

int lm_prescription(lm_io *io)
{
    rx r;
    FILE *answers;
    char src[600];
    int rc;
    memset(&r, 0, sizeof r);
    if ((rc = read_prescription(io, &r))) { free(r.ans.s); return rc; }
    answers = fmemopen(r.ans.s, r.ans.len, "r");
    if (!answers) { free(r.ans.s); return LM_FAIL; }
    snprintf(src, sizeof src, "%s (as classic answers)", io->src);
    io->in = answers;
    io->src = src;
    io->line = 0;
    io->cur = "";
    io->interactive = 0;
    rc = lm_classic(io);
    fclose(answers);
    free(r.ans.s);
    return rc;
}
const char *lm_prescription_example(void) { return PS(EXAMPLE); }

/* ---- the converse: classic answers -> prescription ---- */

/* Read all of `in`; if some line starts with "input:", blank every other line (a
 * whole record file; line numbers stay those of the file). */
static char *answers_of(FILE *in, size_t *len)
{
    text t = {0};
    char *buf = NULL;
    size_t cap = 0;
    int only_input = 0;
    while (getline(&buf, &cap, in) >= 0) {
        size_t n = strcspn(buf, "\n");
        buf[n] = '\0';
        put(&t, buf, "");
    }
    free(buf);
    if (t.err || !t.s) { free(t.s); return NULL; }
    only_input = !strncmp(t.s, "input:", 6) || strstr(t.s, "\ninput:") != NULL;
    if (only_input)
        for (char *l = t.s; *l; l = strchr(l, '\n') + 1)
            if (strncmp(l, "input:", 6)) memset(l, ' ', strcspn(l, "\n"));
    *len = t.len;
    return t.s;
}

static void number_text(double v, char *buf, size_t cap)
{
    if (isinf(v)) snprintf(buf, cap, "plane");
    else lm_format_echo(v, buf, cap);
}

static int convert(lm_io *in, lm_io *out)
{
    char a[64], b[64], c[64];
    double near, n, r, z, zl = 0;
    int rc, more, first = 1;
    lm_numspec s_near = {"the eye nearpoint", LM_NONNEG, 0},
               s_index = {"the index of refraction", LM_POSITIVE, 0},
               s_r = {"the radius of the lens surface", LM_ALLOW_PLANE, 0},
               s_z = {"the location of the lens surface", 0, 0},
               s_obj = {"the location of the object plane", 0, 0};
    if ((rc = lm_ask_number(in, NULL, NULL, &s_near, &near)) ||
        (rc = lm_ask_number(in, NULL, NULL, &s_index, &n)))
        return rc;
    lm_say(out, LM_REC, "%s", PS(HEADER));
    number_text(near, a, sizeof a);
    lm_say(out, LM_REC, PS(NEARPOINT), a);
    number_text(n, a, sizeof a);
    lm_say(out, LM_REC, PS(INDEX), a);
    do {
        s_z.flags = first ? 0 : LM_AT_LEAST;
        s_z.min = zl;
        if ((rc = lm_ask_number(in, NULL, NULL, &s_r, &r)) ||
            (rc = lm_ask_number(in, NULL, NULL, &s_z, &z)) ||
            (rc = lm_ask_number(in, NULL, NULL, &s_index, &n)) ||
            (rc = lm_ask_yn(in, NULL, NULL, "another lens surface (y or n)", &more)))
            return rc;
        number_text(r, a, sizeof a); number_text(z, b, sizeof b); number_text(n, c, sizeof c);
        lm_say(out, LM_REC, PS(SURFACE), a, b, c);
        zl = z;
        first = 0;
    } while (more);
    do {
        if ((rc = lm_ask_number(in, NULL, NULL, &s_obj, &z)) ||
            (rc = lm_ask_yn(in, NULL, NULL, "another object plane (y or n)", &more)))
            return rc;
        number_text(z, a, sizeof a);
        lm_say(out, LM_REC, PS(OBJECT), a);
    } while (more);
    lm_check_leftover(in);
    return LM_GO;
}

int lm_to_prescription(lm_io *io)
{
    size_t len = 0;
    char *ans = answers_of(io->in, &len);
    FILE *mem;
    lm_io in;
    int rc;
    if (!ans) { fprintf(stderr, PS(NO_SURFACE), io->src); return LM_FAIL; }
    mem = fmemopen(ans, len, "r");
    if (!mem) { free(ans); return LM_FAIL; }
    if (lm_io_open(&in, "/dev/null", mem, io->src, 0) < 0) { fclose(mem); free(ans); return LM_FAIL; }
    rc = convert(&in, io);
    lm_io_close(&in);
    fclose(mem);
    free(ans);
    return rc;
}
const char *lm_to_prescription_example(void) { return PS(TO_EXAMPLE); }
