/* paraxial.h -- public face of the paraxial engine: ray-transfer (ABCD) matrices,
 * lens systems, cardinal points, object/image planes, and how well each result is
 * determined by its inputs.  The engine never prints anything.
 *
 * Conventions.  Light travels left to right along +z.  A ray at a reference plane is
 * the column (y, n*theta): height and index times angle.  A radius is positive when
 * the centre of curvature lies right of the surface; 0 or +-inf is a plane.
 * Distances inside matrices are reduced (distance / index of the medium crossed), so
 * every matrix has det 1.  Lengths are in one unit of the user's choice throughout;
 * powers are in 1/unit (px_diopters, below, converts to diopters). */
#ifndef PARAXIAL_H
#define PARAXIAL_H
#include <stddef.h>

/* Result codes.  PX_BAD (= 2, with the calculations below): an input outside the
 * domain (negative thickness, index <= 0, not a number); nothing was changed. */
enum { PX_OK = 0, PX_AT_INFINITY = 1, PX_NOMEM = 3 };

/* [a b; c d] acting on the column (y, n*theta). */
typedef struct px_mat { double a, b, c, d; } px_mat;

px_mat px_identity(void);
px_mat px_translation(double reduced);            /* [1 t; 0 1], t = distance / n */
px_mat px_refraction(double n1, double n2, double r); /* r: radius, +-inf = plane */
px_mat px_mul(px_mat l, px_mat r);                /* l*r, in the listing's order */
px_mat px_mul_fma(px_mat l, px_mat r);            /* l*r, each entry a*b+c*d to ~1 ulp */
px_mat px_mul_abs(px_mat l, px_mat r);            /* |l|*|r|: rounding-error scale */
double px_det(px_mat m);                          /* a*d - c*b, listing's order */
double px_det_accurate(px_mat m);                 /* a*d - b*c with an fma correction */

/* One elementary step of a system, kept for the condition estimates. */
typedef struct px_step {
    double e;        /* translation: reduced thickness t/n; refraction: (n1 - n2)/R */
    double w;        /* sum of |de/dx|*|x| over the inputs x (positions, radius, indices) */
    px_mat pre;      /* the system matrix before this step */
    int refract;     /* 1: refraction (e is entry c), 0: translation (e is entry b) */
} px_step;
#define PX_INLINE_STEPS 8

/* A lens system built surface by surface.  `m` is the product in the original
 * listing's order of operations (the classic dialogue prints it, round-off and all);
 * hi + lo is the same product in double-double, exact to about 1e-32 relative to the
 * sizes of the summed terms, which the accurate results use.  A system with more than
 * PX_INLINE_STEPS steps owns heap memory: px_system_free it, and do not copy it. */
typedef struct px_system {
    px_mat m, abs;            /* listing order; product of |matrices| (rounding scale) */
    px_mat hi, lo;            /* double-double product */
    double z_first, z_last;   /* reference planes 1 and 2 */
    double n_obj, n_img;      /* media left of the first, right of the last surface */
    int nsurf;
    int err;                  /* 0, or PX_BAD / PX_NOMEM from the last failed step */
    int nsteps, cap;
    px_step *heap;            /* all steps once there are more than PX_INLINE_STEPS */
    px_step inl[PX_INLINE_STEPS];
} px_system;

void px_system_init(px_system *s, double n_obj);
void px_system_free(px_system *s);
/* Adding a surface at z takes two steps, so that a caller can show the system in
 * between (the original does).  px_system_translate moves reference plane 2 to z and
 * returns 1 if that took a translation (z right of it), 0 otherwise (first surface,
 * or a thin lens: same z), -1 on an error (z left of plane 2 -- a negative
 * thickness --, z not finite, or no memory; s->err says which; nothing changed).
 * px_system_refract then adds the refraction at a surface of radius r (0 or +-inf: a
 * plane) with index n_right to its right, and returns that surface's refraction
 * matrix (the identity, with s->err = PX_BAD, if n_right is not a positive number). */
int px_system_translate(px_system *s, double z);
px_mat px_system_refract(px_system *s, double r, double n_right);
/* The same by thickness: a gap t >= 0 (PX_BAD if t < 0 or not finite) and a
 * surface; return PX_OK, PX_BAD or PX_NOMEM. */
int px_system_gap(px_system *s, double t);
int px_system_surface(px_system *s, double r, double n_right);

/* How well a function f(A, B, C, D) of the system matrix is determined by the
 * inputs: sum over every input x of |df/dx|*|x|, for the gradient (ga, gb, gc, gd) of
 * f.  Perturbing every input by a relative eps moves f by at most about eps times
 * this (to first order); computed exactly, with the signs of every partial product,
 * so it does not overflow or overestimate on long chains whose products stay bounded. */
