/* t_physics.c -- the trace engine's optics against independent formulas: vector
 * Snell at every angle (grazing and TIR included), Fresnel R + T = 1, Brewster,
 * normal incidence, the textbook sin/tan forms; s and p powers carried separately
 * (glass sphere: the split itself, against a path-by-path calculation; two tilted
 * faces: against Jones calculus); mirrors, depth limit, cutoff, Gaussian beam
 * envelope; energy balance in every scene. */
#include <stdio.h>
#include "unit.h"
#include "tt.h"

static const trace_api *tr;

static int balance_ok(const trace_summary *s)
{
    double e = s->detected + s->absorbed + s->escaped + s->cutoff;
    return s->emitted > 0 && fabs(e - s->emitted) <= 1e-9 * s->emitted;
}

static void snell(void)
{
    const double pairs[][2] = {{1, 1.5}, {1.5, 1}, {1, 2.42}, {1.333, 1}, {1.7, 1.69}};
    int bad = 0, badtir = 0, n = 0;
    double worst = 0;
    for (size_t k = 0; k < sizeof pairs / sizeof pairs[0]; k++) {
        double n1 = pairs[k][0], n2 = pairs[k][1];
        for (int i = 0; i <= 9000; i++) {
            double th = (i == 9000 ? 90.0 : i * 0.01) * 3.14159265358979323846 / 180;
            double d[3] = {sin(th), 0, cos(th)}, nrm[3] = {0, 0, -1}, out[3];
            /* rotate the setup off the coordinate planes */
            double a = 0.3, d2[3] = {d[0] * cos(a) - d[1] * sin(a),
                                     d[0] * sin(a) + d[1] * cos(a), d[2]};
            int ok = tr->refract(d2, nrm, n1, n2, out);
            double si = n1 * sin(th);
            n++;
            if (si > n2) {                          /* TIR expected */
                if (ok || fabs(out[2] + d2[2]) > 1e-15 || fabs(out[0] - d2[0]) > 1e-15)
                    badtir++;
                continue;
            }
            if (!ok) { bad++; continue; }
            double st = hypot(out[0], out[1]);      /* sine of the refraction angle */
            double e = fabs(n2 * st - si);
            double len = sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
            /* coplanar: out in the plane of d and the normal */
            double cop = fabs(out[0] * d2[1] - out[1] * d2[0]);
            if (e > worst) worst = e;
            if (e > 1e-14 || fabs(len - 1) > 1e-15 || cop > 1e-15 || out[2] < 0) bad++;
        }
    }
    CHECK(bad == 0 && badtir == 0, "Snell: %d directions, n1 sin1 = n2 sin2 to %.1e, "
          "unit, coplanar; TIR as a mirror (%d bad, %d bad TIR)", n, worst, bad, badtir);
    /* grazing incidence into denser glass: refracted at the critical angle */
    double d[3] = {1, 0, 0}, nrm[3] = {0, 0, 1}, out[3];
    int ok = tr->refract(d, nrm, 1.0, 1.5, out);
    CHECK(ok && fabs(hypot(out[0], out[1]) - 1 / 1.5) < 1e-15,
          "grazing incidence refracts at the critical angle (sin %.17g)", out[0]);
}

