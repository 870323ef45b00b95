/* ask.c -- one session's input and record file.  Answers are blank-separated tokens
 * (several per line, like the original's cin >>); a line may start with "input:" so
 * that `grep input: rec` replays.  On a terminal a bad answer is explained and asked
 * again; in a replay it is reported as FILE:LINE and the session stops (exit 2).
 * The record is flushed before every read; a signal while we wait for input ends the
 * session at once, one during a computation sets the stop flag that long operations
 * poll (lm_stop_requested), so an interrupted session keeps every accepted answer. */
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>
#include <readline/readline.h>
#include <readline/history.h>
#include "ask.h"
#include "common/lm_out.h"

static char history_path[4096];

/* Stopping.  The signal handler only records the signal, except while we wait for
 * an answer (nothing half-done then: the record was flushed before the read), or on
 * a second signal (the user insists): then it runs the stop hooks and exits at once.
 * Long operations poll lm_stop_requested() and unwind themselves; main() turns a
 * recorded signal into exit status 128+N. */
static volatile sig_atomic_t stop_sig, waiting_for_input;
#define MAX_HOOKS 8
static struct { void (*fn)(void *); void *ctx; } hooks[MAX_HOOKS];
static volatile sig_atomic_t nhooks;

void lm_run_stop_hooks(void)
{
    for (int i = nhooks - 1; i >= 0; i--)
        if (hooks[i].fn) hooks[i].fn(hooks[i].ctx);
}

int lm_on_stop(void (*fn)(void *ctx), void *ctx)
{
    if (nhooks >= MAX_HOOKS) return -1;
    hooks[nhooks].ctx = ctx;
    hooks[nhooks].fn = fn;
    nhooks++;
    return 0;
}

void lm_on_stop_remove(void (*fn)(void *ctx), void *ctx)
{
    for (int i = 0; i < nhooks; i++)
        if (hooks[i].fn == fn && hooks[i].ctx == ctx) hooks[i].fn = NULL;
}

int lm_stop_requested(void) { return stop_sig; }

static void stop_now(int sig)
{
    static const char msg[] =
        "\nlensmat: interrupted; the record file keeps every answer accepted so far\n";
    ssize_t r;
    lm_run_stop_hooks();
    r = write(2, msg, sizeof msg - 1);
    (void)r;
    _exit(128 + sig);
}

static void on_signal(int sig)
{
    int again = stop_sig != 0;
    stop_sig = sig;
    if (waiting_for_input || again) stop_now(sig);
}

static void signals_setup(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGHUP, &sa, NULL);
}

static void history_setup(void)
{
    const char *home = getenv("HOME");
    if (!home) return;
    snprintf(history_path, sizeof history_path, "%s/.lensmat_history", home);
    using_history();
    read_history(history_path);
}

