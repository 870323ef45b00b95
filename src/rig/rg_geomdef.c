/* rg_geomdef.c -- the geometry as data: the example rig, the rig-file keys of the
 * geometry (one key and its numbers per line, lengths in mm, angles in degrees; the
 * machine's reader hands every line here first), the consistency check, joint names,
 * and the geometry block of the engine's table. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "rig/rg_geom.h"
#include "rig/rg_vec.h"

static const char *jnames[RG_NJOINTS] = {"m1a", "m1b", "u", "v", "m2a", "m2b"};
const char *rg_joint_name(int j) { return j >= 0 && j < RG_NJOINTS ? jnames[j] : NULL; }

#define DEG (RG_PI / 180)

/* The example rig (README "Rig geometry"): eye at the origin looking toward -z; the
 * detector 65 mm away, 20 deg below the axis; p2 the plane z = -60 with m2 at the
 * apex's solution; m1 50 mm from m2 across the m2-apex leg (45 deg folds at both
 * mirrors for the apex); the laser along -x onto m1.  Zero poses point at the apex. */
void rg_geometry_default(rg_geometry *g)
{
    memset(g, 0, sizeof *g);
    rg_cornea *k = &g->cornea;
    k->model = RG_CONIC;
    k->R = 7.8;
    k->Q = -0.25;
    k->R2 = 7.8;
    k->zone = 4.0;
    double zero[3] = {0, 0, 0};
    rg_eye_pose(k, 0, 0, 0, zero);
    v3set(g->detector, 0, -65 * sin(20 * DEG), -65 * cos(20 * DEG));
    v3set(g->p2_at, 0, 0, -60);
    v3set(g->p2_u, 1, 0, 0);
    v3set(g->p2_v, 0, 1, 0);
    /* the apex's backward ray is the detector ray mirrored in the axis */
    double back[3] = {0, sin(20 * DEG), -cos(20 * DEG)}, c2[3], up[3], c1[3];
    v3scale(c2, back, 60 / cos(20 * DEG));
    v3set(up, 0, cos(20 * DEG), sin(20 * DEG));     /* across the m2 -> apex leg */
    v3axpy(c1, c2, 50, up);
    v3copy(g->m2.center, c2);
    v3copy(g->m1.center, c1);
    v3set(g->laser_dir, -1, 0, 0);
    v3axpy(g->laser_at, c1, 150, (double[3]){1, 0, 0});
    double d12[3], n1[3], n2[3];
    v3sub(d12, c2, c1);
    v3norm(d12);
    v3sub(n1, d12, g->laser_dir);
    v3norm(n1);
    v3scale(n2, back, -1);
    v3sub(n2, n2, d12);
    v3norm(n2);
    rg_gimbal *m[2] = {&g->m1, &g->m2};
    double *nn[2] = {n1, n2};
    double ax[2][3] = {{0, 0, 1}, {1, 0, 0}};
    for (int i = 0; i < 2; i++) {
        v3copy(m[i]->normal0, nn[i]);
        v3copy(m[i]->axis1, ax[i]);
        v3cross(m[i]->axis2, m[i]->axis1, nn[i]);
        v3norm(m[i]->axis2);
        m[i]->radius = 5;
        m[i]->mount_radius = 7;
        m[i]->mount_depth = 8;
    }
    g->m1.offset = 0.8;
    g->m2.offset = 1.2;
    /* the built-in geometry's resolution (no rig file): 200 steps per degree on the
     * mirror mounts (0.005 deg), 400 steps per mm on the stage (2.5 um).  The machine
     * in golden/rig/example.rig has since taken faster, coarser parts for scan time
     * (88.9 steps/deg, 100 steps/mm: doc/scan-time.md); its file says its own. */
    for (int j = 0; j < RG_NJOINTS; j++) {
        int stage = j == RG_J_U || j == RG_J_V;
        g->joint[j].steps_per = stage ? 400 : 200 / DEG;
        g->joint[j].lo = j == RG_J_U ? -60 : j == RG_J_V ? -60 : -45 * DEG;
        g->joint[j].hi = j == RG_J_U ? 60 : j == RG_J_V ? 100 : 45 * DEG;
    }
}

