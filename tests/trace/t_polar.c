/* t_polar.c -- polarization ray tracing (src/trace/tr_polar.c) against closed forms
 * written here, not taken from the engine: the Fresnel amplitudes rs rp ts tp (Hecht,
 * "Optics", eqs. 4.34, 4.40-4.42, complex cos t for TIR) read off a traced interface's
 * PRT matrix at 0-89 degrees both ways; the retardance of a traced Fresnel rhomb
 * (two TIRs at 54.6 degrees in n = 1.51: Born & Wolf, "Principles of Optics",
 * section 1.5.4, give 45 degrees a reflection for n = 1.51 at 48 deg 37' and 54 deg
 * 37'); Malus's law through two traced polarizers; a traced quarter-wave plate making
 * circular light (Stokes V = 1) and a half-wave plate turning 45 degrees to -45;
 * the proper retardance (frames carried by parallel transport) of two TIRs in one
 * plane and in crossed planes, whatever the Stokes reference and the path's azimuth;
 * a quarter-wave MgF2 coating's R ((n0 ns - n1^2)/(n0 ns + n1^2))^2 and R + T = 1
 * oblique; unpolarized scenes: the same powers with and without polarization; the
 * energy balance. */
#include <complex.h>
#include <stdio.h>
#include "unit.h"
#include "tt.h"

static const trace_api *tr;
#define PI 3.14159265358979323846

typedef struct rec { trace_hit h[64]; trace_polar_hit p[64]; int n, np; } rec;
static int keep_hit(void *ctx, const trace_hit *h)
{
    rec *x = ctx;
    if (x->n < 64) x->h[x->n++] = *h;
    return 0;
}
static int keep_pol(void *ctx, const trace_polar_hit *p)
{
    rec *x = ctx;
    if (x->np < 64) x->p[x->np++] = *p;
    return 0;
}

static void add_plane(trace_scene *sc, const double at[3], const double nrm[3], double r,
                      int kind, double n1, double n2)
{
    trace_surface s = {0};
    trace_material m = {kind, n1, n2};
    s.shape = TRACE_PLANE;
    memcpy(s.at, at, sizeof s.at);
    memcpy(s.axis, nrm, sizeof s.axis);
    s.r_outer = r;
    if (tr->add_surface(sc, &s, &m) < 0) printf("FAIL add_surface: %s\n", tr->error(sc));
}

static int add_rect(trace_scene *sc, const double at[3], const double nrm[3], double w,
                    double hgt, const double up[3], int kind, double n1, double n2)
{
    trace_surface s = {0};
    trace_material m = {kind, n1, n2};
    s.shape = TRACE_PLANE;
    s.aperture = TRACE_AP_RECT;
    memcpy(s.at, at, sizeof s.at);
    memcpy(s.axis, nrm, sizeof s.axis);
    memcpy(s.up, up, sizeof s.up);
    s.width = w;
    s.height = hgt;
    return tr->add_surface(sc, &s, &m);
}

static trace_scene *one_ray(const double o[3], const double d[3], const double *e, double n)
{
    trace_scene *sc = tr->scene_new();
    trace_ray r = {{o[0], o[1], o[2]}, {d[0], d[1], d[2]}, 1};
    trace_source s = {0};
    s.type = TRACE_SRC_RAYS;
    s.count = 1;
    s.ray = &r;
    s.n_medium = n;
    s.lambda = 0.55;
    if (e) { s.pol = TRACE_LINEAR; memcpy(s.pol_dir, e, sizeof s.pol_dir); }
    tr->add_source(sc, &s, NULL);
    return sc;
}

/* Trace with polarization on, the Stokes frame's reference xref (NULL: +x), records into x. */
static int run_ref(trace_scene *sc, rec *x, int reflections, const double xref[3],
                   trace_summary *sum)
{
    trace_options o;
    tr->options_default(&o);
    o.reflections = reflections;
    o.cutoff = 0;
    o.threads = 1;
    trace_sink k = {x, NULL, keep_hit, NULL};
    x->n = x->np = 0;
    if (tr->polarization(sc, 1, xref, keep_pol, x)) return -1;
    return tr->run(sc, &o, &k, sum);
}

