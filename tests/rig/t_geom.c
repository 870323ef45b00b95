/* t_geom.c -- the rig geometry (sections 33, 38, 39) against independent
 * computations: cornea points and normals against the sag formulas typed again,
 * gimbals against rotation matrices, every solution against an independent forward
 * model and a forward trace through the trace engine (targets and the detector
 * point recovered to 1e-9 mm, the reflection law at every mirror), stiff cases
 * (grazing, near-parallel to p2, blocking, decentred and tilted eyes at the edge of
 * travel), quantisation, the rig-file keys. */
#include <pthread.h>
#include "unit.h"
#include "rig/rt.h"

static const rig_api *rg;
static const trace_api *tr;
static char err[1024];

static void cornea_set(rg_cornea *c, int model)
{
    c->model = model;
    c->R = 7.8; c->Q = model == RG_SPHERE ? 0 : -0.25;
    c->R2 = 7.4; c->Q2 = -0.1; c->axis = 25 * RT_DEG;
    c->nasph = model == RG_ASPHERE ? 2 : 0;
    c->asph[0] = 2e-4; c->asph[1] = -3e-6;
}

/* ---- cornea models ---------------------------------------------------------- */
static void cornea_models(void)
{
    static const char *name[] = {"sphere", "conic", "asphere", "biconic"};
    for (int model = RG_SPHERE; model <= RG_BICONIC; model++) {
        rg_geometry g;
        rg->geometry_default(&g);
        cornea_set(&g.cornea, model);
        double at[3] = {0.3, -0.2, 0.4};
        rg->eye_pose(&g.cornea, 3 * RT_DEG, -4 * RT_DEG, 20 * RT_DEG, at);
        double worst_on = 0, worst_n = 0;
        int bad = 0, n = 0;
        for (double h = 0; h <= 4.0; h += 0.25)
            for (double ph = 0; ph < 2 * RT_PI; ph += RT_PI / 7) {
                rg_target t = {RG_T_HEIGHT, h, ph};
                double p[3], nn[3], ref[3];
                if (rg->cornea_point(&g.cornea, &t, p, nn, err, sizeof err)) { bad++; continue; }
                n++;
                double e[3];
                rt_to_eye(&g.cornea, p, e);
                worst_on = fmax(worst_on, fabs(rt_above(&g.cornea, p)));
                worst_on = fmax(worst_on, fabs(hypot(e[0], e[1]) - h));
                rt_normal(&g.cornea, p, ref);
                worst_n = fmax(worst_n, rt_dist(ref, nn));
            }
        CHECK(bad == 0 && worst_on < 1e-12 && worst_n < 1e-8,
              "%s cornea, tilted and decentred eye: %d points on the surface to %.1e mm, "
              "normals = sag-gradient normals to %.1e", name[model], n, worst_on, worst_n);
    }
    /* spherical coordinates on a sphere are the sphere's own */
    rg_cornea c;
    memset(&c, 0, sizeof c);
    cornea_set(&c, RG_SPHERE);
    double z0[3] = {0, 0, 0};
    rg->eye_pose(&c, 0, 0, 0, z0);
    double worst = 0;
    for (double th = 0; th < 80 * RT_DEG; th += 7 * RT_DEG)
        for (double ph = 0; ph < 2 * RT_PI; ph += 0.9) {
            rg_target t = {RG_T_ANGLES, th, ph};
            double p[3], n[3], want[3] = {c.R * sin(th) * cos(ph), c.R * sin(th) * sin(ph),
                                          c.R - c.R * cos(th)};
            rg->cornea_point(&c, &t, p, n, err, sizeof err);
            worst = fmax(worst, rt_dist(p, want));
        }
    CHECK(worst < 1e-13, "sphere: target (theta, phi) is R(sin t cos p, sin t sin p, 1 - cos t) "
          "to %.1e mm", worst);
    /* conic: the point lies on the ray from the apex centre of curvature */
    cornea_set(&c, RG_CONIC);
    worst = 0;
    for (double th = 0; th < 60 * RT_DEG; th += 5 * RT_DEG) {
        rg_target t = {RG_T_ANGLES, th, 1.1};
        double p[3], n[3], ctr[3] = {0, 0, c.R}, w[3] = {sin(th) * cos(1.1), sin(th) * sin(1.1), -cos(th)};
        rg->cornea_point(&c, &t, p, n, err, sizeof err);
        worst = fmax(worst, rt_line_dist(ctr, w, p) + fabs(rt_above(&c, p)));
    }
    CHECK(worst < 1e-12, "conic: angle targets on the ray from the centre of curvature and "
          "on the surface (%.1e mm)", worst);
    /* biconic meridians are the two conics */
    cornea_set(&c, RG_BICONIC);
    rg_cornea f = c, s = c;
    f.model = s.model = RG_CONIC;
    s.R = c.R2; s.Q = c.Q2;
    double dm = 0;
    for (double h = 0; h < 5; h += 0.5) {
        double pf[3], ps[3], nf[3], ns[3], qf[3], qs[3];
        rg_target tf = {RG_T_HEIGHT, h, c.axis}, ts = {RG_T_HEIGHT, h, c.axis + RT_PI / 2}, t0 = {RG_T_HEIGHT, h, 0};
        rg->cornea_point(&c, &tf, pf, nf, err, sizeof err);
        rg->cornea_point(&c, &ts, ps, ns, err, sizeof err);
        tf.b = 0;
        t0.b = RT_PI / 2;
        rg->cornea_point(&f, &tf, qf, nf, err, sizeof err);
        rg->cornea_point(&s, &t0, qs, ns, err, sizeof err);
        dm = fmax(dm, fmax(fabs(pf[2] - qf[2]), fabs(ps[2] - qs[2])));
    }
    CHECK(dm < 1e-14, "biconic: the flat and steep meridians (axis 25 deg) are the conics "
          "(R, Q) and (R2, Q2) to %.1e mm", dm);
    /* off the cornea */
    cornea_set(&c, RG_CONIC);
    rg_target edge = {RG_T_HEIGHT, 9.5, 0}, zone = {RG_T_HEIGHT, 4.5, 0};
    double p[3], n[3];
    int r1 = rg->cornea_point(&c, &edge, p, n, err, sizeof err);
    c.zone = 4;
    int r2 = rg->cornea_point(&c, &zone, p, n, err, sizeof err);
    CHECK(r1 == RG_EUNREACH && r2 == RG_EUNREACH && strstr(err, "zone"),
          "targets past the conic's edge (9.0 mm) and outside the zone refused (%s)", err);
}