static int io_open(lm_io *io, const char *rec_name, FILE *in, const char *in_name,
                   int original, int whole)
{
    memset(io, 0, sizeof *io);
    io->whole = whole;
    {   /* the name as messages show it ("Output was written to file X") */
        size_t cap = 4 * strlen(rec_name) + 4;
        if ((io->rec_shown = malloc(cap))) lm_escape(rec_name, io->rec_shown, cap);
        else io->rec_shown = (char *)"the record file";
    }
    io->original = original;
    io->rec_name = rec_name;
    io->in = in;
    io->src = in_name;
    lm_files_reset();       /* one session per process: its own files only */
    if (in) {
        struct stat st;
        if (fstat(fileno(in), &st) == 0 && S_ISREG(st.st_mode)) {
            io->in_known = 1;
            io->in_dev = st.st_dev;
            io->in_ino = st.st_ino;
            lm_files_answers(in_name && in_name[0] != '<' ? in_name : NULL, &st);
        }
    }
    {
        char msg[1024];
        if (lm_check_output(io, rec_name, msg, sizeof msg)) {
            fprintf(stderr, "lensmat: %s\n", msg);
            return -1;
        }
    }
    /* a whole output is made in memory and written through lm_out by lm_io_close,
     * only after a run that succeeded (a failed one leaves an earlier file as it was) */
    io->rec = whole ? open_memstream(&io->whole_buf, &io->whole_len) : fopen(rec_name, "w");
    if (!io->rec) {
        fprintf(stderr, "lensmat: cannot write the record file %s: %s\n", rec_name,
                strerror(errno));
        return -1;
    }
    {
        struct stat st;
        if (fstat(fileno(io->rec), &st) == 0 && S_ISREG(st.st_mode)) {
            io->rec_known = 1;
            io->rec_dev = st.st_dev;
            io->rec_ino = st.st_ino;
            lm_files_record(rec_name, &st);
        } else lm_files_record(rec_name, NULL);
    }
    /* Interactive means a person types the answers: standard input is a terminal.
     * Prompts still go to stdout (`lensmat x.rec | tee log` keeps them); readline
     * echoes and edits on a terminal: stdout if it is one, else stderr, else the
     * controlling terminal. */
    io->interactive = in == stdin && isatty(0);
    if (io->interactive) {
        history_setup();
        if (!isatty(1)) {
            FILE *tty = isatty(2) ? stderr : fopen("/dev/tty", "w");
            if (tty) rl_outstream = tty;
        }
    }
    signals_setup();
    io->cur = "";
    return 0;
}

int lm_io_close(lm_io *io)
{
    int bad = 0;
    if (io->whole && io->rec) {
        char why[1200], shown[4 * sizeof why];
        int lost = ferror(io->rec) | fclose(io->rec);   /* whole_buf is complete now */
        io->rec = NULL;
        if (lost) {
            fprintf(stderr, "lensmat: %s: out of memory\n", io->rec_shown);
            bad = 1;
        } else if (!io->discard &&
                   lm_out_save(io->rec_name, io->whole_buf, io->whole_len, why, sizeof why)) {
            lm_escape(why, shown, sizeof shown);
            fprintf(stderr, "lensmat: %s\n", shown);
            bad = 1;
        }
        free(io->whole_buf);
        io->whole_buf = NULL;
    }
    if (lm_stdout_check() < 0) bad = 1;
    if (io->rec && (ferror(io->rec) | fclose(io->rec))) {
        fprintf(stderr, "lensmat: error writing the record file %s\n", io->rec_shown);
        bad = 1;
    }
    free(io->buf);
    if (io->rec_shown && strcmp(io->rec_shown, "the record file")) free(io->rec_shown);
    io->rec_shown = NULL;
    io->rec = NULL;
    return bad ? -1 : 0;
}

int lm_stdout_check(void)
{
    static int said;
    errno = 0;
    if (fflush(stdout) == 0 && !ferror(stdout)) return 0;
    if (!said) {
        fprintf(stderr, "lensmat: error writing standard output%s%s\n", errno ? ": " : "",
                errno ? strerror(errno) : "");
        said = 1;
    }
    return -1;
}

int lm_io_open(lm_io *io, const char *rec_name, FILE *in, const char *in_name,
               int original)
{
    return io_open(io, rec_name, in, in_name, original, 0);
}

int lm_io_open_whole(lm_io *io, const char *out_name, FILE *in, const char *in_name)
{
    return io_open(io, out_name, in, in_name, 0, 1);
}

void lm_say(lm_io *io, int where, const char *fmt, ...)
{
    va_list ap;
    if (where & LM_OUT) {
        va_start(ap, fmt);
        vprintf(fmt, ap);
        va_end(ap);
    }
    if (where & LM_REC) {
        va_start(ap, fmt);
        vfprintf(io->rec, fmt, ap);
        va_end(ap);
    }
}

double lm_clean(const lm_io *io, double v) { return io->original ? v : v + 0.0; }

void lm_matrix(lm_io *io, int where, const char *elem_fmt, double a, double b,
               double c, double d)
{
    double e[4] = {a, b, c, d};
    for (int i = 0; i < 4; i++) {
        lm_say(io, where, elem_fmt, lm_clean(io, e[i]));
        if (i % 2) lm_say(io, where, "\n");
    }
}

