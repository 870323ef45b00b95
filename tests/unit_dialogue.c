/* unit_dialogue.c -- the dialogue table against --help and the man page (every
 * dialogue and every option of src/dialogue/table.c appears in both), and the word
 * reader: quoted file names, their echo, escaped messages.  Run from the top of the
 * tree (tests/run.sh does): reads doc/lensmat.1 and runs ./lensmat --help. */
#include <stdlib.h>
#include <string.h>
#include "dialogue/lex.h"
#include "dialogue/table.h"
#include "unit.h"

static char *slurp(FILE *f)
{
    size_t cap = 1 << 16, len = 0, n;
    char *s = malloc(cap);
    while (s && (n = fread(s + len, 1, cap - len - 1, f)) > 0)
        if ((len += n) + 1 == cap && !(s = realloc(s, cap *= 2))) return NULL;
    if (s) s[len] = '\0';
    return s;
}

/* The man page's text as a reader sees the option names: \- is -, fonts dropped. */
static char *man_text(const char *path)
{
    FILE *f = fopen(path, "r");
    char *s, *o, *p;
    if (!f) return NULL;
    s = slurp(f);
    fclose(f);
    if (!s) return NULL;
    for (p = o = s; *p; ) {
        if (p[0] == '\\' && p[1] == '-') { *o++ = '-'; p += 2; }
        else if (p[0] == '\\' && p[1] == 'f' && p[2]) p += 3;
        else *o++ = *p++;
    }
    *o = '\0';
    return s;
}

/* `opt` as a whole option in text: not followed by a letter, digit, - or =. */
static int has_option(const char *text, const char *opt)
{
    size_t n = strlen(opt);
    for (const char *p = text; (p = strstr(p, opt)); p++) {
        char c = p[n], b = p == text ? ' ' : p[-1];
        if ((b == '-' || (b >= 'a' && b <= 'z'))) continue;
        if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '-')) return 1;
    }
    return 0;
}

static void table_documented(void)
{
    FILE *h = popen("./lensmat --help", "r");
    char *help = h ? slurp(h) : NULL, *man = man_text("doc/lensmat.1");
    if (h) pclose(h);
    CHECK(help && strstr(help, "Usage: lensmat"), "./lensmat --help runs");
    CHECK(man && strstr(man, ".TH LENSMAT 1"), "doc/lensmat.1 reads");
    if (!help || !man) return;
    for (size_t i = 0; i < lm_ndialogues; i++) {
        const lm_dialogue *d = &lm_dialogues[i];
        CHECK(has_option(help, d->option), "--help lists %s", d->option);
        CHECK(has_option(man, d->option), "the man page describes %s", d->option);
        CHECK(lm_find_dialogue(d->option) == d, "%s is found by its option", d->option);
        CHECK(d->run && d->summary && *d->summary, "%s has a dialogue and a summary",
              d->option);
    }
    for (size_t i = 0; i < lm_noptions; i++) {
        const lm_option *o = &lm_options[i];
        CHECK(has_option(help, o->name), "--help lists %s", o->name);
        CHECK(has_option(man, o->name), "the man page describes %s", o->name);
        if (o->alias) {
            CHECK(has_option(help, o->alias), "--help lists %s", o->alias);
            CHECK(has_option(man, o->alias), "the man page describes %s", o->alias);
        }
    }
    CHECK(has_option(man, "LENSMAT_LIBDIR") && has_option(help, "LENSMAT_LIBDIR"),
          "LENSMAT_LIBDIR is documented in --help and the man page");
    CHECK(!has_option(man, "--frobnicate"), "control: an option that is not there is not found");
    free(help);
    free(man);
}

/* One word read at the start of `line`: lm_next_word's code, the word in tok. */
static int word(const char *line, char *tok, size_t cap)
{
    const char *cur = line;
    return lm_next_word(&cur, tok, cap);
}

static void words(void)
{
    char tok[64], q[256];
    CHECK(word("  plain.rec rest", tok, sizeof tok) == 1 && !strcmp(tok, "plain.rec"),
          "a plain word");
    CHECK(word("\"my lens.rec\"", tok, sizeof tok) == 1 && !strcmp(tok, "my lens.rec"),
          "a double-quoted word with a blank");
    CHECK(word("'my lens.rec'", tok, sizeof tok) == 1 && !strcmp(tok, "my lens.rec"),
          "a single-quoted word with a blank");
    CHECK(word("\"a\\\"b\\\\c\\x41\"", tok, sizeof tok) == 1 && !strcmp(tok, "a\"b\\cA"),
          "escapes \\\" \\\\ \\xHH inside quotes");
    CHECK(word("\"c:\\new\"", tok, sizeof tok) == 1 && !strcmp(tok, "c:\\new"),
          "another backslash is itself");
    CHECK(word("a\"b", tok, sizeof tok) == 1 && !strcmp(tok, "a\"b"),
          "a quote inside a word is a byte");
    CHECK(word("\"\"", tok, sizeof tok) == 1 && !strcmp(tok, ""), "an empty quoted word");
    CHECK(word("\"open", tok, sizeof tok) == -2, "an unterminated quote");
    CHECK(word("\"a\\x00b\"", tok, sizeof tok) == -3, "a \\x00 escape is refused");
    CHECK(word("   ", tok, sizeof tok) == 0, "end of line");
    CHECK(word("\"0123456789012345678901234567890123456789012345678901234567890123456789\"",
               tok, sizeof tok) == -1, "a quoted word too long for its buffer");
    CHECK(lm_quote_word("plain.rec", q, sizeof q) == 9 && !strcmp(q, "plain.rec"),
          "a plain name is echoed as it is");
    CHECK(lm_quote_word("my lens.rec", q, sizeof q) > 0 && !strcmp(q, "\"my lens.rec\""),
          "a name with a blank is echoed quoted");
    CHECK(lm_quote_word("'x", q, sizeof q) > 0 && !strcmp(q, "\"'x\""),
          "a leading quote is quoted");
    CHECK(lm_quote_word("a\tb\"\\", q, sizeof q) > 0 && !strcmp(q, "\"a\\x09b\\\"\\\\\""),
          "tab, quote and backslash escaped in the echo");
    CHECK(word(q, tok, sizeof tok) == 1 && !strcmp(tok, "a\tb\"\\"), "... and read back");
    lm_escape("\033[31mred\177\x85 \xc3\xa9 \xff", q, sizeof q);
    CHECK(!strcmp(q, "\\x1b[31mred\\x7f\\x85 \xc3\xa9 \\xff"),
          "messages escape ESC, DEL, stray bytes; keep UTF-8 (%s)", q);
    lm_escape("\xc2\x9b", q, sizeof q);
    CHECK(!strcmp(q, "\\xc2\\x9b"), "a C1 control in UTF-8 (CSI) is escaped");
}

int main(void)
{
    table_documented();
    words();
    return unit_failed();
}
