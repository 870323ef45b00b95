/* rigframe.h -- the camera of the --rig dialogue's closed loop (rigframe.c): a traced
 * landing point becomes a synthetic detector frame through the imaging engine, whose
 * centroid is the "detected" spot. */
#ifndef LM_RIGFRAME_H
#define LM_RIGFRAME_H
#include <stddef.h>
#include <stdint.h>
#include "../rig/rig.h"

typedef struct lm_rigcam {
    const struct imaging_api *im;   /* loaded with the first frame */
    struct im_centroider *cz;
    int tried;
    uint64_t frames;                /* frames made: the next frame's seed offset */
} lm_rigcam;

typedef struct lm_rigcam_spot {
    double det[3];      /* the centroid, back in rig coordinates (mm) */
    double sigma;       /* its 1-sigma uncertainty in the detector plane (mm) */
    double off;         /* |centroid - landing point| (mm): the centroid's own error */
    double x, y, w;     /* pixels: centre and 1/e^2 radius found */
    double snr;
} lm_rigcam_spot;

/* Loads the imaging engine on first use: 0, or -1 with a message (not available). */
int lm_rigcam_load(lm_rigcam *c, char *err, size_t cap);
/* One frame of the spot landing at `hit` (the beam b gives its path from the laser:
 * the Gaussian beam of section 46 with the rig's waist), exposure in seconds; the
 * frame's seed is the rig's camera_seed plus the frames made before.  0, or -1 with
 * a message (no spot found, spot off the sensor). */
int lm_rigcam_detect(lm_rigcam *c, const rg_rig *r, const rg_beam *b, const double hit[3],
                     double exposure, lm_rigcam_spot *out, char *err, size_t cap);
void lm_rigcam_free(lm_rigcam *c);
#endif
