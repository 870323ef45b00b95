/* classic.c -- the original lensmat question/answer dialogue: surfaces, cardinal
 * points, object and image planes.  Texts come from prompts/classic.txt; arithmetic
 * from the paraxial engine.  Differences from the original (plane surfaces, afocal
 * systems, objects in the focal plane, nodal planes for unequal media, input checks)
 * are listed in README.md. */
#include <math.h>
#include "ask.h"
#include "dialogues.h"
#include "../paraxial/paraxial.h"
#include "prompts_classic.h"

#define P(k) classic_prompts[CLASSIC_##k]

typedef struct classic {
    lm_io *io;
    double nearpoint;
    px_system sys;
} classic;

static void print_matrix(classic *c, int where, px_mat m)
{
    lm_matrix(c->io, where, P(MATRIX_ELEM), m.a, m.b, m.c, m.d);
}

static int ask_num(classic *c, const char *out, const char *rec, const char *what,
                   unsigned flags, double min, double *v)
{
    lm_numspec spec = {what, flags, min};
    return lm_ask_number(c->io, out, rec, &spec, v);
}

/* One surface: radius, location, index; prints the matrices as the original did. */
static int enter_surface(classic *c)
{
    lm_io *io = c->io;
    double r, z, n;
    int rc;
    px_mat refr;

    if ((rc = ask_num(c, P(RADIUS_OUT), P(RADIUS_REC), P(RADIUS_WHAT), LM_ALLOW_PLANE,
                      0, &r)))
        return rc;
    if ((rc = ask_num(c, P(LOCATION_OUT), P(LOCATION_REC), P(LOCATION_WHAT),
                      c->sys.nsurf ? LM_AT_LEAST : 0, c->sys.z_last, &z)))
        return rc;
    if ((rc = ask_num(c, P(INDEX_RIGHT_OUT), P(INDEX_RIGHT_REC), P(INDEX_RIGHT_WHAT),
                      LM_POSITIVE, 0, &n)))
        return rc;
    if (isinf(r))
        lm_say(io, LM_REC, P(SURFACE_ECHO_PLANE), P(PLANE), z);
    else
        lm_say(io, LM_REC, P(SURFACE_ECHO), r, z);
    if (px_system_translate(&c->sys, z)) {
        /* the original prints the accumulated system here, not the translation */
        lm_say(io, LM_BOTH, P(TRANSLATION));
        print_matrix(c, LM_BOTH, c->sys.m);
    }
    refr = px_system_refract(&c->sys, r, n);
    lm_say(io, LM_BOTH, P(REFRACTION));
    print_matrix(c, LM_BOTH, refr);
    lm_say(io, LM_BOTH, P(SYSTEM));
    print_matrix(c, LM_BOTH, c->sys.m);
    lm_say(io, LM_OUT, P(DET_OUT), lm_clean(io, px_det(c->sys.m)));
    return LM_GO;
}

static void print_cardinal(classic *c)
{
    lm_io *io = c->io;
    px_cardinal k;

    if (px_is_afocal(&c->sys)) {
        lm_say(io, LM_BOTH, P(AFOCAL));
        lm_say(io, LM_BOTH, P(AFOCAL_ANGMAG),
               lm_clean(io, c->sys.m.d * c->sys.n_obj / c->sys.n_img));
        return;
    }
    px_cardinal_points(&c->sys, io->original, &k);
    lm_say(io, LM_BOTH, P(PRINCIPAL1), lm_clean(io, k.principal1));
    lm_say(io, LM_BOTH, P(PRINCIPAL2), lm_clean(io, k.principal2));
    lm_say(io, LM_BOTH, P(NODAL1), lm_clean(io, k.nodal1));
    lm_say(io, LM_BOTH, P(NODAL2), lm_clean(io, k.nodal2));
    lm_say(io, LM_BOTH, P(FOCAL1), lm_clean(io, k.focal1));
    lm_say(io, LM_OUT, P(FOCAL_DIST_OUT), k.focal_dist1);
    lm_say(io, LM_REC, P(FOCAL_DIST1_REC), k.focal_dist1);
    lm_say(io, LM_BOTH, P(FOCAL2), lm_clean(io, k.focal2));
    lm_say(io, LM_OUT, P(FOCAL_DIST_OUT), k.focal_dist2);
    lm_say(io, LM_REC, P(FOCAL_DIST2_REC), k.focal_dist2);
}

/* The eye-nearpoint angular magnification, printed for virtual images. */
static void print_angular(classic *c, double z_obj, double z_img, double mag)
{
    lm_io *io = c->io;
    double s1 = fabs(z_obj - c->sys.z_first), s2 = fabs(z_img - c->sys.z_last);
    if (s1 < c->nearpoint) s1 = c->nearpoint;
    if (s2 < c->nearpoint) s2 = c->nearpoint;
    lm_say(io, LM_OUT, P(DIST_OBJECT_OUT), s1);
    lm_say(io, LM_OUT, P(DIST_IMAGE_OUT), s2);
    lm_say(io, LM_REC, P(DIST_OBJECT_REC), s1);
    lm_say(io, LM_REC, P(DIST_IMAGE_REC), s2);
    lm_say(io, LM_BOTH, P(ANGMAG), lm_clean(io, s1 * mag / s2));
}