/* ---- rig-file keys ------------------------------------------------------------- */
static int num(const char *s, double *x)
{
    char *e;
    if (!s || !*s) return -1;
    *x = strtod(s, &e);
    return *e || !isfinite(*x) ? -1 : 0;
}

static int nums(int argc, const char *const *argv, int want, double *x, char *err,
                size_t errcap)
{
    if (argc - 1 != want) {
        snprintf(err, errcap, "%s takes %d number%s, not %d", argv[0], want,
                 want == 1 ? "" : "s", argc - 1);
        return RG_EINVAL;
    }
    for (int i = 0; i < want; i++)
        if (num(argv[i + 1], &x[i])) {
            snprintf(err, errcap, "%s: '%s' is not a number", argv[0], argv[i + 1]);
            return RG_EINVAL;
        }
    return 0;
}

static int gimbal_key(rg_gimbal *m, const char *suf, int argc, const char *const *argv,
                      char *err, size_t errcap)
{
    double x[3];
    double *vec = !strcmp(suf, "center") ? m->center : !strcmp(suf, "axis1") ? m->axis1
                : !strcmp(suf, "axis2") ? m->axis2 : !strcmp(suf, "normal") ? m->normal0
                : NULL;
    if (vec) {
        if (nums(argc, argv, 3, x, err, errcap)) return RG_EINVAL;
        v3copy(vec, x);
        return 0;
    }
    double *sc = !strcmp(suf, "offset") ? &m->offset : !strcmp(suf, "radius") ? &m->radius
               : !strcmp(suf, "mount_radius") ? &m->mount_radius
               : !strcmp(suf, "mount_depth") ? &m->mount_depth : NULL;
    if (!sc) return 1;
    if (nums(argc, argv, 1, x, err, errcap)) return RG_EINVAL;
    if (sc != &m->offset && x[0] < 0) {
        snprintf(err, errcap, "%s must not be negative", argv[0]);
        return RG_EINVAL;
    }
    *sc = x[0];
    return 0;
}

