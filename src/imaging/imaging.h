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
    im_stop_fn stop;           /* asked before anything is written (NULL: never):
                                  non-zero -> IM_ESTOP, no file written */
    void *stop_ctx;
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
    int dashed;                /* 1: dashed (e.g. a ray's virtual continuation) */
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
/* A marker the plot drew: point `point` of series `series`, centred on pixel (x, y). */
typedef struct im_plot_mark { int series, point; double x, y; } im_plot_mark;
#define IM_MAXPLOTMARK 64
typedef struct im_plot_info {
    int skipped;               /* points left out (not finite, <= 0 on a log axis) */
    double xmin, xmax, ymin, ymax;   /* the axes' ranges */
    /* The plot area in PNG pixels: xmin at x = box_x0, xmax at box_x1, ymax at
     * box_y0 (top), ymin at box_y1; values placed linearly, or by log10 on a log axis. */
    double box_x0, box_y0, box_x1, box_y1;
    int nmark;                 /* markers drawn (IM_MARKERS series), the first
                                  IM_MAXPLOTMARK of them in mark[] */
    im_plot_mark mark[IM_MAXPLOTMARK];
} im_plot_info;

/* A map of a scalar on a grid (cornea maps: elevation, axial and tangential
 * curvature, residuals): v[j * nx + i] is the value at column i (x from xmin to
 * xmax), row j (y from ymax at the top down to ymin), NaN where there is none; drawn
 * in colour bands of `step` (dark blue low .. dark red high) with a colour bar.
 * PNG only (out->svg must be NULL). */
typedef struct im_map {
    const char *title, *unit, *note;       /* note: a line under the map, or NULL */
    const char *xlabel, *ylabel;           /* NULL: "x (mm)", "y (mm)" */
    int nx, ny;
    const double *v;
    double xmin, xmax, ymin, ymax;         /* the grid's extent (cell edges) */
    double disc;                           /* > 0: outline the disc of this radius
                                              about (0, 0) */
    double step;                           /* band width; 0: the first of steps[]
                                              giving at most max_bands bands, else a
                                              1-2-5 step */
    const double *steps; int nsteps;       /* e.g. 0.25 0.5 1 ... D (topographers) */
    int max_bands;                         /* 0: 24 */
    double lo, hi;                         /* lo < hi: a fixed scale (scans compared
                                              on one scale); else the data's range */
    int symmetric;                         /* 1: centred on 0 (elevation, residual) */
    int npts;                              /* scattered points painted on the scale */
    const double *px, *py, *pv;
    const unsigned char *mark;             /* NULL, or 1: ring point k (rejected) */
    double point_r;                        /* their radius in pixels (0: 3) */
} im_map;
typedef struct im_map_info {
    double lo, hi, step;                   /* the scale drawn */
    int nbands, skipped;                   /* bands; grid cells without a value */
    double vmin, vmax;                     /* the data's range */
    double box_x0, box_y0, box_x1, box_y1; /* the map's box in PNG pixels */
} im_map_info;

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
    /* A map (im_map); info (optional): the scale drawn. */
    int (*map)(const im_map *m, const im_out *out, im_map_info *info, char *err,
               size_t errcap);
};
/* ==== end of pictures ============================================================ */


/* ==== frames and centroids ======================================================= */
/* Frames are detector images: row-major 16-bit samples with `bits` significant bits
 * (8, 12 or 16; a sample is 0 .. 2^bits - 1).  Pixel coordinates: (0,0) is the centre
 * of the first pixel of the first row, x along a row, y down the rows; pixel (i,j)
 * covers [i-0.5, i+0.5] x [j-0.5, j+0.5].  Frames are made by the engine (synthesis,
 * readers, frame_new) and released with frame_free. */
typedef struct im_frame {
    int width, height;          /* pixels, both >= 1 */
    int bits;                   /* 8, 12 or 16 */
    uint16_t *px;               /* width*height samples; row y starts at px + y*width */
    double t;                   /* time stamp (s) from a camera or video, else the
                                   index of the frame in its sequence */
} im_frame;