static int image_object(classic *c)
{
    lm_io *io = c->io;
    double z_obj;
    px_image im;
    int rc;

    if ((rc = ask_num(c, P(OBJECT), P(OBJECT), P(OBJECT_WHAT), 0, 0, &z_obj)))
        return rc;
    lm_say(io, LM_BOTH, P(OBJECT_PLANE), z_obj);
    if (px_image_plane(&c->sys, z_obj, &im) == PX_AT_INFINITY) {
        if (im.dz_obj < 0.) lm_say(io, LM_OUT, P(OBJECT_ERROR_OUT));
        lm_say(io, LM_BOTH, P(IMAGE_INFINITY));
        lm_say(io, LM_BOTH, P(OBJECT_TRANSLATION));
        print_matrix(c, LM_BOTH, im.obj_t);
        /* parallel rays leave at n*theta = C*y: compare with the object at the
         * nearpoint, angle y/nearpoint */
        lm_say(io, LM_BOTH, P(ANGMAG),
               lm_clean(io, -c->sys.m.c * c->nearpoint / c->sys.n_img));
        return LM_GO;
    }
    if (im.dz_obj < 0.) lm_say(io, LM_OUT, P(OBJECT_ERROR_OUT));
    lm_say(io, LM_BOTH, P(IMAGE_PLANE), lm_clean(io, im.z_img));
    lm_say(io, LM_BOTH, P(OBJECT_TRANSLATION));
    print_matrix(c, LM_BOTH, im.obj_t);
    lm_say(io, LM_BOTH, P(IMAGE_TRANSLATION));
    print_matrix(c, LM_BOTH, im.img_t);
    lm_say(io, LM_BOTH, P(OBJECT_IMAGE));
    print_matrix(c, LM_BOTH, im.obj_to_img);
    lm_say(io, LM_BOTH, P(MAGNIFICATION), lm_clean(io, im.mag));
    if (im.z_img < c->sys.z_last) print_angular(c, z_obj, im.z_img, im.mag);
    return LM_GO;
}

int lm_classic(lm_io *io)
{
    classic c = {io, 0, {{0, 0, 0, 0}, {0, 0, 0, 0}, 0, 0, 0, 0, 0}};
    double n_obj;
    int rc, more;

    if ((rc = ask_num(&c, P(NEARPOINT_OUT), P(NEARPOINT_REC), P(NEARPOINT_WHAT),
                      LM_NONNEG, 0, &c.nearpoint)))
        return rc;
    lm_say(io, LM_REC, P(NEARPOINT_ECHO), c.nearpoint);
    if ((rc = ask_num(&c, P(INDEX_LEFT_OUT), P(INDEX_LEFT_REC), P(INDEX_LEFT_WHAT),
                      LM_POSITIVE, 0, &n_obj)))
        return rc;
    lm_say(io, LM_REC, P(INDEX_ECHO), n_obj);
    px_system_init(&c.sys, n_obj);
    do {
        if ((rc = enter_surface(&c))) return rc;
        if ((rc = lm_ask_yn(io, P(ANOTHER_SURFACE), P(ANOTHER_SURFACE),
                            P(ANOTHER_SURFACE_WHAT), &more)))
            return rc;
    } while (more);
    lm_say(io, LM_OUT, P(REF1_OUT), c.sys.z_first);
    lm_say(io, LM_OUT, P(REF2_OUT), c.sys.z_last);
    lm_say(io, LM_OUT, P(FINAL_OUT));
    lm_say(io, LM_REC, P(REF1_REC), c.sys.z_first);
    lm_say(io, LM_REC, P(REF2_REC), c.sys.z_last);
    lm_say(io, LM_REC, P(FINAL_REC));
    print_matrix(&c, LM_BOTH, c.sys.m);
    print_cardinal(&c);
    do {
        if ((rc = image_object(&c))) return rc;
        if ((rc = lm_ask_yn(io, P(ANOTHER_OBJECT), P(ANOTHER_OBJECT),
                            P(ANOTHER_OBJECT_WHAT), &more)))
            return rc;
    } while (more);
    lm_check_leftover(io);
    lm_say(io, LM_OUT, P(WRITTEN_OUT), io->rec_name);
    return LM_GO;
}

const char *lm_classic_usage(void) { return P(USAGE); }
const char *lm_classic_usage_more(void) { return P(USAGE_MORE); }
const char *lm_classic_example(void) { return P(EXAMPLE); }