static void fresnel(void)
{
    const double pairs[][2] = {{1, 1.5}, {1.5, 1}, {1, 3.5}, {1.333, 1.5}};
    int bad = 0;
    double worst = 0, wsin = 0;
    for (size_t k = 0; k < 4; k++) {
        double n1 = pairs[k][0], n2 = pairs[k][1];
        for (int i = 0; i <= 900; i++) {
            double th = i * 0.1 * 3.14159265358979323846 / 180;
            trace_fresnel_coef f;
            tr->fresnel(n1, n2, cos(th), &f);
            double s1 = n1 * sin(th) / n2;
            if (s1 >= 1) {
                if (!f.tir || f.Rs != 1 || f.Rp != 1 || f.Ts != 0) bad++;
                continue;
            }
            double e = fmax(fabs(f.Rs + f.Ts - 1), fabs(f.Rp + f.Tp - 1));
            if (e > worst) worst = e;
            if (e > 1e-14) bad++;
            if (i > 0 && i < 900) {                  /* sin / tan forms */
                double tt = asin(s1), a = th - tt, b = th + tt;
                double rs = sin(a) * sin(a) / (sin(b) * sin(b));
                double rp = tan(a) * tan(a) / (tan(b) * tan(b));
                double ts = sin(2 * th) * sin(2 * tt) / (sin(b) * sin(b));
                double e2 = fmax(fmax(fabs(rs - f.Rs), fabs(rp - f.Rp)), fabs(ts - f.Ts));
                if (e2 > wsin) wsin = e2;
                if (e2 > 1e-12) bad++;
            }
        }
    }
    CHECK(bad == 0, "Fresnel: Rs+Ts = Rp+Tp = 1 to %.1e; matches the sin/tan forms to "
          "%.1e; TIR gives R = 1", worst, wsin);
    trace_fresnel_coef f;
    double nb = atan(1.5);
    tr->fresnel(1.0, 1.5, cos(nb), &f);
    CHECK(f.Rp < 1e-30 && f.Rs > 0.14, "Brewster angle: Rp = %.2e, Rs = %.4f", f.Rp, f.Rs);
    tr->fresnel(1.5, 1.0, cos(atan(1 / 1.5)), &f);
    CHECK(f.Rp < 1e-30, "internal Brewster angle: Rp = %.2e", f.Rp);
    tr->fresnel(1.0, 1.5, 1.0, &f);
    double r0 = (1 - 1.5) / (1 + 1.5);
    CHECK(fabs(f.Rs - r0 * r0) < 1e-16 && fabs(f.Rp - r0 * r0) < 1e-16,
          "normal incidence: Rs = Rp = %.17g = ((n1-n2)/(n1+n2))^2", f.Rs);
    tr->fresnel(1.5, 1.0, cos(0.9), &f);        /* sin 0.9 * 1.5 > 1 */
    double kap = sqrt(1.5 * 1.5 * sin(0.9) * sin(0.9) - 1);
    CHECK(f.tir && fabs(f.rs_phase + 2 * atan2(kap, 1.5 * cos(0.9))) < 1e-14,
          "TIR phase of s: %.15g", f.rs_phase);
}

/* ---- scenes ---- */
typedef struct hits { trace_hit h[512]; int n; } hits;
static int keep(void *ctx, const trace_hit *h)
{
    hits *x = ctx;
    if (x->n < 512) x->h[x->n++] = *h;
    return 0;
}

static trace_scene *one_ray(const double o[3], const double d[3], int pol,
                            const double e[3], double n_medium)
{
    trace_scene *sc = tr->scene_new();
    trace_ray r = {{o[0], o[1], o[2]}, {d[0], d[1], d[2]}, 1};
    trace_source s = {0};
    s.type = TRACE_SRC_RAYS; s.count = 1; s.ray = &r; s.pol = pol; s.n_medium = n_medium;
    if (e) memcpy(s.pol_dir, e, sizeof s.pol_dir);
    tr->add_source(sc, &s, NULL);
    return sc;
}

static void add_sphere(trace_scene *sc, double r, int kind, double nin)
{
    trace_surface s = {0};
    trace_material m = {kind, 1.0, nin};
    s.shape = TRACE_SPHERE;
    s.radius = r;
    tr->add_surface(sc, &s, &m);
}

/* Glass sphere, one ray at impact parameter b: each emergent path against
 * 1/2 prod Ts and 1/2 prod Tp (the plane of incidence never changes on a sphere). */