/* -- synthesis ------------------------------------------------------------------- */
/* The sensor: geometry (pose in scene coordinates, for tracer hits), exposure and a
 * camera noise model.  Electrons per pixel e = qe*(signal + background*exposure) +
 * dark_current*exposure, Poisson when shot_noise, clipped at full_well, plus Gaussian
 * read noise; counts = round(bias + e/gain), clipped to 0 .. 2^bits - 1 (saturation). */
typedef struct im_sensor {
    int width, height;          /* pixels */
    double pitch;               /* pixel pitch, scene length unit (e.g. mm) */
    double origin[3];           /* centre of the sensor (scene coordinates) */
    double xdir[3], ydir[3];    /* directions of increasing x (along a row) and y (down
                                   the rows); made orthonormal (ydir adjusted) */
    int bits;                   /* 8, 12 or 16 */
    double exposure;            /* s */
    double qe;                  /* electrons per photon, 0..1 (0 taken as 1) */
    double gain;                /* electrons per count (0 taken as 1) */
    double full_well;           /* electrons; 0: no limit but the converter's */
    double bias;                /* counts added to every pixel (black level) */
    double background;          /* stray light, photons per pixel per second */
    double dark_current;        /* electrons per pixel per second */
    double read_noise;          /* electrons rms */
    int shot_noise;             /* 1: photon and dark electrons are Poisson */
    double wavelength;          /* m: photon energy for hits given in watts */
} im_sensor;

/* A ray reaching the sensor plane (from the tracer's detector hits). */
typedef struct im_hit {
    double p[3];                /* where it crosses the sensor plane (scene coords) */
    double power;               /* W (photons/s = power*wavelength/(h c)) */
    double path;                /* distance travelled from the beam waist (scene unit),
                                   for the Gaussian splat; 0 if unknown */
} im_hit;

enum im_spot_kind {
    IM_SPOT_ANALYTIC,           /* B + peak*exp(-2 r^2 / w^2) around (x, y), in pixels */
    IM_SPOT_HITS_BIN,           /* each hit a square footprint of side hit_size (scene
                                   unit; 0: a point), power shared by exact pixel-area
                                   overlap */
    IM_SPOT_HITS_GAUSS          /* each hit splatted with the Gaussian beam profile of
                                   section 46: 1/e^2 radius w(z) = sqrt(w0^2 + (theta z)^2)
                                   at z = path, theta = lambda/D (the seed's divergence
                                   for a mirror of diameter D) or lambda/(pi w0) if D = 0;
                                   integrated exactly over each pixel */
};
typedef struct im_spot_src {
    int kind;                   /* enum im_spot_kind */
    /* IM_SPOT_ANALYTIC */
    double x, y;                /* centre, pixels */
    double w;                   /* 1/e^2 radius, pixels */
    double peak;                /* expected counts above bias at the centre (sampled) */
    int integrate;              /* 1: each pixel gets the exact integral of the profile
                                   over its area (peak/pixel-area scaled); 0: the
                                   profile sampled at pixel centres (issue 10's model) */
    /* IM_SPOT_HITS_* */
    const im_hit *hits;
    size_t nhits;
    double hit_size;            /* BIN: side of each hit's square footprint */
    double waist;               /* GAUSS: waist radius w0 (scene unit) */
    double beam_lambda;         /* GAUSS: wavelength in the scene unit (0: sensor's) */
    double mirror_d;            /* GAUSS: aperture D (scene unit), 0: Gaussian beam */
} im_spot_src;

