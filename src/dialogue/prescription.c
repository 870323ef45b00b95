/* prescription.c -- lens files: prescription files (a plain text lens description:
 * nearpoint, object-side index, one surface per line, object planes; format in README
 * "Calculations"), classic records and their answers.  --prescription reads a
 * prescription, checks every line (FILE:LINE messages), turns it into the classic
 * dialogue's answers and runs lm_classic, so its record is an ordinary classic record
 * (grep input: replays it).  --to-prescription reads a classic record or answer file
 * and writes the prescription file.  lm_read_lens reads any of the three into
 * surfaces (for --trace's record choice).  Thickness prescriptions and .zmx files
 * go through the lens model (lensfile.c).  Texts in prompts/prescription.txt. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "ask.h"
#include "dialogues.h"
#include "lex.h"
#include "../paraxial/paraxial.h"
#include "prompts_prescription.h"

#define PS(k) prescription_prompts[PRESCRIPTION_##k]
#define LENS_FILE_MAX (16L << 20)   /* a lens file is small text; /dev/zero is not */

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

/* A NUL byte in s (len bytes) is refused with its line: 0, or -1 with err set. */
static int nul_check(const char *s, size_t len, const char *src, char *err, size_t cap)
{
    const char *t = memchr(s, '\0', len);
    long line = 1;
    if (!t) return 0;
    for (const char *p = s; p < t; p++) line += *p == '\n';
    snprintf(err, cap, PS(NUL_BYTE), src, line);
    return -1;
}

/* All of `in` as one NUL-terminated string of *lenp bytes (lenp may be NULL); NUL
 * bytes are refused unless allow_nul (a UTF-16 .zmx holds them).  NULL with err set
 * if it is too long, cannot be read, or holds a NUL. */
static char *slurp_n(FILE *in, const char *src, char *err, size_t cap, size_t *lenp,
                     int allow_nul)
{
    char *s = NULL, *t;
    size_t len = 0, room = 0, n;
    for (;;) {
        if (len + 65536 + 1 > room) {
            if (len > (size_t)LENS_FILE_MAX) {
                snprintf(err, cap, PS(TOO_BIG), src, LENS_FILE_MAX >> 20);
                free(s);
                return NULL;
            }
            room = 2 * room + 65536 + 1;
            if (!(t = realloc(s, room))) { snprintf(err, cap, PS(NO_MEMORY), src); free(s); return NULL; }
            s = t;
        }
        n = fread(s + len, 1, room - len - 1, in);
        len += n;
        if (n == 0) break;
    }
    if (ferror(in)) {
        snprintf(err, cap, PS(CANNOT_READ), src, strerror(errno));
        free(s);
        return NULL;
    }
    s[len] = '\0';
    if (len >= 3 && !memcmp(s, "\xef\xbb\xbf", 3)) {   /* a UTF-8 byte-order mark */
        len -= 3;
        memmove(s, s + 3, len + 1);
    }
    if (!allow_nul && nul_check(s, len, src, err, cap)) {  /* string functions cut there */
        free(s);
        return NULL;
    }
    if (lenp) *lenp = len;
    return s;
}


/* ---- prescription files -> the classic dialogue's answers ------------------------ */

typedef struct rx {
    const char *src;          /* file name for messages */
    char *err;                /* "FILE:LINE: why" */
    size_t errcap;
    text ans;                 /* the classic dialogue's answers */
    int have_near, have_index, have_wl, nsurf, nobj;
    double z_last;
    char near[LM_TOKEN_MAX], index[LM_TOKEN_MAX];
    char wl[32];              /* "wavelength W": the glasses' default wavelength */
} rx;

static int bad(rx *r, long line, const char *fmt, const char *arg)
{
    char msg[1200];   /* room for any token: the compiler counts a line's four */
    snprintf(msg, sizeof msg, fmt, arg);
    snprintf(r->err, r->errcap, PS(BAD_LINE), r->src, line, msg);
    return LM_FAIL;
}

/* A number token (plane words only where `plane`); 0 or LM_FAIL. */
static int number(rx *r, long line, const char *tok, int plane, double *v)
{
    enum lm_num_status st = lm_parse_number(tok, v);
    if (st == LM_NUM_OK || (plane && st == LM_NUM_PLANE)) return 0;
    return bad(r, line, plane ? PS(BAD_RADIUS) : PS(BAD_NUMBER), tok);
}

/* An index token: a number, a medium, a catalogue or model glass, NAME@WAVELENGTH
 * (lm_index_name, as the classic dialogue takes it); 0 or LM_FAIL with the reason. */
