/* dialogues.h -- every dialogue lensmat offers.  Each one takes an open session and
 * returns LM_GO, LM_QUIT or LM_FAIL (see ask.h); main.c lists them in its table. */
#ifndef DIALOGUES_H
#define DIALOGUES_H
#include "ask.h"

int lm_classic(lm_io *io);
const char *lm_classic_usage(void);
const char *lm_classic_usage_more(void);
const char *lm_classic_example(void);
int lm_trace(lm_io *io);
const char *lm_trace_example(void);

#endif
