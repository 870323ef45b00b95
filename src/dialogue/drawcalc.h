/* drawcalc.h -- what the pictures show, computed for the --draw dialogue (and the
 * --trace dialogue's pictures): a sequential lens's paraxial cardinal points and
 * image (paraxial engine), its real rays and detector hits (trace engine), handed
 * to the imaging engine's drawing calls.  No questions, no printing: the dialogue
 * (draw.c) asks and reports. */
#ifndef DRAWCALC_H
#define DRAWCALC_H
#include <stddef.h>
#include "../trace/trace.h"
#include "../imaging/imaging.h"

/* The scene of a picture: a lens (semi-diameters set), an object point and how
 * much of the first surface the rays fill. */
typedef struct dw_scene {
    const trace_lens *lens;        /* mounts, z_detector: set by the calls */
    double z_obj;                  /* -INFINITY: at infinity */
    double field;                  /* object height (finite), or field angle in
                                      radians (at infinity); 0: on the axis only */
    double frac;                   /* largest ray height / first semi-diameter */
    const char *unit;              /* "mm", ..., or NULL */
    double wavelength;             /* in lens units; 0: none (no Airy disc) */
} dw_scene;

/* First-order results the pictures use (NaN where there is none). */
typedef struct dw_first {
    int afocal;
    double z_f1, z_f2, z_h1, z_h2, z_n1, z_n2;
    double z_img, y_img;           /* the object point's paraxial image (NaN: at infinity) */
    int image_virtual;
} dw_first;
void dw_first_order(const dw_scene *s, dw_first *out);

/* Each returns 0, or -1 with why in err. */
int dw_layout(const trace_api *tr, const imaging_api *im, const dw_scene *s,
              const char *title, const im_out *out, im_layout_info *info,
              char *err, size_t cap);
int dw_spot(const trace_api *tr, const imaging_api *im, const dw_scene *s,
            const char *title, const im_out *out, im_sd_info *info, double *airy,
            char *err, size_t cap);
int dw_fan(const trace_api *tr, const imaging_api *im, const dw_scene *s,
           const char *title, const im_out *out, im_plot_info *info,
           char *err, size_t cap);

/* The tracer's error-against-run-time table (trace/scene.h) for the first element
 * of the lens (surfaces 1 and 2, the glass between them), a grid x grid collimated
 * bundle, plotted on log-log axes: RMS detector error against trace time, one
 * marker per model.  rows: 1 + 3 * DW_TESS_LEVELS filled. */
#define DW_TESS_LEVELS 6
struct sc_tess_row;
struct scene_api;
int dw_table(const struct scene_api *sa, const imaging_api *im, const dw_scene *s,
             long grid, const char *title, const im_out *out, struct sc_tess_row *rows,
             char *err, size_t cap);

#endif