static int index_token(rx *r, long line, const char *tok, double *v)
{
    char echo[LM_TOKEN_MAX + 16], why[300];
    double lambda;
    int k;
    if (lm_parse_number(tok, v) == LM_NUM_OK) return 0;
    k = lm_index_name(tok, v, echo, sizeof echo, &lambda, why, sizeof why);
    if (k == 1) return 0;
    if (k == -1) return bad(r, line, "%s", why);
    return bad(r, line, PS(BAD_INDEX), tok);
}

/* With "wavelength W", an index named without "@" is taken at W: NAME -> NAME@W
 * (numbers stay numbers).  Writes the answer into out (LM_TOKEN_MAX); 0 or LM_FAIL. */
static int at_wavelength(rx *r, long line, const char *tok, char *out)
{
    double v;
    int n;
    if (!r->have_wl || strchr(tok, '@') || lm_parse_number(tok, &v) == LM_NUM_OK)
        n = snprintf(out, LM_TOKEN_MAX, "%s", tok);
    else n = snprintf(out, LM_TOKEN_MAX, "%s@%s", tok, r->wl);
    if (n >= LM_TOKEN_MAX) return bad(r, line, "%s", PS(TOO_LONG));
    return 0;
}

static int keyword(rx *r, long line, const char *key, const char *val)
{
    double v;
    char named[LM_TOKEN_MAX];
    if (!strcmp(key, "wavelength")) {
        if (r->have_wl) return bad(r, line, PS(TWICE), key);
        if (r->have_index) return bad(r, line, "%s", PS(WL_FIRST));
        if (px_wavelength(val, &v) != PX_OK || strlen(val) >= sizeof r->wl)
            return bad(r, line, PS(BAD_WL), val);
        strcpy(r->wl, val);
        r->have_wl = 1;
        return LM_GO;
    }
    if (strcmp(key, "nearpoint")) {
        if (at_wavelength(r, line, val, named)) return LM_FAIL;
        val = named;
    }
    int near = !strcmp(key, "nearpoint");
    if (near ? r->have_near : r->have_index) return bad(r, line, PS(TWICE), key);
    if (near ? number(r, line, val, 0, &v) : index_token(r, line, val, &v)) return LM_FAIL;
    if (near && v < 0) return bad(r, line, "%s", PS(NEGATIVE));
    if (!near && !(v > 0)) return bad(r, line, "%s", PS(NOT_POSITIVE));
    strcpy(near ? r->near : r->index, val);
    *(near ? &r->have_near : &r->have_index) = 1;
    return LM_GO;
}

static int surface(rx *r, long line, char tok[3][LM_TOKEN_MAX])
{
    double rad, z, n;
    char named[LM_TOKEN_MAX];
    if (r->nobj) return bad(r, line, "%s", PS(AFTER_OBJECT));
    if (at_wavelength(r, line, tok[2], named)) return LM_FAIL;
    strcpy(tok[2], named);
    if (number(r, line, tok[0], 1, &rad) || number(r, line, tok[1], 0, &z) ||
        index_token(r, line, tok[2], &n))
        return LM_FAIL;
    if (r->nsurf && z < r->z_last) return bad(r, line, "%s", PS(DECREASING));
    if (!(n > 0)) return bad(r, line, "%s", PS(NOT_POSITIVE));
    if (r->nsurf) put(&r->ans, "y", "");
    put(&r->ans, tok[0], ""); put(&r->ans, tok[1], ""); put(&r->ans, tok[2], "");
    r->z_last = z;
    r->nsurf++;
    return LM_GO;
}

static int one_line(rx *r, long line, char *buf)
{
    char tok[4][LM_TOKEN_MAX];
    const char *cur = buf;
    int n = 0, len;
    char *hash = strchr(buf, '#');
    if (hash) *hash = '\0';
    while (n < 4 && (len = lm_next_token(&cur, tok[n], LM_TOKEN_MAX)) != 0) {
        if (len < 0) return bad(r, line, "%s", PS(TOO_LONG));
        n++;
    }
    if (n == 0) return LM_GO;
    if (n == 2 && (!strcmp(tok[0], "nearpoint") || !strcmp(tok[0], "index") ||
                   !strcmp(tok[0], "wavelength"))) {
        if (r->nsurf) return bad(r, line, "%s", PS(KEYS_FIRST));
        return keyword(r, line, tok[0], tok[1]);
    }
    if (n == 2 && !strcmp(tok[0], "object")) {
        double z;
        if (!r->nsurf) return bad(r, line, "%s", PS(NEED_THREE));
        if (number(r, line, tok[1], 0, &z)) return LM_FAIL;
        put(&r->ans, r->nobj ? "y" : "n", "");
        put(&r->ans, tok[1], "");
        r->nobj++;
        return LM_GO;
    }
    if (n != 3) return bad(r, line, "%s", PS(NEED_THREE));
    return surface(r, line, tok);
}

