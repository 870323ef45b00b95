/* lens.h -- public face of the lens-description model: a sequential lens as lens
 * designers tabulate it (surfaces by curvature or radius, thickness to the next,
 * glass, semi-diameter, conic, even aspheric terms, the aperture stop) with its
 * wavelengths, aperture and fields; the readers and writers of the files that hold
 * one (lensmat thickness prescriptions, Zemax OpticStudio sequential .zmx); and the
 * bridge to the paraxial engine.  No user I/O: readers take a text in memory and
 * return "FILE:LINE: why" strings; writers return a malloc'd text.
 *
 * Conventions (those of src/paraxial): light travels left to right along +z; a
 * radius is positive when its centre of curvature lies to the right; lengths are in
 * the lens's unit (mm unless `unit` says otherwise); wavelengths in micrometres;
 * field angles in degrees.  Surfaces are numbered from 0 in the array (the file
 * formats number them from 1; .zmx's object surface 0 and image surface are not in
 * the array but in `object` and `image_*`). */
#ifndef LENS_H
#define LENS_H
#include <stddef.h>

/* Result codes (the same numbers as the paraxial engine's). */
enum { LN_OK = 0, LN_BAD = 2, LN_NOMEM = 3 };

#define LN_ERR_MAX 1024     /* room for any message of this module */
#define LN_NAME_MAX 64      /* a glass name, a unit */
#define LN_TITLE_MAX 256    /* the lens's title */
#define LN_ASPH_MAX 8       /* even aspheric terms r^2 ... r^16 (.zmx EVENASPH PARM 1-8) */
#define LN_WL_MAX 24        /* wavelengths (OpticStudio's limit) */
#define LN_FIELD_MAX 64     /* fields */
#define LN_CAT_MAX 8        /* glass catalogues a file selects */

enum { LN_STANDARD = 0,     /* sphere or conic (conic 0: sphere) */
       LN_EVENASPH = 1 };   /* conic plus sum asph[i] r^(2i+2) */

/* One surface and the medium right of it.  Radius and curvature are both kept, as
 * read: `r` is what a thickness prescription tabulates, `c` what .zmx stores, so
 * each format writes back its own number exactly (set them with ln_set_radius /
 * ln_set_curvature, which keep the other one consistent: r = 1/c, plane r = inf,
 * c = 0). */
typedef struct ln_surface {
    int type;                      /* LN_STANDARD or LN_EVENASPH */
    double r, c;                   /* radius (+-inf: plane), curvature (0: plane) */
    double t;                      /* thickness to the next surface; the last
                                      surface's: to the image plane (0: not given) */
    /* The medium to the right: "" is air; a catalogue glass ("N-BK7"), a model
     * glass "ND/VD" ("1.5168/64.17"), a number ("1.5"), or a medium the catalogue
     * names, as px_glass_index takes them.  nd, vd (0: not given): the glass's own
     * nd and Vd as a file states them (.zmx GLAS), used when the name is not in the
     * catalogue (ln_index says so). */
    char glass[LN_NAME_MAX];
    double nd, vd;
    double semi;                   /* semi-diameter (clear aperture radius); 0: not given */
    double conic;                  /* k: 0 sphere, -1 paraboloid, < -1 hyperboloid */
    int nasph;                     /* terms given: asph[0..nasph-1] */
    double asph[LN_ASPH_MAX];      /* coefficient of r^(2i+2): asph[0] r^2, asph[1] r^4 ... */
    long line;                     /* the line of the file that started it (0: none) */
    int by_curvature;              /* 1: c is the number given (ln_set_curvature), r = 1/c */
    /* 1: the surface reflects (.zmx GLAS MIRROR, a prescription's `mirror`): light
     * leaves it going back, so `glass` is the medium it arrived in, and thicknesses
     * after an odd number of mirrors are negative (OpticStudio's convention: z is
     * never flipped).  Mirrors in air only (ln_check). */
    int mirror;
    /* 1: not a surface but a coordinate break (.zmx TYPE COORDBRK, a prescription's
     * `coordbrk` line): the surfaces after it are given in a frame decentred by
     * cb_dec (x, y) and tilted by cb_tilt (degrees about x, y, z), cb_order 0:
     * decentre then tilt x, y, z; 1: tilt z, y, x then decentre (OpticStudio's PARM
     * 1-6; the trace engine's trace_rx_surface has the conventions).  Its `t` is the
     * thickness after it, its glass the medium it stands in (set by the readers);
     * radius, conic, semi-diameter are not used.  First-order optics takes every break
     * as zero (the on-axis parts: ln_unfold). */
    int coordbrk, cb_order;
    double cb_dec[2], cb_tilt[3];
} ln_surface;