/* Read one line into io->buf: its length, or -1 at end of input. */
static ssize_t get_line(lm_io *io)
{
    ssize_t n;
    fflush(stdout);
    fflush(io->rec);
    waiting_for_input = 1;
    if (stop_sig) stop_now(stop_sig);   /* a signal came during the last computation */
    if (io->interactive) {
        char *l = readline("");
        waiting_for_input = 0;
        if (!l) return -1;
        if (*l) {
            add_history(l);
            if (*history_path) {
                if (append_history(1, history_path) != 0) write_history(history_path);
                history_truncate_file(history_path, 1000);
            }
        }
        free(io->buf);
        io->buf = l;
        io->cap = strlen(l) + 1;
        return (ssize_t)strlen(l);
    }
    n = getline(&io->buf, &io->cap, io->in);
    waiting_for_input = 0;
    return n;
}

/* Read the next answer line.  A UTF-8 byte-order mark before the first line and
 * comment lines (first non-blank byte '#') are skipped; line numbers still count
 * every line.  Returns 0, -1 at end of input, or -3 for a line holding a NUL byte
 * (reported here: getline keeps it, and every string function would silently cut
 * the line there). */
static int read_line(lm_io *io)
{
    for (;;) {
        ssize_t n = get_line(io);
        const char *p;
        if (n < 0) return -1;
        io->line++;
        p = io->buf;
        if (strlen(p) != (size_t)n) {
            fprintf(stderr, "lensmat: %s:%ld: this line holds a NUL byte (answers are "
                    "text; is this a binary file?)\n", io->src, io->line);
            io->cur = "";
            return -3;
        }
        if (io->line == 1 && !strncmp(p, "\xef\xbb\xbf", 3)) p += 3;
        io->cur = p + strspn(p, " \t");
        if (*io->cur == '#') continue;
        io->cur = lm_line_start(p);
        return 0;
    }
}

/* Fetch the next token, reading lines as needed.  0, -1 at end of input, -2 for a
 * token too long to be an answer, -3 for a line that cannot be read (reported). */
static int next_token(lm_io *io, char *tok)
{
    for (;;) {
        int n = lm_next_token(&io->cur, tok, LM_TOKEN_MAX);
        if (n > 0) return 0;
        if (n < 0) return -2;
        if ((n = read_line(io)) < 0) return n;
    }
}

/* The same for a word that may be quoted (lm_next_word): 0, -1, -2 (too long for
 * cap), -3, or -4 for an unterminated quote, -5 for a \x00 escape. */
static int next_word(lm_io *io, char *tok, size_t cap)
{
    for (;;) {
        int n = lm_next_word(&io->cur, tok, cap);
        if (n > 0) return 0;
        if (n == -1) return -2;
        if (n < 0) return n - 2;
        if ((n = read_line(io)) < 0) return n;
    }
}

/* --example: show the answer on stdout as if it had been typed, in the form the
 * record echoes it (which reads back as the same answer). */
static void show_answer(lm_io *io, const char *tok)
{
    if (io->show_answers) printf("%s\n", tok);
}

/* Report a bad answer.  Terminal: explain, drop the rest of the line, ask again
 * (LM_GO).  Replay: FILE:LINE message and LM_FAIL. */
static int complain(lm_io *io, const char *what, const char *fmt, const char *tok)
{
    char raw[1200], msg[4 * sizeof raw];
    snprintf(raw, sizeof raw, fmt, tok);
    lm_escape(raw, msg, sizeof msg);    /* no answer's bytes reach the terminal raw */
    if (io->interactive) {
        fprintf(stderr, "lensmat: %s: %s; please answer again.\n", what, msg);
        io->cur = "";
        return LM_GO;
    }
    fprintf(stderr, "lensmat: %s:%ld: %s: %s\n", io->src, io->line > 0 ? io->line : 1,
            what, msg);
    return LM_FAIL;
}

