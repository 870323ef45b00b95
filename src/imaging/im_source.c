/* im_source.c -- where frames come from: one image file, a numbered sequence of files
 * (a printf pattern with one %d), a video file or a live camera.  Video and cameras go
 * through lensmat-camera.so, dlopen'ed from beside this module the first time one is
 * opened, so reading PNG frames never maps videoio, FFmpeg or GStreamer. */
#define _GNU_SOURCE 1           /* dladdr */
#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include "im_camera.h"
#include "im_int.h"

enum { SRC_FILE, SRC_SEQ, SRC_VIDEO, SRC_CAMERA };

struct im_source {
    int kind, index, done;
    char *spec;
    void *cam;                 /* camera module handle */
};

static const im_cam_api *cam_api;

int im_camera_loaded(void) { return cam_api != NULL; }

static const im_cam_api *load_camera(char *err, size_t cap)
{
    Dl_info info;
    char path[PATH_MAX];
    const char *slash;
    if (cam_api) return cam_api;
    if (!dladdr((void *)load_camera, &info) || !info.dli_fname ||
        !(slash = strrchr(info.dli_fname, '/'))) {
        im_err(err, cap, IM_EIO, "cannot find where the imaging module lives");
        return NULL;
    }
    snprintf(path, sizeof path, "%.*s/lensmat-camera.so", (int)(slash - info.dli_fname),
             info.dli_fname);
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        im_err(err, cap, IM_EIO, "cannot load %s: %s", path, dlerror());
        return NULL;
    }
    im_cam_get_fn get = (im_cam_get_fn)dlsym(h, IM_CAMERA_SYMBOL);
    cam_api = get ? get(IM_CAMERA_ABI) : NULL;
    if (!cam_api) im_err(err, cap, IM_EABI, "%s: wrong or missing %s", path, IM_CAMERA_SYMBOL);
    return cam_api;
}

/* A pattern is safe to give snprintf when its only conversion is one %d (flags 0,
 * width up to 2 digits); %% stands for '%'. */
static int seq_pattern(const char *s)
{
    int conv = 0;
    for (const char *p = s; *p; p++) {
        if (*p != '%') continue;
        if (p[1] == '%') { p++; continue; }
        p++;
        if (*p == '0') p++;
        for (int k = 0; k < 2 && *p >= '0' && *p <= '9'; k++) p++;
        if (*p != 'd') return -1;
        conv++;
    }
    return conv == 1 ? 1 : conv == 0 ? 0 : -1;
}

static int is_video(const char *s)
{
    static const char *ext[] = {"avi", "mp4", "mkv", "mov", "mjpg", "mjpeg", "webm", "m4v"};
    const char *dot = strrchr(s, '.'), *slash = strrchr(s, '/');
    if (!dot || (slash && dot < slash)) return 0;
    for (size_t k = 0; k < sizeof ext / sizeof ext[0]; k++)
        if (!strcasecmp(dot + 1, ext[k])) return 1;
    return 0;
}

int im_source_open(const char *spec, int first, int timeout_ms, im_source **out,
                   char *err, size_t cap)
{
    im_source *s;
    int kind, index = -1, pat;
    *out = NULL;
    if (!spec || !*spec) return im_err(err, cap, IM_EINVAL, "no frame source named");
    pat = seq_pattern(spec);
    if (pat < 0)
        return im_err(err, cap, IM_EINVAL, "%s: a sequence pattern has exactly one %%d "
                      "(e.g. frame%%04d.png) and no other %% conversion", spec);
    if (!strncmp(spec, "cam:", 4)) {
        char *end;
        long v = strtol(spec + 4, &end, 10);
        if (end == spec + 4 || *end || v < 0 || v > 255)
            return im_err(err, cap, IM_EINVAL, "%s: a camera is cam:N with N 0..255", spec);
        kind = SRC_CAMERA;
        index = (int)v;
    } else if (!strncmp(spec, "/dev/video", 10)) {
        kind = SRC_CAMERA;
    } else if (pat == 1) {
        kind = SRC_SEQ;
    } else if (is_video(spec)) {
        kind = SRC_VIDEO;
    } else {
        kind = SRC_FILE;
    }
    s = calloc(1, sizeof *s);
    if (!s || !(s->spec = strdup(spec))) {
        free(s);
        return im_err(err, cap, IM_ENOMEM, "out of memory");
    }
    s->kind = kind;
    s->index = kind == SRC_SEQ ? first : index;
    if (kind == SRC_VIDEO || kind == SRC_CAMERA) {
        const im_cam_api *c = load_camera(err, cap);
        if (c) s->cam = c->open(spec, kind == SRC_CAMERA, index,
                                timeout_ms > 0 ? timeout_ms : 2000, err, cap);
        if (!s->cam) { free(s->spec); free(s); return IM_EIO; }
    } else if (kind == SRC_SEQ) {
        char name[PATH_MAX];
        struct stat st;
        snprintf(name, sizeof name, spec, first);
        if (stat(name, &st) != 0) {
            int e = errno;
            im_err(err, cap, IM_EIO, "%s: no frame number %d (%s: %s)", spec, first, name,
                   strerror(e));
            free(s->spec); free(s);
            return IM_EIO;
        }
    }
    *out = s;
    return IM_OK;
}

int im_source_next(im_source *s, im_frame **out, char *err, size_t cap)
{
    int rc;
    *out = NULL;
    if (!s) return im_err(err, cap, IM_EINVAL, "no source");
    if (s->done) return 0;
    switch (s->kind) {
    case SRC_FILE:
        s->done = 1;
        return (rc = im_read(s->spec, out, NULL, err, cap)) == IM_OK ? 1 : rc;
    case SRC_SEQ: {
        char name[PATH_MAX];
        struct stat st;
        snprintf(name, sizeof name, s->spec, s->index);
        if (stat(name, &st) != 0 && errno == ENOENT) { s->done = 1; return 0; }
        rc = im_read(name, out, NULL, err, cap);
        if (rc != IM_OK) return rc;
        (*out)->t = s->index++;
        return 1;
    }
    default: {
        uint16_t *px;
        int w, h, bits;
        double t;
        rc = cam_api->next(s->cam, &px, &w, &h, &bits, &t, err, cap);
        if (rc <= 0) { if (rc == 0) s->done = 1; return rc; }
        im_frame *f = calloc(1, sizeof *f);
        if (!f) { free(px); return im_err(err, cap, IM_ENOMEM, "out of memory"); }
        f->width = w; f->height = h; f->bits = bits; f->px = px; f->t = t;
        *out = f;
        return 1;
    }
    }
}

void im_source_close(im_source *s)
{
    if (!s) return;
    if (s->cam && cam_api) cam_api->close(s->cam);
    free(s->spec);
    free(s);
}
