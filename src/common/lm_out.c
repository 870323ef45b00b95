/* lm_out.c -- one output file written safely (see lm_out.h for the rules).  Only libc:
 * the core (./lensmat) links it, and each module that writes files compiles it in with
 * hidden symbols, so no module needs a symbol of the executable. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "lm_out.h"

#define HOPS 40                 /* symbolic links followed, as the kernel does */

static int fail(char *err, size_t cap, const char *name, const char *what, int e)
{
    if (err && cap)
        snprintf(err, cap, "%s: %s%s%s", name, what, e ? ": " : "", e ? strerror(e) : "");
    errno = e;
    return -1;
}

static char *dup_n(const char *s, size_t n)
{
    char *d = malloc(n + 1);
    if (d) { memcpy(d, s, n); d[n] = '\0'; }
    return d;
}

/* path's folder joined with a link's relative target */
static char *beside(const char *path, const char *target)
{
    const char *slash = strrchr(path, '/');
    size_t dl = slash ? (size_t)(slash - path) + 1 : 0, tl = strlen(target);
    char *r = malloc(dl + tl + 1);
    if (!r) return NULL;
    memcpy(r, path, dl);
    memcpy(r + dl, target, tl + 1);
    return r;
}

/* Follows path's links: the last name in the chain (malloc'ed), its lstat in *st and
 * *exists.  NULL with errno on a loop or another error than "not there". */
static char *resolve(const char *path, struct stat *st, int *exists)
{
    char *cur = dup_n(path, strlen(path));
    for (int hops = 0; cur; hops++) {
        char *t, *next;
        ssize_t n;
        if (lstat(cur, st) != 0) {
            if (errno != ENOENT) { int e = errno; free(cur); errno = e; return NULL; }
            *exists = 0;
            return cur;
        }
        if (!S_ISLNK(st->st_mode)) { *exists = 1; return cur; }
        if (hops == HOPS) { free(cur); errno = ELOOP; return NULL; }
        if (!(t = malloc(PATH_MAX + 1))) { free(cur); errno = ENOMEM; return NULL; }
        n = readlink(cur, t, PATH_MAX);
        if (n < 0) { int e = errno; free(t); free(cur); errno = e; return NULL; }
        t[n] = '\0';
        next = t[0] == '/' ? dup_n(t, (size_t)n) : beside(cur, t);
        free(t);
        free(cur);
        cur = next;
    }
    errno = ENOMEM;
    return NULL;
}

char *lm_out_target(const char *path)
{
    struct stat st;
    int exists;
    return resolve(path, &st, &exists);
}

/* The process's umask without changing it (another thread may create a file now):
 * Linux says it in /proc/self/status; elsewhere set and restore. */
static mode_t the_umask(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    mode_t m;
    if (f) {
        while (fgets(line, sizeof line, f))
            if (!strncmp(line, "Umask:", 6)) {
                fclose(f);
                return (mode_t)strtol(line + 6, NULL, 8) & 0777;
            }
        fclose(f);
    }
    m = umask(022);
    umask(m);
    return m;
}

/* final + ".part.XXXXXX", or FOLDER/.lensmat.XXXXXX when that name would be too long */
static char *temp_name(const char *final)
{
    const char *slash = strrchr(final, '/'), *base = slash ? slash + 1 : final;
    size_t fl = strlen(final), dl = (size_t)(base - final);
    char *t = malloc(fl + 16);
    if (!t) return NULL;
    if (strlen(base) + 12 <= 255) snprintf(t, fl + 16, "%s.part.XXXXXX", final);
    else snprintf(t, fl + 16, "%.*s.lensmat.XXXXXX", (int)dl, final);
    return t;
}

static void clear(lm_out *o)
{
    free(o->name);
    free(o->final);
    free(o->tmp);
    free(o->part);
    memset(o, 0, sizeof *o);
    o->fd = -1;
}