double px_sensitivity(const px_system *s, double ga, double gb, double gc, double gd);

/* A result, how sensitive it is, and its relative condition number. */
typedef struct px_value {
    double v;        /* the value */
    double sens;     /* sum |dv/dx|*|x| over every input x */
    double cond;     /* sens/|v| (inf when v = 0 < sens, 0 when both are 0) */
} px_value;
/* Above this relative condition number a result has lost at least half of double's
 * digits to its inputs' rounding: reports say so instead of printing it bare. */
#define PX_ILL_CONDITIONED 1e8
int px_ill_conditioned(px_value v);
/* Does v keep `digits` significant digits: relative error bound DBL_EPSILON * cond
 * at most 10^-digits? */
int px_digits_meaningful(px_value v, int digits);

/* Is C zero within what the inputs' rounding can produce?  (Scale-aware: compared
 * with px_sensitivity of C, not with 0 and not with the product of |matrices|.) */
int px_is_afocal(const px_system *s);

/* The six cardinal points (z coordinates) and focal distances, in the original
 * listing's arithmetic (what --original prints). */
typedef struct px_cardinal {
    double principal1, principal2, nodal1, nodal2, focal1, focal2;
    double focal_dist1, focal_dist2;   /* |principal - focal|, as the original prints */
} px_cardinal;

/* `original` = 1: nodal planes by the original (1-D)/C, right only for n_obj == n_img.
 * 0: nodal planes correct for any media (identical when the media are equal). */
void px_cardinal_points(const px_system *s, int original, px_cardinal *out);

/* Everything first-order about a system, accurately (double-double matrix,
 * cancellation-free forms), each result with its condition.  With media n_o left and
 * n_i right and the matrix [A B; C D] between reference planes z1 and z2:
 *   power P = -C; effective focal length f = -1/C; focal lengths F1 = -n_o/C (F1 to
 *   H1) and F2 = -n_i/C (H2 to F2); front/back focal distances z1 - zF1 = -n_o D/C
 *   and zF2 - z2 = -n_i A/C; zH1 = z1 - n_o (1-D)/C, zH2 = z2 + n_i (1-A)/C;
 *   zN1 = z1 + (n_o D - n_i)/C, zN2 = z2 + (n_o - n_i A)/C (sections 16, 17, 19, 20,
 *   with the document's nodal formula corrected for n_o != n_i).
 * Afocal systems (px_is_afocal) set afocal = 1 and only m, det and angular (the
 * afocal angular magnification D n_o/n_i); the rest is zero.  Returns PX_OK, or the
 * system's error. */
typedef struct px_first {
    int afocal;
    px_mat m;                      /* the accurate system matrix */
    double det;                    /* its determinant (Kahan) */
    px_value power, efl, f_front, f_back, ffd, bfd;
    px_value z_f1, z_f2, z_h1, z_h2, z_n1, z_n2;
    px_value angular;
} px_first;
int px_first_order(const px_system *s, px_first *out);

/* The image of the object plane at z_obj, accurately: reduced object distance
 * d1 = (z1 - z_obj)/n_o, reduced image distance d2 = -(A d1 + B)/(C d1 + D) from
 * plane 2 (image at z2 + n_i d2), lateral magnification 1/(C d1 + D) (not the
 * equal A + d2 C, which cancels), angular magnification (C d1 + D) n_o/n_i.  When
 * C d1 + D is zero within its uncertainty the object is in the first focal plane:
 * returns PX_AT_INFINITY, sets at_infinity and exit_slope = C/n_i (an object point at
 * height y leaves as a parallel bundle of angle exit_slope*y) and leaves d2, z_img,
 * lateral zero. */
typedef struct px_conj {
    int at_infinity;
    px_value d1, d2, z_img, lateral, angular;
    double exit_slope;
} px_conj;
int px_conjugate(const px_system *s, double z_obj, px_conj *out);

/* The original's angular magnification against the naked eye at the near point b:
 * for a virtual image, (s1*m)/s2 with s1 = max(|z_obj - z1|, b) and s2 =
 * max(|z_img - z2|, b) (eye at plane 2); for an image at infinity, -C b/n_i. */
double px_nearpoint_angmag(const px_system *s, double nearpoint, double z_obj,
                           const px_conj *c);

/* Image of the object plane at z_obj in the original listing's arithmetic (what the
 * classic dialogue prints).  Fills the reduced object distance, the reduced image
 * distance d2 (image at z_last + n_img*d2) and the object-to-image matrix.  Returns
 * 0, or PX_AT_INFINITY when the object lies in the first focal plane (the same
 * decision as px_conjugate), in which case d2 is not set. */