/* ---- gimbals ---------------------------------------------------------------- */
static void gimbals(void)
{
    rg_geometry g;
    rg->geometry_default(&g);
    srand(7);
    double worst_n = 0, worst_a = 0;
    int bad = 0;
    for (int i = 0; i < 2000; i++) {
        const rg_gimbal *m = i & 1 ? &g.m1 : &g.m2;
        double a = (rand() / (double)RAND_MAX - 0.5) * 2 * RT_PI / 3;
        double b = (rand() / (double)RAND_MAX - 0.5) * 2 * RT_PI / 3;
        double n[3], ref[3], a2, b2;
        rg->gimbal_normal(m, a, b, n);
        rt_gimbal(m, a, b, ref);
        worst_n = fmax(worst_n, rt_dist(n, ref));
        if (rg->gimbal_angles(m, n, &a2, &b2)) { bad++; continue; }
        worst_a = fmax(worst_a, fmax(fabs(a - a2), fabs(b - b2)));
    }
    CHECK(worst_n < 1e-15 && bad == 0 && worst_a < 1e-11,
          "gimbals: 2000 poses within +-60 deg, normal = rotation matrices to %.1e, angles "
          "recovered to %.1e rad", worst_n, worst_a);
    /* a mount whose inner axis is not across the mirror cannot reach every normal */
    rg_gimbal m = g.m1;
    double k[3] = {0.6 * m.normal0[0] + 0.8 * m.axis2[0], 0.6 * m.normal0[1] + 0.8 * m.axis2[1],
                   0.6 * m.normal0[2] + 0.8 * m.axis2[2]}, a, b;
    memcpy(m.axis2, k, sizeof k);
    rt_unit(m.axis2);
    CHECK(rg->gimbal_angles(&m, m.axis1, &a, &b) != 0,
          "a normal outside a mount's reach is refused");
}

/* ---- solutions -------------------------------------------------------------- */
typedef struct scan_res { int n, fail, miss; double et, ed, law, ind, m2c, p2, it_min, it_max, res; } scan_res;

static void check_solution(const rg_geometry *g, const rg_solution *s, scan_res *r)
{
    rg_verify v;
    if (rg->verify(tr, g, &s->pose, s->target, &v, err, sizeof err) || !v.hit) { r->miss++; return; }
    r->et = fmax(r->et, v.err_target);
    r->ed = fmax(r->ed, v.err_detector);
    r->law = fmax(r->law, v.reflect_err);
    /* independent model: same spot, the reflected line through the detector */
    rt_path p;
    if (rt_forward(g, &s->pose, &p)) { r->miss++; return; }
    r->ind = fmax(r->ind, fmax(rt_dist(p.spot, s->target),
                               rt_line_dist(p.spot, p.d3, g->detector)));
    /* reflection law with the independent normals at both mirrors */
    double w[3];
    rt_reflect(g->laser_dir, p.n1, w);
    r->law = fmax(r->law, rt_dist(w, s->beam.d1));
    rt_reflect(s->beam.d1, p.n2, w);
    r->law = fmax(r->law, rt_dist(w, s->beam.d2));
    /* m2: the beam lands on its centre; the centre is on p2 */
    double c2[3], np[3] = {g->p2_u[1] * g->p2_v[2] - g->p2_u[2] * g->p2_v[1],
                           g->p2_u[2] * g->p2_v[0] - g->p2_u[0] * g->p2_v[2],
                           g->p2_u[0] * g->p2_v[1] - g->p2_u[1] * g->p2_v[0]};
    rt_unit(np);
    for (int i = 0; i < 3; i++)
        c2[i] = g->m2.center[i] + s->pose.j[RG_J_U] * g->p2_u[i] + s->pose.j[RG_J_V] * g->p2_v[i] +
                g->m2.offset * p.n2[i];
    r->m2c = fmax(r->m2c, rt_dist(c2, s->beam.h2));
    double rel[3] = {c2[0] - g->m2.offset * p.n2[0] - g->p2_at[0], c2[1] - g->m2.offset * p.n2[1] - g->p2_at[1],
                     c2[2] - g->m2.offset * p.n2[2] - g->p2_at[2]};
    r->p2 = fmax(r->p2, fabs(rt_dot(rel, np)));
    r->res = fmax(r->res, s->residual);
    r->it_min = fmin(r->it_min, s->iterations);
    r->it_max = fmax(r->it_max, s->iterations);
}