static void sphere_split(void)
{
    const double n = 1.5, b = 0.8, phi = 0.7;
    double o[3] = {b * cos(phi), b * sin(phi), -5}, d[3] = {0, 0, 1};
    trace_scene *sc = one_ray(o, d, TRACE_UNPOLARISED, NULL, 1);
    add_sphere(sc, 1, TRACE_REFRACT, n);
    add_sphere(sc, 10, TRACE_DETECT, 1.0);
    trace_options op;
    tr->options_default(&op);
    op.cutoff = 1e-12;
    op.max_depth = 30;
    static hits hs;
    hs.n = 0;
    trace_sink sink = {&hs, NULL, keep, NULL};
    trace_summary sum;
    int rc = tr->run(sc, &op, &sink, &sum);
    CHECK(rc == 0 && balance_ok(&sum), "glass sphere: energy balance (%llu hits)",
          (unsigned long long)sum.hits);
    /* the independent calculation */
    double ci = sqrt(1 - b * b), st = b / n, ct = sqrt(1 - st * st);
    double rs = (ci - n * ct) / (ci + n * ct), rp = (n * ci - ct) / (n * ci + ct);
    double Rs = rs * rs, Rp = rp * rp, Ts = 1 - Rs, Tp = 1 - Rp;
    int checked = 0, bad = 0;
    double worst = 0, avg_err = 0;
    for (int i = 0; i < hs.n; i++) {
        const trace_hit *h = &hs.h[i];
        int k = h->depth;     /* interactions: k = 1 reflected outside, else k-2 inside */
        double es, ep;
        if (k == 1) { es = 0.5 * Rs; ep = 0.5 * Rp; }
        else { es = 0.5 * Ts * Ts * pow(Rs, k - 2); ep = 0.5 * Tp * Tp * pow(Rp, k - 2); }
        double avg = k == 1 ? 0.5 * (Rs + Rp) :
            pow(0.5 * (Ts + Tp), 2) * pow(0.5 * (Rs + Rp), k - 2);
        /* each component to 1e-12 of the path's power */
        double e = fmax(fabs(h->power_s - es), fabs(h->power_p - ep)) / (es + ep);
        if (e > worst) worst = e;
        if (e > 1e-12) bad++;
        if (k == 4) avg_err = fabs(avg - (es + ep)) / (es + ep);
        checked++;
    }
    CHECK(checked >= 5 && bad == 0, "glass sphere: s and p of %d emergent paths match "
          "1/2 prod Ts, 1/2 prod Tp to %.1e of each path's power", checked, worst);
    CHECK(avg_err > 0.2, "(averaging R,T per interface would be off by %.0f%% on the "
          "T R R T path: the test can tell)", 100 * avg_err);
    tr->scene_free(sc);
}

/* Jones calculus through two tilted faces of a glass block (planes of incidence not
 * parallel), linear polarisation at an arbitrary angle. */
static void jones_step(double E[3], double d[3], const double nrm[3], double n1,
                       double n2)
{
    double s[3], p1[3], p2[3], dt[3], m[3];
    double dn = d[0] * nrm[0] + d[1] * nrm[1] + d[2] * nrm[2];
    for (int i = 0; i < 3; i++) m[i] = dn > 0 ? -nrm[i] : nrm[i];
    double ci = fabs(dn);
    s[0] = d[1] * m[2] - d[2] * m[1]; s[1] = d[2] * m[0] - d[0] * m[2];
    s[2] = d[0] * m[1] - d[1] * m[0];
    double l = sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (int i = 0; i < 3; i++) s[i] /= l;
    double mu = n1 / n2, ct = sqrt(1 - mu * mu * (1 - ci * ci));
    for (int i = 0; i < 3; i++) dt[i] = mu * d[i] + (mu * ci - ct) * m[i];
    /* p = d x s before and after */
    p1[0] = d[1] * s[2] - d[2] * s[1]; p1[1] = d[2] * s[0] - d[0] * s[2];
    p1[2] = d[0] * s[1] - d[1] * s[0];
    p2[0] = dt[1] * s[2] - dt[2] * s[1]; p2[1] = dt[2] * s[0] - dt[0] * s[2];
    p2[2] = dt[0] * s[1] - dt[1] * s[0];
    double Es = E[0] * s[0] + E[1] * s[1] + E[2] * s[2];
    double Ep = E[0] * p1[0] + E[1] * p1[1] + E[2] * p1[2];
    double ts = 2 * n1 * ci / (n1 * ci + n2 * ct), tp = 2 * n1 * ci / (n2 * ci + n1 * ct);
    double k = sqrt(n2 * ct / (n1 * ci));        /* power flux factor */
    for (int i = 0; i < 3; i++) {
        E[i] = k * (ts * Es * s[i] + tp * Ep * p2[i]);
        d[i] = dt[i];
    }
}