typedef struct px_image {
    double dz_obj, d2, z_img;
    px_mat obj_t, img_t, obj_to_img;
    double mag;
} px_image;
int px_image_plane(const px_system *s, double z_obj, px_image *out);

/* Indices of a few media by name ("air", "water", "silicon", ...; case-insensitive);
 * 0 if unknown. */
double px_medium_index(const char *name);

/* ---- calculations ---------------------------------------------------------------
 * The document's first-order formulas as pure functions (src/paraxial/calc_*.c):
 * sections 4, 8-10, 14, 21-26, 31.7-31.13, 37, 41, 56-58.  Lengths in the user's
 * unit; powers in 1/unit (px_diopters converts).  Infinite distances are +-INFINITY.
 * Functions returning int give PX_OK, PX_AT_INFINITY (a result at infinity), or
 * PX_BAD (inputs outside the formula's domain; nothing useful is set). */
enum { PX_BAD = 2 };

typedef enum px_unit { PX_MM = 0, PX_CM = 1, PX_M = 2 } px_unit;
double px_unit_meters(px_unit u);                   /* 1e-3, 1e-2, 1 */
double px_diopters(double power, px_unit u);        /* 1/unit -> 1/m */
double px_power_of_diopters(double dpt, px_unit u); /* 1/m -> 1/unit */

/* Section 4: Gauss's formula n1/z1 + (n2-n1)/R = n2/z2, surface at z = 0.  z1 may be
 * -inf.  focal_obj/focal_img are +-inf when the surface has no power (plane, n1 = n2). */
typedef struct px_gauss {
    double power;                 /* (n2 - n1)/R */
    double z2, mag;               /* image plane; lateral magnification n1 z2/(n2 z1) */
    double focal_obj, focal_img;  /* -n1 R/(n2-n1), n2 R/(n2-n1) */
} px_gauss;
int px_gauss_surface(double n1, double n2, double r, double z1, px_gauss *out);

/* Sections 8-10, 21, 23: lens of index n, radii r1, r2 (+-inf: plane), thickness t,
 * media n1 left and n3 right; surface 1 at z = 0, surface 2 at z = t.  Returns PX_OK,
 * PX_AT_INFINITY (afocal: first.afocal), PX_BAD or PX_NOMEM. */
typedef struct px_lens {
    px_system sys;             /* the two surfaces (px_system_free it when done) */
    px_first first;            /* matrix, power, focal lengths, cardinal points */
    double maker_power;        /* lens maker's equation (21), any media */
    double thin_power;         /* the thin-lens limit t -> 0 (section 10) */
} px_lens;
int px_thick_lens(double n1, double r1, double t, double n, double r2, double n3,
                  px_lens *out);

/* Section 57: 1/f = 1/do + 1/di with the section's signs (f > 0 converging, do > 0
 * real object, di > 0 real image).  `unknown` is the quantity to compute; with
 * PX_THIN_NONE each is computed from the other two, as the section's script does,
 * and the magnification is -di'/do' of the computed di', do'. */
enum { PX_THIN_F = 0, PX_THIN_DO = 1, PX_THIN_DI = 2, PX_THIN_NONE = 3 };
typedef struct px_thin {
    double f, d_o, d_i;        /* the completed (or, for NONE, computed) triple */
    double mag, power;         /* -di/do, 1/f */
} px_thin;
int px_thin_equation(int unknown, double f, double d_o, double d_i, px_thin *out);

/* Section 56: thin lenses f1, f2 (in air) t apart; first lens at z = 0. */
typedef struct px_pair {
    px_mat m;                  /* lens 1 to lens 2 */
    int afocal;
    double power, f;           /* 1/f1 + 1/f2 - t/(f1 f2), its reciprocal */
    double ffd, bfd;           /* lens 1 - F1, F2 - lens 2 */
    double z_h1, z_h2;         /* principal planes */
} px_pair;
int px_thin_pair(double f1, double f2, double t, px_pair *out);

/* Sections 31.7-31.8: magnifier of focal length f, eye nearpoint b, object at d_o. */
typedef struct px_magnifier {
    double d_i, lateral;       /* virtual image distance, lateral magnification */
    double angular;            /* b/d_o: eye at the lens */
    double angular_limit;      /* b/f: image at infinity */
    double best_alpha, best_d_o, best_angular; /* image at the nearpoint */
} px_magnifier;
int px_magnify(double f, double nearpoint, double d_o, px_magnifier *out);