int rg_geometry_key(rg_geometry *g, int argc, const char *const *argv, char *err,
                    size_t errcap)
{
    if (argc < 1 || !argv[0]) return 1;
    const char *key = argv[0];
    rg_cornea *k = &g->cornea;
    double x[RG_MAXASPH];
    if ((key[0] == 'm') && (key[1] == '1' || key[1] == '2') && key[2] == '_')
        return gimbal_key(key[1] == '1' ? &g->m1 : &g->m2, key + 3, argc, argv, err,
                          errcap);
    double *vec = !strcmp(key, "laser_at") ? g->laser_at
                : !strcmp(key, "laser_dir") ? g->laser_dir
                : !strcmp(key, "p2_at") ? g->p2_at : !strcmp(key, "p2_u") ? g->p2_u
                : !strcmp(key, "p2_v") ? g->p2_v : !strcmp(key, "detector") ? g->detector
                : !strcmp(key, "eye_at") ? k->trans : NULL;
    if (vec) {
        if (nums(argc, argv, 3, x, err, errcap)) return RG_EINVAL;
        v3copy(vec, x);
        return 0;
    }
    if (!strcmp(key, "eye_rot")) {
        double at[3];
        if (nums(argc, argv, 3, x, err, errcap)) return RG_EINVAL;
        v3copy(at, k->trans);
        rg_eye_pose(k, x[0] * DEG, x[1] * DEG, x[2] * DEG, at);
        return 0;
    }
    if (!strcmp(key, "cornea")) {
        static const char *m[] = {"sphere", "conic", "asphere", "biconic"};
        if (argc != 2) {
            snprintf(err, errcap, "cornea takes one word: sphere, conic, asphere or "
                     "biconic");
            return RG_EINVAL;
        }
        for (int i = 0; i < 4; i++)
            if (!strcmp(argv[1], m[i])) { k->model = i; return 0; }
        snprintf(err, errcap, "cornea: '%s' is not sphere, conic, asphere or biconic",
                 argv[1]);
        return RG_EINVAL;
    }
    if (!strcmp(key, "cornea_asph")) {
        if (argc - 1 > RG_MAXASPH) {
            snprintf(err, errcap, "cornea_asph takes at most %d coefficients",
                     RG_MAXASPH);
            return RG_EINVAL;
        }
        if (nums(argc, argv, argc - 1, x, err, errcap)) return RG_EINVAL;
        k->nasph = argc - 1;
        for (int i = 0; i < RG_MAXASPH; i++) k->asph[i] = i < k->nasph ? x[i] : 0;
        return 0;
    }
    double *sc = !strcmp(key, "cornea_R") ? &k->R : !strcmp(key, "cornea_Q") ? &k->Q
               : !strcmp(key, "cornea_R2") ? &k->R2 : !strcmp(key, "cornea_Q2") ? &k->Q2
               : !strcmp(key, "cornea_axis") ? &k->axis
               : !strcmp(key, "cornea_zone") ? &k->zone : NULL;
    if (sc) {
        if (nums(argc, argv, 1, x, err, errcap)) return RG_EINVAL;
        if ((sc == &k->R || sc == &k->R2) && !(x[0] > 0)) {
            snprintf(err, errcap, "%s must be > 0 (mm)", key);
            return RG_EINVAL;
        }
        if (sc == &k->zone && x[0] < 0) {
            snprintf(err, errcap, "cornea_zone must not be negative");
            return RG_EINVAL;
        }
        *sc = sc == &k->axis ? x[0] * DEG : x[0];
        return 0;
    }
    if (!strcmp(key, "joint")) {
        if (argc != 5) {
            snprintf(err, errcap, "joint takes NAME STEPS_PER LO HI");
            return RG_EINVAL;
        }
        int j = -1;
        for (int i = 0; i < RG_NJOINTS; i++)
            if (!strcmp(argv[1], jnames[i])) j = i;
        if (j < 0) {
            snprintf(err, errcap, "joint: '%s' is not m1a, m1b, u, v, m2a or m2b",
                     argv[1]);
            return RG_EINVAL;
        }
        for (int i = 0; i < 3; i++)
            if (num(argv[i + 2], &x[i])) {
                snprintf(err, errcap, "joint %s: '%s' is not a number", argv[1],
                         argv[i + 2]);
                return RG_EINVAL;
            }
        if (x[0] < 0 || x[1] > x[2]) {
            snprintf(err, errcap, "joint %s: steps must be >= 0 and LO <= HI", argv[1]);
            return RG_EINVAL;
        }
        int stage = j == RG_J_U || j == RG_J_V;
        g->joint[j].steps_per = stage ? x[0] : x[0] / DEG;
        g->joint[j].lo = stage ? x[1] : x[1] * DEG;
        g->joint[j].hi = stage ? x[2] : x[2] * DEG;
        return 0;
    }
    return 1;
}

static int unit(double *v, const char *what, char *err, size_t errcap)
{
    if (!(v3norm(v) > 1e-12) || !isfinite(v[0] + v[1] + v[2])) {
        snprintf(err, errcap, "%s must be a non-zero vector", what);
        return RG_EINVAL;
    }
    return 0;
}

static int line_dist_ok(const double at[3], const double dir[3], const double p[3],
                        double tol)
{
    double rel[3], perp[3];
    v3sub(rel, p, at);
    v3axpy(perp, rel, -v3dot(rel, dir), dir);
    return v3len(perp) <= tol;
}