/* -- centroids ------------------------------------------------------------------- */
enum im_centroid_method {
    IM_CM_GAUSS = 0,            /* moments start, refined by a 2-D Gaussian least-squares
                                   fit (GSL multifit_nlinear, trust region LM) */
    IM_CM_MOMENTS,              /* intensity-weighted centre of the window, raw counts */
    IM_CM_MOMENTS_BG            /* background-subtracted centre of gravity of the spot's
                                   connected pixels above threshold */
};
typedef struct im_centroid_opt {
    int method;                 /* enum im_centroid_method */
    double threshold;           /* detection threshold on the matched-filter SNR (the
                                   spot's integrated SNR, below); 0: the level at which
                                   noise alone gives 1e-4 false spots per frame (6.23
                                   for 640x480 and w = 3 px, 5.73 for 128x128; 5 would
                                   give 0.08 and 0.004) */
    int min_pixels;             /* fewest connected pixels whose matched-filter SNR is
                                   above the threshold for a spot (0: 1, so that "none"
                                   always means best_snr <= threshold) */
    int max_spots;              /* detected spots beyond this are counted, not fitted
                                   (0: 16) */
    double saturation;          /* counts at or above which a pixel is saturated (the
                                   camera's level: full well / gain + bias, or its ADC's
                                   2^b - 1 when b < bits, e.g. 12-bit data in a 16-bit
                                   PNG); 0: 2^bits - 1, or a lower level found in the
                                   frame itself (a pile-up, im_centroid_result) */
    double gain;                /* electrons per count for the shot-noise part of the
                                   noise model (0: additive noise only) */
    double read_noise;          /* noise sigma in counts (0: measured from the frame) */
    double window;              /* fit window half-width in pixels (0: 2w+1, 3..25) */
    int plane;                  /* 1: fit the background as a tilted plane (a steep
                                   gradient under the spot), 0: a constant */
    double spot_w;              /* the expected spot's 1/e^2 radius (pixels) the
                                   matched filter is made for (0: 3; 0.5 .. 12) */
} im_centroid_opt;
/* Detection.  A spot is found where the matched filter for the expected spot
 *     T(p) = sum_i (g_i - gbar) v_i / (sigma sqrt(sum_i (g_i - gbar)^2)),
 *     g_i = exp(-2 |i - p|^2 / spot_w^2) over the square of half-width ceil(2 spot_w)
 * about pixel p (clipped to the frame; gbar its mean, so a constant or linear
 * background gives 0) is a local maximum above the threshold: T is the spot's
 * integrated SNR with the background unknown, N(0, 1) on noise alone, and for a spot
 * of peak A centred on p its mean is (A / sigma) sqrt(sum_i (g_i - gbar)^2) (2.43 A/sigma
 * for w = 3 px, against 1 A/sigma for its brightest pixel).  T is evaluated exactly
 * where a cheap screen (the same filter on 2x2-binned pixels, at threshold - 2) points,
 * and over the connected region where it stays above the threshold. */

enum im_spot_flags {
    IM_SF_SEVERAL   = 1,        /* one of several spots in the frame */
    IM_SF_SATURATED = 2,        /* saturated pixels left out: fitted from the wings;
                                   its sx, sy are the wings' formal ones and hold only
                                   as far as the spot is the Gaussian the fit assumes:
                                   not a confident uncertainty */
    IM_SF_EDGE      = 4,        /* cut by the frame edge (window or 1/e^2 disc) */
    IM_SF_FIT_FAILED = 8,       /* the fit did not converge: moments given instead */
    IM_SF_MOMENTS   = 16        /* located by moments (method or fallback) */
};
typedef struct im_spot {
    double x, y;                /* centre, pixels */
    double sx, sy;              /* 1-sigma uncertainty of x, y (pixels): fit covariance
                                   with the noise model's pixel variances */
    double amp;                 /* peak above background, counts */
    double w;                   /* 1/e^2 radius, pixels */
    double bg;                  /* local background, counts */
    double power;               /* counts above background (fit: amp*pi*w^2/2) */
    double snr;                 /* the detection statistic, the one the threshold is
                                   on: the matched filter's SNR T at its maximum (the
                                   spot's integrated SNR, below); the peak pixel's is
                                   amp / noise */
    double chi2;                /* fit: reduced chi-square (1 when the model is right) */
    int npix;                   /* connected pixels above threshold */
    int nsat;                   /* saturated pixels left out of the fit */
    int iter;                   /* fit iterations */
    int flags;                  /* enum im_spot_flags */
} im_spot;

