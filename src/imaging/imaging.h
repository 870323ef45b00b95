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
/* Every picture is written as PNG (OpenCV imgcodecs) and, when svg is not NULL, as
 * SVG (plain text, the same drawing in vector form).  Each file is written to a
 * temporary name beside it and renamed when complete, so a failed or stopped write
 * leaves nothing under the final name.  Coordinates handed back (im_mark) are PNG
 * pixels: x to the right, y down, (0, 0) the centre of the top-left pixel. */
typedef struct im_out {
    const char *png;           /* required */
    const char *svg;           /* NULL: no SVG */
    int width, height;         /* pixels; 0: the picture's default */
} im_out;

/* A place the drawing code put something, for tests and logs. */
#define IM_MARKNAME 12
typedef struct im_mark {
    char name[IM_MARKNAME];    /* "F1" "F2" "H1" "H2" "N1" "N2" "object" "image" */
    double x, y;               /* the tick's foot on the axis / the arrow's foot */
    double label_x, label_y;   /* where its label's baseline starts */
} im_mark;

/* A sequential lens in its meridional section (the y-z plane, light along +z).
 * Sag of a surface at height s: z(s) = c s^2 / (1 + sqrt(1 - (1+k) c^2 s^2))
 * + sum asph[i] s^(2i+2), c = 1/radius (radius 0 or inf: plane), as trace.h. */
#define IM_MAXASPH 8
typedef struct im_surface {
    double z, radius, conic;
    double asph[IM_MAXASPH];
    int nasph;
    double semi;               /* semi-diameter (> 0) */
    double n_right;            /* index to the right (bodies are shaded where != air) */
} im_surface;

/* A ray drawn as a polyline of n points (z, y), e.g. the segments of a traced ray. */
typedef struct im_ray {
    const double *zy;          /* 2 n doubles */
    int n;
    int group;                 /* colour: 0, 1, ... (e.g. the object point) */
} im_ray;

typedef struct im_layout {
    const char *title;         /* NULL: none */
    const char *unit;          /* length unit for the scale bar ("mm"; NULL: "units") */
    double n_object;           /* index left of the first surface */
    int nsurf;
    const im_surface *surf;
    int nray;
    const im_ray *ray;
    /* cardinal points (z on the axis); NaN: not drawn */
    double z_f1, z_f2, z_h1, z_h2, z_n1, z_n2;
    /* object and image arrows from the axis to height y at z; NaN z: none.  A
     * virtual image is drawn dashed. */
    double z_obj, y_obj, z_img, y_img;
    int image_virtual;
} im_layout;

#define IM_MAXMARK 16
typedef struct im_layout_info {
    double px_per_unit;        /* the scale: pixels per lens unit (same along z and y) */
    double x0, y0;             /* pixel of the point z = 0 on the axis */
    int nmark;
    im_mark mark[IM_MAXMARK];  /* every tick and arrow drawn */
    int offpicture;            /* cardinal points left out: too far from the lens */
} im_layout_info;

/* A spot diagram: hits (x, y) in a detector or image plane, coloured by group. */
#define IM_MAXGROUP 8
typedef struct im_sd_point { double x, y; int group; } im_sd_point;
typedef struct im_spotdiag {
    const char *title;
    const char *unit;
    int n;
    const im_sd_point *pt;
    int ngroup;                          /* 1 .. IM_MAXGROUP */
    const char *const *group_name;       /* ngroup names (NULL: "1", "2", ...) */
    int panels;                          /* 1: one panel per group, each about its own
                                            centroid, same scale (fields); 0: all in
                                            one panel about the overall centroid
                                            (wavelengths) */
    double airy_radius;                  /* 0: unknown (not drawn) */
} im_spotdiag;
typedef struct im_sd_stat {
    int n;
    double cx, cy;             /* centroid */
    double rms, rmax;          /* RMS and maximum radius about the centroid */
} im_sd_stat;
typedef struct im_sd_info {
    im_sd_stat all;
    im_sd_stat group[IM_MAXGROUP];
    double px_per_unit;
} im_sd_info;

/* A plot of series (lines and/or markers), linear or log axes; a ray fan is one
 * with x = relative pupil height and y = transverse aberration. */
enum { IM_LINES = 1, IM_MARKERS = 2 };
typedef struct im_series {
    const char *name;          /* legend; NULL: not in the legend */
    int n;
    const double *x, *y;
    int style;                 /* IM_LINES | IM_MARKERS */
} im_series;
typedef struct im_plot {
    const char *title, *xlabel, *ylabel;
    int logx, logy;            /* points <= 0 on a log axis are left out (counted) */
    int zero_line;             /* 1: draw y = 0 (ray fans) */
    int nseries;
    const im_series *series;
    const char *note;          /* a line under the legend, or NULL */
} im_plot;
typedef struct im_plot_info {
    int skipped;               /* points left out (not finite, <= 0 on a log axis) */
    double xmin, xmax, ymin, ymax;   /* the axes' ranges */
} im_plot_info;

typedef struct im_draw_api im_draw_api;
struct im_draw_api {
    int (*layout)(const im_layout *l, const im_out *out, im_layout_info *info,
                  char *err, size_t errcap);
    int (*spot)(const im_spotdiag *s, const im_out *out, im_sd_info *info,
                char *err, size_t errcap);
    int (*plot)(const im_plot *p, const im_out *out, im_plot_info *info,
                char *err, size_t errcap);
    /* Statistics alone (no picture): the spot's centroid, RMS and max radius. */
    void (*spot_stat)(const im_sd_point *pt, int n, int group, im_sd_stat *out);
};
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