int rg_geometry_check(rg_geometry *g, char *err, size_t errcap)
{
    rg_gimbal *m[2] = {&g->m1, &g->m2};
    const char *nm[2] = {"m1", "m2"};
    char what[40];
    if (unit(g->laser_dir, "laser_dir", err, errcap) ||
        unit(g->p2_u, "p2_u", err, errcap) || unit(g->p2_v, "p2_v", err, errcap))
        return RG_EINVAL;
    for (int i = 0; i < 2; i++) {
        snprintf(what, sizeof what, "%s_axis1", nm[i]);
        if (unit(m[i]->axis1, what, err, errcap)) return RG_EINVAL;
        snprintf(what, sizeof what, "%s_axis2", nm[i]);
        if (unit(m[i]->axis2, what, err, errcap)) return RG_EINVAL;
        snprintf(what, sizeof what, "%s_normal", nm[i]);
        if (unit(m[i]->normal0, what, err, errcap)) return RG_EINVAL;
        double c[3];
        v3cross(c, m[i]->axis1, m[i]->axis2);
        if (v3len(c) < 1e-6) {
            snprintf(err, errcap, "%s's two rotation axes are parallel", nm[i]);
            return RG_EINVAL;
        }
        if (fabs(v3dot(m[i]->axis2, m[i]->normal0)) > 1 - 1e-9) {
            snprintf(err, errcap, "%s's inner axis is along its normal: it cannot tilt "
                     "the mirror", nm[i]);
            return RG_EINVAL;
        }
        if (!isfinite(m[i]->offset) || !(m[i]->radius >= 0) ||
            !(m[i]->mount_radius >= 0) || !(m[i]->mount_depth >= 0)) {
            snprintf(err, errcap, "%s: offset, radius and mount sizes must be finite "
                     "(sizes >= 0)", nm[i]);
            return RG_EINVAL;
        }
    }
    double np2[3];
    v3cross(np2, g->p2_u, g->p2_v);
    if (unit(np2, "p2_u x p2_v (p2_u and p2_v parallel)", err, errcap)) return RG_EINVAL;
    double rel[3];
    v3sub(rel, g->m2.center, g->p2_at);
    if (fabs(v3dot(rel, np2)) > 1e-9 * (1 + v3len(rel))) {
        snprintf(err, errcap, "m2_center is %.6g mm off the plane p2",
                 v3dot(rel, np2));
        return RG_EINVAL;
    }
    if (!line_dist_ok(g->laser_at, g->laser_dir, g->m1.center, 1e-6)) {
        snprintf(err, errcap, "m1_center is off the laser beam's line (section 38 puts "
                 "it on the beam)");
        return RG_EINVAL;
    }
    rg_cornea *k = &g->cornea;
    if (k->model < RG_SPHERE || k->model > RG_BICONIC || !(k->R > 0) ||
        (k->model == RG_BICONIC && !(k->R2 > 0)) || k->nasph < 0 ||
        k->nasph > RG_MAXASPH || !(k->zone >= 0) || !isfinite(k->Q) ||
        !isfinite(k->Q2) || !isfinite(k->axis)) {
        snprintf(err, errcap, "cornea: model, radii (> 0), conic constants, up to %d "
                 "aspheric terms and zone (>= 0) must be valid", RG_MAXASPH);
        return RG_EINVAL;
    }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double d = 0;
            for (int l = 0; l < 3; l++) d += k->rot[l * 3 + i] * k->rot[l * 3 + j];
            if (fabs(d - (i == j)) > 1e-9) {
                snprintf(err, errcap, "eye rotation is not a rotation matrix");
                return RG_EINVAL;
            }
        }
    for (int j = 0; j < RG_NJOINTS; j++)
        if (!(g->joint[j].steps_per >= 0) || !(g->joint[j].lo <= g->joint[j].hi)) {
            snprintf(err, errcap, "joint %s: steps must be >= 0 and lo <= hi", jnames[j]);
            return RG_EINVAL;
        }
    for (int i = 0; i < 3; i++)
        if (!isfinite(g->laser_at[i] + g->detector[i] + g->p2_at[i] + g->m1.center[i] +
                      g->m2.center[i] + k->trans[i])) {
            snprintf(err, errcap, "a point of the geometry is not finite");
            return RG_EINVAL;
        }
    return RG_OK;
}

void rg_geometry_fill(rig_api *a)
{
    a->geometry_default = rg_geometry_default;
    a->geometry_key = rg_geometry_key;
    a->geometry_check = rg_geometry_check;
    a->eye_pose = rg_eye_pose;
    a->joint_name = rg_joint_name;
    a->cornea_point = rg_cornea_point;
    a->cornea_curvature = rg_cornea_curvature;
    a->solve = rg_solve;
    a->forward = rg_forward;
    a->gimbal_normal = rg_gimbal_normal;
    a->gimbal_angles = rg_gimbal_angles;
    a->jacobian = rg_jacobian;
    a->quantise = rg_quantise;
    a->verify = rg_verify_pose;
    a->diag_text = rg_diag_text;
}