/* Section 31.10: objective fo, eyepiece fe, optical tube length T, nearpoint b. */
typedef struct px_compound {
    double d_o;                /* object distance that puts the image T past F'o */
    double m_objective;        /* -T/fo */
    double m_eyepiece;         /* b/fe */
    double total;              /* -T b/(fo fe): inverted */
    double length;             /* lens separation fo + T + fe */
} px_compound;
int px_compound_microscope(double fo, double fe, double tube, double nearpoint,
                           px_compound *out);

/* Sections 31.11-31.13: objective fo, eyepiece fe (< 0: Galileo), focal points
 * coinciding; erector > 0 puts the focal points that far apart with an erector lens
 * of focal length erector/4 midway (terrestrial).  Angular magnification = D. */
typedef struct px_telescope {
    px_mat m;                  /* objective to eyepiece */
    int afocal;
    double length, angular, erector_f;
} px_telescope;
int px_telescope_make(double fo, double fe, double erector, px_telescope *out);

/* Section 14: least squares from n measured (object distance x, image distance y,
 * magnification m), optical distances, 2 <= n <= PX_FIT_MAX.  `fit` fits c0 + c1 x to y (the dialogue
 * passes GSL's, loaded from the fit module); returns 0 on success. */
#define PX_FIT_MAX 1000
typedef int (*px_linfit)(const double *x, const double *y, int n, double *c0,
                         double *c1, double *sumsq);
typedef struct px_fit {
    px_mat m;
    double det;                /* A D - B C of the fitted matrix */
    double rss_cd, rss_ab;     /* residual sums of squares of the two fits */
    double max_condition;      /* max |(A x + B) + y (C x + D)|: imaging condition */
} px_fit;
int px_fit_matrix(const double *x, const double *y, const double *mag, int n,
                  px_linfit fit, px_fit *out);

/* Section 24: from the focal points zf1, zf2 and principal points zh1, zh2 (z), the
 * reference planes z1, z2 and media n1, n2.  *mismatch: relative disagreement of
 * the two focal lengths (0 for consistent data). */
int px_matrix_from_cardinal(double n1, double n2, double z1, double z2, double zf1,
                            double zf2, double zh1, double zh2, px_mat *out,
                            double *mismatch);
/* Section 26: from the nodal points zn1, zn2 and the front and back focal lengths
 * ffl = z1 - zf1, bfl = zf2 - z2.  Also gives the principal points. */
int px_matrix_from_nodal(double n1, double n2, double z1, double z2, double zn1,
                         double zn2, double ffl, double bfl, px_mat *out,
                         double *zh1, double *zh2, double *mismatch);

/* Sections 41, 57 (Examples 4-5): spectacle power (1/unit) that images an object at
 * `target` onto the eye's near point (far: object at infinity onto the far point). */
double px_vision_near(double nearpoint, double target);
double px_vision_far(double farpoint);

/* Sections 37: cornea as one refracting surface, power (n - 1)/R (1/unit). */
#define PX_N_CORNEA 1.376
#define PX_N_KERATOMETRIC 1.3375
double px_cornea_power(double radius, double n);
double px_cornea_radius(double power, double n);
double px_cornea_dradius(double power, double dpower, double n);  /* |dR| */
/* Section 37's own form: p = 1/s' = (n-1)/(n R), dR = dp/((n/(n-1)) p^2). */
double px_cornea_doc_radius(double p, double n);
double px_cornea_doc_dradius(double p, double dp, double n);

/* ---- glasses and wavelengths (src/paraxial/glass.c, colour.c) --------------------
 * The catalogue is data/glass.txt, compiled in.  Wavelengths are in micrometres. */