static int end_of_input(lm_io *io, const char *what)
{
    if (io->interactive) {
        printf("\n");
        fprintf(stderr, "lensmat: session ended; the record file %s keeps every "
                "answer so far\n", io->rec_name);
        return LM_QUIT;
    }
    fprintf(stderr, "lensmat: %s:%ld: end of input while asking for %s\n", io->src,
            io->line + 1, what);
    return LM_FAIL;
}

/* Check a parsed number against the spec; NULL if fine, else the complaint. */
static const char *violates(const lm_numspec *spec, enum lm_num_status st, double v)
{
    if (st == LM_NUM_PLANE)
        return (spec->flags & (LM_ALLOW_PLANE | LM_ALLOW_INF)) ? NULL :
        "'%s': infinity is allowed only for a radius (a plane surface)";
    if (st != LM_NUM_OK) return NULL;
    if ((spec->flags & LM_POSITIVE) && !(v > 0)) return "'%s' must be greater than 0";
    if ((spec->flags & LM_NONNEG) && v < 0) return "'%s' must not be negative";
    if ((spec->flags & LM_NONZERO) && v == 0) return "'%s' must not be 0";
    if ((spec->flags & LM_AT_LEAST) && v < spec->min)
        return "'%s' lies left of the previous surface (locations must not decrease)";
    return NULL;
}

int lm_ask_number(lm_io *io, const char *out, const char *rec, const lm_numspec *spec,
                  double *v)
{
    char tok[LM_TOKEN_MAX], echo[LM_TOKEN_MAX + 16];
    if (rec) lm_say(io, LM_REC, "%s", rec);
    for (;;) {
        int r;
        enum lm_num_status st;
        const char *bad;
        if (out) lm_say(io, LM_OUT, "%s", out);
        r = next_token(io, tok);
        if (r == -1) return end_of_input(io, spec->what);
        if (r == -3) return LM_FAIL;
        if (r == -2) {
            if (complain(io, spec->what, "%san answer longer than 255 characters", "")) 
                return LM_FAIL;
            continue;
        }
        st = lm_parse_number(tok, v);
        if (st == LM_NUM_SYNTAX && (spec->flags & LM_INDEX)) {
            char why[300];
            double lambda;
            int k = lm_index_name(tok, v, echo, sizeof echo, &lambda, why, sizeof why);
            if (k == 1 && lambda == 0) {               /* a medium's name */
                lm_say(io, LM_REC, "input: %s\n", echo);
                show_answer(io, echo);
                if (!strcmp(echo, "air"))   /* two airs in lensmat: say which this is */
                    lm_say(io, LM_BOTH, "(air: index %.7g, air at 589 nm, as this dialogue "
                           "and positions prescriptions take it; lens files by thickness, "
                           ".zmx and --colour take air as 1)\n", *v);
                else lm_say(io, LM_BOTH, "(%s: index %g)\n", echo, *v);
                return LM_GO;
            }
            if (k == 1) {                              /* a glass at a wavelength */
                lm_say(io, LM_REC, "input: %s\n", echo);
                show_answer(io, echo);
                lm_say(io, LM_BOTH, "(%s: index %.6f at %.1f nm)\n", echo, *v,
                       lambda * 1000);
                return LM_GO;
            }
            if (k == -1) {
                if (complain(io, spec->what, "%s", why)) return LM_FAIL;
                continue;
            }
        }
        if (st != LM_NUM_OK && st != LM_NUM_PLANE) {
            /* for an index, a word gets the media named; "1,5" just is not a number */
            int word = (spec->flags & LM_INDEX) && isalpha((unsigned char)tok[0]);
            if (complain(io, spec->what, st == LM_NUM_SYNTAX && !word ?
                         "'%s' is not a number" : st == LM_NUM_SYNTAX ?
                         "'%s' is not a number, nor a medium or glass lensmat knows (air, "
                         "water, cornea, crown, N-BK7, SF2, 1.5168/64.17, ...)" : st == LM_NUM_NAN ?
                         "'%s': nan is not a number" :
                         "'%s' is out of range (|x| <= 1e30)", tok)) return LM_FAIL;
            continue;
        }
        bad = violates(spec, st, *v);
        if (bad) {
            if (complain(io, spec->what, bad, tok)) return LM_FAIL;
            continue;
        }
        if (st == LM_NUM_PLANE && !(spec->flags & LM_ALLOW_PLANE))
            snprintf(echo, sizeof echo, "%s", *v < 0 ? "-inf" : "inf");
        else if (st == LM_NUM_PLANE) snprintf(echo, sizeof echo, "plane");
        else lm_format_echo(*v, echo, sizeof echo);
        if ((spec->flags & LM_ALLOW_PLANE) && *v == 0.0) *v = INFINITY;
        lm_say(io, LM_REC, "input: %s\n", echo);
        show_answer(io, echo);
        return LM_GO;
    }
}