int lm_out_open(lm_out *o, const char *path, unsigned flags, char *err, size_t cap)
{
    struct stat st;
    int exists = 0, e;
    memset(o, 0, sizeof *o);
    o->fd = -1;
    if (!path || !*path) return fail(err, cap, "lensmat", "an empty output file name", 0);
    if (!(o->name = dup_n(path, strlen(path)))) goto nomem;
    if (!strcmp(path, "-")) {
        if (flags & LM_OUT_REGULAR) {
            clear(o);
            return fail(err, cap, path, "standard output cannot hold this file (it must "
                        "be a regular file)", 0);
        }
        o->how = LM_OUT_STDOUT;
        o->fd = 1;
        if (!(flags & LM_OUT_FD)) o->f = stdout;
        else fflush(stdout);            /* what was printed comes first */
        return 0;
    }
    if (!(o->final = resolve(path, &st, &exists))) {
        e = errno;
        clear(o);
        return fail(err, cap, path, "cannot write", e);
    }
    if (exists && S_ISDIR(st.st_mode)) {
        clear(o);
        return fail(err, cap, path, "is a folder, not a file", 0);
    }
    if (exists && S_ISSOCK(st.st_mode)) {
        clear(o);
        return fail(err, cap, path, "is a socket; lensmat writes files, FIFOs and devices",
                    0);
    }
    if (exists && !S_ISREG(st.st_mode)) {       /* a device or a FIFO: in place */
        if (flags & LM_OUT_REGULAR) {
            clear(o);
            return fail(err, cap, path, "is not a regular file (this output must be one)",
                        0);
        }
        o->fd = open(o->final, O_WRONLY | O_NOCTTY | O_CLOEXEC);
        if (o->fd < 0) { e = errno; clear(o); return fail(err, cap, path, "cannot write", e); }
        o->how = LM_OUT_INPLACE;
    } else {
        size_t fl = strlen(o->final);
        mode_t mode = exists ? (st.st_mode & 07777) : (0666 & ~the_umask());
        if (!(o->tmp = temp_name(o->final)) || !(o->part = malloc(fl + 6))) goto nomem;
        memcpy(o->part, o->final, fl);
        memcpy(o->part + fl, ".part", 6);
        o->fd = mkstemp(o->tmp);
        if (o->fd < 0) { e = errno; clear(o); return fail(err, cap, path, "cannot write", e); }
        if (fchmod(o->fd, mode) != 0) { /* mkstemp made it 0600: not fatal */ }
        if (fcntl(o->fd, F_SETFD, FD_CLOEXEC) != 0) { /* only hygiene */ }
        o->how = LM_OUT_TEMP;
    }
    if (!(flags & LM_OUT_FD) && !(o->f = fdopen(o->fd, "w"))) {
        e = errno;
        lm_out_abort(o, 0);
        return fail(err, cap, path, "cannot write", e);
    }
    return 0;
nomem:
    clear(o);
    return fail(err, cap, path, "out of memory", 0);
}

int lm_out_commit(lm_out *o, char *err, size_t cap)
{
    int e = 0;
    const char *what = "write error";
    char *name = o->name;
    if (o->how == LM_OUT_STDOUT) {
        errno = 0;
        if (o->f && (fflush(o->f) != 0 || ferror(o->f))) e = errno ? errno : EIO;
        o->name = NULL;
        clear(o);
        if (e) { fail(err, cap, "standard output", what, e); free(name); return -1; }
        free(name);
        return 0;
    }
    if (o->f) {
        errno = 0;
        if (fflush(o->f) != 0 || ferror(o->f)) e = errno ? errno : EIO;
    }
    /* on disk before it takes the name; a device or FIFO has nothing to sync */
    if (!e && o->how == LM_OUT_TEMP && fsync(o->fd) != 0) e = errno;
    if (o->f) {
        if (fclose(o->f) != 0 && !e) e = errno;
    } else if (o->fd >= 0 && close(o->fd) != 0 && !e) e = errno;
    o->f = NULL;
    o->fd = -1;
    if (!e && o->how == LM_OUT_TEMP && rename(o->tmp, o->final) != 0) {
        e = errno;
        what = "cannot put the file in place";
    }
    if (e && o->how == LM_OUT_TEMP) unlink(o->tmp);
    o->name = NULL;
    clear(o);
    if (e) fail(err, cap, name, what, e);
    free(name);
    return e ? -1 : 0;
}

void lm_out_abort(lm_out *o, int keep_part)
{
    if (o->how == LM_OUT_STDOUT) {
        if (o->f) fflush(o->f);
    } else {
        if (o->f) fclose(o->f);
        else if (o->fd >= 0) close(o->fd);
        if (o->how == LM_OUT_TEMP && o->tmp) {
            if (!keep_part || rename(o->tmp, o->part) != 0) unlink(o->tmp);
        }
    }
    clear(o);
}

int lm_out_commit_fd_now(lm_out *o)
{
    int rc = 0;
    if (o->how == LM_OUT_STDOUT || o->fd < 0) { o->fd = -1; return 0; }
    if (close(o->fd) != 0) rc = -1;
    o->fd = -1;
    if (o->how == LM_OUT_TEMP) {
        if (rc == 0 && rename(o->tmp, o->final) != 0) rc = -1;
        if (rc) unlink(o->tmp);
    }
    o->how = 0;
    return rc;
}

void lm_out_abort_fd_now(lm_out *o)
{
    if (o->how == LM_OUT_STDOUT || o->fd < 0) { o->fd = -1; return; }
    close(o->fd);
    o->fd = -1;
    if (o->how == LM_OUT_TEMP && rename(o->tmp, o->part) != 0) unlink(o->tmp);
    o->how = 0;
}

void lm_out_free(lm_out *o)
{
    if (o->how && (o->fd >= 0 || o->f)) lm_out_abort(o, 0);
    else clear(o);
}

int lm_out_save(const char *path, const void *data, size_t len, char *err, size_t cap)
{
    lm_out o;
    const char *p = data;
    if (lm_out_open(&o, path, LM_OUT_FD, err, cap)) return -1;
    while (len > 0) {
        ssize_t n = write(o.fd, p, len);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) {
            int e = n < 0 ? errno : ENOSPC;
            char *name = o.name;
            o.name = NULL;
            lm_out_abort(&o, 0);
            fail(err, cap, !strcmp(path, "-") ? "standard output" : name ? name : path,
                 "write error", e);
            free(name);
            return -1;
        }
        p += n;
        len -= (size_t)n;
    }
    return lm_out_commit(&o, err, cap);
}
