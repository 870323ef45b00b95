/* tt.h -- shared by the trace engine's tests and bench (tests/trace/): the engine's
 * table, a published Cooke triplet, an independent paraxial y-nu trace and an
 * independent double-precision sequential real-ray trace to compare with. */
#ifndef TT_H
#define TT_H
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "trace/trace.h"

#pragma GCC diagnostic ignored "-Wunused-function"

static const trace_api *tt_api(void)
{
    const trace_api *tr = trace_get_api(TRACE_ABI);
    if (!tr) { printf("FAIL no engine table\n"); exit(1); }
    return tr;
}

/* Cooke triplet of the Zemax lens-design tutorial (f ~ 50 mm), SK16 / F2 / SK16 at
 * the d line (fixed indices), vertex positions from its thicknesses; stop near
 * surface 4; used at f/4 (entrance pupil 12.5 mm). */
#define TT_NSURF 6
static const double tt_R[TT_NSURF] = {22.01359, -435.76044, -22.21328, 20.29192,
                                      79.68360, -18.39533};
static const double tt_T[TT_NSURF] = {3.25896, 6.00764, 0.99963, 4.75041, 2.95208,
                                      42.20778};
static const double tt_N[TT_NSURF] = {1.62041, 1.0, 1.62004, 1.0, 1.62041, 1.0};
static const double tt_SD[TT_NSURF] = {8.0, 8.0, 5.5, 5.5, 7.5, 7.5};
#define TT_EPD 12.5

static void tt_triplet(trace_lens_surface s[TT_NSURF], trace_lens *l, int sd)
{
    double z = 0;
    for (int i = 0; i < TT_NSURF; i++) {
        s[i].radius = tt_R[i];
        s[i].z = z;
        s[i].n_right = tt_N[i];
        s[i].semi_diameter = sd ? tt_SD[i] : 0;
        z += tt_T[i];
    }
    l->n_object = 1;
    l->nsurf = TT_NSURF;
    l->surf = s;
    l->mounts = sd;
    l->z_detector = NAN;
}

/* Paraxial y-nu trace: image z of an axial object at z_obj (-inf: at infinity). */
static double tt_paraxial_image(const trace_lens *l, double z_obj)
{
    double y = 1, u, n = l->n_object, z = l->surf[0].z;
    u = isinf(z_obj) ? 0 : y / (z - z_obj);          /* angle of the marginal ray */
    for (int i = 0; i < l->nsurf; i++) {
        const trace_lens_surface *s = &l->surf[i];
        if (i) { y += u * (s->z - z); z = s->z; }
        double c = (isfinite(s->radius) && s->radius != 0) ? 1 / s->radius : 0;
        double nu = n * u - y * (s->n_right - n) * c;
        n = s->n_right;
        u = nu / n;
    }
    return z - y / u;
}

/* The triplet with mounts and a detector at its paraxial focus in a new scene, lit from
 * z = -5 by a collimated grid of count x count rays over a disc of the given radius
 * (TT_EPD / 2: the pupil); NULL if the engine refuses it (add_lens copies the lens). */
static trace_scene *tt_triplet_grid(const trace_api *tr, long count, double radius)
{
    trace_lens_surface s[TT_NSURF];
    trace_lens l;
    tt_triplet(s, &l, 1);
    l.z_detector = tt_paraxial_image(&l, -INFINITY);
    trace_scene *sc = tr->scene_new();
    trace_source src = {0};
    src.type = TRACE_SRC_GRID;
    src.at[2] = -5; src.dir[2] = 1; src.up[1] = 1;
    src.radius = radius;
    src.count = count;
    if (sc && (tr->add_lens(sc, &l) < 0 || tr->add_source(sc, &src, NULL) < 0)) {
        tr->scene_free(sc);
        return NULL;
    }
    return sc;
}

/* Effective focal length (paraxial, object at infinity). */
static double tt_efl(const trace_lens *l)
{
    double y = 1, u = 0, n = l->n_object, z = l->surf[0].z;
    for (int i = 0; i < l->nsurf; i++) {
        const trace_lens_surface *s = &l->surf[i];
        if (i) { y += u * (s->z - z); z = s->z; }
        double c = (isfinite(s->radius) && s->radius != 0) ? 1 / s->radius : 0;
        u = (n * u - y * (s->n_right - n) * c) / s->n_right;
        n = s->n_right;
    }
    return -1 / u;
}

/* Independent real-ray trace in double through spherical surfaces (no Embree, no
 * engine code): ray o, d (unit) to the plane z = zi; returns 0 or -1 if it misses. */
static int tt_real_trace(const trace_lens *l, const double o0[3], const double d0[3],
                         double zi, double out[3], double dout[3])
{
    double o[3] = {o0[0], o0[1], o0[2]}, d[3] = {d0[0], d0[1], d0[2]};
    double n = l->n_object;
    for (int i = 0; i < l->nsurf; i++) {
        const trace_lens_surface *s = &l->surf[i];
        double t, p[3], m[3];
        if (!isfinite(s->radius) || s->radius == 0) {
            t = (s->z - o[2]) / d[2];
            m[0] = 0; m[1] = 0; m[2] = 1;
            for (int k = 0; k < 3; k++) p[k] = o[k] + t * d[k];
        } else {
            double R = s->radius, c[3] = {0, 0, s->z + R};
            double q[3] = {o[0] - c[0], o[1] - c[1], o[2] - c[2]};
            double b = q[0] * d[0] + q[1] * d[1] + q[2] * d[2];
            double cc = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] - R * R;
            double disc = b * b - cc;
            if (disc < 0) return -1;
            /* the root on the vertex side: R > 0 the first crossing, else the second */
            t = R > 0 ? -b - sqrt(disc) : -b + sqrt(disc);
            for (int k = 0; k < 3; k++) p[k] = o[k] + t * d[k];
            for (int k = 0; k < 3; k++) m[k] = (c[k] - p[k]) / R;   /* +z at the vertex */
        }
        double n2 = s->n_right, mu = n / n2;
        double ci = d[0] * m[0] + d[1] * m[1] + d[2] * m[2];      /* > 0 */
        double k2 = 1 - mu * mu * (1 - ci * ci);
        if (k2 < 0) return -1;
        double g = sqrt(k2) - mu * ci;
        for (int k = 0; k < 3; k++) d[k] = mu * d[k] + g * m[k];
        double dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int k = 0; k < 3; k++) { d[k] /= dl; o[k] = p[k]; }
        n = n2;
    }
    double t = (zi - o[2]) / d[2];
    for (int k = 0; k < 3; k++) { out[k] = o[k] + t * d[k]; dout[k] = d[k]; }
    return 0;
}

#endif
