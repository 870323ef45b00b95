/* imaging.h -- public face of the imaging engine: pictures of lenses and rays, detector
 * frames and laser-spot centroids, on OpenCV 4.6 behind a thin C++ shim.  No C++ type
 * crosses this header.  The engine lives in build/lib/lensmat-imaging.so (the camera,
 * OpenCV videoio, in build/lib/lensmat-camera.so, loaded only to open a live camera or
 * a video file); a caller gets the one exported function with
 *     imaging_get_api_fn get = (imaging_get_api_fn)lm_engine_symbol("imaging",
 *                                                                   IMAGING_API_SYMBOL);
 *     const imaging_api *im = get ? get(IMAGING_ABI) : NULL;
 * The engine never prints and never exits: functions return 0 (IM_OK) or a negative
 * IM_E* code with a message in the caller's err buffer.  Long operations take a stop
 * callback (im_stop_fn) and poll it at least every ~50 ms of work.
 *
 * Two parts, each with its own section below: pictures (im_draw*.cpp/.c) and frames
 * and centroids (im_frame*, im_centroid*). */
#ifndef IMAGING_H
#define IMAGING_H
#include <stddef.h>
#include <stdint.h>

#define IMAGING_ABI 1
#define IMAGING_API_SYMBOL "imaging_get_api"

enum { IM_OK = 0, IM_EINVAL = -1, IM_ENOMEM = -2, IM_EIO = -3, IM_ESTOP = -4,
       IM_EFORMAT = -5, IM_EABI = -6 };

/* Returns non-zero when the caller wants the operation to stop (e.g. SIGINT). */
typedef int (*im_stop_fn)(void *ctx);

/* ==== pictures: lens layouts, spot diagrams, ray fans, plots ==================== */
/* (declarations of the drawing part go here) */
typedef struct im_draw_api im_draw_api;
/* ==== end of pictures ============================================================ */


/* ==== frames and centroids ======================================================= */
/* (declarations of the frame part go here) */
typedef struct im_frame_api im_frame_api;
/* ==== end of frames and centroids ================================================ */


typedef struct imaging_api {
    int abi;                                   /* IMAGING_ABI */
    const char *(*version)(void);              /* engine and OpenCV versions */
    const im_draw_api *draw;                   /* pictures */
    const im_frame_api *frame;                 /* frames and centroids */
} imaging_api;

typedef const imaging_api *(*imaging_get_api_fn)(int abi);
const imaging_api *imaging_get_api(int abi);

#endif
