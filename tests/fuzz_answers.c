/* fuzz_answers.c -- libFuzzer target for the answer reader and the number parser.
 * Each input is (1) split into lines and tokens and every token parsed as a number
 * and as y/n, checking the invariants the dialogue relies on (numbers finite and in
 * range, the record echo reads back exactly), then (2) replayed as a whole classic
 * session, which must end (no endless loop) with LM_GO or LM_FAIL. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "dialogue/ask.h"
#include "dialogue/dialogues.h"
#include "dialogue/lex.h"

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

static void lex_all(const char *text)
{
    char *copy = strdup(text), *save = NULL, tok[LM_TOKEN_MAX];
    for (char *line = strtok_r(copy, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
        const char *cur = lm_line_start(line);
        int n;
        while ((n = lm_next_token(&cur, tok, sizeof tok)) != 0)
            if (n > 0) check_token(tok);
    }
    free(copy);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static int quiet;
    char *text = malloc(size + 1);
    lm_io io;
    FILE *in;
    int rc;

    if (!quiet) { quiet = 1; if (!freopen("/dev/null", "w", stdout)) abort(); }
    memcpy(text, data, size);
    text[size] = '\0';
    lex_all(text);
    in = fmemopen(text, size ? size : 1, "r");
    if (in && lm_io_open(&io, "/dev/null", in, "<fuzz>", 0) == 0) {
        rc = lm_classic(&io);
        if (rc != LM_GO && rc != LM_FAIL) abort();
        lm_io_close(&io);
    }
    if (in) fclose(in);
    free(text);
    return 0;
}
