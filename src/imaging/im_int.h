/* im_int.h -- the imaging module's internal seams (never included outside
 * src/imaging/): how the table in im_api.c finds its two halves, and the helpers the
 * frame files share.  C and C++ (the OpenCV shim) both include it. */
#ifndef IM_INT_H
#define IM_INT_H
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include "imaging.h"

#ifdef __cplusplus
extern "C" {
#endif

#define IM_EXPORT __attribute__((visibility("default")))

/* The pictures half (im_draw*.c/.cpp) provides its table here.  Declared weak in
 * im_api.c: until that half is built in, imaging_api.draw is NULL. */
const im_draw_api *im_draw_table(void);
/* The frames half (im_api.c). */
const im_frame_api *im_frame_table(void);

/* Message into err (cap bytes, may be NULL); returns code. */
int im_err(char *err, size_t cap, int code, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* Frames (im_frame.c). */
im_frame *im_frame_new(int width, int height, int bits);
im_frame *im_frame_new_raw(int width, int height, int bits);   /* samples unset */
void im_frame_free(im_frame *f);
int im_decode_raw(const void *buf, size_t len, const char *name, int width, int height,
                  int bits, im_frame **out, char *err, size_t cap);
int im_read_file(const char *path, size_t maxlen, void **buf, size_t *len,
                 char *err, size_t cap);
int im_write_atomic(const char *path, const void *buf, size_t len, char *err, size_t cap);
/* Checks the structure of a PNG in memory (signature, chunk lengths and CRCs, IHDR
 * first with a sane size and depth, IEND present) before OpenCV sees it. */
int im_png_check(const unsigned char *b, size_t n, const char *name, char *err, size_t cap);
#define IM_MAX_PIXELS (1L << 26)         /* 64 Mpixel: larger frames are refused */
#define IM_MAX_FILE   (512L << 20)       /* bytes read from one image file */

/* OpenCV shim (im_frame_io.cpp). */
int im_cv_decode(const void *buf, size_t len, const char *name, im_frame **out,
                 int *was_colour, char *err, size_t cap);
int im_cv_encode(const im_frame *f, const char *ext, void **buf, size_t *len,
                 char *err, size_t cap);
const char *im_cv_version(void);

/* The reading front (im_frame.c): by content. */
int im_decode(const void *buf, size_t len, const char *name, im_frame **out,
              int *was_colour, char *err, size_t cap);
int im_read(const char *path, im_frame **out, int *was_colour, char *err, size_t cap);
int im_read_raw(const char *path, int width, int height, int bits, im_frame **out,
                char *err, size_t cap);
int im_write(const im_frame *f, const char *path, char *err, size_t cap);

/* The rest of the frame table (im_synth.c, im_source.c, im_centroid.c). */
int im_synth(const im_sensor *s, const im_spot_src *spots, int nspots, uint64_t seed,
             int threads, im_frame **out, char *err, size_t cap);
int im_synth_expected(const im_sensor *s, const im_spot_src *spots, int nspots,
                      double *counts, char *err, size_t cap);
int im_source_open(const char *spec, int first, int timeout_ms, im_source **out,
                   char *err, size_t cap);
int im_source_next(im_source *src, im_frame **out, char *err, size_t cap);
void im_source_close(im_source *src);
int im_camera_loaded(void);
im_centroider *im_centroider_new(void);
void im_centroider_free(im_centroider *c);
int im_centroid(im_centroider *c, const im_frame *f, const im_centroid_opt *opt,
                im_spot *spots, int cap, im_centroid_result *res, char *err, size_t errcap);
double im_false_alarm_threshold(int width, int height, double w, double pfa);

#ifdef __cplusplus
}
#endif
#endif