static scan_res scan(const rg_geometry *g, int n, double thmax)
{
    scan_res r = {0};
    r.it_min = 1e9;
    for (int i = 0; i < n; i++) {
        rg_target t = rt_scan(i, n, thmax);
        rg_solution s;
        if (rg->solve(g, &t, NULL, &s, err, sizeof err)) {
            r.fail++;
            if (r.fail == 1) printf("  first failure: theta %.3f deg: %s\n", t.a / RT_DEG, err);
            continue;
        }
        r.n++;
        check_solution(g, &s, &r);
    }
    return r;
}

static void report(const char *what, scan_res r, int want, int newton)
{
    CHECK(r.n == want && r.miss == 0 && r.et < 1e-9 && r.ed < 1e-9 && r.law < 1e-12 &&
          r.ind < 1e-7 && r.m2c < 1e-9 && r.p2 < 1e-12 &&
          (newton ? r.it_min >= 1 : r.it_max == 0),
          "%s: %d/%d solved, traced beam hits target to %.1e mm and detector to %.1e mm; "
          "reflection law to %.1e; independent model %.1e mm; beam on m2's centre %.1e mm; "
          "%g..%g construction passes + Newton steps", what, r.n, want, r.et, r.ed, r.law, r.ind, r.m2c,
          r.it_min, r.it_max);
}

static void solutions(void)
{
    rg_geometry g;
    rg->geometry_default(&g);
    CHECK(rg->geometry_check(&g, err, sizeof err) == RG_OK, "example geometry is consistent");
    report("example rig (mirror offsets 0.8 / 1.2 mm)", scan(&g, 300, 12 * RT_DEG), 300, 1);
    rg_geometry z = g;
    z.m1.offset = z.m2.offset = 0;
    report("mirrors on their axes (closed form alone)", scan(&z, 300, 12 * RT_DEG), 300, 0);
    static const char *name[] = {"sphere", "conic", "asphere", "biconic"};
    for (int model = RG_SPHERE; model <= RG_BICONIC; model++) {
        rg_geometry c = g;
        cornea_set(&c.cornea, model);
        double at[3] = {0.5, -0.4, 0.6};
        rg->eye_pose(&c.cornea, 4 * RT_DEG, -3 * RT_DEG, 10 * RT_DEG, at);
        char what[120];
        snprintf(what, sizeof what, "%s cornea, eye tilted (4, -3, 10 deg), decentred", name[model]);
        report(what, scan(&c, 120, 8 * RT_DEG), 120, 1);
    }
    /* conics of every kind: hyperboloid (keratoconus-like), paraboloid, oblate */
    static const double qs[] = {-1.5, -1.0, 0.5};
    for (int i = 0; i < 3; i++) {
        rg_geometry c = g;
        c.cornea.Q = qs[i];
        char what[80];
        snprintf(what, sizeof what, "conic cornea Q = %g", qs[i]);
        report(what, scan(&c, 60, 10 * RT_DEG), 60, 1);
    }
    /* a stage whose axes are not at right angles (p2_v 10 deg off): u, v still exact */
    rg_geometry sk = g;
    sk.p2_v[0] = sin(10 * RT_DEG);
    sk.p2_v[1] = cos(10 * RT_DEG);
    report("stage axes 80 deg apart", scan(&sk, 60, 10 * RT_DEG), 60, 1);
    /* thick mirrors far off their axes: the construction must still converge */
    rg_geometry th = g;
    th.m1.offset = 10;
    th.m2.offset = -6;
    rg_target t0 = {RG_T_ANGLES, 0, 0};
    rg_solution s0;
    int r0 = rg->solve(&th, &t0, NULL, &s0, err, sizeof err);
    CHECK(r0 == RG_EUNREACH && (s0.diag & RG_D_MISS_MIRROR),
          "m1's surface 10 mm off its axes: the beam misses its 5 mm rim: %s", err);
    th.m1.offset = 4;
    th.m1.radius = th.m2.radius = 8;
    th.m1.mount_radius = th.m2.mount_radius = 10;
    report("mirror offsets 4 / -6 mm (8 mm rims)", scan(&th, 100, 7 * RT_DEG), 100, 1);
    /* Newton alone from the zero-offset closed form lands on the same poses */
    rg_solve_opts nopt = {0};
    nopt.newton_only = 1;
    double dp = 0;
    int nits = 100, nok = 0;
    for (int i = 0; i < 50; i++) {
        rg_target t = rt_scan(i, 50, 12 * RT_DEG);
        rg_solution a, b;
        if (rg->solve(&g, &t, NULL, &a, err, sizeof err) ||
            rg->solve(&g, &t, &nopt, &b, err, sizeof err)) continue;
        nok++;
        nits = b.iterations < nits ? b.iterations : nits;
        for (int j = 0; j < RG_NJOINTS; j++) dp = fmax(dp, fabs(a.pose.j[j] - b.pose.j[j]));
    }
    CHECK(nok == 50 && nits >= 2 && dp < 1e-11,
          "Newton on the exact model (>= %d iterations) and the repeated construction agree "
          "on 50 poses to %.1e (rad, mm)", nits, dp);
    /* the tracer inside solve: every solution checked in the same call */
    rg_solve_opts topt = {0};
    topt.trace = tr;
    double terr = 0;
    int tok = 0, tbits = 0;
    for (int i = 0; i < 40; i++) {
        rg_target t = rt_scan(i, 40, 12 * RT_DEG);
        rg_solution a;
        if (rg->solve(&g, &t, &topt, &a, err, sizeof err) == RG_OK) tok++;
        terr = fmax(terr, a.traced_err);
        tbits |= a.diag & RG_D_TRACE_MISS;
    }
    topt.trace_tol = 1e-16;             /* tighter than rounding: must be reported */
    rg_target t1 = {RG_T_ANGLES, 5 * RT_DEG, 1.0};
    rg_solution a1;
    int r1 = rg->solve(&g, &t1, &topt, &a1, err, sizeof err);
    CHECK(tok == 40 && !tbits && terr < 1e-9 && r1 == RG_EUNREACH &&
          (a1.diag & RG_D_TRACE_MISS) && strstr(err, "traced"),
          "solve with the tracer: 40 solutions traced to %.1e mm; a miss over trace_tol is "
          "refused (%s)", terr, err);
    /* height/meridian targets */
    rg_target t = {RG_T_HEIGHT, 1.3, 0.7};
    rg_solution s;
    scan_res r = {0};
    r.it_min = 1e9;
    int rc = rg->solve(&g, &t, NULL, &s, err, sizeof err);
    if (!rc) check_solution(&g, &s, &r);
    CHECK(rc == 0 && r.miss == 0 && r.et < 1e-9 && r.ed < 1e-9 &&
          fabs(hypot(s.target[0], s.target[1]) - 1.3) < 1e-12,
          "height/meridian target (1.3 mm, 40 deg) solved and traced to %.1e mm", r.et);
}

