/* classic.c -- the original lensmat question/answer dialogue: surfaces, cardinal
 * points, object and image planes.  Texts come from prompts/classic.txt; arithmetic
 * from the paraxial engine.  Differences from the original (plane surfaces, afocal
 * systems, objects in the focal plane, nodal planes for unequal media, input checks)
 * are listed in README.md.  Default mode: every number line prints the listing's value
 * when that is accurate to its printed digits (so the bytes stay the original's), else
 * the engine's accurate value, and says when a result is ill-conditioned; --original
 * prints the listing's values always. */
#include <float.h>
#include <math.h>
#include <string.h>
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

/* The number to print for a result whose listing value is `orig` and accurate value
 * `acc`: the listing's unless it is off by more than half a unit of its 6th printed
 * digit and more than the inputs' own rounding can explain. */
static double pick(const classic *c, double orig, px_value acc)
{
    double tol;
    if (c->io->original || !isfinite(acc.v)) return orig;
    tol = orig == 0 ? 0 : 0.5 * pow(10, floor(log10(fabs(orig))) - 5);
    if (fabs(orig - acc.v) <= fmax(tol, 2 * DBL_EPSILON * acc.sens)) return orig;
    return acc.v;
}

/* Print a result line (fmt has one %g): in default mode, a result with no digit left
 * prints "undetermined" instead of a number, an ill-conditioned one adds a note. */
static void say_value(classic *c, int where, const char *fmt, double orig, px_value acc)
{
    lm_io *io = c->io;
    const char *pc = strchr(fmt, '%');
    if (!io->original && !px_digits_meaningful(acc, 1) && pc) {
        lm_say(io, where, "%.*s", (int)(pc - fmt), fmt);
        lm_say(io, where, P(UNDETERMINED), acc.cond);
        return;
    }
    lm_say(io, where, fmt, lm_clean(io, pick(c, orig, acc)));
    if (!io->original && px_ill_conditioned(acc))
        lm_say(io, where, P(ILL_CONDITIONED), acc.cond,
               (int)floor(-log10(DBL_EPSILON * acc.cond)));
}

static int ask_num(classic *c, const char *out, const char *rec, const char *what,
                   unsigned flags, double min, double *v)
{
    lm_numspec spec = {what, flags, min};
    return lm_ask_number(c->io, out, rec, &spec, v);
}

/* An index: a number or a medium's name (lm_ask_index). */
static int ask_index(classic *c, const char *out, const char *rec, const char *what,
                     double *v)
{
    lm_numspec spec = {what, LM_POSITIVE, 0};
    return lm_ask_index(c->io, out, rec, &spec, v);
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
    if ((rc = ask_index(c, P(INDEX_RIGHT_OUT), P(INDEX_RIGHT_REC), P(INDEX_RIGHT_WHAT),
                        &n)))
        return rc;
    if (isinf(r))
        lm_say(io, LM_REC, P(SURFACE_ECHO_PLANE), P(PLANE), z);
    else
        lm_say(io, LM_REC, P(SURFACE_ECHO), r, z);
    if ((rc = px_system_translate(&c->sys, z)) < 0) return LM_FAIL;  /* checked above */
    if (rc) {
        /* the original prints the accumulated system here, not the translation */
        lm_say(io, LM_BOTH, P(TRANSLATION));
        print_matrix(c, LM_BOTH, c->sys.m);
    }
    refr = px_system_refract(&c->sys, r, n);
    if (c->sys.err) return LM_FAIL;
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
    px_first f;
    px_value fd1, fd2;

    px_first_order(&c->sys, &f);
    if (f.afocal) {
        lm_say(io, LM_BOTH, P(AFOCAL));
        say_value(c, LM_BOTH, P(AFOCAL_ANGMAG), c->sys.m.d * c->sys.n_obj / c->sys.n_img,
                  f.angular);
        return;
    }
    px_cardinal_points(&c->sys, io->original, &k);
    fd1 = f.f_front;
    fd1.v = fabs(fd1.v);
    fd2 = f.f_back;
    fd2.v = fabs(fd2.v);
    say_value(c, LM_BOTH, P(PRINCIPAL1), k.principal1, f.z_h1);
    say_value(c, LM_BOTH, P(PRINCIPAL2), k.principal2, f.z_h2);
    say_value(c, LM_BOTH, P(NODAL1), k.nodal1, f.z_n1);
    say_value(c, LM_BOTH, P(NODAL2), k.nodal2, f.z_n2);
    say_value(c, LM_BOTH, P(FOCAL1), k.focal1, f.z_f1);
    say_value(c, LM_OUT, P(FOCAL_DIST_OUT), k.focal_dist1, fd1);
    say_value(c, LM_REC, P(FOCAL_DIST1_REC), k.focal_dist1, fd1);
    say_value(c, LM_BOTH, P(FOCAL2), k.focal2, f.z_f2);
    say_value(c, LM_OUT, P(FOCAL_DIST_OUT), k.focal_dist2, fd2);
    say_value(c, LM_REC, P(FOCAL_DIST2_REC), k.focal_dist2, fd2);
}

