/* paraxial.h -- public face of the paraxial engine (ABCD matrices, cardinal points,
 * object/image planes).  Rays are (y, n*theta); every matrix has det 1.  Lengths are
 * in whatever unit the user chose; the engine never prints anything. */
#ifndef PARAXIAL_H
#define PARAXIAL_H

/* [a b; c d] acting on the column (y, n*theta). */
typedef struct px_mat { double a, b, c, d; } px_mat;

px_mat px_identity(void);
px_mat px_translation(double reduced);            /* [1 t; 0 1], t = distance / n */
px_mat px_refraction(double n1, double n2, double r); /* r: radius, +-inf = plane */
px_mat px_mul(px_mat l, px_mat r);                /* l*r, in the listing's order */
px_mat px_mul_abs(px_mat l, px_mat r);            /* |l|*|r|: rounding-error scale */
double px_det(px_mat m);                          /* a*d - c*b, listing's order */
double px_det_accurate(px_mat m);                 /* a*d - b*c with an fma correction */

/* A lens system built surface by surface, as the classic dialogue enters it.  `abs`
 * is the product of the elementwise absolute values: the size of what was summed into
 * each entry, which scales the rounding error of that entry. */
typedef struct px_system {
    px_mat m, abs;
    double z_first, z_last;   /* reference planes 1 and 2 */
    double n_obj, n_img;      /* media left of the first, right of the last surface */
    int nsurf;
} px_system;

void px_system_init(px_system *s, double n_obj);
/* Adding a surface at z takes two steps, so that a caller can show the system in
 * between (the original does).  px_system_translate moves reference plane 2 to z and
 * returns 1 if that took a translation (z right of it), 0 otherwise (first surface,
 * or a thin lens: same z).  px_system_refract then adds the refraction at a surface
 * of radius r (0 or +-inf: a plane) with index n_right to its right, and returns
 * that surface's refraction matrix. */
int px_system_translate(px_system *s, double z);
px_mat px_system_refract(px_system *s, double r, double n_right);

/* Is C zero within the rounding error of its computation? */
int px_is_afocal(const px_system *s);

/* The six cardinal points (z coordinates) and focal distances. */
typedef struct px_cardinal {
    double principal1, principal2, nodal1, nodal2, focal1, focal2;
    double focal_dist1, focal_dist2;   /* |principal - focal|, as the original prints */
} px_cardinal;

/* `original` = 1: nodal planes by the original (1-D)/C, right only for n_obj == n_img.
 * 0: nodal planes correct for any media (identical when the media are equal). */
void px_cardinal_points(const px_system *s, int original, px_cardinal *out);

/* Image of the object plane at z_obj.  Fills the reduced object distance, the
 * reduced image distance d2 (image at z_last + n_img*d2) and the object-to-image
 * matrix.  Returns 0, or PX_AT_INFINITY when the object lies in the first focal
 * plane (C*d1 + D is zero within rounding), in which case d2 is not set. */
enum { PX_OK = 0, PX_AT_INFINITY = 1 };
typedef struct px_image {
    double dz_obj, d2, z_img;
    px_mat obj_t, img_t, obj_to_img;
    double mag;
} px_image;
int px_image_plane(const px_system *s, double z_obj, px_image *out);

#endif