/* ---- stiff and refused cases ------------------------------------------------ */
static void stiff(void)
{
    rg_geometry g;
    rg->geometry_default(&g);
    rg_solution s;
    rg_target apex = {RG_T_ANGLES, 0, 0};
    /* p2 turned so the apex's backward ray meets it at 3 deg (warning), then 1 deg */
    for (int k = 0; k < 2; k++) {
        double ang = (k ? 1.0 : 3.0) * RT_DEG;
        rg_geometry q = g;
        double b[3] = {0, sin(20 * RT_DEG), -cos(20 * RT_DEG)};
        double v[3] = {0, b[1] * cos(ang) - b[2] * sin(ang), b[1] * sin(ang) + b[2] * cos(ang)};
        memcpy(q.p2_v, v, sizeof v);
        memcpy(q.p2_at, q.m2.center, sizeof v);
        int rc = rg->solve(&q, &apex, NULL, &s, err, sizeof err);
        if (!k) {
            scan_res r = {0};
            r.it_min = 1e9;
            if (!rc) check_solution(&q, &s, &r);
            CHECK(rc == RG_OK && (s.diag & RG_D_NEAR_PARALLEL) && r.miss == 0 && r.et < 1e-9 &&
                  r.ed < 1e-9 && fabs(s.p2_angle - ang) < 1e-9,
                  "backward ray 3 deg from p2: solved exactly (%.1e mm), warned (rc %d diag %#x "
                  "angle %.3f: %s)", r.et, rc, s.diag, s.p2_angle / RT_DEG, err);
        } else
            CHECK(rc == RG_EUNREACH && (s.diag & RG_D_PARALLEL_P2) && strstr(err, "parallel"),
                  "backward ray 1 deg from p2 refused: %s", err);
    }
    /* a target whose tangent plane faces away from the detector */
    rg_geometry nz = g;
    nz.cornea.zone = 0;
    rg_target far = {RG_T_ANGLES, 65 * RT_DEG, RT_PI / 2};
    int rc = rg->solve(&nz, &far, NULL, &s, err, sizeof err);
    CHECK(rc == RG_EUNREACH && (s.diag & RG_D_GRAZING) && strstr(err, "on the cornea 82.7"),
          "grazing target (theta 65 deg, 83 deg incidence) refused, incidence stated: %s", err);
    far.a = 75 * RT_DEG;
    rc = rg->solve(&nz, &far, NULL, &s, err, sizeof err);
    CHECK(rc == RG_EUNREACH && (s.diag & RG_D_DETECTOR_SIDE),
          "target whose tangent plane hides the detector (theta 75 deg) refused: %s", err);
    far.a = 55 * RT_DEG;
    rc = rg->solve(&nz, &far, NULL, &s, err, sizeof err);
    CHECK(rc == RG_EUNREACH && (s.diag & RG_D_BEHIND_P2),
          "target whose backward ray leaves p2 behind (theta 55 deg) refused: %s", err);
    /* grazing at a mirror: the example's ~45.7 deg folds against a 40 deg limit */
    rg_solve_opts lim = {0};
    lim.max_incidence = 40 * RT_DEG;
    rg_target ap0 = {RG_T_ANGLES, 0, 0};
    rc = rg->solve(&g, &ap0, &lim, &s, err, sizeof err);
    CHECK(rc == RG_EUNREACH && (s.diag & RG_D_GRAZING) && strstr(err, "incidence m1 45.") &&
          fabs(s.beam.inc1 / RT_DEG - 45.66) < 0.05,
          "mirror incidence over the limit refused with the angles: %s", err);
    /* grazing at the cornea just inside the limit is still exact */
    rg_geometry wide = g;
    for (int j = 0; j < RG_NJOINTS; j++) wide.joint[j].lo = wide.joint[j].hi = 0;
    wide.cornea.zone = 0;
    rg_solve_opts o = {0};
    o.max_incidence = 89.9 * RT_DEG;
    int ok = 0;
    double worst = 0, inc = 0;
    for (double th = 30; th < 52; th += 1) {
        rg_target t = {RG_T_ANGLES, th * RT_DEG, -RT_PI / 2};
        if (rg->solve(&wide, &t, &o, &s, err, sizeof err)) continue;
        rg_verify v;
        if (rg->verify(tr, &wide, &s.pose, s.target, &v, err, sizeof err) || !v.hit) continue;
        ok++;
        worst = fmax(worst, fmax(v.err_target, v.err_detector));
        inc = fmax(inc, s.beam.inc3);
    }
    CHECK(ok >= 5 && worst < 1e-9, "steep targets toward the detector side (%d, cornea "
          "incidence up to %.1f deg): exact to %.1e mm", ok, inc / RT_DEG, worst);
    /* the normal points at the detector: m2 sits on the detector ray */
    rg_geometry sp = wide;
    cornea_set(&sp.cornea, RG_SPHERE);
    double w[3] = {sp.detector[0], sp.detector[1], sp.detector[2] - sp.cornea.R};
    rt_unit(w);
    rg_target block = {RG_T_ANGLES, acos(-w[2]), atan2(w[1], w[0])};
    rc = rg->solve(&sp, &block, NULL, &s, err, sizeof err);
    CHECK(rc == RG_EUNREACH && (s.diag & RG_D_M2_BLOCKS) && strstr(err, "m2"),
          "normal pointing at the detector: m2 blocks the detector ray: %s", err);
    rg_target up = {RG_T_ANGLES, 20 * RT_DEG, RT_PI / 2};
    rc = rg->solve(&wide, &up, NULL, &s, err, sizeof err);
    CHECK(rc == RG_EUNREACH && (s.diag & RG_D_M1_BLOCKS),
          "theta 20 deg toward m1: m1 blocks the beam to the cornea: %s", err);
    /* decentred, tilted eye at the edge of travel */
    rg_geometry e = g;
    double at[3] = {0.8, 0.6, -0.5};
    rg->eye_pose(&e.cornea, 5 * RT_DEG, 4 * RT_DEG, 0, at);
    rg_target t = {RG_T_ANGLES, 9 * RT_DEG, 0.3};
    rc = rg->solve(&e, &t, NULL, &s, err, sizeof err);
    int jmax = 0;
    for (int j = 0; j < RG_NJOINTS; j++)
        if (fabs(s.pose.j[j]) / e.joint[j].hi > fabs(s.pose.j[jmax]) / e.joint[jmax].hi) jmax = j;
    double need = s.pose.j[jmax];
    rg_geometry in = e, out = e;
    if (need > 0) { in.joint[jmax].hi = need + 1e-9; out.joint[jmax].hi = need - 1e-6; }
    else { in.joint[jmax].lo = need - 1e-9; out.joint[jmax].lo = need + 1e-6; }
    rg_solution s2;
    int r_in = rg->solve(&in, &t, NULL, &s2, err, sizeof err);
    scan_res r = {0};
    r.it_min = 1e9;
    if (!r_in) check_solution(&in, &s2, &r);
    int r_out = rg->solve(&out, &t, NULL, &s2, err, sizeof err);
    CHECK(rc == 0 && r_in == 0 && r.miss == 0 && r.et < 1e-9 && r.ed < 1e-9 &&
          r_out == RG_ETRAVEL && s2.diag == RG_D_TRAVEL,
          "decentred tilted eye, joint %s at the end of its travel: exact (%.1e mm); 1e-6 past "
          "it refused (%d %d %d %#x: %s)", rg->joint_name(jmax), r.et, rc, r_in, r_out, s2.diag, err);
    /* conditioning: the Jacobian predicts the spot's moves; a small limit warns */
    rg_target mid = {RG_T_ANGLES, 6 * RT_DEG, 1.0};
    rg->solve(&g, &mid, NULL, &s, err, sizeof err);
    double J[4 * RG_NJOINTS], cond, lin = 0;
    rg->jacobian(&g, &s.pose, J, &cond, err, sizeof err);
    for (int j = 0; j < RG_NJOINTS; j++) {
        rg_pose p = s.pose;
        double h = 1e-5;
        p.j[j] += h;
        rg_beam b;
        rg->forward(&g, &p, &b, err, sizeof err);
        double mv = rt_dist(b.spot, s.beam.spot);
        double pr = hypot(J[0 * RG_NJOINTS + j], J[1 * RG_NJOINTS + j]) * h;
        lin = fmax(lin, fabs(mv - pr) / fmax(mv, 1e-12));
    }
    o.max_incidence = 0;
    o.cond_max = cond / 2;
    rc = rg->solve(&g, &mid, &o, &s, err, sizeof err);
    CHECK(lin < 1e-3 && cond >= 1 && rc == RG_OK && (s.diag & RG_D_ILLCOND) &&
          strstr(err, "condition number"),
          "Jacobian predicts spot moves to %.1e; condition number %.3g stated when over the "
          "limit: %s", lin, cond, err);
}

