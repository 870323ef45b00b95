/* dialogues.h -- every dialogue lensmat offers.  Each one takes an open session and
 * returns LM_GO, LM_QUIT or LM_FAIL (see ask.h); main.c lists them in its table. */
#ifndef DIALOGUES_H
#define DIALOGUES_H
#include "ask.h"

int lm_classic(lm_io *io);
const char *lm_classic_usage(void);
const char *lm_classic_usage_more(void);
const char *lm_classic_example(void);
int lm_trace(lm_io *io);
int lm_draw(lm_io *io);        const char *lm_draw_example(void);
const char *lm_trace_example(void);
int lm_rig(lm_io *io);
const char *lm_rig_example(void);

/* The calculation dialogues (lenscalc.c, instrcalc.c, fitcalc.c) and prescription
 * files (prescription.c); each has its embedded example. */
int lm_thick(lm_io *io);       const char *lm_thick_example(void);
int lm_thin(lm_io *io);        const char *lm_thin_example(void);
int lm_gauss(lm_io *io);       const char *lm_gauss_example(void);
int lm_pair(lm_io *io);        const char *lm_pair_example(void);
int lm_magnifier(lm_io *io);   const char *lm_magnifier_example(void);
int lm_microscope(lm_io *io);  const char *lm_microscope_example(void);
int lm_telescope(lm_io *io);   const char *lm_telescope_example(void);
int lm_vision(lm_io *io);      const char *lm_vision_example(void);
int lm_beam(lm_io *io);        const char *lm_beam_example(void);
int lm_cornea(lm_io *io);      const char *lm_cornea_example(void);
int lm_cornea_scan(lm_io *io); const char *lm_cornea_scan_example(void);
int lm_fit(lm_io *io);         const char *lm_fit_example(void);
int lm_prescription(lm_io *io);    const char *lm_prescription_example(void);
int lm_to_prescription(lm_io *io); const char *lm_to_prescription_example(void);
int lm_spot(lm_io *io);        const char *lm_spot_example(void);   /* spot.c: --spot */
int lm_colour(lm_io *io);       const char *lm_colour_example(void);   /* colour.c */
int lm_pupil(lm_io *io);        const char *lm_pupil_example(void);    /* pupil.c */
int lm_optimise(lm_io *io);     const char *lm_optimise_example(void); /* optimise.c */
int lm_tolerance(lm_io *io);    const char *lm_tolerance_example(void); /* tolerance.c */
int lm_wave(lm_io *io);         const char *lm_wave_example(void);     /* wave.c */
int lm_polar(lm_io *io);        const char *lm_polar_example(void);    /* polar.c */

/* A lens read from a file (prescription.c): a classic record, its grep'd or plain
 * answers, or a prescription file.  lm_read_lens: LM_GO, or LM_FAIL with
 * "FILE[:LINE]: why" in err (nothing printed); free with lm_lens_file_free. */
/* glass: the catalogue or model glass the index was named by ("N-SK16",
 * "1.5168/64.17"; taken at d), "" when it was a number or a medium's constant. */
typedef struct lm_lens_surface {
    double radius, z, n_right;         /* plane: inf */
    char glass[64];
} lm_lens_surface;
typedef struct lm_lens_file {
    double nearpoint, n_object;        /* n_object: index left of the first surface */
    char obj_glass[64];                /* as lm_lens_surface.glass */
    int nsurf, nobj;
    lm_lens_surface *surf;
    double *obj;                       /* the object planes' locations */
    long leftover_line;                /* > 0: answers after the end, from this line */
} lm_lens_file;
int  lm_read_lens(const char *path, lm_lens_file *lf, char *err, size_t cap);
void lm_lens_file_free(lm_lens_file *lf);
/* The same from a text in memory (len bytes; s is cut up). */
int  lm_lens_of_text(const char *src, char *s, size_t len, lm_lens_file *lf, char *err,
                     size_t cap);

/* Lens files of the lens model (lensfile.c): a thickness prescription or a .zmx?
 * lm_model_answers: its classic dialogue answers (malloc'd text in *out, *outlen
 * bytes); unless quiet, the reader's notes and what the classic cannot take go to
 * stderr.  LM_GO, or LM_FAIL with "FILE:LINE: why" in err.  --to-zmx and
 * --to-thickness convert any lens file. */
int lm_is_model_file(const char *s, size_t len);
int lm_model_answers(const char *src, const char *s, size_t len, char **out, size_t *outlen,
                     int quiet, char *err, size_t cap);
int lm_to_zmx(lm_io *io);       const char *lm_to_zmx_example(void);
int lm_to_thickness(lm_io *io); const char *lm_to_thickness_example(void);

#endif