/* Aperture kinds. */
enum { LN_AP_NONE = 0,
       LN_AP_EPD = 1,              /* entrance pupil diameter */
       LN_AP_FNUM = 2,             /* image-space f-number (object at infinity) */
       LN_AP_NA = 3 };             /* object-space numerical aperture n sin(u) */
/* Field kinds. */
enum { LN_FIELD_ANGLE = 0,         /* object field angles, degrees */
       LN_FIELD_HEIGHT = 1 };      /* object heights, lens units */

typedef struct ln_field { double x, y, weight; } ln_field;

typedef struct ln_lens {
    char title[LN_TITLE_MAX];      /* "" if none */
    char unit[LN_NAME_MAX];        /* "mm" (default), "cm", "in", "m" */
    /* The object: distance from the object plane to surface 0 (> 0: left of it; inf:
     * at infinity) and the medium left of surface 0 ("" air), as ln_surface.glass. */
    double object;
    char obj_glass[LN_NAME_MAX];
    double obj_nd, obj_vd;
    double nearpoint;              /* the classic dialogue's eye nearpoint (25 if not given) */
    /* Object planes for the classic dialogue, as positions (surface 0 at z = 0);
     * a thickness prescription's `object` lines.  Empty for a .zmx. */
    int nplanes;
    double *planes;
    int nsurf, cap;
    ln_surface *surf;
    int stop;                      /* the aperture stop's index; -1: not given */
    double image_c, image_semi;    /* the image surface's curvature and semi-diameter */
    /* Wavelengths (um), primary first, with weights (1 if not given). */
    int nwl;
    double wl[LN_WL_MAX], wl_weight[LN_WL_MAX];
    int ap_kind;                   /* LN_AP_* */
    double ap_value;               /* the EPD, f-number or NA */
    int field_kind;                /* LN_FIELD_* */
    int nfield;
    ln_field field[LN_FIELD_MAX];
    /* The glass catalogues the file selects, in the order glasses are looked up
     * (.zmx GCAT, a prescription's `catalog` line); ncat 0: none selected (the
     * built-in catalogue first, then every AGF catalogue available). */
    int ncat;
    char catalogs[LN_CAT_MAX][LN_NAME_MAX];
} ln_lens;

/* An empty lens (no surfaces, object at infinity in air, no stop, no wavelength,
 * no aperture, unit mm, nearpoint 25); free what it holds with ln_free (which
 * leaves it empty again).  A lens owns its arrays: copy one with ln_copy only. */
void ln_init(ln_lens *l);
void ln_free(ln_lens *l);
int ln_copy(ln_lens *dst, const ln_lens *src);            /* LN_OK or LN_NOMEM */
/* A new surface at the end (a plane, thickness 0, air, LN_STANDARD), or NULL when
 * out of memory.  The pointer is valid until the next ln_add_surface. */
ln_surface *ln_add_surface(ln_lens *l);
int ln_add_plane(ln_lens *l, double z);                   /* LN_OK or LN_NOMEM */
void ln_set_radius(ln_surface *s, double r);              /* 0 or +-inf: a plane */
void ln_set_curvature(ln_surface *s, double c);
/* The primary wavelength: wl[0], or the d line (0.5875618) when none is given. */
double ln_primary(const ln_lens *l);

/* The index right of surface i (i = -1: the object medium) at lambda_um: the glass
 * through px_glass_index; a name the catalogue does not hold but with the file's nd
 * (and vd) as the model glass ND/VD (vd 0: the constant nd), *fallback set to 1
 * then (NULL allowed).  LN_OK, or LN_BAD with the reason in why (no line number:
 * callers add their own). */
int ln_index(const ln_lens *l, int i, double lambda_um, double *n, int *fallback,
             char *why, size_t cap);
/* The sag of surface s at height h (conic and aspheric terms): z(h).  NaN where the
 * conic has no real point (1 - (1+k) c^2 h^2 < 0). */