/* ---- the Jacobian and its condition number, independently -------------------- */
/* Eigenvalues of a symmetric 4x4 by cyclic Jacobi rotations. */
static void jacobi4(double A[4][4], double ev[4])
{
    for (int sweep = 0; sweep < 60; sweep++)
        for (int p = 0; p < 4; p++)
            for (int q = p + 1; q < 4; q++) {
                if (fabs(A[p][q]) < 1e-300) continue;
                double th = 0.5 * atan2(2 * A[p][q], A[q][q] - A[p][p]);
                double c = cos(th), s = sin(th);
                for (int k = 0; k < 4; k++) {       /* A = G^T A G */
                    double a = A[k][p], b = A[k][q];
                    A[k][p] = c * a - s * b;
                    A[k][q] = s * a + c * b;
                }
                for (int k = 0; k < 4; k++) {
                    double a = A[p][k], b = A[q][k];
                    A[p][k] = c * a - s * b;
                    A[q][k] = s * a + c * b;
                }
            }
    for (int i = 0; i < 4; i++) ev[i] = A[i][i];
}

static void jacobian_indep(void)
{
    rg_geometry g;
    rg->geometry_default(&g);
    rg_target t = {RG_T_ANGLES, 8 * RT_DEG, 2.2};
    rg_solution s;
    rg->solve(&g, &t, NULL, &s, err, sizeof err);
    double J[4 * RG_NJOINTS], cond;
    rg->jacobian(&g, &s.pose, J, &cond, err, sizeof err);
    /* the test's own spot coordinates: tangent plane at the spot, detector plane
     * normal along apex -> detector */
    rt_path b0;
    rt_forward(&g, &s.pose, &b0);
    double nn[3] = {b0.nc[0], b0.nc[1], b0.nc[2]}, w[3] = {g.detector[0] - g.cornea.trans[0],
                    g.detector[1] - g.cornea.trans[1], g.detector[2] - g.cornea.trans[2]};
    rt_unit(w);
    double worst = 0;
    for (int k = 0; k < RG_NJOINTS; k++) {
        double h = 1e-4, pt[2][2];     /* spot moves for +h and -h */
        for (int sgn = 0; sgn < 2; sgn++) {
            rg_pose p = s.pose;
            p.j[k] += sgn ? -h : h;
            rt_path b;
            rt_forward(&g, &p, &b);
            /* detector hit: the reflected line meets the detector plane */
            double r[3] = {g.detector[0] - b.spot[0], g.detector[1] - b.spot[1], g.detector[2] - b.spot[2]};
            double tt = rt_dot(r, w) / rt_dot(b.d3, w), det[3];
            for (int i = 0; i < 3; i++) det[i] = b.spot[i] + tt * b.d3[i];
            double ds[3] = {b.spot[0] - b0.spot[0], b.spot[1] - b0.spot[1], b.spot[2] - b0.spot[2]};
            double dd[3] = {det[0] - g.detector[0], det[1] - g.detector[1], det[2] - g.detector[2]};
            /* compare through norms in each plane: bases may differ by a rotation */
            double ps = rt_dot(ds, nn);
            pt[sgn][0] = sqrt(fmax(0, rt_dot(ds, ds) - ps * ps));
            pt[sgn][1] = sqrt(rt_dot(dd, dd));
        }
        double eng_s = hypot(J[0 * RG_NJOINTS + k], J[1 * RG_NJOINTS + k]);
        double eng_d = hypot(J[2 * RG_NJOINTS + k], J[3 * RG_NJOINTS + k]);
        double ind_s = 0.5 * (pt[0][0] + pt[1][0]) / h, ind_d = 0.5 * (pt[0][1] + pt[1][1]) / h;
        worst = fmax(worst, fmax(fabs(eng_s - ind_s) / ind_s, fabs(eng_d - ind_d) / ind_d));
    }
    /* condition number from the engine's J, scaled by one step, by Jacobi on J J^T */
    double A[4][4] = {{0}}, ev[4];
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            for (int k = 0; k < RG_NJOINTS; k++) {
                double sc = 1 / g.joint[k].steps_per;
                A[r][c] += J[r * RG_NJOINTS + k] * J[c * RG_NJOINTS + k] * sc * sc;
            }
    jacobi4(A, ev);
    double lmax = 0, lmin = INFINITY;
    for (int i = 0; i < 4; i++) { lmax = fmax(lmax, ev[i]); lmin = fmin(lmin, ev[i]); }
    double cind = sqrt(lmax / lmin);
    CHECK(worst < 1e-3 && fabs(cind - cond) < 1e-6 * cond,
          "Jacobian columns (spot speed on the cornea and the detector per joint) agree with "
          "the independent model to %.1e; condition number %.6g = Jacobi on J J^T %.6g",
          worst, cond, cind);
}

