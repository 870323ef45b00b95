/* fuzz_answers.c -- libFuzzer target for every dialogue, the answer reader and the
 * number parser.  Each input is (1) split into lines and tokens, every token parsed
 * as a number, as y/n and as a (quoted) word, checking the invariants the dialogues
 * rely on (numbers finite and in range, the record echo reads back exactly, quoted
 * words read back as themselves, escaped messages hold no control byte), then
 * (2) replayed as one dialogue's session: the first byte chooses it from the table
 * lm_dialogues[] ('a' the first, 'b' the second, ...; so a dialogue added to the
 * table is fuzzed with no change here), the rest are its answers.  The session must
 * end (no endless loop) with LM_GO or LM_FAIL, and neither stdout nor the record
 * may hold a printed nan or inf.  Engine modules are disabled: a dialogue that
 * needs one must fail cleanly when it comes to it. */
#include <ctype.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>
#include "dialogue/ask.h"
#include "dialogue/engine.h"
#include "dialogue/lex.h"
#include "dialogue/table.h"

static void check_token(const char *tok)
{
    double v = 0;
    char echo[64];
    enum lm_num_status st = lm_parse_number(tok, &v);
    if (st == LM_NUM_OK) {
        if (!isfinite(v) || fabs(v) > LM_NUM_LIMIT) abort();
        lm_format_echo(v, echo, sizeof echo);
        if (strtod(echo, NULL) != v) abort();
        double w;
        if (lm_parse_number(echo, &w) != LM_NUM_OK || w != v) abort();
    }
    if (st == LM_NUM_PLANE && !isinf(v)) abort();
    int yn = lm_parse_yn(tok);
    if (yn && yn != 'y' && yn != 'n') abort();
}

/* A word must read back as itself from its quoted form, and an escaped message must
 * hold no control byte. */
static void check_word(const char *word)
{
    char q[4 * LM_TOKEN_MAX + 3], back[LM_TOKEN_MAX], esc[4 * LM_TOKEN_MAX + 1];
    const char *cur = q;
    if (lm_quote_word(word, q, sizeof q) < 0) abort();
    if (lm_next_word(&cur, back, sizeof back) != 1 || strcmp(back, word)) abort();
    if (lm_next_word(&cur, back, sizeof back) != 0) abort();
    lm_escape(word, esc, sizeof esc);
    for (const unsigned char *p = (const unsigned char *)esc; *p; p++)
        if (*p < 0x20 || *p == 0x7f) abort();
}

static void lex_all(const char *text)
{
    char *copy = strdup(text), *save = NULL, tok[LM_TOKEN_MAX];
    for (char *line = strtok_r(copy, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
        const char *cur = lm_line_start(line);
        int n;
        while ((n = lm_next_token(&cur, tok, sizeof tok)) != 0)
            if (n > 0) check_token(tok);
        cur = lm_line_start(line);
        while ((n = lm_next_word(&cur, tok, sizeof tok)) != 0)
            if (n > 0) check_word(tok);
    }
    free(copy);
}

static char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    char *s = NULL;
    size_t cap = 0, n;
    *len = 0;
    if (!f) abort();
    do {
        if (*len + 4096 + 1 > cap && !(s = realloc(s, cap = 2 * cap + 4096 + 1))) abort();
        n = fread(s + *len, 1, cap - *len - 1, f);
        *len += n;
    } while (n);
    fclose(f);
    s[*len] = '\0';
    return s;
}

/* A printed nan or inf: the word nan or inf, except in the prompts' own phrases
 * ("0, inf or plane", "inf: at infinity", "(plane: inf)", "plane/inf") and on
 * "input:" lines (an answer of inf is echoed as such). */
static int bad_number_word(const char *text, size_t len)
{
    for (size_t i = 0; i + 3 <= len; i++) {
        const char *p = text + i;
        size_t ls = i;
        if (strncasecmp(p, "nan", 3) && strncasecmp(p, "inf", 3)) continue;
        if ((i && isalpha((unsigned char)p[-1])) || isalpha((unsigned char)p[3])) continue;
        while (ls && text[ls - 1] != '\n') ls--;
        if (!strncmp(text + ls, "input:", 6)) continue;
        if (!strncasecmp(p, "inf", 3) &&
            (p[3] == ':' || !strncmp(p + 3, " or", 3) || (i && p[-1] == '/') ||
             (i >= 7 && !strncmp(p - 7, "plane: ", 7)) ||
             (i >= 10 && !strncmp(p - 10, "infinity: ", 10))))
            continue;
        return 1;
    }
    return 0;
}

static char out_path[64], rec_path[64];

static void setup(void)
{
    int fd;
    /* in memory (tmpfs) where there is one: a disk file's truncation per run costs
     * more than the run */
    const char *dir = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
    snprintf(out_path, sizeof out_path, "%s/lensmat-fuzz-out-XXXXXX", dir);
    snprintf(rec_path, sizeof rec_path, "%s/lensmat-fuzz-rec-XXXXXX", dir);
    if ((fd = mkstemp(out_path)) < 0) abort();
    close(fd);
    if ((fd = mkstemp(rec_path)) < 0) abort();
    close(fd);
    if (!freopen(out_path, "w+", stdout)) abort();
    lm_engine_disable();
}

static void cleanup(void) { unlink(out_path); unlink(rec_path); }

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static int ready;
    const lm_dialogue *d;
    char *text, *out, *rec;
    size_t nout, nrec;
    lm_io io;
    FILE *in;
    int rc;

    if (!ready) { ready = 1; setup(); atexit(cleanup); }
    if (size == 0) return 0;
    d = &lm_dialogues[(unsigned)(data[0] + 256 - 'a') % lm_ndialogues];
    data++, size--;
    text = malloc(size + 1);
    memcpy(text, data, size);
    text[size] = '\0';
    lex_all(text);
    fflush(stdout);
    if (ftruncate(fileno(stdout), 0) != 0) abort();
    rewind(stdout);
    in = fmemopen(text, size ? size : 1, "r");
    if (in && lm_io_open(&io, rec_path, in, "<fuzz>", 0) == 0) {
        rc = d->run(&io);
        if (rc != LM_GO && rc != LM_FAIL) {
            fprintf(stderr, "%s ended with %d\n", d->option, rc);
            abort();
        }
        lm_io_close(&io);
        fflush(stdout);
        out = slurp(out_path, &nout);
        rec = slurp(rec_path, &nrec);
        /* --to-zmx and --to-thickness write a lens file: its titles and glass names
         * are the input's own words (fuzz_lens checks its numbers read back) */
        int lens_file = !strcmp(d->option, "--to-zmx") || !strcmp(d->option, "--to-thickness");
        if (bad_number_word(out, nout) || (!lens_file && bad_number_word(rec, nrec))) {
            fprintf(stderr, "%s printed nan or inf:\n---- stdout\n%s\n---- record\n%s\n",
                    d->option, out, rec);
            abort();
        }
        free(out);
        free(rec);
    }
    if (in) fclose(in);
    free(text);
    return 0;
}
