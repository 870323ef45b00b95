/* bench_load.c -- what the first picture or frame costs a session that has not loaded
 * the imaging engine: dlopen of lensmat-imaging.so (OpenCV core, imgproc, imgcodecs,
 * GSL) with its table, then the first frame read (OpenCV's codecs waking up), then the
 * camera module for a video.  Linked with libdl only (not with the module), one
 * measurement per process; scripts/bench_imaging.sh takes the median of several.
 * Usage: bench_load LIBDIR PNG [AVI] -> "load_ms first_read_ms camera_ms". */
#include <dlfcn.h>
#include <stdio.h>
#include <time.h>
#include <stdint.h>
#include <string.h>
#include "imaging/imaging.h"
#include "imaging/im_camera.h"

/* bench_load LIBDIR --make-avi PATH: a 10-frame 640x480 video for the camera figure. */
static int make_avi(const char *dir, const char *out)
{
    static uint16_t px[640 * 480];
    const uint16_t *frames[10];
    char path[4096], err[256];
    snprintf(path, sizeof path, "%s/lensmat-camera.so", dir);
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    im_cam_get_fn get = h ? (im_cam_get_fn)dlsym(h, IM_CAMERA_SYMBOL) : NULL;
    const im_cam_api *c = get ? get(IM_CAMERA_ABI) : NULL;
    if (!c) return 1;
    for (int i = 0; i < 640 * 480; i++) px[i] = (uint16_t)(i % 640 / 3);
    for (int k = 0; k < 10; k++) frames[k] = px;
    if (c->write_video(out, frames, 10, 640, 480, 8, 10, err, sizeof err)) {
        fprintf(stderr, "bench_load: %s\n", err);
        return 1;
    }
    return 0;
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

int main(int argc, char **argv)
{
    char path[4096], err[256];
    if (argc < 3) return 2;
    if (argc == 4 && !strcmp(argv[2], "--make-avi")) return make_avi(argv[1], argv[3]);
    snprintf(path, sizeof path, "%s/lensmat-imaging.so", argv[1]);
    double t0 = now();
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    imaging_get_api_fn get = h ? (imaging_get_api_fn)dlsym(h, IMAGING_API_SYMBOL) : NULL;
    const imaging_api *im = get ? get(IMAGING_ABI) : NULL;
    double t1 = now();
    if (!im) { fprintf(stderr, "bench_load: %s: %s\n", path, dlerror()); return 1; }
    im_frame *f;
    if (im->frame->read(argv[2], &f, NULL, err, sizeof err)) {
        fprintf(stderr, "bench_load: %s\n", err);
        return 1;
    }
    double t2 = now(), t3;
    im->frame->frame_free(f);
    double tc = now();
    t3 = tc;
    if (argc > 3) {
        im_source *s;
        if (im->frame->source_open(argv[3], 0, 0, &s, err, sizeof err) == 0 &&
            im->frame->source_next(s, &f, err, sizeof err) == 1) {
            im->frame->frame_free(f);
            im->frame->source_close(s);
        }
        t3 = now();
    }
    printf("%.3f %.3f %.3f\n", t1 - t0, t2 - t1, t3 - tc);
    return 0;
}