/* The eye-nearpoint angular magnification, printed for virtual images. */
static void print_angular(classic *c, double z_obj, double z_img, double mag,
                          const px_conj *cj)
{
    lm_io *io = c->io;
    double s1 = fabs(z_obj - c->sys.z_first), s2 = fabs(z_img - c->sys.z_last);
    px_value acc_s2 = cj->z_img, acc_ang = cj->lateral;
    if (s1 < c->nearpoint) s1 = c->nearpoint;
    if (s2 < c->nearpoint) s2 = c->nearpoint;
    acc_s2.v = fmax(fabs(cj->z_img.v - c->sys.z_last), c->nearpoint);
    acc_ang.v = px_nearpoint_angmag(&c->sys, c->nearpoint, z_obj, cj);
    acc_ang.sens = cj->lateral.sens * fabs(acc_ang.v / cj->lateral.v) +
                   cj->z_img.sens * fabs(acc_ang.v) / acc_s2.v;
    lm_say(io, LM_OUT, P(DIST_OBJECT_OUT), s1);
    say_value(c, LM_OUT, P(DIST_IMAGE_OUT), s2, acc_s2);
    lm_say(io, LM_REC, P(DIST_OBJECT_REC), s1);
    say_value(c, LM_REC, P(DIST_IMAGE_REC), s2, acc_s2);
    say_value(c, LM_BOTH, P(ANGMAG), s1 * mag / s2, acc_ang);
}

