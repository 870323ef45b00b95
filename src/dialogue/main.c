/* main.c -- the command line: choose a dialogue (one option, from the table in
 * table.c), check the engine module it needs is there, open the session (answers from
 * a terminal, a replay file or the embedded example; the record file), run it, and
 * turn its outcome into the exit status. */
#include <errno.h>
#include <stdlib.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "ask.h"
#include "dialogues.h"
#include "engine.h"
#include "table.h"
#include "prompts_main.h"

#ifndef LENSMAT_VERSION
#define LENSMAT_VERSION "0.1"
#endif
#define P(k) main_prompts[MAIN_##k]

typedef struct options {
    const lm_dialogue *dlg;
    const char *outfile, *input;
    int original, example;
} options;

static void help(void)
{
    printf("%s", P(HELP));
    for (size_t i = 0; i < lm_ndialogues; i++)
        printf(P(HELP_DIALOGUE), lm_dialogues[i].option, lm_dialogues[i].summary);
    printf("%s", P(HELP_OPTIONS));
}

/* An argument for a message: its control bytes escaped. */
static const char *shown(const char *arg)
{
    static char buf[2][1024];
    static int k;
    k = !k;
    lm_escape(arg, buf[k], sizeof buf[k]);
    return buf[k];
}

/* Returns -1 to go on, else the exit status (after --help, --version or an error). */
static int parse_args(int argc, char **argv, options *o)
{
    int operands = 0;                   /* after "--": every argument is an OUTFILE */
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const lm_dialogue *d;
        if (operands || a[0] != '-' || !a[1]) {
            if (o->outfile) {
                fprintf(stderr, P(TOO_MANY), shown(o->outfile), shown(a));
                return 1;
            }
            o->outfile = a;
            continue;
        }
        if (!strcmp(a, "--")) { operands = 1; continue; }
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            help();
            return lm_stdout_check() ? 2 : 0;
        }
        if (!strcmp(a, "--version")) {
            printf(P(VERSION), LENSMAT_VERSION);
            return lm_stdout_check() ? 2 : 0;
        }
        if (!strcmp(a, "--original")) { o->original = 1; continue; }
        if (!strcmp(a, "--example")) { o->example = 1; continue; }
        if (!strcmp(a, "-i") || !strcmp(a, "--input")) {
            if (++i == argc) { fprintf(stderr, P(NEED_ARG), a); return 1; }
            o->input = argv[i];
            continue;
        }
        if (!strncmp(a, "--input=", 8)) {
            if (!a[8]) { fprintf(stderr, P(NEED_ARG), "--input"); return 1; }
            o->input = a + 8;
            continue;
        }
        if ((d = lm_find_dialogue(a))) {
            if (o->dlg && o->dlg != d) {
                fprintf(stderr, P(TWO_DIALOGUES), o->dlg->option, a);
                return 1;
            }
            o->dlg = d;
            continue;
        }
        fprintf(stderr, P(BAD_OPTION), shown(a));
        return 1;
    }
    if (!o->dlg) o->dlg = &lm_dialogues[0];
    if (o->original && !o->dlg->original) {
        fprintf(stderr, P(ORIGINAL_NOTHING), o->dlg->option);
        return 1;
    }
    return -1;
}

/* An example's data files (doc/triplet.rx, golden/rig/example.rig) are installed
 * data: a relative name in an example's answers that is not there from the current
 * folder is taken from beside lensmat (the build tree) or from EXEDIR/../share/lensmat
 * (make install), where the modules are found too.  The answers then name it by that
 * path.  Returns a malloc'd text, or NULL (out of memory). */
static char *example_text(const char *ex)
{
    char exe[4096], path[8192], *out, *slash;
    size_t cap = strlen(ex) * 2 + 4096, n = 0;
    ssize_t k = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (!(out = malloc(cap))) return NULL;
    exe[k > 0 ? k : 0] = '\0';
    if ((slash = strrchr(exe, '/'))) *slash = '\0';
    for (const char *p = ex; *p; ) {
        size_t len = strcspn(p, "\n");
        int done = 0;
        if (len && len < 1024 && p[0] != '/' && memchr(p, '/', len) && exe[0]) {
            char name[1024];
            memcpy(name, p, len);
            name[len] = '\0';
            if (access(name, R_OK) != 0) {
                static const char *const dirs[] = {"", "/../share/lensmat"};
                for (size_t i = 0; i < 2 && !done; i++) {
                    snprintf(path, sizeof path, "%s%s/%s", exe, dirs[i], name);
                    if (access(path, R_OK) == 0 && !strpbrk(path, " \t\"'\\#") &&
                        n + strlen(path) + 2 < cap) {
                        memcpy(out + n, path, strlen(path));
                        n += strlen(path);
                        done = 1;
                    }
                }
            }
        }
        if (!done) {
            if (n + len + 2 >= cap) break;
            memcpy(out + n, p, len);
            n += len;
        }
        p += len;
        if (*p == '\n') { out[n++] = '\n'; p++; }
    }
    out[n] = '\0';
    return out;
}