#define PX_LAMBDA_F 0.4861327     /* hydrogen F */
#define PX_LAMBDA_D 0.5875618     /* helium d: where nd and Vd are given */
#define PX_LAMBDA_C 0.6562725     /* hydrogen C */
#define PX_LAMBDA_E 0.5460740     /* mercury e */
#define PX_LAMBDA_G 0.4358343     /* mercury g */
#define PX_LAMBDA_HENE 0.6328     /* helium-neon laser (the cornea rig's) */
/* Dispersion models.  PX_GLASS_AGF + N is the Zemax AGF catalogues' formula number N
 * (l in um, coefficients c0 c1 ... in the order of the AGF "CD" line):
 *   1 Schott      n^2 = c0 + c1 l^2 + c2 l^-2 + c3 l^-4 + c4 l^-6 + c5 l^-8
 *   2 Sellmeier 1 n^2 - 1 = sum_{i<3} c_2i l^2 / (l^2 - c_2i+1)
 *   3 Herzberger  n = c0 + c1 L + c2 L^2 + c3 l^2 + c4 l^4 + c5 l^6, L = 1/(l^2 - 0.028)
 *   4 Sellmeier 2 n^2 - 1 = c0 + c1 l^2 / (l^2 - c2^2) + c3 l^2 / (l^2 - c4^2)
 *   5 Conrady     n = c0 + c1 / l + c2 / l^3.5
 *   6 Sellmeier 3 n^2 - 1 = sum_{i<4} c_2i l^2 / (l^2 - c_2i+1)
 *   7 Handbook of Optics 1  n^2 = c0 + c1 / (l^2 - c2) - c3 l^2
 *   8 Handbook of Optics 2  n^2 = c0 + c1 l^2 / (l^2 - c2) - c3 l^2
 *   9 Sellmeier 4 n^2 = c0 + c1 l^2 / (l^2 - c2) + c3 l^2 / (l^2 - c4)
 *  10 Extended    n^2 = c0 + c1 l^2 + c2 l^-2 + ... + c7 l^-12
 *  11 Sellmeier 5 n^2 - 1 = sum_{i<5} c_2i l^2 / (l^2 - c_2i+1)
 *  12 Extended 2  n^2 = c0 + c1 l^2 + c2 l^-2 + c3 l^-4 + c4 l^-6 + c5 l^-8 + c6 l^4 + c7 l^6
 *  13 Extended 3  n^2 = c0 + c1 l^2 + c2 l^4 + c3 l^-2 + c4 l^-4 + ... + c8 l^-12 */
enum { PX_GLASS_SELLMEIER, PX_GLASS_SELLMEIER_L, PX_GLASS_CONST, PX_GLASS_AGF = 100 };
#define PX_GLASS_MAXCOEF 10
typedef struct px_glass_rec {
    const char *name;
    int model;                 /* PX_GLASS_* */
    double lmin, lmax;         /* validity range, um */
    const char *nd, *vd;       /* published values as printed ("-": none) */
    int ncoef;
    double coef[PX_GLASS_MAXCOEF];
    const char *catalog;       /* "LENSMAT" (data/glass.txt) or an AGF catalogue's name */
    const char *status;        /* an AGF glass's status ("standard", "preferred",
                                  "obsolete", "special", "melt"), or "" */
} px_glass_rec;
/* n of a record at l (um), without the range check (NaN where the formula has no
 * real value). */
double px_glass_formula(const px_glass_rec *g, double l);
/* Result codes of the look-ups below, besides PX_OK: */
enum { PX_NO_GLASS = 4,        /* no such glass, or not "nd/Vd" */
       PX_GLASS_RANGE = 5 };   /* the wavelength lies outside the glass's range */
/* The catalogue's entry for a name (case-insensitive), or NULL; and by number
 * (0 <= i < px_glass_count()) for listings.  A name is looked up in the built-in
 * catalogue (data/glass.txt) first, then in the AGF catalogues (glass_cat.c) in the
 * order they were loaded; "CATALOG:NAME" looks in that catalogue only ("LENSMAT:" is
 * the built-in one).  The built-in catalogue's count and entries only: the AGF
 * catalogues have px_glass_cat_* below. */
const px_glass_rec *px_glass_find(const char *name);
int px_glass_count(void);
const px_glass_rec *px_glass_at(int i);

/* ---- AGF catalogues (agf.c reads one, glass_cat.c keeps them) --------------------
 * A Zemax AGF glass catalogue (the glass makers' own files): NM lines (name, formula
 * number 1-13, glass code, nd, Vd, exclude, status), CD (coefficients), LD (validity
 * range, um), IT (internal transmittance: wavelength um, transmittance, thickness mm),
 * ED/TD/OD/CC/GC/MD/BD (read and not used: thermal, environmental and cost data and
 * comments).  In UTF-8, Latin-1 or UTF-16 with or without a byte-order mark. */
typedef struct px_glass_cat {
    char *name;                /* the catalogue's name (its file name, upper case) */
    char *path;                /* where it was read from ("" for a text given in memory) */
    int n;
    px_glass_rec *rec;         /* n glasses (names and strings owned by the catalogue) */
    int ntau;
    struct px_tau_rec *tau;    /* their IT tables, one per glass that has one */
    char *notes;               /* "SRC:LINE: what was skipped" lines, or NULL */
} px_glass_cat;
/* Read an AGF text (len bytes) as catalogue `name`; src names it in messages.
 * PX_OK; PX_BAD with "SRC:LINE: why" in err (a file that is not an AGF catalogue:
 * no NM line, a formula number outside 1-13, coefficients that are not numbers);
 * PX_NOMEM.  Lines it cannot use inside a glass are noted (cat->notes), not fatal. */
int px_agf_read(const char *text, size_t len, const char *name, const char *src,
                px_glass_cat *cat, char *err, size_t cap);
