/* lensrx.h -- a lens file made ready for rays aimed at its stop, for the dialogues
 * that need real rays through a prescription (--wave): the file asked and read
 * (src/lens), whatever it leaves out asked (stop, aperture, fields), the primary
 * wavelength's first-order pupils and image plane (src/paraxial), and per wavelength
 * the trace module's trace_rx and aim requests.  The same steps as --pupil's
 * (pupil.c), with the questions' texts from the calling dialogue's prompts. */
#ifndef LENSRX_H
#define LENSRX_H
#include "calcio.h"
#include "../lens/lens.h"
#include "../paraxial/paraxial.h"
#include "../trace/trace.h"

#define LR_MAXFIELD 16

typedef struct lr_texts {
    const char *file, *file_what, *note, *stop, *stop_what, *stop_bad, *ap_kind,
        *ap_kind_what, *ap_value, *ap_value_what, *nfield, *nfield_what, *nfield_bad,
        *field_angle, *field_height, *field_what, *field_bad, *again_field, *count_what,
        *count_bad;
} lr_texts;

typedef struct lr_lens {
    calc *c;
    const lr_texts *t;
    ln_lens lens;
    int have;
    ln_notes notes;
    int finite_angles;         /* set by the caller: field angles accepted with a finite
                                  object (--pupil turns them into heights) */
    /* lr_prepare: */
    px_csurf cs[PX_PUPIL_MAXSURF];
    char names[PX_PUPIL_MAXSURF + 1][LN_NAME_MAX];
    const char *obj;
    px_pupil prim;             /* the primary wavelength's pupils */
    double z_image;            /* the image plane rays are carried to (not finite:
                                  afocal at the image, no plane to carry them to) */
    int image_from_file;       /* 1: the file's last thickness; 0: paraxial focus */
    double scale;              /* the lens's size (efl, stop) */
    /* A folded or tilted lens (mirrors, coordinate breaks): first order from it
     * unfolded (ln_unfold, as --pupil), real rays traced folded.  unf.nsurf 0: not
     * folded; zl, zl_u the last surface's z folded and unfolded, sig -1 when light
     * leaves it going -z: an unfolded image-space z u is zl + sig (u - zl_u). */
    ln_lens unf;
    double zl, zl_u, sig;
} lr_lens;

typedef struct lr_wl {
    double lambda;             /* um */
    px_pupil p;                /* z_xp, z_img: in the folded lens's last frame */
    trace_rx rx;
    trace_rx_surface surf[PX_PUPIL_MAXSURF];
    double s;                  /* marginal-ray scale: primary stop size / this one */
} lr_wl;

/* Read and check the lens file `word` for aimed rays (the session's file registry, the
 * lens model's checks and shape check, a real object, at most PX_PUPIL_MAXSURF
 * surfaces; field angles with a finite object only if finite_angles): 0 with the lens
 * and its notes, or 1 with "why" in msg.  --pupil's and lr_ask_lens's reader. */
int lr_read_file(lm_io *io, const char *word, int finite_angles, ln_lens *l,
                 ln_notes *notes, char *msg, size_t cap);
/* Ask the lens file and what it leaves out; print its notes.  LM_GO, LM_QUIT, LM_FAIL. */
int lr_ask_lens(lr_lens *L, calc *c, const lr_texts *t);
/* A whole number lo..hi (t->count_what, t->count_bad). */
int lr_ask_count(lr_lens *L, const char *q, const char *bad, int lo, int hi, int *v);
/* Pupils and image plane at the primary wavelength: 0 (check z_image), or -1 with why. */
int lr_prepare(lr_lens *L, char *why, size_t cap);
/* Surface s of a lens file at vertex z as the tracer's trace_rx_surface (all but its
 * index: the caller's, per wavelength). */
void lr_rx_surface(const ln_surface *s, double z, trace_rx_surface *t);
/* Wavelength lambda (um): its pupils and trace_rx.  0, or -1 with why. */
int lr_at(const lr_lens *L, double lambda, lr_wl *w, char *why, size_t cap);
/* The aim request for pupil point (px, py) (stop coordinates, 1 at its rim) of field f. */
void lr_request(const lr_lens *L, const lr_wl *w, const ln_field *f, double px, double py,
                trace_aim_req *rq);
void lr_free(lr_lens *L);

#endif