/* Where the answers come from: the embedded example, a file, or stdin. */
static char *example_buf;       /* the example's text, while the session reads it */
static FILE *open_answers(const options *o, const char **name)
{
    FILE *f;
    struct stat st;
    if (o->example) {
        const char *ex = o->dlg->example ? o->dlg->example() : NULL;
        if (!ex) { fprintf(stderr, P(NO_EXAMPLE), o->dlg->option); return NULL; }
        *name = "<example>";
        if (!(example_buf = example_text(ex))) return NULL;
        return fmemopen(example_buf, strlen(example_buf), "r");
    }
    if (!o->input) { *name = "<stdin>"; return stdin; }
    *name = o->input;
    f = fopen(o->input, "r");
    if (!f) fprintf(stderr, P(CANNOT_READ), shown(o->input), strerror(errno));
    else if (fstat(fileno(f), &st) == 0 && S_ISDIR(st.st_mode)) {
        fprintf(stderr, P(CANNOT_READ), shown(o->input), strerror(EISDIR));
        fclose(f);
        f = NULL;
    }
    return f;
}

int main(int argc, char **argv)
{
    options o = {0};
    lm_io io;
    FILE *in;
    const char *in_name;
    int rc = parse_args(argc, argv, &o);

    if (rc >= 0) return rc;
    if (!o.outfile) {
        if (argc == 1 + o.original) {   /* the original's usage text; no OUTFILE: 1 */
            printf("%s%s", lm_classic_usage(), o.original ? "" : lm_classic_usage_more());
            return lm_stdout_check() ? 2 : 1;
        }
        fprintf(stderr, "%s", P(NEED_OUTFILE));
        return 1;
    }
    if (!strcmp(o.outfile, "-") && !lm_whole_output(o.dlg)) {
        fprintf(stderr, P(DASH_OUTFILE), o.dlg->option);
        return 1;
    }
    /* before the first question: a session that could not finish is not begun */
    if (o.dlg->needs && !lm_engine_present(o.dlg->needs)) {
        fprintf(stderr, P(NEEDS_MODULE), o.dlg->option, o.dlg->needs);
        return 1;
    }
    {   /* an OUTFILE that is a lens file or the like: the -i forgotten */
        static const char *const from_input[] = {"--prescription", "--to-prescription",
                                                 "--to-zmx", "--to-thickness", NULL};
        char msg[3000];
        int k = 0;
        while (from_input[k] && strcmp(from_input[k], o.dlg->option)) k++;
        int conv = from_input[k] != NULL;
        if (conv && !strncmp(o.dlg->option, "--to-", 5) && (o.input || o.example ||
                                                             !isatty(0)))
            conv = o.dlg->option[5] == 'z' ? 2 : o.dlg->option[5] == 't' ? 3 : 4;
            /* it writes a lens file: an old one of its kind is its earlier output */
        if (lm_outfile_check(o.outfile, o.dlg->option, conv, msg, sizeof msg)) {
            fprintf(stderr, "lensmat: %s\n", msg);
            return 1;
        }
    }
    if (!(in = open_answers(&o, &in_name))) return 1;
    if ((lm_whole_output(o.dlg) ? lm_io_open_whole(&io, o.outfile, in, in_name)
                             : lm_io_open(&io, o.outfile, in, in_name, o.original)) < 0) {
        if (in != stdin) fclose(in);
        return 1;
    }
    io.show_answers = o.example;
    rc = o.dlg->run(&io);
    io.discard = rc != LM_GO || lm_stop_requested();
    if (lm_io_close(&io) < 0) rc = LM_FAIL;
    if (in != stdin) fclose(in);
    free(example_buf);
    if (lm_stop_requested()) {
        lm_run_stop_hooks();
        return 128 + lm_stop_requested();
    }
    return rc == LM_FAIL ? 2 : 0;
}