void px_agf_free(px_glass_cat *cat);
/* The catalogues available: every *.agf file (any case) in the directories of
 * $LENSMAT_GLASS_PATH (':'-separated; a file there is read too), then data/agf/ and
 * ../shared/glass/ (relative to the working directory), read once on first use;
 * a catalogue name seen twice is taken from the first place only.  Files that fail
 * to read are listed in px_glass_cat_notes() and skipped. */
int px_glass_cat_count(void);
const px_glass_cat *px_glass_cat_at(int i);
const px_glass_cat *px_glass_cat_find(const char *name);   /* case-insensitive */
const char *px_glass_cat_notes(void);                      /* "" when none */
/* Every catalogue entry of a name (built-in first, then the AGF catalogues in
 * order), at most max of them; returns how many there are. */
int px_glass_find_all(const char *name, const px_glass_rec **out, int max);
/* The number of materials the catalogues give: the built-in ones plus every AGF
 * glass (a name in several catalogues counts once per catalogue). */
int px_glass_total(void);
/* The index of a catalogue glass or a model glass at lambda_um.  A model glass is
 * "ND/VD" (e.g. "1.5168/64.17", 1 < ND < 3, 5 <= VD <= 150): n = A + B/l^2, the line
 * in 1/l^2 through nd at d with nF - nC = (nd - 1)/Vd; valid 0.36-1.0 um.  Returns
 * PX_OK, PX_NO_GLASS, PX_GLASS_RANGE, or PX_BAD (lambda not a positive number).
 * A plain number (0 < n <= 100) and a name of px_medium_index not in the catalogue
 * are constant indices. */
int px_glass_index(const char *name, double lambda_um, double *n);
/* A former glass name's successor in the catalogue (data/glass.txt "former" lines:
 * BK7 -> N-BK7 ...), case-insensitive, with *why the catalogue's reason (NULL
 * allowed); NULL when the name is not a former one.  Only the lens readers map
 * names (a note says so); px_glass_index never does (the classic dialogue's "bk7" is
 * its constant 1.5168). */
const char *px_glass_former(const char *name, const char **why);
int px_glass_model(double nd, double vd, double lambda_um, double *n);
/* A wavelength: the shorthands F d C e g (any case) and "hene", or a number, taken
 * as nm when above 100, else um (0.6328, 632.8).  PX_OK with *um set, or PX_BAD. */
int px_wavelength(const char *tok, double *um);
/* Abbe number (nd - 1)/(nF - nC) of a glass (PX_GLASS_RANGE if F or C is outside). */
int px_glass_abbe(const char *name, double *vd);

/* Internal transmittance (data/glass.txt "tau" lines): a table of a glass's internal
 * transmittance t[i] of a sample `thickness` mm thick at l[i] um (ascending); or
 * ("k" lines, thickness 0) of its extinction coefficient k: alpha = 4 pi k / lambda. */
#define PX_TAU_MAX 40
typedef struct px_tau_rec {
    const char *name;
    double thickness;          /* mm; 0: t[] holds extinction coefficients k */
    int n;
    double l[PX_TAU_MAX], t[PX_TAU_MAX];
} px_tau_rec;
enum { PX_NO_TAU = 6 };        /* a glass (or medium) without transmittance data */
/* The k-th table (0, 1, ...) of a glass (case-insensitive name), or NULL. */
const px_tau_rec *px_glass_tau(const char *name, int k);
/* The absorption coefficient alpha (1/mm; intensity falls as exp(-alpha L)) of a
 * catalogue glass at lambda_um: -ln(t)/thickness of its thickest table (4 pi k/lambda
 * of a k table, used when it has no transmittance table), alpha (so ln t) linear in
 * lambda between the tabulated points.  PX_OK; PX_NO_TAU (no data: a model glass, a
 * number, a glass without a table), PX_NO_GLASS, PX_GLASS_RANGE (outside the span of
 * points with t > 0, which px_glass_absorption_range gives), PX_BAD. */
int px_glass_absorption(const char *name, double lambda_um, double *alpha);
int px_glass_absorption_range(const char *name, double *lmin, double *lmax);

/* A prescription by thickness, per wavelength (colour.c): surface i has radius r
 * (0 or +-inf: plane), the medium `glass` (a catalogue or model glass name) to its
 * right, and thickness t to the next surface (the last surface's t is ignored).
 * Object medium obj_glass.  For each wavelength: every first-order quantity
 * (px_first: efl, bfd, ffd, cardinal points; surface 1 at z = 0). */