/* ---- quantisation ----------------------------------------------------------- */
static double quant_max(rg_geometry g, double spd, double spmm, double *ed, double *res,
                        int *ongrid, double *trace_agree)
{
    for (int j = 0; j < RG_NJOINTS; j++)
        g.joint[j].steps_per = (j == RG_J_U || j == RG_J_V) ? spmm : spd / RT_DEG;
    double ec = 0;
    *ed = *res = *trace_agree = 0;
    *ongrid = 1;
    for (int i = 0; i < 60; i++) {
        rg_target t = rt_scan(i, 60, 10 * RT_DEG);
        rg_solution s;
        rg_quantised q;
        if (rg->solve(&g, &t, NULL, &s, err, sizeof err) ||
            rg->quantise(&g, &t, &s, &q, err, sizeof err)) { ec = INFINITY; continue; }
        ec = fmax(ec, q.err_cornea);
        *ed = fmax(*ed, q.err_detector);
        *res = fmax(*res, q.err_cornea_resolved);
        for (int j = 0; j < RG_NJOINTS; j++)
            if (g.joint[j].steps_per > 0 &&
                fabs(q.pose.j[j] * g.joint[j].steps_per - (double)q.steps[j]) > 1e-6)
                *ongrid = 0;
        rg_verify v;
        if (i % 10 == 0) {
            if (rg->verify(tr, &g, &q.pose, s.target, &v, err, sizeof err) || !v.hit) *trace_agree = INFINITY;
            else *trace_agree = fmax(*trace_agree, fmax(fabs(v.err_target - q.err_cornea),
                                                         fabs(v.err_detector - q.err_detector)));
        }
    }
    return ec;
}