double ln_sag(const ln_surface *s, double h);
/* Is the lens usable by the first-order engines: at least one surface, finite
 * thicknesses (>= 0, <= 0 after an odd number of mirrors; mirrors in air), every
 * glass with an index at every wavelength (and at the primary), stop in range,
 * aperture and fields sane.  LN_OK, or LN_BAD with "SRC:LINE: why" (the surface's
 * line, when it has one) in err. */
int ln_check(const ln_lens *l, const char *src, char *err, size_t cap);

/* Can the lens be made (lens_shape.c): each surface reaches its semi-diameter
 * (semi <= |radius| on a sphere) and no two neighbouring surfaces cross inside the
 * zone both cover.  ln_shape_check: surfaces s[0..n-1] with their vertices at z[]
 * (semi 0: not given, not checked); LN_OK, or LN_BAD with why (no file name) and
 * *bad the surface whose answer makes it impossible (the later of two that cross).
 * ln_check_shape: the same for a lens, "SRC:LINE: why" in err.  Every dialogue that
 * traces a lens with its semi-diameters checks it with one of them where the lens
 * or its semi-diameters are entered (a reader does not: a .zmx's automatic DIAM
 * may reach past an edge, and converting such a file loses nothing). */
int ln_shape_check(const ln_surface *s, const double *z, int n, int *bad, char *why,
                   size_t cap);
int ln_check_shape(const ln_lens *l, const char *src, char *err, size_t cap);

/* ---- the paraxial engine (lens_paraxial.c) ---------------------------------------
 * The lens as px_csurf surfaces (radius, thickness, glass) for px_colour_run and
 * px_seidel_run (out: nsurf of them): glass strings point into the lens, or (air
 * "", a name not in the catalogue with a file's nd/vd fallback) into `names`, which
 * must hold nsurf + 1 strings of LN_NAME_MAX; *obj_glass is set the same way.  The conic and
 * aspheric terms do not change paraxial optics (they are r^4 and higher, except
 * asph[0], an r^2 term, which adds 2*asph[0] to the curvature: included).
 * LN_OK or LN_BAD with the reason. */
struct px_csurf;
struct px_system;
int ln_to_csurf(const ln_lens *l, struct px_csurf *out, char (*names)[LN_NAME_MAX],
                const char **obj_glass, char *err, size_t cap);
/* The lens as a px_system at lambda_um (px_system_init'd here, surface 0 at z = 0;
 * px_system_free it).  A lens with mirrors is taken unfolded (ln_unfold).  LN_OK,
 * LN_BAD (err says why) or LN_NOMEM. */
int ln_paraxial(const ln_lens *l, double lambda_um, struct px_system *s, char *err,
                size_t cap);
/* The paraxial curvature of surface s: c + 2 asph[0]. */
double ln_paraxial_curvature(const ln_surface *s);
/* How many surfaces reflect. */
int ln_mirrors(const ln_lens *l);
/* How many coordinate breaks the lens holds. */
int ln_breaks(const ln_lens *l);
/* The lens unfolded (lens_paraxial.c): the same first-order optics with every mirror
 * replaced by refracting surfaces, light always going +z.  Coordinate breaks are
 * dropped (their thickness joins the gap before them): first-order data are those of
 * the lens with every tilt and decentre zero.  A mirror of paraxial
 * radius R in air (power -2/R as it faces the light) becomes a surface of radius -R/2
 * into a medium of index 2 and a plane back into air at the same place (power
 * (2 - 1)/(-R/2) = -2/R); the surfaces after an odd number of mirrors have their
 * radii, aspheric terms and thicknesses negated (z mirrored), so thicknesses are
 * positive.  `out` is ln_init'd here (ln_free it); *map (may be NULL) is set to a
 * malloc'd array: map[k] = the original surface of unfolded surface k.  LN_OK,
 * LN_BAD (a mirror not in air: a Mangin mirror's glass would need index 2n(lambda))
 * or LN_NOMEM. */
int ln_unfold(const ln_lens *l, ln_lens *out, int **map, char *err, size_t cap);

/* ---- files --------------------------------------------------------------------
 * Notes: what a reader skipped or substituted, one "SRC:LINE: what" line each
 * ('\n'-separated in s, n of them); free with ln_notes_free.  A reader never fails
 * for what it can skip: it fails (LN_BAD, err) only when the lens itself cannot be
 * built (no surface, a number that is not one, a surface type it cannot represent
 * between others...). */
