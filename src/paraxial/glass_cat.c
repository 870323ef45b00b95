/* glass_cat.c -- the AGF glass catalogues available to this process: found on first
 * use in $LENSMAT_GLASS_PATH, data/agf/ and ../shared/glass/, read by agf.c, kept
 * for the life of the process (a few hundred kilobytes for the big makers' files).
 * The only file I/O of the paraxial engine: it reads catalogues, never writes.
 *
 * Why not at start-up: the classic dialogue starts in about 2 ms and names no AGF
 * glass; the catalogues are read the first time a name is not in the built-in
 * catalogue (px_glass_find) or a caller asks for them. */
#include <ctype.h>
#include <dirent.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include "paraxial.h"

#define CAT_MAX 64
#define FILE_MAX (32 << 20)

static px_glass_cat cats[CAT_MAX];
static int ncat;
static char *notes;                   /* "what failed" lines */
static size_t nlen, ncap;
static pthread_once_t once = PTHREAD_ONCE_INIT;

static void note(const char *fmt, const char *a, const char *b)
{
    char line[1200];
    size_t k;
    snprintf(line, sizeof line, fmt, a, b);
    k = strlen(line);
    if (nlen + k + 2 > ncap) {
        size_t c = (ncap + k + 2) * 2;
        char *t = realloc(notes, c);
        if (!t) return;
        notes = t;
        ncap = c;
    }
    memcpy(notes + nlen, line, k);
    nlen += k;
    notes[nlen++] = '\n';
    notes[nlen] = '\0';
}

static int has_agf_suffix(const char *f)
{
    size_t n = strlen(f);
    return n > 4 && !strcasecmp(f + n - 4, ".agf");
}

/* One file: its catalogue name is the file name without ".agf", in upper case. */
static void load_file(const char *path)
{
    const char *base = strrchr(path, '/');
    char name[256], err[1024];
    FILE *f;
    char *buf;
    size_t n = 0, got;
    base = base ? base + 1 : path;
    snprintf(name, sizeof name, "%.*s", (int)(strlen(base) - 4), base);
    for (char *q = name; *q; q++) *q = (char)toupper((unsigned char)*q);
    for (int i = 0; i < ncat; i++)
        if (!strcasecmp(cats[i].name, name)) return;    /* the first place wins */
    if (ncat == CAT_MAX) { note("%s: more than 64 catalogues: skipped%s", path, ""); return; }
    if (!(f = fopen(path, "rb"))) { note("%s: cannot be read%s", path, ""); return; }
    if (!(buf = malloc(FILE_MAX + 1))) { fclose(f); return; }
    while ((got = fread(buf + n, 1, FILE_MAX + 1 - n, f)) > 0) n += got;
    fclose(f);
    if (n > FILE_MAX) note("%s: larger than 32 MiB: not a glass catalogue%s", path, "");
    else if (px_agf_read(buf, n, name, path, &cats[ncat], err, sizeof err) != PX_OK)
        note("%s%s", err, "");
    else {
        free(cats[ncat].path);
        size_t pl = strlen(path) + 1;
        if ((cats[ncat].path = malloc(pl))) memcpy(cats[ncat].path, path, pl);
        ncat++;
    }
    free(buf);
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Every *.agf of a directory, in name order (the same order on every machine). */
static void load_dir(const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    char **names = NULL;
    int n = 0, cap = 0;
    if (!d) return;
    while ((e = readdir(d))) {
        if (!has_agf_suffix(e->d_name)) continue;
        if (n == cap) {
            char **t = realloc(names, (size_t)(cap = cap ? 2 * cap : 16) * sizeof *t);
            if (!t) break;
            names = t;
        }
        size_t k = strlen(dir) + strlen(e->d_name) + 2;
        if (!(names[n] = malloc(k))) break;
        snprintf(names[n++], k, "%s/%s", dir, e->d_name);
    }
    closedir(d);
    if (n) qsort(names, (size_t)n, sizeof *names, cmp_str);
    for (int i = 0; i < n; i++) { load_file(names[i]); free(names[i]); }
    free(names);
}

static void load_place(const char *p)
{
    struct stat st;
    if (!*p || stat(p, &st) != 0) return;
    if (S_ISDIR(st.st_mode)) load_dir(p);
    else if (has_agf_suffix(p)) load_file(p);
}

static void load_all(void)
{
    const char *env = getenv("LENSMAT_GLASS_PATH");
    if (env) {
        char *copy = malloc(strlen(env) + 1), *save = NULL;
        if (copy) {
            strcpy(copy, env);
            for (char *p = strtok_r(copy, ":", &save); p; p = strtok_r(NULL, ":", &save))
                load_place(p);
            free(copy);
        }
    }
    load_place("data/agf");
    load_place("../shared/glass");
}

static void ensure(void) { pthread_once(&once, load_all); }

int px_glass_cat_count(void) { ensure(); return ncat; }

const px_glass_cat *px_glass_cat_at(int i)
{
    ensure();
    return i >= 0 && i < ncat ? &cats[i] : NULL;
}

const px_glass_cat *px_glass_cat_find(const char *name)
{
    ensure();
    for (int i = 0; i < ncat; i++)
        if (!strcasecmp(cats[i].name, name)) return &cats[i];
    return NULL;
}

const char *px_glass_cat_notes(void) { ensure(); return notes ? notes : ""; }

int px_glass_total(void)
{
    int n = px_glass_count();
    ensure();
    for (int i = 0; i < ncat; i++) n += cats[i].n;
    return n;
}
