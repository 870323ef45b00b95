/* im_api.c -- the imaging module's one exported function, imaging_get_api, and the
 * table of the frames-and-centroids half.  The pictures half supplies im_draw_table()
 * (weak here, so the module builds and works without it). */
#include <stdio.h>
#include "im_int.h"

#pragma weak im_draw_table

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