static int run(trace_scene *sc, rec *x, int reflections, trace_summary *sum)
{
    return run_ref(sc, x, reflections, NULL, sum);
}

static int balance_ok(const trace_summary *s)
{
    double e = s->detected + s->absorbed + s->escaped + s->cutoff;
    return s->emitted > 0 && fabs(e - s->emitted) <= 1e-12 * s->emitted;
}

/* b^T P a of a record's PRT matrix */
static double complex pq(const trace_polar_hit *p, const double b[3], const double a[3])
{
    double complex v = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) v += b[i] * (p->prt[i][j][0] + I * p->prt[i][j][1]) * a[j];
    return v;
}

static void cross(const double a[3], const double b[3], double c[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* Hecht's amplitudes with cos t complex (Im > 0) under TIR */
static void hecht(double n1, double n2, double th, double complex a[4])
{
    double ci = cos(th), st = n1 / n2 * sin(th);
    double complex ct = st <= 1 ? csqrt(1 - st * st) : I * sqrt(st * st - 1);
    a[0] = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
    a[1] = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
    a[2] = 2 * n1 * ci / (n1 * ci + n2 * ct);
    a[3] = 2 * n1 * ci / (n2 * ci + n1 * ct);
}

/* One ray at angle th through the plane z = 0 (n1 below, n2 above), a detector sphere
 * around it: the transmitted and reflected rays' PRT amplitudes against hecht(). */
static double fresnel_one(double n1, double n2, double th, const trace_polar_surface *ps,
                          double *R, double *T)
{
    double o[3] = {-2 * sin(th), 0.1, -2 * cos(th)}, d[3] = {sin(th), 0, cos(th)};
    double z0[3] = {0, 0.1, 0}, nz[3] = {0, 0, 1};
    trace_scene *sc = one_ray(o, d, NULL, n1);
    add_plane(sc, z0, nz, 5, TRACE_REFRACT, n1, n2);
    if (ps) tr->set_polar(sc, 0, ps);
    trace_surface s = {0};
    trace_material m = {TRACE_DETECT, 1, 1};
    s.shape = TRACE_SPHERE;
    s.radius = 10;
    tr->add_surface(sc, &s, &m);
    static rec x;
    trace_summary sum;
    double worst = 1;
    if (run(sc, &x, 1, &sum) || x.n != x.np || !balance_ok(&sum)) goto out;
    double complex a[4];
    hecht(n1, n2, th, a);
    double sv[3] = {0, 1, 0}, pin[3], pt[3], pr[3];   /* s = k x n / |k x n| (sign free) */
    cross(d, sv, pin);
    worst = 0;
    *R = *T = 0;
    for (int i = 0; i < x.n; i++) {
        const double *k = x.h[i].dir;
        int refl = x.h[i].history & 1;
        cross(k, sv, refl ? pr : pt);
        double complex as = pq(&x.p[i], sv, sv), ap = pq(&x.p[i], refl ? pr : pt, pin);
        double e = fmax(cabs(as - a[refl ? 0 : 2]), cabs(ap - a[refl ? 1 : 3]));
        if (!ps && e > worst) worst = e;
        if (refl) *R = x.p[i].stokes[0]; else *T = x.p[i].stokes[0];
    }
    if (!ps && x.n != (n1 * sin(th) < n2 ? 2 : 1)) worst = 1;
out:
    tr->scene_free(sc);
    return worst;
}

static void fresnel(void)
{
    const double pairs[][2] = {{1, 1.5}, {1.5, 1}, {1, 2.42}, {1.333, 1}};
    double worst = 0, R, T;
    int n = 0;
    for (int k = 0; k < 4; k++)
        for (int i = 0; i < 90; i++, n++) {
            double e = fresnel_one(pairs[k][0], pairs[k][1], i * PI / 180, NULL, &R, &T);
            if (e > worst) worst = e;
        }
    CHECK(worst < 1e-14, "PRT of a traced interface: rs rp ts tp (TIR phases too) = Hecht's "
          "complex forms, 4 index pairs x 0..89 deg (%d rays): worst %.2e", n, worst);
    printf("BENCH wave_prt_fresnel_abs_err %.3g abs\n", worst);
}

/* A Fresnel rhomb: light enters a face normal to it, meets the long faces twice at
 * 54.6 degrees (TIR), leaves normally.  45-degree light in; retardance and Stokes out. */
static void rhomb(void)
{
    const double n = 1.51, th = 54.6 * PI / 180, h = 10, ta = tan(th);
    double d1[3] = {sin(th), 0, cos(th)}, a[3] = {0, 0, h / 2}, b[3] = {2 * h * ta, 0, h / 2};
    double o[3] = {a[0] - d1[0], 0, a[2] - d1[2]}, up[3] = {0, 1, 0}, nz[3] = {0, 0, 1};
    double top[3] = {h * ta, 0, h}, bot[3] = {h * ta, 0, 0};
    double e[3], s[3] = {0, 1, 0}, p[3];
    cross(d1, s, p);
    for (int i = 0; i < 3; i++) e[i] = (s[i] + p[i]) / sqrt(2);   /* 45 deg to the plane */
    trace_scene *sc = one_ray(o, d1, e, 1);
    add_plane(sc, a, d1, 1, TRACE_REFRACT, 1, n);
    add_rect(sc, top, nz, 2 * h * ta, 2 * h, up, TRACE_REFRACT, n, 1);
    add_rect(sc, bot, nz, 2 * h * ta, 2 * h, up, TRACE_REFRACT, 1, n);
    add_plane(sc, b, d1, 1, TRACE_REFRACT, n, 1);
    double det[3] = {b[0] + 5 * d1[0], 0, b[2] + 5 * d1[2]};
    add_plane(sc, det, d1, 5, TRACE_DETECT, 1, 1);
    static rec x;
    trace_summary sum;
    int rc = run(sc, &x, 0, &sum);
    /* the closed form: tan(delta/2) = cos th sqrt(sin^2 th - m^2) / sin^2 th, m = 1/n */
    double m = 1 / n, s2 = sin(th) * sin(th);
    double one = 2 * atan(cos(th) * sqrt(s2 - m * m) / s2) * 180 / PI;
    double got = rc == 0 && x.np == 1 ? x.p[0].retardance * 180 / PI : NAN;
    CHECK(rc == 0 && x.np == 1 && sum.tir == 2 && fabs(got - 2 * one) < 1e-10,
          "Fresnel rhomb (n 1.51, 54.6 deg): 2 TIRs, traced retardance %.12f deg = "
          "2 x the closed form %.12f", got, one);
    CHECK(fabs(got - 90) < 0.05, "... = Born & Wolf's 2 x 45 deg to %.4f deg", fabs(got - 90));
    double *S = x.p[0].stokes;
    CHECK(rc == 0 && fabs(fabs(S[3]) / S[0] - sin(2 * one * PI / 180)) < 1e-12 &&
          fabs(S[3]) / S[0] > 0.99999, "... 45-degree light leaves circular: |V|/I = %.9f",
          fabs(S[3]) / S[0]);
    printf("BENCH wave_rhomb_retardance_err_deg %.3g deg\n", fabs(got - 2 * one));
    printf("BENCH wave_rhomb_vs_published_deg %.3g deg\n", fabs(got - 90));
    tr->scene_free(sc);
}

/* The TIR retardance closed form (Born & Wolf 1.5.4): glass n into air at th. */
static double tir_delta(double n, double th)
{
    double m = 1 / n, s2 = sin(th) * sin(th);
    return 2 * atan(cos(th) * sqrt(s2 - m * m) / s2);
}

/* One ray in glass (n 1.5) along +z meets two planes at th1 and th2 by TIR, the second
 * plane of incidence turned by psi about the ray from the first's (psi 0: one plane,
 * 90 degrees: crossed), then a detector; the first plane's own azimuth phi about z.
 * Returns the hit's retardance (radians) with the Stokes reference xref, or NaN. */
static double two_tirs(double th1, double th2, double psi, double phi, const double xref[3],
                       int *ntir)
{
    const double n = 1.5, o[3] = {0, 0, 0}, z[3] = {0, 0, 1};
    double c = cos(phi), s = sin(phi);
    double N1[3] = {-s * sin(th1), c * sin(th1), -cos(th1)}, A[3] = {0, 0, 5}, k1[3], B[3];
    for (int i = 0; i < 3; i++) k1[i] = z[i] + 2 * cos(th1) * N1[i];
    for (int i = 0; i < 3; i++) B[i] = A[i] + 5 * k1[i];
    /* u: the first plane's s direction (x turned by phi); w = k1 x u, both _|_ k1 */
    double u[3] = {c, s, 0}, w[3], N2[3], k2[3], C[3];
    cross(k1, u, w);
    for (int i = 0; i < 3; i++)
        N2[i] = -cos(th2) * k1[i] + sin(th2) * (cos(psi) * w[i] + sin(psi) * u[i]);
    for (int i = 0; i < 3; i++) k2[i] = k1[i] + 2 * cos(th2) * N2[i];
    for (int i = 0; i < 3; i++) C[i] = B[i] + 5 * k2[i];
    double e[3] = {1, 2, 0};   /* linear light, neither s nor p */
    trace_scene *sc = one_ray(o, z, e, n);
    add_plane(sc, A, N1, 1, TRACE_REFRACT, 1, n);
    add_plane(sc, B, N2, 1, TRACE_REFRACT, 1, n);
    add_plane(sc, C, k2, 2, TRACE_DETECT, n, n);
    static rec x;
    trace_summary sum;
    int rc = run_ref(sc, &x, 0, xref, &sum);
    tr->scene_free(sc);
    *ntir = (int)sum.tir;
    return rc == 0 && x.np == 1 ? x.p[0].retardance : NAN;
}

/* The proper retardance (parallel transport taken out, tr_polar.c's Q): the same for
 * every Stokes reference and every turn of the whole path about the ray; a single TIR
 * is the closed form whatever its plane; two TIRs in one plane add, in crossed planes
 * subtract (the second one's s is the first one's p: delta1 - delta2, 0 for equal
 * angles), as the 2x2 Jones calculus in the local s, p frames gives. */
static void proper(void)
{
    const double D = PI / 180, refs[4][3] = {{1, 0, 0}, {0, 1, 0}, {0.3, -0.8, 0.5}, {1, 1, 1}};
    double worst1 = 0, worst2 = 0, worst3 = 0;
    int bad = 0, nt;
    for (int r = 0; r < 4; r++)
        for (int k = 0; k < 5; k++) {
            double phi = (17 + 41 * k) * D, th = (44 + 5 * k) * D;
            /* th2 = 0 would not reflect: a single TIR is the pair with a normal exit */
            double d1 = tir_delta(1.5, th), d2 = tir_delta(1.5, 52 * D);
            double one = two_tirs(th, 52 * D, 0, phi, refs[r], &nt);
            if (nt != 2) bad++;
            double e = fabs(one - fmod(d1 + d2, 2 * PI));
            if (!(e <= worst1)) worst1 = e;
            double cr = two_tirs(th, 52 * D, 90 * D, phi, refs[r], &nt);
            if (nt != 2) bad++;
            e = fabs(cr - fabs(d1 - d2));
            if (!(e <= worst2)) worst2 = e;
            double eq = two_tirs(th, th, 90 * D, phi, refs[r], &nt);
            if (nt != 2) bad++;
            if (!(fabs(eq) <= worst3)) worst3 = fabs(eq);
        }
    CHECK(bad == 0 && worst1 < 1e-12, "proper retardance: two TIRs in one plane = delta1 + "
          "delta2 for 4 Stokes references x 5 azimuths and angles: worst %.2e rad", worst1);
    CHECK(bad == 0 && worst2 < 1e-12, "... in crossed planes = |delta1 - delta2|: worst %.2e "
          "rad", worst2);
    CHECK(bad == 0 && worst3 < 1e-12, "... crossed at equal angles cancel: worst %.2e rad",
          worst3);
    printf("BENCH wave_proper_retardance_abs_err %.3g rad\n", worst1 > worst2 ? worst1 : worst2);
}

/* Elements in air along +z: each a plane refract 1 1 with its element. */
static double stokes_through(const double *e, int n, const trace_polar_surface *ps,
                             double S[4], trace_summary *sum)
{
    double o[3] = {0, 0, -1}, d[3] = {0, 0, 1}, nz[3] = {0, 0, 1};
    trace_scene *sc = one_ray(o, d, e, 1);
    for (int i = 0; i < n; i++) {
        double at[3] = {0, 0, i + 1.0};
        add_plane(sc, at, nz, 5, TRACE_REFRACT, 1, 1);
        tr->set_polar(sc, i, &ps[i]);
    }
    double at[3] = {0, 0, n + 2.0};
    add_plane(sc, at, nz, 5, TRACE_DETECT, 1, 1);
    static rec x;
    int rc = run(sc, &x, 1, sum);
    tr->scene_free(sc);
    if (rc || x.np != 1) return -1;
    memcpy(S, x.p[0].stokes, 4 * sizeof *S);
    return 0;
}

static void elements(void)
{
    trace_polar_surface ps[2];
    double S[4], worst = 0;
    trace_summary sum;
    int bad = 0;
    memset(ps, 0, sizeof ps);
    for (int k = 0; k <= 18; k++) {         /* Malus: I = I0/2 cos^2 theta */
        double t = k * 5 * PI / 180;
        ps[0].element = ps[1].element = TRACE_POL_POLARIZER;
        ps[0].axis[0] = 1;
        ps[1].axis[0] = cos(t); ps[1].axis[1] = sin(t);
        if (stokes_through(NULL, 2, ps, S, &sum) || !balance_ok(&sum)) { bad++; continue; }
        double want = 0.5 * cos(t) * cos(t), e = fabs(S[0] - want);
        if (fabs(sum.detected - S[0]) > 1e-15 || fabs(sum.absorbed - (1 - want)) > 1e-14) bad++;
        if (e > worst) worst = e;
    }
    CHECK(bad == 0 && worst < 1e-15, "Malus's law through two traced polarizers, 0..90 deg: "
          "S0 = cos^2/2 to %.1e; the rest absorbed, balance holds", worst);
    printf("BENCH wave_malus_abs_err %.3g abs\n", worst);
    /* quarter-wave plate, fast axis x, 45-degree light: V = +1 (the --polar calculator's
     * "qwp 0" on its 45-degree input); fast axis 45 degrees on x light: V = -1 */
    double e45[3] = {1, 1, 0}, ex[3] = {1, 0, 0};
    memset(ps, 0, sizeof ps);
    ps[0].element = TRACE_POL_RETARDER;
    ps[0].axis[0] = 1;
    ps[0].retardance = PI / 2;
    int ok = !stokes_through(e45, 1, ps, S, &sum);
    CHECK(ok && fabs(S[0] - 1) < 1e-15 && fabs(S[3] - 1) < 1e-15 && fabs(S[1]) < 1e-15 &&
          fabs(S[2]) < 1e-15, "traced quarter-wave plate: 45-degree light -> Stokes "
          "%.3g %.3g %.3g %.16g (circular, V = 1)", S[0], S[1], S[2], S[3]);
    ps[0].axis[1] = 1;
    ok = !stokes_through(ex, 1, ps, S, &sum);
    CHECK(ok && fabs(S[3] + 1) < 1e-15, "... fast axis at 45 degrees, x light: V = %.16g",
          S[3]);
    ps[0].axis[1] = 0;
    ps[0].retardance = PI;
    ok = !stokes_through(e45, 1, ps, S, &sum);
    CHECK(ok && fabs(S[2] + 1) < 1e-15 && fabs(S[3]) < 1e-15,
          "half-wave plate: 45 degrees -> -45 degrees (S2 = %.16g)", S[2]);
    /* unpolarized light through a polarizer: half, fully polarized along its axis */
    memset(ps, 0, sizeof ps);
    ps[0].element = TRACE_POL_POLARIZER;
    ps[0].axis[1] = 1;
    ok = !stokes_through(NULL, 1, ps, S, &sum);
    CHECK(ok && fabs(S[0] - 0.5) < 1e-15 && fabs(S[1] + 0.5) < 1e-15,
          "unpolarized light through a y polarizer: S0 %.16g, S1 %.16g", S[0], S[1]);
}

/* A quarter-wave MgF2 layer on N-BK7 at 550 nm */
static void coating(void)
{
    const double n0 = 1, n1 = 1.38, ns = 1.5168, lam = 0.55;
    trace_polar_surface ps = {0};
    ps.nlayer = 1;
    ps.layer_n[0] = n1;
    ps.layer_d[0] = lam / (4 * n1);
    double R, T, want = pow((n0 * ns - n1 * n1) / (n0 * ns + n1 * n1), 2);
    fresnel_one(n0, ns, 0, &ps, &R, &T);
    double rel = fabs(R / want - 1);
    CHECK(rel < 1e-12 && fabs(R + T - 1) < 1e-14, "traced quarter-wave MgF2 on N-BK7: R = "
          "%.15g = ((n0 ns - n1^2)/(n0 ns + n1^2))^2 (rel %.1e), R + T = 1", R, rel);
    printf("BENCH wave_trace_coating_R_rel_err %.3g ratio\n", rel);
    double worst = 0;
    for (int i = 0; i < 90; i += 5) {
        fresnel_one(n0, ns, i * PI / 180, &ps, &R, &T);
        if (fabs(R + T - 1) > worst || !(R > 0 && T > 0)) worst = fmax(worst, fabs(R + T - 1));
        if (!(R > 0 && T > 0)) worst = 1;
    }
    CHECK(worst < 1e-13, "... oblique (0..85 deg, unpolarized): R + T = 1 to %.1e", worst);
    ps.layer_d[0] = 0;                       /* an absentee layer: the bare surface */
    double Rb, Tb;
    fresnel_one(n0, ns, 30 * PI / 180, &ps, &R, &T);
    fresnel_one(n0, ns, 30 * PI / 180, NULL, &Rb, &Tb);
    CHECK(R > 0.01 && fabs(R - Rb) < 1e-15 && fabs(T - Tb) < 1e-15,
          "a zero-thickness layer gives the bare surface: R %.15g, %.15g", R, Rb);
}

/* Unpolarized scene (the triplet with mounts, Fresnel, reflections) with and without
 * polarization: the same hits and the same s and p powers. */
typedef struct all { trace_hit *h; long n, cap; } all;
static int keep_all(void *ctx, const trace_hit *h)
{
    all *a = ctx;
    if (a->n == a->cap) {
        a->cap = a->cap ? 2 * a->cap : 1024;
        a->h = realloc(a->h, (size_t)a->cap * sizeof *a->h);
    }
    a->h[a->n++] = *h;
    return 0;
}

static void same_powers(void)
{
    trace_lens_surface s[TT_NSURF];
    trace_lens l;
    all a[2] = {{0}, {0}};
    trace_summary sum[2];
    for (int k = 0; k < 2; k++) {
        tt_triplet(s, &l, 1);
        l.mounts = 1;
        l.z_detector = 60;
        trace_scene *sc = tr->scene_new();
        tr->add_lens(sc, &l);
        trace_source src = {0};
        src.type = TRACE_SRC_GRID;
        src.at[2] = -1;
        src.dir[2] = 1;
        src.radius = 6;
        src.count = 15;
        tr->add_source(sc, &src, NULL);
        if (k) tr->polarization(sc, 1, NULL, NULL, NULL);
        trace_options o;
        tr->options_default(&o);
        o.threads = 2;
        trace_sink sk = {&a[k], NULL, keep_all, NULL};
        tr->run(sc, &o, &sk, &sum[k]);
        tr->scene_free(sc);
    }
    double worst = 0;
    int same = a[0].n == a[1].n && a[0].n > 100 && sum[0].segments == sum[1].segments;
    for (long i = 0; same && i < a[0].n; i++) {
        const trace_hit *x = &a[0].h[i], *y = &a[1].h[i];
        double p = x->power_s + x->power_p;
        double e = fmax(fabs(x->power_s - y->power_s), fabs(x->power_p - y->power_p)) / p;
        if (x->ray != y->ray || x->history != y->history) same = 0;
        for (int j = 0; j < 3; j++) if (x->pos[j] != y->pos[j]) same = 0;
        if (e > worst) worst = e;
    }
    CHECK(same && worst < 1e-12 && balance_ok(&sum[1]) &&
          fabs(sum[0].detected - sum[1].detected) < 1e-12 * sum[0].detected,
          "the triplet (mounts, Fresnel, reflections), unpolarized: %ld hits at the same "
          "points, s and p powers with P as without to %.1e", a[0].n, worst);
    free(a[0].h);
    free(a[1].h);
}

static void pure(void)
{
    double k[3] = {sin(0.5), 0, cos(0.5)}, nrm[3] = {0, 0, 1}, P[3][3][2], ko[3];
    int tir = tr->prt_interface(k, nrm, 1, 1.5, NULL, 0.55, 0, P, ko);
    double complex a[4];
    hecht(1, 1.5, 0.5, a);
    double sv[3] = {0, 1, 0};
    double complex ts = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) ts += sv[i] * (P[i][j][0] + I * P[i][j][1]) * sv[j];
    CHECK(!tir && cabs(ts - a[2]) < 1e-15 && fabs(1.5 * hypot(ko[0], ko[1]) - sin(0.5)) < 1e-15,
          "prt_interface: ts = %.16g, Snell", creal(ts));
    tir = tr->prt_interface(k, nrm, 1.5, 1, NULL, 0.55, 0, P, ko);
    CHECK(tir == 0, "prt_interface: 1.5 -> 1 at 28.6 deg is not TIR");
    double k2[3] = {sin(0.8), 0, cos(0.8)};
    CHECK(tr->prt_interface(k2, nrm, 1.5, 1, NULL, 0.55, 0, P, ko) == 1,
          "prt_interface: 1.5 -> 1 at 45.8 deg is TIR");
    trace_scene *sc = tr->scene_new();
    trace_polar_surface ps = {0};
    ps.element = TRACE_POL_POLARIZER;
    CHECK(tr->set_polar(sc, 0, &ps) == TRACE_EINVAL, "set_polar: no such surface refused");
    double z0[3] = {0, 0, 0};
    add_plane(sc, z0, nrm, 1, TRACE_MIRROR, 1, 1);
    CHECK(tr->set_polar(sc, 0, &ps) == TRACE_EINVAL, "set_polar on a mirror refused: %s",
          tr->error(sc));
    add_plane(sc, z0, nrm, 2, TRACE_REFRACT, 1, 1);
    CHECK(tr->set_polar(sc, 1, &ps) == TRACE_EINVAL, "a polarizer without an axis refused: %s",
          tr->error(sc));
    tr->scene_free(sc);
}

int main(void)
{
    tr = tt_api();
    fresnel();
    rhomb();
    proper();
    elements();
    coating();
    same_powers();
    pure();
    return unit_failed();
}
