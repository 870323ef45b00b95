/* im_api.c -- the imaging module's one exported function, imaging_get_api, and the
 * table of the frames-and-centroids half.  The pictures half supplies im_draw_table()
 * (weak here, so the module builds and works without it). */
#include <stdio.h>
#include "im_int.h"

#pragma weak im_draw_table

int im_synth(const im_sensor *s, const im_spot_src *spots, int nspots, uint64_t seed,
             int threads, im_frame **out, char *err, size_t cap);
int im_synth_expected(const im_sensor *s, const im_spot_src *spots, int nspots,
                      double *counts, char *err, size_t cap);
int im_read(const char *path, im_frame **out, int *was_colour, char *err, size_t cap);
int im_read_raw(const char *path, int width, int height, int bits, im_frame **out,
                char *err, size_t cap);
int im_write(const im_frame *f, const char *path, char *err, size_t cap);
int im_source_open(const char *spec, int first, int timeout_ms, im_source **out,
                   char *err, size_t cap);
int im_source_next(im_source *src, im_frame **out, char *err, size_t cap);
void im_source_close(im_source *src);
int im_camera_loaded(void);
im_centroider *im_centroider_new(void);
void im_centroider_free(im_centroider *c);
int im_centroid(im_centroider *c, const im_frame *f, const im_centroid_opt *opt,
                im_spot *spots, int cap, im_centroid_result *res, char *err, size_t errcap);

static const im_frame_api frame_table = {
    im_frame_new, im_frame_free, im_synth, im_synth_expected,
    im_read, im_decode, im_read_raw, im_write,
    im_source_open, im_source_next, im_source_close, im_camera_loaded,
    im_centroider_new, im_centroider_free, im_centroid,
};

const im_frame_api *im_frame_table(void) { return &frame_table; }

static const char *version(void)
{
    static char v[96];
    if (!v[0]) snprintf(v, sizeof v, "lensmat imaging %d, OpenCV %s", IMAGING_ABI,
                        im_cv_version());
    return v;
}

IM_EXPORT const imaging_api *imaging_get_api(int abi)
{
    static imaging_api api;
    if (abi != IMAGING_ABI) return NULL;
    if (!api.abi) {
        api.version = version;
        api.draw = im_draw_table ? im_draw_table() : NULL;
        api.frame = im_frame_table();
        api.abi = IMAGING_ABI;
    }
    return &api;
}