/* The prescription in `s` (modified: lines are cut in place) -> r->ans, the classic
 * answers.  LM_GO, or LM_FAIL with r->err set. */
static int read_prescription(rx *r, char *s)
{
    text head = {0};
    long line = 0;
    int rc = LM_GO;
    while (rc == LM_GO && *s) {
        char *nl = strchr(s, '\n');
        if (nl) *nl = '\0';
        rc = one_line(r, ++line, s);
        s = nl ? nl + 1 : s + strlen(s);
    }
    if (rc) return rc;
    if (!r->nsurf) { snprintf(r->err, r->errcap, PS(NO_SURFACE), r->src); return LM_FAIL; }
    if (!r->nobj) { snprintf(r->err, r->errcap, PS(NO_OBJECT), r->src); return LM_FAIL; }
    put(&r->ans, "n", "");
    put(&head, r->have_near ? r->near : "25", "");
    put(&head, r->have_index ? r->index : "1", "");
    put(&head, r->ans.s ? r->ans.s : "", "");
    if (head.err || r->ans.err) {
        free(head.s);
        snprintf(r->err, r->errcap, PS(NO_MEMORY), r->src);
        return LM_FAIL;
    }
    free(r->ans.s);
    r->ans = head;
    return LM_GO;
}

/* An error on stderr, an answer's control bytes escaped (lm_escape). */
static void say_error(const char *err)
{
    char shown[4 * 1200];
    lm_escape(err, shown, sizeof shown);
    fprintf(stderr, PS(ERROR), shown);
}

