/* designio.h -- what the design dialogues (--optimise, --tolerance) share: the two
 * modules' tables, a file read whole, an output written through a unique temporary
 * name and renamed, and the lens + merit question pair. */
#ifndef DESIGNIO_H
#define DESIGNIO_H
#include <stddef.h>
#include "ask.h"
#include "../design/design.h"

typedef struct dz_files {
    char lens[4096], merit[4096];      /* names as answered ("-": no merit file) */
    ds_problem *p;
} dz_files;

const ds_api *dz_api(void);            /* NULL after saying why on stderr */
char *dz_slurp(const char *path, size_t *len, char *msg, size_t cap);
/* Ask the lens file, then the merit file ("-": the lens file's own design lines);
 * each refused at its answer with the reader's FILE:LINE.  fq/mq: the questions. */
int dz_ask_files(lm_io *io, const char *fq, const char *fwhat, const char *mq,
                 const char *mwhat, dz_files *f);
/* Write text to path through path.tmp.XXXXXX and rename; 0, or -1 with why (the
 * temporary removed, an existing file at path untouched). */
int dz_write(const char *path, const char *text, size_t len, char *msg, size_t cap);
/* An output name: not an input (same device and inode), not the record. */
int dz_check_out(const lm_io *io, const dz_files *f, const char *path, char *msg, size_t cap);
#endif