enum im_outcome { IM_FOUND_NONE = 0, IM_FOUND_ONE = 1, IM_FOUND_SEVERAL = 2 };
typedef struct im_centroid_result {
    int outcome;                /* enum im_outcome */
    int nspots;                 /* spots written (sorted by power, brightest first) */
    int ndetected;              /* spots detected (may exceed nspots) */
    double background;          /* median background, counts */
    double noise;               /* noise sigma used, counts */
    double best_snr;            /* the detection statistic (matched-filter SNR T):
                                   NONE: the best candidate's, at or below the
                                   threshold; otherwise the brightest spot's */
    double best_x, best_y;      /* where that candidate or spot is (pixels) */
    double saturation;          /* the saturation level used (counts) */
    double threshold;           /* the detection threshold used */
    int sat_source;             /* enum im_sat_source: where that level came from */
} im_centroid_result;
enum im_sat_source {
    IM_SAT_FULL_SCALE = 0,      /* 2^bits - 1 */
    IM_SAT_GIVEN,               /* opt->saturation */
    IM_SAT_PILEUP               /* found in the frame: its brightest value held by
                                   several pixels with none just below (a clipped
                                   plateau: at least 5 such pixels and more than twice
                                   those in the band below, or 2 at an ADC's full scale
                                   2^b - 1 or its MSB-aligned (2^b - 1) << (16 - b),
                                   b = 8, 10, 12, 14, below the file's) */
};

/* Scratch kept between frames (about 100 kB plus a byte per pixel); one per thread:
 * calls with different centroiders may run at the same time. */
typedef struct im_centroider im_centroider;

/* -- sources: files, sequences, video, cameras ----------------------------------- */
typedef struct im_source im_source;

struct im_frame_api {
    /* frames */
    im_frame *(*frame_new)(int width, int height, int bits);   /* zeroed; NULL: bad size
                                                                   or no memory */
    void (*frame_free)(im_frame *f);
    /* Synthesise one frame.  Deterministic for (sensor, spots, seed) whatever `threads`
     * (0: 1): each row draws from its own generator seeded from (seed, row). */
    int (*synth)(const im_sensor *s, const im_spot_src *spots, int nspots,
                 uint64_t seed, int threads, im_frame **out, char *err, size_t cap);
    /* The expected (noise-free, unquantised) counts above bias, width*height doubles. */
    int (*synth_expected)(const im_sensor *s, const im_spot_src *spots, int nspots,
                          double *counts, char *err, size_t cap);

    /* Readers.  read: PNG or TIFF (8 or 16 bit; colour is turned to grey, flagged by
     * *was_colour if non-NULL), by content, not by name.  decode: the same from memory
     * (`name` for messages).  read_raw: little-endian 16-bit samples, exactly
     * width*height*2 bytes, values within `bits`.  Messages name the file. */
    int (*read)(const char *path, im_frame **out, int *was_colour, char *err, size_t cap);
    int (*decode)(const void *buf, size_t len, const char *name, im_frame **out,
                  int *was_colour, char *err, size_t cap);
    int (*read_raw)(const char *path, int width, int height, int bits, im_frame **out,
                    char *err, size_t cap);
    /* Writers: PNG (by .png), TIFF (.tif/.tiff) or raw (.raw), 16-bit for bits > 8;
     * written to a temporary file beside `path` and renamed when complete, never over
     * an existing file that is not a regular file. */
    int (*write)(const im_frame *f, const char *path, char *err, size_t cap);

    /* Sources.  spec: "FILE" (one frame), "PATTERN" with one printf %d conversion
     * (a numbered sequence from `first`, ends at the first missing number), a video
     * file (.avi .mp4 .mkv .mov .mjpg), "cam:N" or "/dev/videoN" (a live camera).
     * Video and cameras load build/lib/lensmat-camera.so (beside this module) on
     * first use.  next: 1 and a frame (caller frees), 0 at the end, < 0 on error
     * (a camera that stops delivering is an error after timeout_ms, 0: 2000, where the
     * backend takes a timeout -- FFmpeg, GStreamer; V4L2 waits its own 10 s). */
    int (*source_open)(const char *spec, int first, int timeout_ms, im_source **out,
                       char *err, size_t cap);
    int (*source_next)(im_source *src, im_frame **out, char *err, size_t cap);
    void (*source_close)(im_source *src);
    int (*camera_loaded)(void);       /* 1 once lensmat-camera.so is mapped */

    /* Centroids.  ctx may be NULL (scratch allocated for this call).  Writes up to
     * `cap` spots, brightest first, and the outcome to *res. */
    im_centroider *(*centroider_new)(void);
    void (*centroider_free)(im_centroider *c);
    int (*centroid)(im_centroider *c, const im_frame *f, const im_centroid_opt *opt,
                    im_spot *spots, int cap, im_centroid_result *res,
                    char *err, size_t errcap);
};
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