int lm_ask_yn(lm_io *io, const char *out, const char *rec, const char *what, int *yes)
{
    char tok[LM_TOKEN_MAX];
    if (rec) lm_say(io, LM_REC, "%s", rec);
    for (;;) {
        int r, c;
        if (out) lm_say(io, LM_OUT, "%s", out);
        r = next_token(io, tok);
        if (r == -1) return end_of_input(io, what);
        if (r == -3) return LM_FAIL;
        c = r == 0 ? lm_parse_yn(tok) : 0;
        if (!c) {
            if (complain(io, what, "'%s': answer y or n", r == 0 ? tok : "(too long)"))
                return LM_FAIL;
            continue;
        }
        *yes = c == 'y';
        lm_say(io, LM_REC, "input: %c\n", c);
        show_answer(io, c == 'y' ? "y" : "n");
        return LM_GO;
    }
}

int lm_ask_choice(lm_io *io, const char *out, const char *rec, const char *what,
                  const char *const *choices, int *idx)
{
    char tok[LM_TOKEN_MAX];
    if (rec) lm_say(io, LM_REC, "%s", rec);
    for (;;) {
        int r, i;
        if (out) lm_say(io, LM_OUT, "%s", out);
        r = next_token(io, tok);
        if (r == -1) return end_of_input(io, what);
        if (r == -3) return LM_FAIL;
        for (i = 0; r == 0 && choices[i]; i++)
            if (!strcasecmp(tok, choices[i])) break;
        if (r != 0 || !choices[i]) {
            if (complain(io, what, "'%s' is not one of the choices offered",
                         r == 0 ? tok : "(too long)"))
                return LM_FAIL;
            continue;
        }
        *idx = i;
        lm_say(io, LM_REC, "input: %s\n", choices[i]);
        show_answer(io, choices[i]);
        return LM_GO;
    }
}

/* Word answers may be quoted ("a b.rec"); the record echoes the word in the form that
 * reads back as it (lm_quote_word), which is the word itself for a plain name. */
int lm_ask_word(lm_io *io, const char *out, const char *rec, const char *what,
                int (*check)(void *ctx, const char *word, char *msg, size_t cap),
                void *ctx, char *buf, size_t cap)
{
    enum { WORD_MAX = 4096 };
    char tok[WORD_MAX], echo[4 * WORD_MAX + 3], msg[1024];
    if (rec) lm_say(io, LM_REC, "%s", rec);
    for (;;) {
        int r;
        if (out) lm_say(io, LM_OUT, "%s", out);
        r = next_word(io, tok, sizeof tok);
        if (r == -1) return end_of_input(io, what);
        if (r == -3) return LM_FAIL;
        if (r == 0 && strlen(tok) >= cap) r = -2;
        msg[0] = '\0';
        if (r == 0 && io->word_alone) {     /* a file name: alone on its line */
            const char *rest = io->cur;
            char next[LM_TOKEN_MAX];
            if (lm_next_token(&rest, next, sizeof next) != 0) {
                char a[64], b[64];
                snprintf(a, sizeof a, "%.40s", tok);
                snprintf(b, sizeof b, "%.40s", next);
                snprintf(msg, sizeof msg, "'%s' and then '%s' on the same line: a file "
                         "name that holds a blank must be quoted (\"%s %s\"), and nothing "
                         "may follow a file name on its line", a, b, a, b);
                r = -6;
            }
        }
        if (r == 0 && check && check(ctx, tok, msg, sizeof msg)) r = -6;
        if (r != 0) {
            if (r == -2) snprintf(msg, sizeof msg, "the answer is too long");
            if (r == -4) snprintf(msg, sizeof msg, "a quote is not closed on its line");
            if (r == -5) snprintf(msg, sizeof msg, "\\x00: no name holds a NUL byte");
            if (complain(io, what, "%s", msg)) return LM_FAIL;
            continue;
        }
        memcpy(buf, tok, strlen(tok) + 1);
        lm_quote_word(tok, echo, sizeof echo);
        lm_say(io, LM_REC, "input: %s\n", echo);
        show_answer(io, echo);
        return LM_GO;
    }
}