int lm_prescription(lm_io *io)
{
    rx r;
    FILE *answers;
    char src[600], err[1200], *s;
    size_t len;
    int rc;
    memset(&r, 0, sizeof r);
    r.src = io->src;
    r.err = err;
    r.errcap = sizeof err;
    if (!(s = slurp_n(io->in, io->src, err, sizeof err, &len, 1))) rc = LM_FAIL;
    else if (lm_is_model_file(s, len))     /* by thickness, or a .zmx: lensfile.c */
        rc = lm_model_answers(io->src, s, len, &r.ans.s, &r.ans.len, 0, err, sizeof err);
    else if (nul_check(s, len, io->src, err, sizeof err)) rc = LM_FAIL;
    else rc = read_prescription(&r, s);
    free(s);
    if (rc) { say_error(err); free(r.ans.s); return rc; }
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

/* ---- the classic dialogue's answers -> a lens ------------------------------------ */

/* The answers' tokens, line by line (lines are cut in place), as lm_ask reads them. */
typedef struct cursor {
    const char *src;
    char *next;               /* the next line, or NULL at the end */
    const char *cur;          /* unread part of the current line */
    long line;
    char *err;
    size_t errcap;
    char last[LM_TOKEN_MAX];  /* the last token num() read */
} cursor;

static int fail_at(cursor *c, const char *what, const char *fmt, const char *tok)
{
    char msg[600];
    snprintf(msg, sizeof msg, fmt, tok);
    snprintf(c->err, c->errcap, PS(ANSWER_ERROR), c->src, c->line > 0 ? c->line : 1,
             what, msg);
    return LM_FAIL;
}

/* Move to the next line that is not a comment (first non-blank byte '#', as lm_ask
 * skips them): 0, or -1 at the end. */
static int next_line(cursor *c)
{
    char *nl;
    do {
        if (!c->next || !*c->next) return -1;
        if ((nl = strchr(c->next, '\n'))) *nl = '\0';
        c->cur = lm_line_start(c->next);
        c->next = nl ? nl + 1 : NULL;
        c->line++;
    } while (c->cur[strspn(c->cur, " \t")] == '#');
    return 0;
}

static int token(cursor *c, const char *what, char tok[LM_TOKEN_MAX])
{
    for (;;) {
        int n = lm_next_token(&c->cur, tok, LM_TOKEN_MAX);
        if (n > 0) return LM_GO;
        if (n < 0) return fail_at(c, what, "%s", PS(A_TOO_LONG));
        if (next_line(c)) {
            snprintf(c->err, c->errcap, PS(END_OF_INPUT), c->src, c->line + 1, what);
            return LM_FAIL;
        }
    }
}

/* A number answer with the checks lm_ask_number makes for these lm_numspec flags
 * (LM_ALLOW_PLANE, LM_POSITIVE, LM_NONNEG, LM_AT_LEAST). */
static int num(cursor *c, const char *what, unsigned flags, double min, double *v)
{
    char tok[LM_TOKEN_MAX];
    enum lm_num_status st;
    if (token(c, what, tok)) return LM_FAIL;
    memcpy(c->last, tok, sizeof c->last);
    st = (flags & LM_INDEX) ? lm_parse_index(tok, v) : lm_parse_number(tok, v);
    if (st == LM_NUM_PLANE && (flags & LM_ALLOW_PLANE)) { *v = INFINITY; return LM_GO; }
    if (st != LM_NUM_OK) {
        char msg[LM_TOKEN_MAX + 100];
        snprintf(msg, sizeof msg, PS(A_NOT_NUMBER), tok, lm_num_status_text(st));
        return fail_at(c, what, "%s", msg);
    }
    if ((flags & LM_POSITIVE) && !(*v > 0)) return fail_at(c, what, PS(A_POSITIVE), tok);
    if ((flags & LM_NONNEG) && *v < 0) return fail_at(c, what, PS(A_NONNEG), tok);
    if ((flags & LM_AT_LEAST) && *v < min) return fail_at(c, what, PS(A_LEFT), tok);
    if ((flags & LM_ALLOW_PLANE) && *v == 0) *v = INFINITY;
    return LM_GO;
}

/* An index answer: num's checks, and the glass it names (a catalogue or model glass
 * without "@": the classic takes it at d, as a lens model does at its primary d),
 * so that a converted lens keeps the glass, not only its number. */
static int index_answer(cursor *c, const char *what, double *v, char *glass, size_t cap)
{
    char echo[LM_TOKEN_MAX], why[300];
    double l, n;
    glass[0] = '\0';
    if (num(c, what, LM_POSITIVE | LM_INDEX, 0, v)) return LM_FAIL;
    if (lm_parse_number(c->last, &n) == LM_NUM_SYNTAX && !strchr(c->last, '@') &&
        lm_index_name(c->last, &n, echo, sizeof echo, &l, why, sizeof why) == 1 && l > 0)
        snprintf(glass, cap, "%.63s", echo);
    return LM_GO;
}

static int yn(cursor *c, const char *what, int *yes)
{
    char tok[LM_TOKEN_MAX];
    int ch;
    if (token(c, what, tok)) return LM_FAIL;
    if (!(ch = lm_parse_yn(tok))) return fail_at(c, what, PS(A_YN), tok);
    *yes = ch == 'y';
    return LM_GO;
}

/* Room for n elements of `size` bytes in a (which has room for n - 1): the room
 * doubles when n is a power of 2.  NULL if out of memory (a is then still valid). */
static void *grow(void *a, int n, size_t size)
{
    return n & (n - 1) ? a : realloc(a, size * (size_t)n * 2);
}

static int read_answers(cursor *c, lm_lens_file *lf)
{
    double s[3], z, *no;
    char glass[64];
    lm_lens_surface *ns;
    char tok[LM_TOKEN_MAX];
    int more;
    if (num(c, PS(W_NEARPOINT), LM_NONNEG, 0, &lf->nearpoint) ||
        index_answer(c, PS(W_INDEX), &lf->n_object, lf->obj_glass, sizeof lf->obj_glass))
        return LM_FAIL;
    do {
        if (num(c, PS(W_RADIUS), LM_ALLOW_PLANE, 0, &s[0]) ||
            num(c, PS(W_LOCATION), lf->nsurf ? LM_AT_LEAST : 0,
                lf->nsurf ? lf->surf[lf->nsurf - 1].z : 0, &s[1]) ||
            index_answer(c, PS(W_INDEX), &s[2], glass, sizeof glass) ||
            yn(c, PS(W_ANOTHER_SURFACE), &more))
            return LM_FAIL;
        if (!(ns = grow(lf->surf, lf->nsurf + 1, sizeof *ns))) return fail_at(c, "", "%s", PS(A_MEMORY));
        lf->surf = ns;
        ns[lf->nsurf] = (lm_lens_surface){s[0], s[1], s[2], ""};
        memcpy(ns[lf->nsurf++].glass, glass, sizeof glass);
    } while (more);
    do {
        if (num(c, PS(W_OBJECT), 0, 0, &z) || yn(c, PS(W_ANOTHER_OBJECT), &more)) return LM_FAIL;
        if (!(no = grow(lf->obj, lf->nobj + 1, sizeof *no))) return fail_at(c, "", "%s", PS(A_MEMORY));
        lf->obj = no;
        no[lf->nobj++] = z;
    } while (more);
    /* answers left over (the classic dialogue warns and ignores them) */
    do if (lm_next_token(&c->cur, tok, sizeof tok) != 0) { lf->leftover_line = c->line; break; }
    while (!next_line(c));
    return LM_GO;
}

/* Does some line begin with a prescription keyword? (classic answers never do) */
static int is_prescription(const char *s)
{
    static const char *const keys[] = {"nearpoint", "index", "object"};
    for (const char *l = s; l; l = strchr(l, '\n'), l = l ? l + 1 : NULL) {
        size_t n;
        l += strspn(l, " \t");
        n = strcspn(l, " \t\r\n#");
        for (int i = 0; i < 3; i++)
            if (n == strlen(keys[i]) && !strncmp(l, keys[i], n)) return 1;
    }
    return 0;
}

/* A record (input: lines among others) whose first line is not the classic's first
 * question was made by another dialogue: say which (prompts' record_marks), rather
 * than fail on its first answer ("'mm' is not a number").  1 with err set, or 0. */
/* Is s a record (prompts with input: lines), rather than answers (input: lines and
 * plain answers, read alike, as a dialogue replays them)?  A record's first line is
 * a prompt; an answers file's first answer, the nearpoint, is a number.  *first:
 * the first line that is not a comment. */
static int is_record(const char *s, const char **first)
{
    const char *f = s, *p;
    char tok[LM_TOKEN_MAX];
    double v;
    if (strncmp(s, "input:", 6) && !strstr(s, "\ninput:")) return 0;
    for (;;) {                                       /* comment and blank lines */
        const char *b = f + strspn(f, " \t\r");
        const char *nl;
        if (*b != '#' && *b != '\n') break;
        if (!(nl = strchr(f, '\n'))) return 0;
        f = nl + 1;
    }
    *first = f;
    p = f + strspn(f, " \t");
    if (!strncmp(p, "input:", 6) || !*p) return 0;
    if (lm_next_token(&p, tok, sizeof tok) <= 0) return 0;
    return lm_parse_number(tok, &v) != LM_NUM_OK && lm_parse_number(tok, &v) != LM_NUM_PLANE;
}

static int other_record(const char *src, const char *s, char *err, size_t cap)
{
    const char *first = s, *marks = PS(RECORD_MARKS);
    if (!is_record(s, &first) ||
        !strncmp(first, PS(CLASSIC_FIRST), strlen(PS(CLASSIC_FIRST))))
        return 0;
    for (const char *m = marks; *m; ) {
        const char *tab = strchr(m, '\t'), *nl = strchr(m, '\n');
        if (!tab || !nl) break;
        for (const char *l = s; l; l = strchr(l, '\n'), l = l ? l + 1 : NULL)
            if (!strncmp(l, tab + 1, (size_t)(nl - tab - 1))) {
                char opt[32];
                snprintf(opt, sizeof opt, "%.*s", (int)(tab - m), m);
                snprintf(err, cap, PS(OTHER_RECORD), src, opt);
                return 1;
            }
        m = nl + 1;
    }
    {
        char line[80];
        size_t n = strcspn(first, "\r\n");
        snprintf(line, sizeof line, "%.*s", (int)(n < 70 ? n : 70), first);
        snprintf(err, cap, PS(OTHER_RECORD_UNKNOWN), src, line);
    }
    return 1;
}

/* In a record (is_record: prompts and "input:" lines), blank every other line;
 * line numbers stay those of the file. */
static void keep_input_lines(char *s)
{
    const char *first;
    if (!is_record(s, &first)) return;      /* answers: every line, as a replay reads */
    for (char *l = s; l; l = strchr(l, '\n'), l = l ? l + 1 : NULL)
        if (strncmp(l, "input:", 6)) memset(l, ' ', strcspn(l, "\n"));
}

/* The lens in text s (a prescription, a classic record or its answers; s is cut up).
 * LM_GO, or LM_FAIL with "FILE:LINE: why" in err. */
static int lens_of_text(const char *src, char *s, size_t len, lm_lens_file *lf, char *err,
                        size_t cap, int quiet)
{
    cursor c = {src, s, "", 0, err, cap, ""};
    char asrc[600], *ans;
    size_t alen;
    rx r;
    int rc;
    memset(lf, 0, sizeof *lf);
    if (lm_is_model_file(s, len)) {         /* by thickness, or a .zmx: lensfile.c */
        if (lm_model_answers(src, s, len, &ans, &alen, quiet, err, cap)) return LM_FAIL;
        snprintf(asrc, sizeof asrc, "%s (as classic answers)", src);
        c.src = asrc;
        c.next = ans;
        rc = read_answers(&c, lf);
        free(ans);
        if (rc) lm_lens_file_free(lf);
        return rc;
    }
    if (nul_check(s, len, src, err, cap)) return LM_FAIL;
    if (other_record(src, s, err, cap)) return LM_FAIL;
    keep_input_lines(s);
    if (!is_prescription(s)) {
        rc = read_answers(&c, lf);
    } else {
        memset(&r, 0, sizeof r);
        r.src = src;
        r.err = err;
        r.errcap = cap;
        rc = read_prescription(&r, s);
        snprintf(asrc, sizeof asrc, "%s (as classic answers)", src);
        c.src = asrc;
        c.next = r.ans.s;
        if (!rc) rc = read_answers(&c, lf);
        free(r.ans.s);
    }
    if (rc) lm_lens_file_free(lf);
    return rc;
}

int lm_read_lens(const char *path, lm_lens_file *lf, char *err, size_t cap)
{
    struct stat st;
    FILE *f;
    char *s;
    size_t len;
    int rc;
    memset(lf, 0, sizeof *lf);
    if (stat(path, &st) || !(f = fopen(path, "r"))) {
        snprintf(err, cap, PS(CANNOT_OPEN), path, strerror(errno));
        return LM_FAIL;
    }
    if (!S_ISREG(st.st_mode)) {
        fclose(f);
        snprintf(err, cap, PS(NOT_REGULAR), path);
        return LM_FAIL;
    }
    s = slurp_n(f, path, err, cap, &len, 1);
    fclose(f);
    if (!s) return LM_FAIL;
    rc = lens_of_text(path, s, len, lf, err, cap, 1);
    free(s);
    return rc;
}

int lm_lens_of_text(const char *src, char *s, size_t len, lm_lens_file *lf, char *err,
                    size_t cap)
{
    return lens_of_text(src, s, len, lf, err, cap, 1);
}

void lm_lens_file_free(lm_lens_file *lf)
{
    free(lf->surf);
    free(lf->obj);
    memset(lf, 0, sizeof *lf);
}

/* ---- the converse: classic answers -> prescription ---- */

static void number_text(double v, char *buf, size_t cap)
{
    if (isinf(v)) snprintf(buf, cap, "plane");
    else lm_format_echo(v, buf, cap);
}

static void write_prescription(lm_io *out, const lm_lens_file *lf)
{
    char a[64], b[64], c[64];
    lm_say(out, LM_REC, "%s", PS(HEADER));
    number_text(lf->nearpoint, a, sizeof a);
    lm_say(out, LM_REC, PS(NEARPOINT), a);
    number_text(lf->n_object, a, sizeof a);
    lm_say(out, LM_REC, PS(INDEX), a);
    for (int i = 0; i < lf->nsurf; i++) {
        const lm_lens_surface *s = &lf->surf[i];
        number_text(s->radius, a, sizeof a);
        number_text(s->z, b, sizeof b);
        number_text(s->n_right, c, sizeof c);
        lm_say(out, LM_REC, PS(SURFACE), a, b, c);
    }
    for (int i = 0; i < lf->nobj; i++) {
        number_text(lf->obj[i], a, sizeof a);
        lm_say(out, LM_REC, PS(OBJECT), a);
    }
}

int lm_to_prescription(lm_io *io)
{
    lm_lens_file lf;
    size_t len;
    char err[1200], *s = slurp_n(io->in, io->src, err, sizeof err, &len, 1);
    if (!s || lens_of_text(io->src, s, len, &lf, err, sizeof err, 0)) {
        free(s);
        say_error(err);
        return LM_FAIL;
    }
    free(s);
    write_prescription(io, &lf);
    if (lf.leftover_line) fprintf(stderr, PS(LEFTOVER), io->src, lf.leftover_line);
    lm_lens_file_free(&lf);
    return LM_GO;
}
const char *lm_to_prescription_example(void) { return PS(TO_EXAMPLE); }