static void quantisation_eyes(void)
{
    /* biconic, tilted and decentred eye: quantised poses traced land where the model says */
    rg_geometry g;
    rg->geometry_default(&g);
    cornea_set(&g.cornea, RG_BICONIC);
    double at[3] = {-0.4, 0.3, 0.2};
    rg->eye_pose(&g.cornea, -3 * RT_DEG, 2 * RT_DEG, 40 * RT_DEG, at);
    int n = 0, bad = 0;
    double worst = 0, agree = 0;
    for (int i = 0; i < 40; i++) {
        rg_target t = rt_scan(i, 40, 8 * RT_DEG);
        rg_solution s;
        rg_quantised q;
        rg_verify v;
        rt_path p;
        if (rg->solve(&g, &t, NULL, &s, err, sizeof err) ||
            rg->quantise(&g, &t, &s, &q, err, sizeof err) || rt_forward(&g, &q.pose, &p)) {
            bad++;
            continue;
        }
        n++;
        worst = fmax(worst, q.err_cornea);
        agree = fmax(agree, rt_dist(p.spot, q.beam.spot));
        if (!rg->verify(tr, &g, &q.pose, s.target, &v, err, sizeof err) && v.hit)
            agree = fmax(agree, fmax(fabs(v.err_target - q.err_cornea),
                                     fabs(v.err_detector - q.err_detector)));
        else
            bad++;
    }
    CHECK(bad == 0 && n == 40 && worst < 2 * (RT_DEG / 200) * 80 * 2 && agree < 1e-9,
          "biconic, tilted decentred eye: 40 quantised poses land within %.2f um, the "
          "independent model and the tracer agree on the landing errors to %.1e mm", worst * 1e3, agree);
}

static void quantisation(void)
{
    rg_geometry g;
    rg->geometry_default(&g);
    double ed, res, ta, ed2, res2, ta2, ed0, res0, ta0;
    int on, on2, on0;
    double ec = quant_max(g, 200, 400, &ed, &res, &on, &ta);
    double ec2 = quant_max(g, 2000, 4000, &ed2, &res2, &on2, &ta2);
    double ec0 = quant_max(g, 0, 0, &ed0, &res0, &on0, &ta0);
    /* one angle step moves the beam leaving m2 by 2 * step * ~70 mm */
    double bound = 2 * (RT_DEG / 200) * 80 * 2;
    CHECK(on && on2 && ec > 0 && ec < bound && res < 1e-9 && res2 < 1e-9,
          "quantised poses on the step grid; stage-only error absorbed by the angles "
          "(%.1e mm); 200 steps/deg: cornea %.2f um (bound %.1f), detector %.1f um",
          res, ec * 1e3, bound * 1e3, ed * 1e3);
    CHECK(ec2 < ec / 4 && ec2 > ec / 40 && ed2 < ed / 4,
          "10x finer steps: cornea error %.3f um (%.1fx smaller), detector %.2f um",
          ec2 * 1e3, ec / ec2, ed2 * 1e3);
    CHECK(ec0 < 1e-9 && ed0 < 1e-9, "continuous joints: no landing error (%.1e, %.1e mm)",
          ec0, ed0);
    CHECK(ta < 1e-9 && ta2 < 1e-9, "the tracer lands quantised poses where the forward "
          "model says (%.1e mm)", fmax(ta, ta2));
}

/* ---- rig-file keys ---------------------------------------------------------- */
static int key(rg_geometry *g, const char *line)
{
    char buf[512], *w[16];
    int n = 0;
    snprintf(buf, sizeof buf, "%s", line);
    for (char *t = strtok(buf, " "); t && n < 16; t = strtok(NULL, " ")) w[n++] = t;
    return rg->geometry_key(g, n, (const char *const *)w, err, sizeof err);
}

