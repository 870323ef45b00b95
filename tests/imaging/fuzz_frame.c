/* fuzz_frame.c -- libFuzzer target for the frame readers: the by-content front (PNG
 * structure and image-data checks, then OpenCV's PNG/TIFF decoders) and the raw reader
 * with a size taken from the first bytes; every frame that decodes is then handed to
 * the centroid (detection, moments, the GSL fit).  Built as C++ (it links the OpenCV shim). */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "imaging/im_int.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char err[256];
    im_frame *f = NULL;
    if (im_decode(data, size, "fuzz", &f, NULL, err, sizeof err) == IM_OK) {
        if (!f || f->width < 1 || f->height < 1 || !f->px) abort();
        unsigned long s = 0;
        for (size_t i = 0; i < (size_t)f->width * f->height; i++) s += f->px[i];
        (void)s;
        /* and the centroid on whatever decoded (spots, edges, saturation, flat frames) */
        im_spot spots[4];
        im_centroid_result r;
        if (im_centroid(NULL, f, NULL, spots, 4, &r, err, sizeof err) == IM_OK &&
            (r.nspots < 0 || r.nspots > 4 || r.nspots > r.ndetected))
            abort();
        im_frame_free(f);
    } else if (f) {
        abort();                       /* a failure must not hand back a frame */
    }
    if (size >= 4) {
        int w = data[0] | (data[1] & 0x7) << 8, h = data[2] | (data[3] & 0x7) << 8;
        int bits = (data[1] >> 4) % 3 == 0 ? 8 : (data[1] >> 4) % 3 == 1 ? 12 : 16;
        f = NULL;
        if (im_decode_raw(data + 4, size - 4, "fuzz", w, h, bits, &f, err, sizeof err) == IM_OK)
            im_frame_free(f);
    }
    return 0;
}