static void two_faces(void)
{
    double n1 = 1.0, n2 = 1.6;
    double nA[3] = {0, sin(0.5), -cos(0.5)}, nB[3] = {sin(0.6), 0, cos(0.6)};
    double l = 0;
    trace_surface a = {0}, b = {0};
    a.shape = b.shape = TRACE_PLANE;
    a.aperture = b.aperture = TRACE_AP_DISC;
    a.r_outer = b.r_outer = 50;
    a.axis[0] = -nA[0]; a.axis[1] = -nA[1]; a.axis[2] = -nA[2];   /* front: -axis */
    b.at[2] = 5;
    b.axis[0] = nB[0]; b.axis[1] = nB[1]; b.axis[2] = nB[2];
    (void)l;
    double o[3] = {0.1, 0.2, -5}, d[3] = {0.15, -0.1, 1};
    double dl = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int i = 0; i < 3; i++) d[i] /= dl;
    double e0[3] = {cos(1.0), sin(1.0), 0};      /* E direction before projection */
    trace_scene *sc = one_ray(o, d, TRACE_LINEAR, e0, n1);
    trace_material ma = {TRACE_REFRACT, n1, n2}, mb = {TRACE_REFRACT, n2, n1};
    tr->add_surface(sc, &a, &ma);
    tr->add_surface(sc, &b, &mb);
    trace_surface det = {0};
    trace_material md = {TRACE_DETECT, 1, 1};
    det.shape = TRACE_PLANE; det.aperture = TRACE_AP_DISC; det.r_outer = 100;
    det.at[2] = 20; det.axis[2] = 1;
    tr->add_surface(sc, &det, &md);
    trace_options op;
    tr->options_default(&op);
    op.reflections = 0;
    static hits hs;
    hs.n = 0;
    trace_sink sink = {&hs, NULL, keep, NULL};
    trace_summary sum;
    tr->run(sc, &op, &sink, &sum);
    /* Jones */
    double E[3], dd[3] = {d[0], d[1], d[2]};
    double k = e0[0] * d[0] + e0[1] * d[1] + e0[2] * d[2];
    for (int i = 0; i < 3; i++) E[i] = e0[i] - k * d[i];
    double el = sqrt(E[0] * E[0] + E[1] * E[1] + E[2] * E[2]);
    for (int i = 0; i < 3; i++) E[i] /= el;
    jones_step(E, dd, nA, n1, n2);
    jones_step(E, dd, nB, n2, n1);
    double P = E[0] * E[0] + E[1] * E[1] + E[2] * E[2];
    CHECK(hs.n == 1 && fabs(hs.h[0].power_s + hs.h[0].power_p - P) < 1e-14,
          "two tilted faces: transmitted power %.15f, Jones %.15f",
          hs.n ? hs.h[0].power_s + hs.h[0].power_p : -1, P);
    if (hs.n == 1) {
        const trace_hit *h = &hs.h[0];
        double Es = E[0] * h->s_dir[0] + E[1] * h->s_dir[1] + E[2] * h->s_dir[2];
        CHECK(fabs(h->power_s - Es * Es) < 1e-14,
              "two tilted faces: power along the engine's s (%.15f) matches Jones "
              "(%.15f)", h->power_s, Es * Es);
        CHECK(fabs(hs.h[0].dir[0] - dd[0]) < 1e-15 && fabs(hs.h[0].dir[1] - dd[1]) < 1e-15,
              "two tilted faces: direction as the Jones trace's");
    }
    CHECK(balance_ok(&sum) && sum.cut_reflection == 2, "two faces: energy balance with "
          "reflections dropped as cut off");
    tr->scene_free(sc);
}