int lm_ask_file(lm_io *io, const char *out, const char *rec, const char *what,
                int (*check)(void *ctx, const char *word, char *msg, size_t cap),
                void *ctx, char *buf, size_t cap)
{
    int rc;
    io->word_alone = 1;
    rc = lm_ask_word(io, out, rec, what, check, ctx, buf, cap);
    io->word_alone = 0;
    return rc;
}

/* Answers left after the end: on the last line read, or on any later line (a file
 * of blank lines is read to its end, up to 100 000 lines; comment lines are no
 * answers). */
void lm_check_leftover(lm_io *io)
{
    char tok[LM_TOKEN_MAX], shown[4 * LM_TOKEN_MAX];
    long lines = 0;
    if (io->interactive) return;
    for (;;) {
        int n = lm_next_token(&io->cur, tok, sizeof tok);
        if (n != 0) {
            lm_escape(n > 0 ? tok : "(a long token)", shown, sizeof shown);
            fprintf(stderr, "lensmat: %s:%ld: warning: answers after the end of the "
                    "dialogue were ignored (from '%s' on)\n", io->src, io->line, shown);
            return;
        }
        if (++lines > 100000 || read_line(io) != 0) return;
    }
}

/* ---- answers checked together, indices by name (see ask.h) ---------------------- */
#include <ctype.h>
#include "../paraxial/paraxial.h"

void lm_mark_set(lm_io *io, lm_mark *m)
{
    fflush(io->rec);
    m->rec_off = ftell(io->rec);
}

int lm_mark_reject(lm_io *io, const lm_mark *m, const char *what, const char *msg,
                   const char *again, const char *rec_prompt)
{
    fflush(io->rec);
    if (m->rec_off >= 0 && ftruncate(fileno(io->rec), m->rec_off) == 0)
        fseek(io->rec, m->rec_off, SEEK_SET);
    else    /* a record that cannot be cut back (a pipe): say so in it */
        fprintf(io->rec, "(the answers above were rejected: %s)\n", msg);
    if (io->interactive) {
        fprintf(stderr, "lensmat: %s: %s; %s.\n", what, msg, again);
        io->cur = "";
        return LM_GO;
    }
    fprintf(stderr, "lensmat: %s:%ld: %s: %s\n", io->src, io->line > 0 ? io->line : 1,
            what, msg);
    if (rec_prompt) fputs(rec_prompt, io->rec);
    return LM_FAIL;
}

/* NAME or NAME@WAVELENGTH: the seed's media by their bare names keep their constant
 * indices (the classic's values: "water" is 1.333); a catalogue glass, a model glass
 * "nd/Vd", or any name with "@" takes the catalogue's formula, at the d line unless a
 * wavelength is named.  The echo is the catalogue's spelling (media: lower case) and
 * the wavelength as given (shorthands canonical), so a replay reads the same. */