static int image_object(classic *c)
{
    lm_io *io = c->io;
    double z_obj;
    px_image im;
    px_conj cj;
    px_value ang;
    double z_img;
    int rc;

    if ((rc = ask_num(c, P(OBJECT), P(OBJECT), P(OBJECT_WHAT), 0, 0, &z_obj)))
        return rc;
    lm_say(io, LM_BOTH, P(OBJECT_PLANE), z_obj);
    px_conjugate(&c->sys, z_obj, &cj);
    if (px_image_plane(&c->sys, z_obj, &im) == PX_AT_INFINITY) {
        if (im.dz_obj < 0.) lm_say(io, LM_OUT, P(OBJECT_ERROR_OUT));
        lm_say(io, LM_BOTH, P(IMAGE_INFINITY));
        lm_say(io, LM_BOTH, P(OBJECT_TRANSLATION));
        print_matrix(c, LM_BOTH, im.obj_t);
        /* parallel rays leave at n*theta = C*y: compare with the object at the
         * nearpoint, angle y/nearpoint */
        ang.v = px_nearpoint_angmag(&c->sys, c->nearpoint, z_obj, &cj);
        ang.sens = px_sensitivity(&c->sys, 0, 0, c->nearpoint / c->sys.n_img, 0);
        ang.cond = ang.v ? ang.sens / fabs(ang.v) : 0;
        say_value(c, LM_BOTH, P(ANGMAG), -c->sys.m.c * c->nearpoint / c->sys.n_img, ang);
        return LM_GO;
    }
    if (im.dz_obj < 0.) lm_say(io, LM_OUT, P(OBJECT_ERROR_OUT));
    z_img = pick(c, im.z_img, cj.z_img);
    say_value(c, LM_BOTH, P(IMAGE_PLANE), im.z_img, cj.z_img);
    lm_say(io, LM_BOTH, P(OBJECT_TRANSLATION));
    print_matrix(c, LM_BOTH, im.obj_t);
    lm_say(io, LM_BOTH, P(IMAGE_TRANSLATION));
    print_matrix(c, LM_BOTH, im.img_t);
    lm_say(io, LM_BOTH, P(OBJECT_IMAGE));
    print_matrix(c, LM_BOTH, im.obj_to_img);
    say_value(c, LM_BOTH, P(MAGNIFICATION), im.mag, cj.lateral);
    if (z_img < c->sys.z_last) print_angular(c, z_obj, im.z_img, im.mag, &cj);
    return LM_GO;
}

/* The dialogue proper; c->sys is initialised (and later freed) by lm_classic. */
static int classic_run(classic *c)
{
    lm_io *io = c->io;
    double n_obj;
    int rc, more;

    if ((rc = ask_num(c, P(NEARPOINT_OUT), P(NEARPOINT_REC), P(NEARPOINT_WHAT),
                      LM_NONNEG, 0, &c->nearpoint)))
        return rc;
    lm_say(io, LM_REC, P(NEARPOINT_ECHO), c->nearpoint);
    if ((rc = ask_index(c, P(INDEX_LEFT_OUT), P(INDEX_LEFT_REC), P(INDEX_LEFT_WHAT),
                        &n_obj)))
        return rc;
    lm_say(io, LM_REC, P(INDEX_ECHO), n_obj);
    px_system_init(&c->sys, n_obj);   /* no steps yet: nothing to free */
    do {
        if ((rc = enter_surface(c))) return rc;
        if ((rc = lm_ask_yn(io, P(ANOTHER_SURFACE), P(ANOTHER_SURFACE),
                            P(ANOTHER_SURFACE_WHAT), &more)))
            return rc;
    } while (more);
    lm_say(io, LM_OUT, P(REF1_OUT), c->sys.z_first);
    lm_say(io, LM_OUT, P(REF2_OUT), c->sys.z_last);
    lm_say(io, LM_OUT, P(FINAL_OUT));
    lm_say(io, LM_REC, P(REF1_REC), c->sys.z_first);
    lm_say(io, LM_REC, P(REF2_REC), c->sys.z_last);
    lm_say(io, LM_REC, P(FINAL_REC));
    print_matrix(c, LM_BOTH, c->sys.m);
    print_cardinal(c);
    do {
        if ((rc = image_object(c))) return rc;
        if ((rc = lm_ask_yn(io, P(ANOTHER_OBJECT), P(ANOTHER_OBJECT),
                            P(ANOTHER_OBJECT_WHAT), &more)))
            return rc;
    } while (more);
    lm_check_leftover(io);
    lm_say(io, LM_OUT, P(WRITTEN_OUT), io->rec_shown);
    return LM_GO;
}

int lm_classic(lm_io *io)
{
    classic c;
    int rc;

    c.io = io;
    c.nearpoint = 0;
    px_system_init(&c.sys, 1.0);
    rc = classic_run(&c);
    px_system_free(&c.sys);
    return rc;
}

const char *lm_classic_usage(void) { return P(USAGE); }
const char *lm_classic_usage_more(void) { return P(USAGE_MORE); }
const char *lm_classic_example(void) { return P(EXAMPLE); }
