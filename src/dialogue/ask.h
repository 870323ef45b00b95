/* ask.h -- the session: where answers come from (terminal with readline, or a
 * replayed file), the record file, and asking one question.  Every dialogue talks to
 * the user through this and nothing else. */
#ifndef ASK_H
#define ASK_H
#include <stdio.h>
#include "lex.h"

/* Return codes of every ask: go on, stop cleanly (Ctrl-D on a terminal), or stop
 * with an error already reported (replay: exit status 2). */
enum { LM_GO = 0, LM_QUIT = 1, LM_FAIL = 2 };

typedef struct lm_io {
    FILE *rec;              /* the record file; every accepted answer is flushed */
    const char *rec_name;
    FILE *in;               /* answers when not interactive */
    const char *src;        /* name for messages: a file name or "<stdin>" */
    long line;              /* line number of the current answer line */
    int interactive;        /* terminal: readline, re-ask on errors */
    int original;           /* --original: keep the original program's bytes */
    int show_answers;       /* --example: print each answer on stdout, as if typed */
    char *buf;              /* current answer line */
    size_t cap;
    const char *cur;        /* unread part of buf */
    int in_known, rec_known;   /* in_dev/in_ino, rec_dev/rec_ino are valid */
    unsigned long long in_dev, in_ino, rec_dev, rec_ino;
    int word_alone;         /* lm_ask_file: the word must end its line */
    char *rec_shown;        /* rec_name for messages, control bytes escaped */
    int whole;              /* lm_io_open_whole: rec is a memory stream */
    int discard;            /* set by the caller before lm_io_close: the run failed,
                               a whole output is not written */
    char *whole_buf;
    size_t whole_len;
} lm_io;

/* Output streams for lm_say. */
enum { LM_OUT = 1, LM_REC = 2, LM_BOTH = 3 };

/* Answers come from `in` (named in_name in messages); on a terminal stdin they are
 * read with readline.  Returns 0, or -1 (message printed) if OUTFILE cannot be made. */
int  lm_io_open(lm_io *io, const char *rec_name, FILE *in, const char *in_name,
                int original);
/* For a dialogue whose OUTFILE is one document made from its input (--to-zmx,
 * --to-thickness, --to-prescription): what it writes to the record (io->rec) is kept
 * in memory and lm_io_close writes it through src/common/lm_out.h ("-" is standard
 * output; a device or FIFO in place; else a temporary renamed over OUTFILE) unless
 * io->discard is set, so a failed run leaves an earlier OUTFILE as it was. */
int  lm_io_open_whole(lm_io *io, const char *out_name, FILE *in, const char *in_name);
int  lm_io_close(lm_io *io);          /* flushes and closes; 0 or -1 (said on stderr) */
/* Flushes standard output: 0, or -1 after saying once on stderr that it failed
 * (`lensmat ... > /dev/full`); main turns that into exit status 2. */
int  lm_stdout_check(void);
void lm_say(lm_io *io, int where, const char *fmt, ...);
void lm_matrix(lm_io *io, int where, const char *elem_fmt, double a, double b,
               double c, double d);
double lm_clean(const lm_io *io, double v);   /* -0 -> 0 unless --original */

/* Constraints a number answer must meet. */
enum {
    LM_ALLOW_PLANE = 1,     /* inf / plane / 0 accepted (a plane surface): *v = inf */
    LM_POSITIVE = 2,        /* > 0 */
    LM_NONNEG = 4,          /* >= 0 */
    LM_AT_LEAST = 8,        /* >= spec.min */
    LM_ALLOW_INF = 16,      /* inf / -inf accepted as such (a distance at infinity);
                               unlike LM_ALLOW_PLANE, 0 stays 0 */
    LM_NONZERO = 32,        /* != 0 */
    LM_INDEX = 64           /* an index: a medium's name is accepted too (lm_ask_index) */
};
typedef struct lm_numspec {
    const char *what;       /* "the radius of the lens surface", for messages */
    unsigned flags;
    double min;
} lm_numspec;

/* Print `out` on stdout and `rec` in the record (either may be NULL), read one
 * number, echo it to the record as "input: ...".  Returns LM_GO, LM_QUIT, LM_FAIL. */
int lm_ask_number(lm_io *io, const char *out, const char *rec, const lm_numspec *spec,
                  double *v);
/* The same for a y/n answer; *yes is 1 or 0. */
int lm_ask_yn(lm_io *io, const char *out, const char *rec, const char *what, int *yes);
/* The same for one word of `choices` (NULL-terminated, any case accepted); *idx is
 * its index and the record echoes it as written in `choices`. */
int lm_ask_choice(lm_io *io, const char *out, const char *rec, const char *what,
                  const char *const *choices, int *idx);
/* The same for one word (a file name): blank-free, or quoted ("my lens.rec", see
 * lm_next_word) to hold blanks; copied into buf (cap bytes; longer answers are
 * refused), echoed as "input: WORD" (quoted again when it needs it, lm_quote_word).  check (may be NULL) returns 0 to
 * accept, else writes why into msg: the answer is then handled like a bad number
 * (terminal: message and ask again; replay: SRC:LINE message, LM_FAIL) and is not
 * echoed, so a record never holds a rejected answer. */
int lm_ask_word(lm_io *io, const char *out, const char *rec, const char *what,
                int (*check)(void *ctx, const char *word, char *msg, size_t cap),
                void *ctx, char *buf, size_t cap);
/* lm_ask_word for a file name: the name must be the last answer on its line, so
 * that `my log.txt` typed without quotes is not taken as "my" (and "log.txt" as the
 * next answer): two words are explained with the quoting rule (terminal: asked
 * again; replay: SRC:LINE, LM_FAIL). */
