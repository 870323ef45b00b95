/* files.c -- the session's files: every file it reads (the answers, lens files,
 * scenes and their meshes, rig files, frames) and every file it writes (the record,
 * each output named in an answer or a scene), so that no output is ever one of the
 * session's inputs and no input is one of its outputs, under any spelling, hard link
 * or symbolic link.  Also the first look at an existing OUTFILE: lensmat writes its
 * record there, so a lens file, scene or answers file named as OUTFILE (the `-i`
 * forgotten) is refused before it is touched.  One session per process: the
 * registry is static and lm_io_open resets it. */
#define _DEFAULT_SOURCE     /* realpath */
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include "ask.h"
#include "lex.h"
#include "../lens/lens.h"

enum { F_ANSWERS, F_INPUT, F_RECORD, F_OUTPUT };

typedef struct fent {
    int kind, known;                 /* known: dev/ino valid (the file existed) */
    unsigned long long dev, ino;
    char *canon;                     /* realpath, or realpath(folder)/name */
    char *name;                      /* as given, for messages */
    const char *role;                /* "the lens file": what the session reads it as */
} fent;

static fent *ents;
static size_t nents, capents;

void lm_files_reset(void)
{
    for (size_t i = 0; i < nents; i++) {
        free(ents[i].canon);
        free(ents[i].name);
    }
    free(ents);
    ents = NULL;
    nents = capents = 0;
}

/* The path with every folder and link resolved: realpath when it exists, else the
 * resolved folder and the last name (an output not written yet); NULL if neither. */
static char *canon_path(const char *path)
{
    char buf[PATH_MAX], *r = realpath(path, buf), *slash, *dir, *out;
    size_t n;
    if (r) return strdup(buf);
    slash = strrchr(path, '/');
    if (!slash) dir = strdup(".");
    else if (slash == path) dir = strdup("/");
    else dir = strndup(path, (size_t)(slash - path));
    if (!dir) return NULL;
    r = realpath(dir, buf);
    free(dir);
    if (!r) return NULL;
    n = strlen(buf) + strlen(slash ? slash + 1 : path) + 2;
    if (!(out = malloc(n))) return NULL;
    snprintf(out, n, "%s/%s", strcmp(buf, "/") ? buf : "", slash ? slash + 1 : path);
    return out;
}

/* Fill e for path (NULL name: an open stream's st only).  0, or -1 out of memory. */
static int describe(fent *e, int kind, const char *path, const struct stat *st)
{
    struct stat s;
    memset(e, 0, sizeof *e);
    e->kind = kind;
    if (!st && path && stat(path, &s) == 0) st = &s;
    if (st) {
        e->known = 1;
        e->dev = st->st_dev;
        e->ino = st->st_ino;
    }
    e->canon = path ? canon_path(path) : NULL;
    e->name = strdup(path ? path : "");
    return e->name ? 0 : -1;
}

static void drop(fent *e)
{
    free(e->canon);
    free(e->name);
}

static int same(const fent *a, const fent *b)
{
    if (a->known && b->known) return a->dev == b->dev && a->ino == b->ino;
    return a->canon && b->canon && !strcmp(a->canon, b->canon);
}

static void add(fent *e)
{
    for (size_t i = 0; i < nents; i++)
        if (ents[i].kind == e->kind && same(&ents[i], e) && ents[i].known == e->known) {
            drop(e);
            return;
        }
    if (nents == capents) {
        size_t c = capents ? capents * 2 : 16;
        fent *n = realloc(ents, c * sizeof *n);
        if (!n) { drop(e); return; }    /* out of memory: the check is lost, not the run */
        ents = n;
        capents = c;
    }
    ents[nents++] = *e;
}

/* The first registered file of one of kinds (a bit set) that is e; NULL if none. */
static const fent *find(const fent *e, unsigned kinds)
{
    for (size_t i = 0; i < nents; i++)
        if ((kinds >> ents[i].kind & 1) && same(&ents[i], e)) return &ents[i];
    return NULL;
}

void lm_files_note(const char *role, const char *path, const void *st)
{
    fent e;
    if (describe(&e, F_INPUT, path, st) == 0) {
        e.role = role;
        add(&e);
    }
}

void lm_files_answers(const char *path, const void *st)
{
    fent e;
    if (describe(&e, F_ANSWERS, path, st) == 0) add(&e);
}

void lm_files_record(const char *path, const void *st)
{
    fent e;
    if (describe(&e, F_RECORD, path, st) == 0) add(&e);
}

int lm_check_output(const lm_io *io, const char *path, char *msg, size_t cap)
{
    fent e;
    const fent *f;
    (void)io;
    if (describe(&e, F_OUTPUT, path, NULL)) return 0;
    if (!(f = find(&e, 1u << F_ANSWERS | 1u << F_RECORD))) f = find(&e, 1u << F_INPUT);
    if (f && f->kind == F_ANSWERS)
        snprintf(msg, cap, "%s is the file the answers are read from; refusing to "
                 "write over it", path);
    else if (f && f->kind == F_RECORD)
        snprintf(msg, cap, "%s is the record file of this session; refusing to write "
                 "over it", path);
    else if (f && !strcmp(f->name, path))
        snprintf(msg, cap, "%s is %s this session reads; refusing to write over it",
                 path, f->role ? f->role : "an input");
    else if (f)
        snprintf(msg, cap, "%s is %s, %s this session reads; refusing to write over it",
                 path, f->name, f->role ? f->role : "an input");
    if (f) { drop(&e); return -1; }
    add(&e);
    return 0;
}

