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
    double threshold;           /* detection threshold, noise sigmas above the local
                                   background (0: 5) */
    int min_pixels;             /* fewest connected pixels above it for a spot (0: 3) */
    int max_spots;              /* detected spots beyond this are counted, not fitted
                                   (0: 16) */
    double saturation;          /* counts at or above which a pixel is saturated
                                   (0: 2^bits - 1) */
    double gain;                /* electrons per count for the shot-noise part of the
                                   noise model (0: additive noise only) */
    double read_noise;          /* noise sigma in counts (0: measured from the frame) */
    double window;              /* fit window half-width in pixels (0: 2w+1, 3..25) */
    int plane;                  /* 1: fit the background as a tilted plane (a steep
                                   gradient under the spot), 0: a constant */
} im_centroid_opt;

enum im_spot_flags {
    IM_SF_SEVERAL   = 1,        /* one of several spots in the frame */
    IM_SF_SATURATED = 2,        /* saturated pixels left out: fitted from the wings */
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
    double snr;                 /* amp / noise sigma */
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
    double best_snr;            /* NONE: the best candidate's (peak - bg)/noise, below
                                   threshold; otherwise the brightest spot's */
    double best_x, best_y;      /* where that candidate or spot is (pixels) */
} im_centroid_result;

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