static void keys(void)
{
    rg_geometry d, g;
    rg->geometry_default(&d);
    rg->geometry_check(&d, err, sizeof err);
    memset(&g, 0, sizeof g);
    char line[512];
    int bad = 0;
#define V3(k, v) snprintf(line, sizeof line, "%s %.17g %.17g %.17g", k, v[0], v[1], v[2]); bad += key(&g, line) != 0
#define S1(k, v) snprintf(line, sizeof line, "%s %.17g", k, v); bad += key(&g, line) != 0
    V3("laser_at", d.laser_at); V3("laser_dir", d.laser_dir);
    V3("p2_at", d.p2_at); V3("p2_u", d.p2_u); V3("p2_v", d.p2_v); V3("detector", d.detector);
    const rg_gimbal *m[2] = {&d.m1, &d.m2};
    for (int i = 0; i < 2; i++) {
        char k[40];
        snprintf(k, sizeof k, "m%d_center", i + 1); V3(k, m[i]->center);
        snprintf(k, sizeof k, "m%d_axis1", i + 1); V3(k, m[i]->axis1);
        snprintf(k, sizeof k, "m%d_axis2", i + 1); V3(k, m[i]->axis2);
        snprintf(k, sizeof k, "m%d_normal", i + 1); V3(k, m[i]->normal0);
        snprintf(k, sizeof k, "m%d_offset", i + 1); S1(k, m[i]->offset);
        snprintf(k, sizeof k, "m%d_radius", i + 1); S1(k, m[i]->radius);
        snprintf(k, sizeof k, "m%d_mount_radius", i + 1); S1(k, m[i]->mount_radius);
        snprintf(k, sizeof k, "m%d_mount_depth", i + 1); S1(k, m[i]->mount_depth);
    }
    bad += key(&g, "cornea conic") != 0;
    S1("cornea_R", d.cornea.R); S1("cornea_Q", d.cornea.Q); S1("cornea_R2", d.cornea.R2);
    S1("cornea_zone", d.cornea.zone);
    bad += key(&g, "eye_rot 0 0 0") != 0;
    bad += key(&g, "eye_at 0 0 0") != 0;
    for (int j = 0; j < RG_NJOINTS; j++) {
        int st = j == RG_J_U || j == RG_J_V;
        double u = st ? 1 : RT_DEG;
        snprintf(line, sizeof line, "joint %s %.17g %.17g %.17g", rg->joint_name(j),
                 d.joint[j].steps_per * u, d.joint[j].lo / u, d.joint[j].hi / u);
        bad += key(&g, line) != 0;
    }
    int ck = rg->geometry_check(&g, err, sizeof err);
    const double *a = (const double *)&g, *b = (const double *)&d;
    double diff = 0;
    /* compare field by field through the solutions they give */
    rg_target t = {RG_T_ANGLES, 7 * RT_DEG, 2.0};
    rg_solution s1, s2;
    rg->solve(&g, &t, NULL, &s1, err, sizeof err);
    rg->solve(&d, &t, NULL, &s2, err, sizeof err);
    for (int j = 0; j < RG_NJOINTS; j++) diff = fmax(diff, fabs(s1.pose.j[j] - s2.pose.j[j]));
    (void)a; (void)b;
    CHECK(bad == 0 && ck == 0 && diff < 1e-12 && fabs(g.joint[RG_J_M1A].steps_per - d.joint[RG_J_M1A].steps_per) < 1e-9,
          "the example geometry written as rig-file keys reads back to the same solutions "
          "(%.1e)", diff);
    /* bad values and keys that are not the geometry's */
    static const char *badl[] = {"laser_at 1 2", "laser_at 1 2 x", "m1_radius -1",
                                 "cornea ellipse", "cornea_R 0", "joint m3a 1 2 3",
                                 "joint u 1 5 2", "cornea_asph 1 2 3 4 5 6 7 8",
                                 "cornea_R nan", "detector 1 2 inf"};
    int refused = 0;
    for (size_t i = 0; i < sizeof badl / sizeof *badl; i++)
        if (key(&g, badl[i]) == RG_EINVAL && err[0]) refused++;
    CHECK(refused == (int)(sizeof badl / sizeof *badl), "%d bad geometry lines refused "
          "with a message (last: %s)", refused, err);
    CHECK(key(&g, "axis m1a") == 1 && key(&g, "laser 24") == 1 && key(&g, "chip gpiochip0") == 1,
          "machine keys are left to the machine's reader");
    key(&g, "eye_rot 90 0 0");
    CHECK(fabs(g.cornea.rot[7] - 1) < 1e-15 && fabs(g.cornea.rot[5] + 1) < 1e-15,
          "eye_rot 90 0 0 turns the eye's axis (+z) onto -y... rot = Rx(90)");
    rg_geometry c = d;
    c.m2.center[2] += 0.1;
    int r1 = rg->geometry_check(&c, err, sizeof err);
    c = d;
    c.m1.center[1] += 0.1;
    int r2 = rg->geometry_check(&c, err, sizeof err);
    c = d;
    memcpy(c.m1.axis2, c.m1.axis1, sizeof c.m1.axis1);
    int r3 = rg->geometry_check(&c, err, sizeof err);
    c = d;
    memset(c.p2_u, 0, sizeof c.p2_u);
    int r4 = rg->geometry_check(&c, err, sizeof err);
    CHECK(r1 && r2 && r3 && r4, "inconsistent geometries refused: m2 off p2, m1 off the "
          "beam, parallel axes, zero vector (%s)", err);
}

/* ---- pure functions: two threads get the same poses as one ------------------ */
typedef struct th_job { rg_geometry g; rg_pose pose[200]; int rc[200]; } th_job;
static void *th_run(void *arg)
{
    th_job *j = arg;
    char e[512];
    for (int i = 0; i < 200; i++) {
        rg_target t = rt_scan(i, 200, 14 * RT_DEG);
        rg_solution s;
        rg_quantised q;
        j->rc[i] = rg->solve(&j->g, &t, NULL, &s, e, sizeof e);
        if (!j->rc[i]) j->rc[i] = rg->quantise(&j->g, &t, &s, &q, e, sizeof e);
        j->pose[i] = j->rc[i] ? s.pose : q.pose;
    }
    return NULL;
}
static void threads(void)
{
    static th_job a, b, c;
    rg->geometry_default(&a.g);
    b.g = c.g = a.g;
    th_run(&c);
    pthread_t t1, t2;
    pthread_create(&t1, NULL, th_run, &a);
    pthread_create(&t2, NULL, th_run, &b);
    pthread_join(t1, NULL);
    pthread_join(t2, NULL);
    int same = 1, fails = 0;
    for (int i = 0; i < 200; i++) {
        same &= a.rc[i] == c.rc[i] && b.rc[i] == c.rc[i] &&
                !memcmp(&a.pose[i], &c.pose[i], sizeof c.pose[i]) &&
                !memcmp(&b.pose[i], &c.pose[i], sizeof c.pose[i]);
        fails += c.rc[i] != 0;
    }
    CHECK(same && fails > 0 && fails < 200, "two threads solving and quantising at once "
          "get the same bits as one (200 targets, %d refused)", fails);
}

int main(void)
{
    rg = rt_rig();
    tr = rt_trace();
    CHECK(rig_get_api(RIG_ABI + 1) == NULL && !strcmp(rg->joint_name(RG_J_M2B), "m2b") &&
          rg->joint_name(RG_NJOINTS) == NULL, "ABI check and joint names");
    char b[512];
    CHECK(strstr(rg->diag_text(RG_D_M2_BLOCKS | RG_D_TRAVEL, b, sizeof b), "travel") != NULL,
          "diagnostics named: %s", b);
    cornea_models();
    gimbals();
    solutions();
    stiff();
    jacobian_indep();
    quantisation();
    quantisation_eyes();
    threads();
    keys();
    return unit_failed();
}