int lm_ask_file(lm_io *io, const char *out, const char *rec, const char *what,
                int (*check)(void *ctx, const char *word, char *msg, size_t cap),
                void *ctx, char *buf, size_t cap);
/* lm_ask_word for a whole number lo..hi: *v.  A bad answer's message is `bad`
 * formatted with the answer (%s), lo and hi (%d, %d: a text may leave the last ones
 * out). */
int lm_ask_count(lm_io *io, const char *out, const char *rec, const char *what,
                 const char *bad, int lo, int hi, int *v);
/* Stopping (SIGINT, SIGTERM, SIGHUP).  A signal while lensmat waits for an answer,
 * or a second signal, runs the stop hooks and exits with 128+N at once.  During a
 * computation it only sets the stop flag: every long operation polls
 * lm_stop_requested() (at least every ~50 ms of work), leaves no output under its
 * final name, and returns LM_FAIL; main() then exits with 128+N.
 * lm_stop_requested: the signal number, or 0. */
int  lm_stop_requested(void);
/* Stop hooks run, newest first, from the signal handler before such an exit (so they
 * must be async-signal-safe: e.g. one write or ioctl that switches a laser off) and
 * from lm_run_stop_hooks.  At most 8; lm_on_stop returns 0 or -1 when full. */
int  lm_on_stop(void (*fn)(void *ctx), void *ctx);
void lm_on_stop_remove(void (*fn)(void *ctx), void *ctx);
void lm_run_stop_hooks(void);
/* The session's files (files.c).  No output may be a file the session reads (the
 * answers, lens files, scenes and meshes, rig files, frames) and no input one it
 * writes (the record, outputs named so far), under any spelling, hard link or
 * symbolic link (same device and inode; a file not there yet by its resolved path).
 * lm_check_output: 0 if path may be written (also when it does not exist yet; it is
 * then an output of the session), else -1 with why in msg.  Every dialogue checks
 * each output with it before opening anything for writing.  lm_check_input: the
 * same for a file about to be read (a file-name answer's check calls it first): 0
 * and registered as an input (role: "the lens file", for messages), or -1 with why. */
int  lm_check_output(const lm_io *io, const char *path, char *msg, size_t cap);
int  lm_check_input(const lm_io *io, const char *path, const char *role, char *msg,
                    size_t cap);
/* Files a module read for the session (a scene's meshes): registered as inputs
 * (role: "the mesh file", for messages; st: a struct stat, or NULL to stat path). */
void lm_files_note(const char *role, const char *path, const void *st);
void lm_files_reset(void);
void lm_files_answers(const char *path, const void *st);
void lm_files_record(const char *path, const void *st);
/* An existing OUTFILE that is no lensmat record (a lens file, scene, rig file,
 * answers file, binary or other text: the -i forgotten) is refused before anything
 * is opened: -1 with the message (it names -i when lens_from_input: the dialogue
 * reads its lens from -i), else 0.  Remove the file first to overwrite it.
 * lens_from_input 2, 3, 4: --to-zmx, --to-thickness, --to-prescription with their
 * input given (-i, or not a terminal): an OUTFILE of the kind the converter writes
 * (.zmx, prescription by thickness, by positions) is its earlier output. */
int  lm_outfile_check(const char *path, const char *option, int lens_from_input,
                      char *msg, size_t cap);
/* After the last question: warn about answers left unread, on the last line read or
 * on any later one, with that line (replay only). */
void lm_check_leftover(lm_io *io);

/* ---- answers checked together, indices by name ---------------------------------
 * A group of answers that are each fine but may not go together (an erector lens
 * with Galileo's eyepiece, two equal object distances): lm_mark_set before the
 * group's first question, then, if the group does not hold, lm_mark_reject: the
 * record loses everything written since the mark (the rejected answers are never
 * kept).  Terminal: "lensmat: WHAT: MSG; AGAIN." on stderr, the rest of the line
 * dropped, LM_GO: the dialogue asks the group again from its first question.
 * Replay: "lensmat: SRC:LINE: WHAT: MSG" and LM_FAIL; the record then ends with
 * rec_prompt (the first question of the group, may be NULL), exactly as a replay
 * that ran out of answers there would leave it, so its grep'd answers replay to
 * the same record. */
typedef struct lm_mark { long rec_off; } lm_mark;
void lm_mark_set(lm_io *io, lm_mark *m);
int  lm_mark_reject(lm_io *io, const lm_mark *m, const char *what, const char *msg,
                    const char *again, const char *rec_prompt);
/* An index of refraction: a number, or a medium the paraxial engine names (air,
 * water, cornea, crown, ...; px_medium_index).  Returns LM_NUM_OK with *v set, or
 * the number's status. */
enum lm_num_status lm_parse_index(const char *tok, double *v);
/* An index by name: a medium (bare name, the seed's constant), a catalogue glass or
 * a model glass "nd/Vd" (src/paraxial/glass.c), optionally "@WAVELENGTH" (F d C e g
 * hene, nm or um; default d).  1: *v, the echo for the record and *lambda (um; 0 for
 * a medium's constant) set; 0: not a name; -1: a name whose index cannot be given
 * (unknown glass after "@", bad wavelength, outside the formula's range): why says. */
int lm_index_name(const char *tok, double *v, char *echo, size_t cap, double *lambda,
                  char *why, size_t wcap);
/* lm_ask_number for an index (spec's flags as there): a medium name is accepted,
 * echoed as its name (lower case) so the replay is exact, and its index is shown
 * on stdout and in the record ("(water: index 1.333)"); a number is handled and
 * echoed exactly as lm_ask_number does. */
int  lm_ask_index(lm_io *io, const char *out, const char *rec, const lm_numspec *spec,
                  double *v);

#endif
