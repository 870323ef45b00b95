/* im_camera.h -- the seam between the imaging module and lensmat-camera.so (OpenCV
 * videoio: V4L2 cameras, FFmpeg/GStreamer video files), loaded by im_source.c only when
 * a camera or a video file is opened.  Frames cross as malloc'd 16-bit grey buffers. */
#ifndef IM_CAMERA_H
#define IM_CAMERA_H
#include <stddef.h>
#include <stdint.h>

#define IM_CAMERA_ABI 1
#define IM_CAMERA_SYMBOL "camera_get_api"

typedef struct im_cam_api {
    int abi;
    /* kind 0: a video file at `spec`; 1: camera device index `index` or path `spec`. */
    void *(*open)(const char *spec, int kind, int index, int timeout_ms,
                  char *err, size_t cap);
    /* 1 and a frame (px malloc'd, caller frees), 0 at the end of a video, < 0 on error. */
    int (*next)(void *h, uint16_t **px, int *width, int *height, int *bits, double *t,
                char *err, size_t cap);
    void (*close)(void *h);
    /* Writes frames (scaled to 8 bits) as an MJPG AVI; used by
     * the tests and to save synthetic sequences.  Returns 0 or < 0 with a message. */
    int (*write_video)(const char *path, const uint16_t *const *frames, int n, int width,
                       int height, int bits, double fps, char *err, size_t cap);
} im_cam_api;

typedef const im_cam_api *(*im_cam_get_fn)(int abi);

#endif
