/* main.c -- the command line: choose a dialogue (one option), open the session
 * (answers from a terminal, a replay file or the embedded example; the record
 * file), run it, and turn its outcome into the exit status. */
#include <stdio.h>
#include <string.h>
#include "ask.h"
#include "dialogues.h"
#include "prompts_main.h"

#ifndef LENSMAT_VERSION
#define LENSMAT_VERSION "0.1"
#endif
#define P(k) main_prompts[MAIN_##k]

typedef struct dialogue {
    const char *option;             /* the option that chooses it */
    const char *summary;            /* one line for --help */
    int (*run)(lm_io *io);
    const char *(*example)(void);   /* embedded example answers, or NULL */
} dialogue;

static const dialogue dialogues[] = {
    {"--classic", "the original lens-entry dialogue (the default)", lm_classic,
     lm_classic_example},
    {"--trace", "ray tracing: scene files, a lens's real fan, tessellation table", lm_trace,
     lm_trace_example},
    {"--rig", "the cornea rig: home, move, expose, scan (sim or libgpiod; 36-39)", lm_rig, lm_rig_example},
    {"--thick", "thick lens: R1, R2, t, n, any media (sections 8-10, 21)", lm_thick, lm_thick_example},
    {"--thin", "thin lens equation: f, do, di from the other two (57)", lm_thin, lm_thin_example},
    {"--gauss", "Gauss's formula, one refracting surface (section 4)", lm_gauss, lm_gauss_example},
    {"--pair", "two thin lenses t apart (section 56)", lm_pair, lm_pair_example},
    {"--magnifier", "simple magnifier (sections 31.7-31.8)", lm_magnifier, lm_magnifier_example},
    {"--microscope", "single-lens and compound microscopes (31.9-31.10, 58)", lm_microscope, lm_microscope_example},
    {"--telescope", "astronomical, terrestrial, Galileo telescopes (31.11-31.13)", lm_telescope, lm_telescope_example},
    {"--vision", "spectacle power for a near or far point (41, 57)", lm_vision, lm_vision_example},
    {"--cornea", "corneal radius <-> power, measuring accuracy (section 37)", lm_cornea, lm_cornea_example},
    {"--fit", "lens matrix from measurements (lsq), cardinal or nodal points (14, 24, 26)", lm_fit, lm_fit_example},
    {"--prescription", "run the classic dialogue from a prescription file (-i FILE)", lm_prescription, lm_prescription_example},
    {"--to-prescription", "write a classic record or answers (-i FILE) as a prescription", lm_to_prescription, lm_to_prescription_example},
};
#define NDIALOGUES (sizeof dialogues / sizeof dialogues[0])

typedef struct options {
    const dialogue *dlg;
    const char *outfile, *input;
    int original, example;
} options;

static void help(void)
{
    printf("%s", P(HELP));
    for (size_t i = 0; i < NDIALOGUES; i++)
        printf(P(HELP_DIALOGUE), dialogues[i].option, dialogues[i].summary);
    printf("%s", P(HELP_OPTIONS));
}

static const dialogue *find_dialogue(const char *opt)
{
    for (size_t i = 0; i < NDIALOGUES; i++)
        if (!strcmp(opt, dialogues[i].option)) return &dialogues[i];
    return NULL;
}

/* Returns -1 to go on, else the exit status (after --help, --version or an error). */
static int parse_args(int argc, char **argv, options *o)
{
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        const dialogue *d;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) { help(); return 0; }
        if (!strcmp(a, "--version")) { printf(P(VERSION), LENSMAT_VERSION); return 0; }
        if (!strcmp(a, "--original")) { o->original = 1; continue; }
        if (!strcmp(a, "--example")) { o->example = 1; continue; }
        if (!strcmp(a, "-i") || !strcmp(a, "--input")) {
            if (++i == argc) { fprintf(stderr, P(NEED_ARG), a); return 1; }
            o->input = argv[i];
            continue;
        }
        if ((d = find_dialogue(a))) {
            if (o->dlg && o->dlg != d) {
                fprintf(stderr, P(TWO_DIALOGUES), o->dlg->option, a);
                return 1;
            }
            o->dlg = d;
            continue;
        }
        if (a[0] == '-' && a[1]) { fprintf(stderr, P(BAD_OPTION), a); return 1; }
        if (o->outfile) { fprintf(stderr, P(TOO_MANY), o->outfile, a); return 1; }
        o->outfile = a;
    }
    if (!o->dlg) o->dlg = &dialogues[0];
    return -1;
}

/* Where the answers come from: the embedded example, a file, or stdin. */
static FILE *open_answers(const options *o, const char **name)
{
    FILE *f;
    if (o->example) {
        const char *ex = o->dlg->example ? o->dlg->example() : NULL;
        if (!ex) { fprintf(stderr, P(NO_EXAMPLE), o->dlg->option); return NULL; }
        *name = "<example>";
        return fmemopen((void *)ex, strlen(ex), "r");
    }
    if (!o->input) { *name = "<stdin>"; return stdin; }
    *name = o->input;
    f = fopen(o->input, "r");
    if (!f) perror(o->input);
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
        if (argc == 1 + o.original) {   /* the original's usage text */
            printf("%s%s", lm_classic_usage(), o.original ? "" : lm_classic_usage_more());
            return 0;
        }
        fprintf(stderr, "%s", P(NEED_OUTFILE));
        return 1;
    }
    if (!(in = open_answers(&o, &in_name))) return 1;
    if (lm_io_open(&io, o.outfile, in, in_name, o.original) < 0) return 1;
    rc = o.dlg->run(&io);
    if (lm_io_close(&io) < 0 && rc == LM_GO) rc = LM_FAIL;
    if (in != stdin) fclose(in);
    if (lm_stop_requested()) {
        lm_run_stop_hooks();
        return 128 + lm_stop_requested();
    }
    return rc == LM_FAIL ? 2 : 0;
}