typedef struct px_csurf { double r, t; const char *glass; } px_csurf;
#define PX_COLOUR_MAXWL 8
typedef struct px_colour {
    int nwl;
    double lambda[PX_COLOUR_MAXWL];
    px_first first[PX_COLOUR_MAXWL];
    /* with wavelengths F, d, C at 0, 1, 2 (px_colour_fdc): */
    double long_colour;        /* bfd(F) - bfd(C): longitudinal colour, object at inf */
    double lat_colour_rel;     /* (efl(F) - efl(C))/efl(d): lateral colour per unit
                                  image height, object at infinity */
    int bad_surface;           /* on failure: the surface (0-based) whose glass failed,
                                  -1 for the object medium */
} px_colour;
int px_colour_run(const px_csurf *s, int nsurf, const char *obj_glass,
                  const double *lambda, int nwl, px_colour *out);
/* The same at F, d, C, with long_colour and lat_colour_rel. */
int px_colour_fdc(const px_csurf *s, int nsurf, const char *obj_glass, px_colour *out);

/* Third-order (Seidel) sums of a prescription by thickness (seidel.c), object at
 * infinity, aperture stop at surface 1: the marginal ray enters at height y1 parallel
 * to the axis, the chief ray through the vertex of surface 1 at slope ubar1.
 * Welford's forms ("Aberrations of Optical Systems", 1986, ch. 8): with A = n i and
 * Abar = n ibar (i = u + y c), H = n (ubar y - u ybar) the Lagrange invariant,
 *   SI = -sum A^2 y D(u/n), SII = -sum A Abar y D(u/n), SIII = -sum Abar^2 y D(u/n),
 *   SIV = -sum H^2 c D(1/n), SV = sum (Abar/A)(SIII_k + SIV_k),
 *   CI = sum A y D(dn/n), CII = sum Abar y D(dn/n),  dn = nF - nC,
 * D(x) = x' - x across a surface; indices at d.  Paraxial slopes u = dy/dz; a
 * refraction n'u' = n u - y c (n' - n).  Per surface and total; also the last
 * surface's marginal slope u' and index n': the transverse spherical aberration at
 * the paraxial focus is SI/(2 n' u') with these slopes (Welford's -SI/(2 n' u') with
 * his sign of u), the axial colour bfd(F) - bfd(C) about -CI/(n' u'^2).  PX_BAD when
 * a surface has A = 0 but a field term (SV's form fails), or a bad thickness. */
#define PX_SEIDEL_MAXSURF 64
typedef struct px_seidel_sums { double s1, s2, s3, s4, s5, c1, c2; } px_seidel_sums;
typedef struct px_seidel {
    int nsurf;
    px_seidel_sums surf[PX_SEIDEL_MAXSURF], total;
    double u_last, n_last, h;  /* image-space marginal slope and index; H */
    double ybar1;              /* chief-ray height at surface 1 (entrance pupil at
                                  z = -ybar1/ubar1 from surface 1) */
    int stop;                  /* the aperture stop (0-based surface) */
} px_seidel;
int px_seidel_run(const px_csurf *s, int nsurf, const char *obj_glass, double y1,
                  double ubar1, px_seidel *out);
/* The same with the aperture stop at surface `stop` (0-based; 0 is px_seidel_run):
 * the chief ray enters at slope ubar1 and height ybar1 chosen so that it crosses
 * the axis at the stop's vertex (PX_BAD if the stop is imaged at infinity). */
int px_seidel_run_stop(const px_csurf *s, int nsurf, const char *obj_glass, double y1,
                       double ubar1, int stop, px_seidel *out);

/* ---- first-order pupils (pupil.c) -----------------------------------------------
 * A prescription by thickness (px_csurf, surface 1 at z = 0) at one wavelength, its
 * aperture stop (0-based surface index), an aperture and an object.  Two paraxial
 * rays are traced (y-nu: height y and n u at every surface; u = dy/dz after the
 * surface): the marginal ray (from the object's axial point to the rim of the stop)
 * and the chief ray (from the edge of the field through the centre of the stop).
 * Aperture, as in lens design programs:
 *   PX_AP_EPD   entrance pupil diameter;
 *   PX_AP_FNUM  image-space f-number efl/EPD (the EPD follows; needs a focal system);
 *   PX_AP_NA    object-space numerical aperture n u of the paraxial marginal ray
 *               (finite objects only);
 *   PX_AP_STOP  the stop's semi-diameter itself.
 * Object: obj_dist = distance from the object to surface 1 (INFINITY: at infinity,
 * field = angle in degrees, |angle| < 90); finite: field = object height.  Results:
 * pupils (z of the vertex-plane crossing, surface 1 at 0; semi-diameters), the
 * paraxial image plane and the image height of the field, f-numbers, NAs and the
 * Lagrange invariant H = n (ubar y - u ybar).  A pupil at infinity (telecentric
 * side) has z = +-INFINITY, its semi-diameter INFINITY.  Refusals (out->why says
 * which): PX_BAD (inputs), PX_AT_INFINITY (afocal: no image, no f-number; refused),
 * PX_NO_PUPIL (the stop is conjugate to the object: the marginal ray cannot reach
 * its rim, or the chief ray is undefined). */