typedef struct ln_notes { char *s; size_t len, cap; int n; } ln_notes;
void ln_notes_free(ln_notes *n);

/* How a reader takes a glass name (lens_glass.c): the catalogue entry for it -- in
 * the catalogues the lens selects (l->catalogs, in order; "LENSMAT" is the built-in
 * one), else the built-in catalogue and then every AGF catalogue available --, or
 * for a former name (BK7) its successor (N-BK7), noted.  out (LN_NAME_MAX) gets the
 * spelling the lens stores: the built-in catalogue's name, or "CATALOG:NAME" for an
 * AGF catalogue's glass.  A name several catalogues hold is noted with the one taken.
 * 1 when found, 0 when no catalogue has it (out untouched). */
int ln_glass_lookup(const ln_lens *l, const char *name, char *out, ln_notes *notes,
                    const char *src, long line);

/* A lensmat prescription by thickness (rx.c; the format in README "Prescription
 * files").  text: the whole file (len bytes, NULs refused), src: its name for
 * messages.  A positions prescription (no `thickness` line) is read too: positions
 * become thicknesses, surface 1 moves to z = 0, and each index is taken as the
 * classic dialogue takes it (a number; a medium's constant; a glass, or NAME@W, at
 * the file's `wavelength` or d) and kept as that number: such a file is at one
 * wavelength.  l is ln_init'd here; on failure it is left empty. */
int ln_read_rx(const char *text, size_t len, const char *src, ln_lens *l,
               ln_notes *notes, char *err, size_t cap);
/* Is this text a thickness prescription (a `thickness` line before any surface)? */
int ln_is_rx_thickness(const char *text, size_t len);
/* The lens as a thickness prescription (every value that reads back the same);
 * malloc'd NUL-terminated text, or NULL when out of memory. */
char *ln_write_rx(const ln_lens *l);

/* Zemax OpticStudio sequential .zmx (zmx.c): UTF-8, Latin-1 or UTF-16LE/BE (with
 * or without a byte-order mark).  Read: SURF, TYPE STANDARD/EVENASPH, CURV, DISZ,
 * GLAS, DIAM, CONI, PARM, STOP, WAVL/WAVM/PWAV/WWGT, ENPD/FNUM/OBNA, FTYP, XFLN/YFLN
 * (XFLD/YFLD), FWGN/FWGT, NAME, UNIT, GCAT, GLAS MIRROR (with the negative
 * thicknesses after it); everything else is noted (ln_notes) in one note, and each
 * unsupported surface type or glass with its line.  A coordinate break (COORDBRK)
 * with no decentre or tilt is skipped (noted); refused (LN_BAD): a coordinate break
 * that tilts or decentres, MODE NSC, a glass not in the catalogues whose nd/Vd are
 * OpticStudio's placeholder 1.5/40.  SURF 0 is the object (its DISZ
 * `object`, its GLAS `obj_glass`), the last SURF the image (image_c, image_semi);
 * wavelengths are reordered primary (PWAV) first. */
int ln_read_zmx(const char *text, size_t len, const char *src, ln_lens *l,
                ln_notes *notes, char *err, size_t cap);
/* Does this text look like a .zmx (a SURF line and a VERS, MODE or UNIT line, in any
 * of the encodings above)? */
int ln_is_zmx(const char *text, size_t len);
/* The lens as a .zmx (UTF-8 text with CRLF line ends, as OpticStudio reads it). */
char *ln_write_zmx(const ln_lens *l);

/* The shortest decimal text that reads back as v ("inf", "-inf" for infinities):
 * buf of 32 bytes at least. */
void ln_format(double v, char *buf, size_t cap);
/* A surface's radius as a table prints it: "plane"; a radius given as such, its
 * shortest decimal (exact); a radius derived from a curvature (by_curvature), the
 * shortest decimal whose reciprocal lies within 1e-14 relative of c (OpticStudio's
 * CURV -7.798487093503899700E-003 is written -128.23, not -128.229999999999: its own
 * 1/R is that far off).  So a thickness prescription written from a .zmx keeps each
 * curvature to 1e-14; the .zmx writer writes curvatures exactly. */
void ln_format_radius(const ln_surface *s, char *buf, size_t cap);

#endif
