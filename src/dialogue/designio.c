/* designio.c -- the design dialogues' shared parts (designio.h): loading the design
 * and trace modules, reading the lens and merit files through the design module,
 * and writing an output so that no half-written file ever has its final name. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "designio.h"
#include "engine.h"
#include "../trace/trace.h"

#define FILE_MAX (16 << 20)

static const trace_api *trace_table(void)
{
    static const trace_api *t;
    if (!t) {
        trace_get_api_fn get = (trace_get_api_fn)lm_engine_symbol("trace", TRACE_API_SYMBOL);
        t = get ? get(TRACE_ABI) : NULL;
        if (get && !t) fprintf(stderr, "lensmat: the trace module's interface does not match\n");
    }
    return t;
}

const ds_api *dz_api(void)
{
    static const ds_api *d;
    if (!d) {
        ds_get_api_fn get = (ds_get_api_fn)lm_engine_symbol("design", DS_API_SYMBOL);
        d = get ? get(DS_ABI) : NULL;
        if (get && !d) fprintf(stderr, "lensmat: the design module's interface does not match\n");
    }
    return d;
}

char *dz_slurp(const char *path, size_t *len, char *msg, size_t cap)
{
    FILE *f = fopen(path, "rb");
    char *buf;
    size_t n = 0, got;
    if (!f) { snprintf(msg, cap, "%s: cannot be read", path); return NULL; }
    if (!(buf = malloc(FILE_MAX + 1))) { fclose(f); snprintf(msg, cap, "out of memory"); return NULL; }
    while ((got = fread(buf + n, 1, FILE_MAX + 1 - n, f)) > 0) n += got;
    fclose(f);
    if (n > FILE_MAX) { free(buf); snprintf(msg, cap, "%s: larger than 16 MiB", path); return NULL; }
    buf[n] = '\0';
    *len = n;
    return buf;
}

static int check_lens(void *ctx, const char *w, char *msg, size_t cap)
{
    dz_files *f = ctx;
    const ds_api *ds = dz_api();
    const trace_api *tr = trace_table();
    size_t len;
    ds_problem *p = NULL;
    char *text;
    if (!ds || !tr) { snprintf(msg, cap, "the design or trace module is missing"); return 1; }
    if (!(text = dz_slurp(w, &len, msg, cap))) return 1;
    int rc = ds->read(text, len, w, NULL, 0, NULL, tr, &p, msg, cap);
    free(text);
    if (rc != DS_OK) return 1;
    ds->free(p);
    snprintf(f->lens, sizeof f->lens, "%s", w);
    return 0;
}

static int check_merit(void *ctx, const char *w, char *msg, size_t cap)
{
    dz_files *f = ctx;
    const ds_api *ds = dz_api();
    size_t len, mlen = 0;
    char *text, *mtext = NULL;
    ds_problem *p = NULL;
    if (!(text = dz_slurp(f->lens, &len, msg, cap))) return 1;
    if (strcmp(w, "-") && !(mtext = dz_slurp(w, &mlen, msg, cap))) { free(text); return 1; }
    int rc = ds->read(text, len, f->lens, mtext, mlen, mtext ? w : NULL, trace_table(), &p,
                      msg, cap);
    free(text);
    free(mtext);
    if (rc != DS_OK) return 1;
    if (f->p) ds->free(f->p);
    f->p = p;
    snprintf(f->merit, sizeof f->merit, "%s", w);
    return 0;
}

int dz_ask_files(lm_io *io, const char *fq, const char *fwhat, const char *mq,
                 const char *mwhat, dz_files *f)
{
    char buf[4096];
    int rc = lm_ask_word(io, fq, fq, fwhat, check_lens, f, buf, sizeof buf);
    if (rc) return rc;
    return lm_ask_word(io, mq, mq, mwhat, check_merit, f, buf, sizeof buf);
}

static int same_file(const char *a, const char *b)
{
    struct stat x, y;
    return stat(a, &x) == 0 && stat(b, &y) == 0 && x.st_dev == y.st_dev && x.st_ino == y.st_ino;
}

int dz_check_out(const lm_io *io, const dz_files *f, const char *path, char *msg, size_t cap)
{
    if (lm_check_output(io, path, msg, cap)) return -1;
    if (same_file(path, f->lens) || (strcmp(f->merit, "-") && same_file(path, f->merit))) {
        snprintf(msg, cap, "%s is an input: the output never overwrites one", path);
        return -1;
    }
    return 0;
}

int dz_write(const char *path, const char *text, size_t len, char *msg, size_t cap)
{
    size_t n = strlen(path);
    char *tmp = malloc(n + 16);
    FILE *fp;
    int fd;
    if (!tmp) { snprintf(msg, cap, "out of memory"); return -1; }
    memcpy(tmp, path, n);
    memcpy(tmp + n, ".tmp.XXXXXX", 12);
    if ((fd = mkstemp(tmp)) < 0) {
        snprintf(msg, cap, "%s: %s", path, strerror(errno));
        free(tmp);
        return -1;
    }
    if (!(fp = fdopen(fd, "wb"))) {
        snprintf(msg, cap, "%s: %s", path, strerror(errno));
        close(fd);
        remove(tmp);
        free(tmp);
        return -1;
    }
    int ok = fwrite(text, 1, len, fp) == len && fflush(fp) == 0 && fsync(fd) == 0;
    int e = errno;
    if (fclose(fp)) { ok = 0; e = errno; }
    if (ok && rename(tmp, path)) { ok = 0; e = errno; }
    if (!ok) {
        snprintf(msg, cap, "%s: %s", path, strerror(e ? e : EIO));
        remove(tmp);
        free(tmp);
        return -1;
    }
    free(tmp);
    return 0;
}
