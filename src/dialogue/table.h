/* table.h -- the table of dialogues and of the general options.  main.c (option
 * parsing, --help), the man page check (tests/unit_table.c) and the dialogue fuzzer
 * (tests/fuzz_answers.c) all read it, so a dialogue added here is chosen by its
 * option, listed by --help and fuzzed without another line anywhere. */
#ifndef TABLE_H
#define TABLE_H
#include <stddef.h>
#include "ask.h"

typedef struct lm_dialogue {
    const char *option;             /* the option that chooses it */
    const char *summary;            /* one line for --help */
    int (*run)(lm_io *io);
    const char *(*example)(void);   /* embedded example answers, or NULL */
    const char *needs;              /* engine module it loads ("trace"), or NULL: main
                                       checks it loads before the first question */
    int original;                   /* --original means something here (the original
                                       program's bytes); elsewhere it is refused */
} lm_dialogue;

extern const lm_dialogue lm_dialogues[];    /* [0] is the default, --classic */
extern const size_t lm_ndialogues;

/* The options that are not dialogues, as --help and the man page list them. */
typedef struct lm_option {
    const char *name;               /* "--input" */
    const char *alias;              /* "-i", or NULL */
    const char *arg;                /* "F", or NULL */
} lm_option;

extern const lm_option lm_options[];
extern const size_t lm_noptions;

const lm_dialogue *lm_find_dialogue(const char *option);   /* NULL if none */
/* 1 if d's OUTFILE is one document made from its input (the converters), not a
 * record: written at the end, only after a run that succeeded, "-" is standard output
 * (lm_io_open_whole). */
int lm_whole_output(const lm_dialogue *d);

#endif