enum { PX_AP_EPD = 0, PX_AP_FNUM = 1, PX_AP_NA = 2, PX_AP_STOP = 3 };
enum { PX_NO_PUPIL = 6 };
#define PX_PUPIL_MAXSURF 64
typedef struct px_pupil_in {
    const px_csurf *s;
    int nsurf, stop;           /* stop: 0-based */
    const char *obj_glass;
    double lambda;             /* um */
    int aperture;              /* PX_AP_* */
    double ap_value;
    double obj_dist;           /* INFINITY, or the object's distance left of surface 1 */
    double field;              /* degrees (object at infinity) or object height */
} px_pupil_in;
typedef struct px_pupil {
    int nsurf, stop;
    double n[PX_PUPIL_MAXSURF + 1];       /* n[0] object space, n[k+1] right of k */
    double z[PX_PUPIL_MAXSURF];           /* vertices, surface 1 at 0 */
    /* the two rays: height at surface k, slope right of it; [0] of u, ub: object */
    double y[PX_PUPIL_MAXSURF], u[PX_PUPIL_MAXSURF + 1];
    double yb[PX_PUPIL_MAXSURF], ub[PX_PUPIL_MAXSURF + 1];
    double efl;                           /* effective focal length -1/C (px_first) */
    double z_ep, r_ep;                    /* entrance pupil */
    double z_xp, r_xp;                    /* exit pupil */
    double r_stop;                        /* the stop's semi-diameter */
    double z_img;                         /* paraxial image plane (inf: at infinity) */
    double h_img;                         /* paraxial image height of the field */
    double fnum;                          /* efl/EPD (image-space f-number) */
    double work_fnum;                     /* 1/(2 n' |u'|): working f-number */
    double na_obj, na_img;                /* n |u| of the marginal ray in object and
                                             image space (0 with the object at inf) */
    double mag;                           /* lateral magnification (finite object) */
    double lagrange;                      /* H */
    const char *why;                      /* a refusal's reason, or "" */
} px_pupil;
int px_pupil_run(const px_pupil_in *in, px_pupil *out);

/* ---- Gaussian beams (beam.c; section 46) ----
 * A beam of vacuum wavelength lambda and beam quality M^2 is carried as its reduced
 * complex parameter qhat = q/n, q = z + i zR in the medium of index n (z: distance
 * past the waist, zR = pi n w0^2 / (M^2 lambda) the Rayleigh range), so that the
 * system matrices of this engine (reduced distances, det 1) act on it directly:
 * qhat' = (A qhat + B) / (C qhat + D).  All lengths in one unit, lambda too.
 * w is the 1/e^2 intensity radius (of the embedded Gaussian times M). */
typedef struct px_beam {
    double qre, qim;           /* qhat = qre + i qim; qim > 0 */
    double lambda, m2;         /* vacuum wavelength, M^2 >= 1 */
    double n;                  /* index of the medium the beam is in */
} px_beam;
typedef struct px_beam_at {
    double w;                  /* beam radius here */
    double r;                  /* wavefront radius (+: diverging, centre left); inf: flat */
    double z_waist;            /* distance from here to the waist (+: waist right) */
    double w0;                 /* waist radius */
    double zr;                 /* Rayleigh range in this medium */
    double theta;              /* far-field half-angle divergence M^2 lambda/(pi n w0) */
    double gouy;               /* Gouy phase atan(z/zR) here, radians */
} px_beam_at;
/* The beam with waist radius w0 a distance z_past past its waist, in index n;
 * PX_OK, or PX_BAD for w0, lambda, n <= 0, m2 < 1 or non-finite values. */
int px_beam_waist(double w0, double z_past, double lambda, double m2, double n,
                  px_beam *b);
/* The beam of radius w and wavefront radius r (inf: flat) at a plane; PX_BAD as
 * above. */
int px_beam_local(double w, double r, double lambda, double m2, double n, px_beam *b);
/* Through the matrix m (from the medium b->n into n_out); PX_BAD when the
 * result is not a beam (the matrix is singular or not finite). */
int px_beam_apply(px_beam *b, px_mat m, double n_out);
void px_beam_props(const px_beam *b, px_beam_at *at);

#endif