int lm_check_input(const lm_io *io, const char *path, const char *role, char *msg,
                   size_t cap)
{
    fent e;
    const fent *f;
    (void)io;
    if (describe(&e, F_INPUT, path, NULL)) return 0;
    if (!(f = find(&e, 1u << F_RECORD))) f = find(&e, 1u << F_OUTPUT);
    if (f && f->kind == F_RECORD)
        snprintf(msg, cap, "%s is the record file of this session (OUTFILE), which it "
                 "is writing: give the record another name to read this file", path);
    else if (f)
        snprintf(msg, cap, "%s is %s, an output of this session: it cannot be read "
                 "as an input too", path, strcmp(f->name, path) ? f->name : "already");
    if (f) { drop(&e); return -1; }
    e.role = role;
    add(&e);
    return 0;
}

/* ---- an existing OUTFILE ---------------------------------------------------------
 * What a text is, when it is no lensmat record: NULL for a record (or nothing to
 * lose), else "a lens file" and the like.  A record holds "input:" lines among its
 * prompts; one cut short before its first answer holds prompts only, so any text
 * that is none of the files below counts as a record. */
static int starts_word(const char *l, const char *w)
{
    size_t n = strlen(w);
    return !strncmp(l, w, n) && (l[n] == ' ' || l[n] == '\t' || l[n] == '\n' ||
                                 l[n] == '\r' || l[n] == '\0');
}

static const char *kind_of_text(const char *s, size_t len, int *as_input)
{
    static const char *const scene_keys[] = {"mesh", "plane", "sphere", "source",
                                             "output", "lens", "detector", "disc", NULL};
    static const char *const rig_keys[] = {"chip", "tick_us", "laser", "interlock",
                                           "heartbeat", "axis", NULL};
    static const char *const lens_keys[] = {"index", "nearpoint", "object", "thickness",
                                            "positions", NULL};
    long lines = 0, inputs = 0, others = 0, scene = 0, rig = 0, lens = 0;
    *as_input = 1;
    if (memchr(s, '\0', len)) return "a binary file (an image, a frame?), not a lensmat record";
    if (ln_is_zmx(s, len)) return "a lens file (.zmx)";
    if (ln_is_rx_thickness(s, len)) return "a lens file (a prescription by thickness)";
    for (const char *l = s; l && l < s + len; l = memchr(l, '\n', (size_t)(s + len - l)),
         l = l ? l + 1 : NULL) {
        const char *p = l + strspn(l, " \t");
        if (p >= s + len) break;
        lines++;
        if (*p == '\n' || *p == '\r' || *p == '#') continue;
        if (!strncmp(p, "input:", 6)) { inputs++; continue; }
        others++;
        for (int i = 0; scene_keys[i]; i++) scene += starts_word(p, scene_keys[i]);
        for (int i = 0; rig_keys[i]; i++) rig += starts_word(p, rig_keys[i]);
        for (int i = 0; lens_keys[i]; i++) lens += starts_word(p, lens_keys[i]);
    }
    if (inputs && others) return NULL;                  /* a record */
    if (inputs) return "an answers file (the input: lines of a record)";
    if (lens && lens >= scene && lens >= rig) return "a lens file (a prescription)";
    if (scene && scene >= rig) return "a scene file";
    if (rig) return "a rig file";
    /* Other text may be a record that ended before its first answer (prompts only):
     * it is written over as before. */
    (void)lines;
    return NULL;
}

int lm_outfile_check(const char *path, const char *option, int lens_from_input,
                     char *msg, size_t cap)
{
    struct stat st;
    FILE *f;
    char *buf;
    size_t n;
    const char *kind;
    char shown[1024];
    int as_input;
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size == 0) return 0;
    if (!(f = fopen(path, "rb"))) return 0;           /* fopen "w" will say why */
    if (!(buf = malloc(65537))) { fclose(f); return 0; }
    n = fread(buf, 1, 65536, f);
    fclose(f);
    buf[n] = '\0';
    kind = kind_of_text(buf, n, &as_input);
    /* a converter given its input writes a lens file: an earlier one is its output */
    if (kind && lens_from_input >= 2 &&
        !strcmp(kind, lens_from_input == 2 ? "a lens file (.zmx)" : lens_from_input == 3 ?
                "a lens file (a prescription by thickness)" : "a lens file (a prescription)"))
        kind = NULL;
    /* an answers file is always read with -i; a lens file by the converters */
    if (kind && as_input && !lens_from_input && strncmp(kind, "an answers", 10))
        as_input = 2;
    free(buf);
    if (!kind) return 0;
    lm_escape(path, shown, sizeof shown);
    path = shown;
    if (as_input == 1)
        snprintf(msg, cap, "OUTFILE %s is %s; did you mean -i %s out.rec?\n"
                 "lensmat: (OUTFILE is where lensmat %s writes its record, which would "
                 "destroy it; to overwrite it on purpose, remove it first)", path, kind,
                 path, option);
    else if (as_input == 2)
        snprintf(msg, cap, "OUTFILE %s is %s; did you mean lensmat %s out.rec, and %s "
                 "as the answer to the file question?\n"
                 "lensmat: (OUTFILE is where lensmat writes its record, which would "
                 "destroy it; to overwrite it on purpose, remove it first)", path, kind,
                 option, path);
    else
        snprintf(msg, cap, "OUTFILE %s exists and is %s\n"
                 "lensmat: (OUTFILE is where lensmat %s writes its record, which would "
                 "destroy it; give a new name, or remove it first to overwrite it on "
                 "purpose)", path, kind, option);
    return -1;
}
