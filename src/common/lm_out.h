/* lm_out.h -- writing one output file the way a careful Unix tool does; the one helper
 * every writer of lensmat uses (the core's converters and record checks, the trace,
 * imaging, cornea and rig modules: each compiles src/common/lm_out.c in, hidden).
 *
 *   - "-" is standard output (flushed, never closed);
 *   - a path that exists and is not a regular file (a character or block device such
 *     as /dev/null, a FIFO) is written in place: opened and written, never renamed
 *     over, never truncated into a plain file;
 *   - a symbolic link is followed (a chain too): its target is what is written, the
 *     link stays a link;
 *   - a regular file, or a name not there yet, is written to a temporary beside it
 *     (mkstemp: NAME.part.XXXXXX in the same folder, so two writers never share one)
 *     with the modes a plain create would give (an existing file keeps its modes),
 *     then fsync'ed and renamed over the name: a reader sees the old file or the new
 *     one, two concurrent writers leave one complete output, a failed run leaves the
 *     old file as it was;
 *   - every error (open, write, flush, fsync, close, rename: /dev/full, a read-only
 *     folder) is reported in err as "NAME: why", and nothing is left behind.
 * See doc/outputs.md. */
#ifndef LM_OUT_H
#define LM_OUT_H
#include <stddef.h>
#include <stdio.h>

#if defined(__GNUC__)
#define LM_OUT_API __attribute__((visibility("hidden")))
#else
#define LM_OUT_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

enum { LM_OUT_STDOUT = 1, LM_OUT_INPLACE = 2, LM_OUT_TEMP = 3 };

/* lm_out_open flags */
enum {
    LM_OUT_FD = 1,          /* no stdio stream: write to o->fd with write(2) */
    LM_OUT_REGULAR = 2      /* the output must be a regular file (it is mapped):
                               refuse devices, FIFOs and "-" */
};

typedef struct lm_out {
    FILE *f;                /* write here (NULL with LM_OUT_FD) */
    int fd;                 /* its descriptor */
    int how;                /* LM_OUT_STDOUT, LM_OUT_INPLACE, LM_OUT_TEMP */
    char *name;             /* as given, for messages */
    char *final;            /* the file the bytes end in: name, or a link's target */
    char *tmp;              /* the temporary (LM_OUT_TEMP), else NULL */
    char *part;             /* final + ".part": where lm_out_abort(o, 1) keeps it */
} lm_out;

/* Opens path for writing as above.  0, or -1 with "PATH: why" in err (nothing made). */
LM_OUT_API int lm_out_open(lm_out *o, const char *path, unsigned flags, char *err,
                           size_t cap);
/* Flushes, fsyncs, closes and renames into place.  0, or -1 with why in err; on an
 * error the temporary is removed and an earlier file under the name is untouched. */
LM_OUT_API int lm_out_commit(lm_out *o, char *err, size_t cap);
/* Gives up: closes, and removes the temporary, or with keep_part renames it to
 * FINAL.part (an incomplete output kept for inspection, never under its name). */
LM_OUT_API void lm_out_abort(lm_out *o, int keep_part);
/* Async-signal-safe ends for a writer that uses LM_OUT_FD (the rig simulator's log on
 * its emergency path): close and rename (commit) or close and keep as .part.  Frees
 * nothing; call lm_out_free later outside the handler.  0 or -1. */
LM_OUT_API int lm_out_commit_fd_now(lm_out *o);
LM_OUT_API void lm_out_abort_fd_now(lm_out *o);
LM_OUT_API void lm_out_free(lm_out *o);

/* The whole of an output at once: lm_out_open, write, lm_out_commit.  0 or -1. */
LM_OUT_API int lm_out_save(const char *path, const void *data, size_t len, char *err,
                           size_t cap);

/* Where the bytes of an output named path would end up (the link's target, resolved),
 * malloc'ed; NULL if it cannot be resolved (a loop).  For comparing outputs. */
LM_OUT_API char *lm_out_target(const char *path);

#ifdef __cplusplus
}
#endif
#endif