int lm_index_name(const char *tok, double *v, char *echo, size_t cap, double *lambda,
                  char *why, size_t wcap)
{
    char name[LM_TOKEN_MAX];
    const char *at = strchr(tok, '@'), *wl = at ? at + 1 : NULL;
    const px_glass_rec *g;
    double n, l = PX_LAMBDA_D;
    size_t len = at ? (size_t)(at - tok) : strlen(tok);
    int r;
    *lambda = 0;
    if (len == 0 || len >= sizeof name) return 0;
    memcpy(name, tok, len);
    name[len] = '\0';
    if (!at && (n = px_medium_index(name)) > 0) {
        size_t i;
        for (i = 0; name[i] && i < cap - 1; i++) echo[i] = (char)tolower((unsigned char)name[i]);
        echo[i] = '\0';
        *v = n;
        return 1;
    }
    g = px_glass_find(name);
    if (!g && !isdigit((unsigned char)name[0])) {
        if (!at) return 0;
        snprintf(why, wcap, "'%.60s' is not a glass lensmat knows (N-BK7, F2, "
                 "F_SILICA, water, ...: data/glass.txt; or nd/Vd)", name);
        return -1;
    }
    if (wl && px_wavelength(wl, &l) != PX_OK) {
        snprintf(why, wcap, "'%.60s' is not a wavelength (F, d, C, e, g, hene, or a "
                 "number: nm above 100, else um)", wl);
        return -1;
    }
    r = px_glass_index(name, l, &n);
    if (r == PX_NO_GLASS) {
        if (!at && !strchr(name, '/')) return 0;
        snprintf(why, wcap, "'%.60s' is neither a catalogue glass nor a model glass "
                 "nd/Vd (1 < nd < 3, 5 <= Vd <= 150)", name);
        return -1;
    }
    if (r == PX_GLASS_RANGE) {
        if (g) snprintf(why, wcap, "%s's formula holds from %g to %g um, not at %g um",
                        g->name, g->lmin, g->lmax, l);
        else snprintf(why, wcap, "a model glass holds from 0.36 to 1 um, not at %g um", l);
        return -1;
    }
    if (r != PX_OK) return 0;
    if (wl) {
        static const char *const lines[] = {"F", "d", "C", "e", "g", "hene"};
        const char *w = wl;
        for (size_t i = 0; i < sizeof lines / sizeof *lines; i++)
            if (!strcasecmp(wl, lines[i])) w = lines[i];
        snprintf(echo, cap, "%s@%s", g ? g->name : name, w);
    } else snprintf(echo, cap, "%s", g ? g->name : name);
    *v = n;
    *lambda = l;
    return 1;
}

enum lm_num_status lm_parse_index(const char *tok, double *v)
{
    enum lm_num_status st = lm_parse_number(tok, v);
    char echo[LM_TOKEN_MAX], why[300];
    double n, l;
    if (st == LM_NUM_SYNTAX && lm_index_name(tok, &n, echo, sizeof echo, &l, why,
                                             sizeof why) == 1) {
        *v = n;
        return LM_NUM_OK;
    }
    return st;
}

int lm_ask_index(lm_io *io, const char *out, const char *rec, const lm_numspec *spec,
                 double *v)
{
    lm_numspec named = *spec;
    named.flags |= LM_INDEX;
    return lm_ask_number(io, out, rec, &named, v);
}

typedef struct count_ctx { int lo, hi, value; const char *bad; } count_ctx;
static int check_count(void *ctx, const char *w, char *msg, size_t cap)
{
    count_ctx *k = ctx;
    char *end;
    long v = strtol(w, &end, 10);
    if (end == w || *end || v < k->lo || v > k->hi) {
        snprintf(msg, cap, k->bad, w, k->lo, k->hi);
        return 1;
    }
    k->value = (int)v;
    return 0;
}

int lm_ask_count(lm_io *io, const char *out, const char *rec, const char *what,
                 const char *bad, int lo, int hi, int *v)
{
    char buf[32];
    count_ctx k = {lo, hi, 0, bad};
    int rc = lm_ask_word(io, out, rec, what, check_count, &k, buf, sizeof buf);
    if (rc == LM_GO) *v = k.value;
    return rc;
}