static void mirrors_and_limits(void)
{
    /* two parallel mirrors, a ray bouncing between them: stopped by the depth limit */
    double o[3] = {0, 0, 0}, d[3] = {0.1, 0, 1};
    trace_scene *sc = one_ray(o, d, TRACE_UNPOLARISED, NULL, 1);
    trace_surface m = {0};
    trace_material mm = {TRACE_MIRROR, 1, 1};
    m.shape = TRACE_PLANE; m.aperture = TRACE_AP_RECT; m.width = 1000; m.height = 10;
    m.up[1] = 1; m.axis[2] = 1; m.at[2] = 1;
    tr->add_surface(sc, &m, &mm);
    m.at[2] = -1;
    tr->add_surface(sc, &m, &mm);
    trace_options op;
    tr->options_default(&op);
    op.max_depth = 25;
    trace_summary sum;
    tr->run(sc, &op, NULL, &sum);
    CHECK(sum.cut_depth == 1 && sum.segments == 25 && balance_ok(&sum) &&
          sum.cutoff == sum.emitted, "mirror cavity: depth limit 25 stops the ray after "
          "25 segments (%llu), its power cut off", (unsigned long long)sum.segments);
    tr->scene_free(sc);

    /* glass plate, reflections followed, cutoff 1e-4: finite tree, balance holds */
    double o2[3] = {0, 0, -3}, d2[3] = {0.3, 0, 1};
    sc = one_ray(o2, d2, TRACE_UNPOLARISED, NULL, 1);
    trace_surface p = {0};
    trace_material g1 = {TRACE_REFRACT, 1, 1.5}, g2 = {TRACE_REFRACT, 1.5, 1};
    p.shape = TRACE_PLANE; p.aperture = TRACE_AP_DISC; p.r_outer = 100; p.axis[2] = 1;
    tr->add_surface(sc, &p, &g1);
    p.at[2] = 1;
    tr->add_surface(sc, &p, &g2);
    op.max_depth = 100;
    op.cutoff = 1e-4;
    tr->run(sc, &op, NULL, &sum);
    CHECK(sum.cut_power > 0 && sum.cut_depth == 0 && balance_ok(&sum) &&
          sum.escaped > 0.999 * sum.emitted,
          "glass plate: cutoff 1e-4 ends the ray tree (%llu segments, %llu cut), energy "
          "balance %.2e", (unsigned long long)sum.segments,
          (unsigned long long)sum.cut_power,
          (sum.detected + sum.absorbed + sum.escaped + sum.cutoff) / sum.emitted - 1);
    tr->scene_free(sc);
}

/* Gaussian beam: the skew rays lie on the hyperboloid w(z) = w0 sqrt(1 + (z/zR)^2). */
static void gaussian(void)
{
    trace_scene *sc = tr->scene_new();
    trace_source s = {0};
    double w0 = 0.5, lam = 632.8e-6, zr = 3.14159265358979323846 * w0 * w0 / lam;
    s.type = TRACE_SRC_GAUSSIAN; s.dir[2] = 1; s.waist = w0; s.wavelength = lam;
    s.rings = 6; s.power = 2;
    tr->add_source(sc, &s, NULL);
    trace_surface det = {0};
    trace_material md = {TRACE_DETECT, 1, 1};
    det.shape = TRACE_PLANE; det.aperture = TRACE_AP_DISC; det.r_outer = 100;
    det.at[2] = zr; det.axis[2] = 1;
    tr->add_surface(sc, &det, &md);
    static hits hs;
    hs.n = 0;
    trace_sink sink = {&hs, NULL, keep, NULL};
    trace_summary sum;
    tr->run(sc, NULL, &sink, &sum);
    int bad = 0;
    for (int i = 0; i < hs.n; i++) {
        long r = 0, j = hs.h[i].ray;
        while (j >= (r ? 6 * r : 1)) { j -= r ? 6 * r : 1; r++; }
        double rho = 2 * w0 * r / 6;                 /* trunc 2 w0, 6 rings */
        double rad = hypot(hs.h[i].pos[0], hs.h[i].pos[1]);
        if (fabs(rad - rho * sqrt(2)) > 1e-12) bad++;
    }
    CHECK(hs.n == 127 && bad == 0 && fabs(sum.detected - 2) < 1e-12,
          "Gaussian beam: %d skew rays at z = zR lie at sqrt(2) times their waist radius "
          "(%d off); power %.15g", hs.n, bad, sum.detected);
    tr->scene_free(sc);
}

int main(void)
{
    tr = tt_api();
    snell();
    fresnel();
    sphere_split();
    two_faces();
    mirrors_and_limits();
    gaussian();
    return unit_failed();
}
