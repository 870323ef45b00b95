/* t_extreme.c -- the trace engine at the extremes (issue 9), a table of rows like
 * tests/unit_paraxial_extreme.c, each asserted against an independent computation
 * written here in long double or closed form (no engine code): far ray starts
 * (precision must not depend on where a ray starts), coordinates beyond single
 * precision, coincident surfaces, sizes whose squares under- or overflow, non-finite
 * results as errors, and compensated power sums at 1e7 rays (the 1e8 row is in
 * `bench_trace sum`, run by scripts/bench_trace.sh: it takes about a minute). */
#include <float.h>
#include <stdio.h>
#include "unit.h"
#include "tt.h"
#include "trace/scene.h"

static const trace_api *tr;

#if defined(__SANITIZE_ADDRESS__)
#define SLOW_BUILD 1
#else
#define SLOW_BUILD 0
#endif

/* ---- a small recorder of detector hits ---- */
typedef struct hits {
    trace_hit h[64];
    int n;
} hits;

static int on_hit(void *ctx, const trace_hit *h)
{
    hits *k = ctx;
    if (k->n < 64) k->h[k->n] = *h;
    k->n++;
    return 0;
}

static trace_options geometry_only(void)
{
    trace_options o;
    tr->options_default(&o);
    o.fresnel = 0;
    o.reflections = 0;
    o.threads = 1;
    return o;
}

static trace_material mat(int kind, double n1, double n2)
{
    trace_material m = {kind, n1, n2};
    return m;
}

static int add_plane(trace_scene *sc, int kind, double z, double r, double n1, double n2)
{
    trace_surface s = {0};
    s.shape = TRACE_PLANE;
    s.at[2] = z;
    s.axis[2] = 1;
    s.aperture = TRACE_AP_DISC;
    s.r_outer = r;
    trace_material m = mat(kind, n1, n2);
    return tr->add_surface(sc, &s, &m);
}

static int add_cap(trace_scene *sc, int kind, double z, double R, double ap, double n1,
                   double n2)
{
    trace_surface s = {0};
    s.shape = TRACE_AXIAL;
    s.at[2] = z;
    s.axis[2] = 1;
    s.radius = R;
    s.aperture = TRACE_AP_DISC;
    s.r_outer = ap;
    trace_material m = mat(kind, n1, n2);
    return tr->add_surface(sc, &s, &m);
}

static int add_rays(trace_scene *sc, const trace_ray *r, int n)
{
    trace_source s = {0};
    s.type = TRACE_SRC_RAYS;
    s.count = n;
    s.ray = r;
    return tr->add_source(sc, &s, NULL);
}

/* ---- 1. precision independent of the start ---- */

/* Exact (long double) x on the plane z = zd of the ray x = h parallel to the axis,
 * refracted n1 -> n2 at the spherical cap of radius R with its vertex at z = 0. */
static long double cap_exact_x(long double h, long double R, long double n1, long double n2,
                               long double zd)
{
    long double zs = R - sqrtl(R * R - h * h);           /* sag at h */
    long double nx = -h / R, nz = (R - zs) / R;          /* unit normal toward +z */
    long double mu = n1 / n2, ci = nz;                   /* d = (0, 0, 1) */
    long double g = sqrtl(1 - mu * mu * (1 - ci * ci)) - mu * ci;
    long double dx = g * nx, dz = mu + g * nz;
    return h + (zd - zs) * dx / dz;
}

static void far_cap(void)
{
    const double L[] = {1, 1e2, 1e4, 1e6, 1e8};
    const double R = 50, h = 3, n2 = 1.5, zd = 100;
    long double want = cap_exact_x(h, R, 1, n2, zd);
    for (size_t i = 0; i < sizeof L / sizeof L[0]; i++) {
        trace_scene *sc = tr->scene_new();
        hits k = {.n = 0};
        trace_sink sink = {&k, NULL, on_hit, NULL};
        trace_options o = geometry_only();
        add_cap(sc, TRACE_REFRACT, 0, R, 12, 1, n2);
        add_plane(sc, TRACE_DETECT, zd, 1e3, 1, 1);
        trace_ray r = {{h, 0, -L[i]}, {0, 0, 1}, 1};
        add_rays(sc, &r, 1);
        int rc = tr->run(sc, &o, &sink, NULL);
        double got = k.n == 1 ? k.h[0].pos[0] : NAN;
        double rel = fabs((double)(got - want) / (double)want);
        CHECK(rc == TRACE_OK && k.n == 1 && rel <= 1e-15,
              "far start: a cap R 50 met by a ray from %g before it: detector x %.17g, "
              "exact %.17Lg (%.1e relative, <= 1e-15)", L[i], got, want, rel);
        tr->scene_free(sc);
    }
}

/* Exact (long double) x on the plane z = zd of the ray x = h parallel to the axis
 * through a ball of radius R and index n centred at the origin. */
static long double ball_exact_x(long double h, long double R, long double n, long double zd)
{
    long double p[3] = {h, 0, -sqrtl(R * R - h * h)}, d[3] = {0, 0, 1}, m[3];
    for (int pass = 0; pass < 2; pass++) {
        long double mu = pass ? n : 1 / n, s = pass ? -1 : 1;
        for (int j = 0; j < 3; j++) m[j] = s * p[j] / R;     /* toward the incident side */
        long double ci = -(d[0] * m[0] + d[1] * m[1] + d[2] * m[2]);
        long double k = mu * ci - sqrtl(1 - mu * mu * (1 - ci * ci));
        for (int j = 0; j < 3; j++) d[j] = mu * d[j] + k * m[j];
        if (!pass) {                                          /* on to the exit point */
            long double t = -2 * (p[0] * d[0] + p[1] * d[1] + p[2] * d[2]);
            for (int j = 0; j < 3; j++) p[j] += t * d[j];
        }
    }
    return p[0] + (zd - p[2]) * d[0] / d[2];
}

static void far_ball(void)
{
    const double L[] = {2, 1e3, 1e6, 1e8};
    long double want = ball_exact_x(0.3L, 1, 1.5L, 5);
    for (size_t i = 0; i < sizeof L / sizeof L[0]; i++) {
        trace_scene *sc = tr->scene_new();
        hits k = {.n = 0};
        trace_sink sink = {&k, NULL, on_hit, NULL};
        trace_options o = geometry_only();
        trace_surface b = {0};
        b.shape = TRACE_SPHERE;
        b.radius = 1;
        trace_material m = mat(TRACE_REFRACT, 1, 1.5);
        tr->add_surface(sc, &b, &m);
        add_plane(sc, TRACE_DETECT, 5, 100, 1, 1);
        trace_ray r = {{0.3, 0, -L[i]}, {0, 0, 1}, 1};
        add_rays(sc, &r, 1);
        int rc = tr->run(sc, &o, &sink, NULL);
        double got = k.n == 1 ? k.h[0].pos[0] : NAN;
        double rel = fabs((double)(got - want) / (double)want);
        CHECK(rc == TRACE_OK && k.n == 1 && rel <= 1e-14,
              "far start: a glass ball met by a ray from %g before it: detector x %.17g, "
              "exact %.17Lg (%.1e relative, <= 1e-14)", L[i], got, want, rel);
        tr->scene_free(sc);
    }
}

/* A cap of radius 1e-3 watched from 1e6 away: every ray that lands on it in exact
 * arithmetic is recorded (Embree's float ray must not miss its box). */
static void tiny_far_cap(void)
{
    trace_scene *sc = tr->scene_new();
    hits k = {.n = 0};
    trace_sink sink = {&k, NULL, on_hit, NULL};
    trace_options o = geometry_only();
    add_cap(sc, TRACE_DETECT, 0, 1e-3, 1e-3, 1, 1);
    enum { N = 33 };
    trace_ray r[N];
    int expect = 0;
    for (int i = 0; i < N; i++) {
        /* aim at (x, 0, 0), x across the aperture and beyond: lands iff |x| <= 1e-3
         * (the cap is a hemisphere of radius 1e-3: its rim is the aperture) */
        double x = -1.6e-3 + 1e-4 * i, z0 = -1e6;
        double d[3] = {x, 0, -z0}, l = sqrt(d[0] * d[0] + d[2] * d[2]);
        r[i] = (trace_ray){{0, 0, z0}, {d[0] / l, 0, d[2] / l}, 1};
        /* where it crosses the aperture plane z = sag(rim) = 1e-3, exactly: x (1 + 1e-3/1e6) */
        long double xr = (long double)x * (1 + 1e-9L);
        if (fabsl(xr) < 1e-3L * (1 - 1e-9L)) expect++;
    }
    add_rays(sc, r, N);
    int rc = tr->run(sc, &o, &sink, NULL);
    CHECK(rc == TRACE_OK && k.n == expect,
          "far start: a cap of radius 1e-3 seen from 1e6 records every ray that lands on "
          "it (%d of %d, exact %d)", k.n, N, expect);
    tr->scene_free(sc);
}

/* A near-axis real ray through the Cooke triplet meets the paraxial focus to 1e-12
 * relative, from any start distance (the lens shortcut and its packets: 8 rays). */
static void far_triplet(void)
{
    const double L[] = {1, 10, 1e2, 1e3, 1e4, 1e5, 1e6};
    trace_lens_surface s[TT_NSURF];
    trace_lens l;
    tt_triplet(s, &l, 0);
    double zp = tt_paraxial_image(&l, -INFINITY);
    for (size_t i = 0; i < sizeof L / sizeof L[0]; i++) {
        trace_scene *sc = tr->scene_new();
        hits k = {.n = 0};
        trace_sink sink = {&k, NULL, on_hit, NULL};
        trace_options o = geometry_only();
        trace_lens ll = l;
        ll.z_detector = zp;
        int id = tr->add_lens(sc, &ll);
        trace_ray r[8];
        for (int j = 0; j < 8; j++)
            r[j] = (trace_ray){{0, 1e-6 * (j + 1), -L[i]}, {0, 0, 1}, 1};
        add_rays(sc, r, 8);
        int rc = id >= 0 ? tr->run(sc, &o, &sink, NULL) : id;
        /* the same rays one by one through Embree: the same bits (packets, far lanes) */
        hits kb = {.n = 0};
        trace_sink sb = {&kb, NULL, on_hit, NULL};
        o.sequential = 0;
        int rcb = rc == TRACE_OK ? tr->run(sc, &o, &sb, NULL) : rc;
        int same = rcb == TRACE_OK && kb.n == k.n &&
                   !memcmp(kb.h, k.h, (size_t)(k.n < 64 ? k.n : 64) * sizeof *k.h);
        double worst = 0;
        for (int j = 0; j < k.n && j < 8; j++) {
            const trace_hit *h = &k.h[j];
            double zc = h->pos[2] - h->pos[1] * h->dir[2] / h->dir[1];
            worst = fmax(worst, fabs(zc - zp) / zp);
        }
        CHECK(rc == TRACE_OK && k.n == 8 && worst <= 1e-12 && same,
              "far start: near-axis rays through the triplet from %g before it cross the "
              "axis at the paraxial focus %.15g to %.1e relative (<= 1e-12); packets and "
              "Embree give the same bits (%s)", L[i], zp, worst, same ? "yes" : "NO");
        tr->scene_free(sc);
    }
}

/* ---- 2. beyond single precision's range ---- */

static void huge(void)
{
    /* a detector rect 1e20 x 1e20 and a detector sphere of radius 1e19: hit */
    {
        trace_scene *sc = tr->scene_new();
        hits k = {.n = 0};
        trace_sink sink = {&k, NULL, on_hit, NULL};
        trace_options o = geometry_only();
        trace_surface p = {0};
        p.shape = TRACE_PLANE;
        p.at[2] = 10;
        p.axis[2] = 1;
        p.aperture = TRACE_AP_RECT;
        p.width = p.height = 1e20;
        trace_material m = mat(TRACE_DETECT, 1, 1);
        tr->add_surface(sc, &p, &m);
        trace_ray r = {{3e18, -2e19, 0}, {0, 0, 1}, 1};
        add_rays(sc, &r, 1);
        int rc = tr->run(sc, &o, &sink, NULL);
        CHECK(rc == TRACE_OK && k.n == 1 && k.h[0].pos[0] == 3e18 && k.h[0].pos[1] == -2e19
              && k.h[0].pos[2] == 10,
              "huge: a detector rect 1e20 x 1e20 is hit at (3e18, -2e19, 10) exactly");
        tr->scene_free(sc);
    }
    {
        trace_scene *sc = tr->scene_new();
        hits k = {.n = 0};
        trace_sink sink = {&k, NULL, on_hit, NULL};
        trace_options o = geometry_only();
        trace_surface p = {0};
        p.shape = TRACE_SPHERE;
        p.radius = 1e19;
        trace_material m = mat(TRACE_DETECT, 1, 1);
        tr->add_surface(sc, &p, &m);
        trace_ray r = {{0, 0, 0}, {0.6, 0, 0.8}, 1};
        add_rays(sc, &r, 1);
        int rc = tr->run(sc, &o, &sink, NULL);
        double e = k.n == 1 ? fabs(hypot(k.h[0].pos[0], k.h[0].pos[2]) - 1e19) / 1e19 : 1;
        CHECK(rc == TRACE_OK && k.n == 1 && e <= 4e-16,
              "huge: a detector sphere of radius 1e19 sees the ray from its centre "
              "(radius to %.1e relative)", e);
        tr->scene_free(sc);
    }
    /* a ray from -1.9e18 (beyond float's safe range for Embree) to a small detector */
    {
        trace_scene *sc = tr->scene_new();
        hits k = {.n = 0};
        trace_sink sink = {&k, NULL, on_hit, NULL};
        trace_options o = geometry_only();
        add_plane(sc, TRACE_DETECT, 10, 1, 1, 1);
        trace_ray r[2] = {{{0.5, 0, -1.9e18}, {0, 0, 1}, 1}, {{0, 0, -1e30}, {0, 0, 1}, 1}};
        add_rays(sc, r, 2);
        int rc = tr->run(sc, &o, &sink, NULL);
        CHECK(rc == TRACE_OK && k.n == 2 && k.h[0].pos[0] == 0.5 && k.h[0].pos[2] == 10 &&
              k.h[1].pos[2] == 10,
              "huge: rays from z = -1.9e18 and -1e30 meet a detector of radius 1 at z = 10");
        tr->scene_free(sc);
    }
    /* glass side of a plane into index 1e-200: the direction overflows; an error with
     * its cause, no abort */
    {
        trace_scene *sc = tr->scene_new();
        trace_options o = geometry_only();
        add_plane(sc, TRACE_REFRACT, 0, 1, 1e-200, 1.5);
        add_plane(sc, TRACE_DETECT, -10, 1, 1, 1);
        trace_ray r = {{0, 0, 1}, {0, 0, -1}, 1};
        trace_source src = {0};
        src.type = TRACE_SRC_RAYS;
        src.count = 1;
        src.ray = &r;
        src.n_medium = 1.5;
        tr->add_source(sc, &src, NULL);
        trace_summary sum;
        int rc = tr->run(sc, &o, NULL, &sum);
        CHECK(rc == TRACE_EINVAL && strstr(tr->error(sc), "failed numerically") &&
              strstr(tr->error(sc), "after surface 1"),
              "huge: a plane into index 1e-200 is an error with its cause (%s)",
              tr->error(sc));
        tr->scene_free(sc);
    }
}

/* ---- 3. coincident surfaces ---- */

/* Fresnel power transmittances at incidence angle cos ci from n1 into n2. */
static void fresnel_T(long double n1, long double n2, long double ci, long double *Ts,
                      long double *Tp)
{
    long double st = n1 / n2 * sqrtl(1 - ci * ci), ct = sqrtl(1 - st * st);
    long double rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
    long double rp = (n2 * ci - n1 * ct) / (n2 * ci + n1 * ct);
    *Ts = 1 - rs * rs;
    *Tp = 1 - rp * rp;
}

/* Two planes at one z, refract 1 1.5 then 1.5 1: a ray at 45 degrees meets both,
 * in order, from either side: T = (Ts^2 + Tp^2) / 2 without reflected rays, and
 * (1 - Rs)/(1 + Rs) and (1 - Rp)/(1 + Rp) averaged with them (the zero-thickness
 * layer's incoherent sum), its direction unchanged. */
static void coincident_planes(void)
{
    long double Ts, Tp;
    fresnel_T(1, 1.5L, sqrtl(0.5L), &Ts, &Tp);
    long double t1 = (Ts * Ts + Tp * Tp) / 2;
    long double t2 = ((Ts / (2 - Ts)) + (Tp / (2 - Tp))) / 2;   /* (1-R)/(1+R) */
    for (int refl = 0; refl < 2; refl++)
        for (int back = 0; back < 2; back++) {
            trace_scene *sc = tr->scene_new();
            hits k = {.n = 0};
            trace_sink sink = {&k, NULL, on_hit, NULL};
            trace_options o;
            tr->options_default(&o);
            o.threads = 1;
            o.reflections = refl;
            o.cutoff = 0;
            o.max_depth = 40;
            add_plane(sc, TRACE_REFRACT, 0, 5, 1, 1.5);
            add_plane(sc, TRACE_REFRACT, 0, 5, 1.5, 1);
            add_plane(sc, TRACE_DETECT, back ? -10 : 10, 100, 1, 1);
            double z0 = back ? 10 : -10, dz = back ? -1 : 1;
            trace_ray r = {{0, -10, z0}, {0, sqrt(0.5), dz * sqrt(0.5)}, 1};
            add_rays(sc, &r, 1);
            trace_summary sum;
            int rc = tr->run(sc, &o, &sink, &sum);
            double want = (double)(refl ? t2 : t1), e = fabs(sum.detected - want);
            double de = k.n ? fabs(k.h[0].dir[1] - sqrt(0.5)) : 1;
            /* with reflections the layer's bounces go on to the depth limit (cutoff 0),
             * the last of them far below rounding */
            CHECK(rc == TRACE_OK && e <= 1e-15 && (refl || sum.cut_depth == 0) &&
                  sum.medium_mismatch == 0 && (refl || (k.n == 1 && de <= 1e-15)),
                  "coincident: planes 1 -> 1.5 -> 1 at one z, a ray from the %s, reflections "
                  "%s: T = %.17g, exact %.17g (%.1e); %d interactions",
                  back ? "back" : "front", refl ? "on" : "off", sum.detected, want, e,
                  (int)sum.interactions);
            tr->scene_free(sc);
        }
}

/* A cemented interface as two caps sharing vertex and radius, 1 -> 1.5 -> 1.6: the
 * rays leave bent as by one interface 1 -> 1.6 (Snell's law chains), none trapped. */
static void coincident_caps(void)
{
    trace_scene *sc = tr->scene_new();
    hits k = {.n = 0};
    trace_sink sink = {&k, NULL, on_hit, NULL};
    trace_options o = geometry_only();
    add_cap(sc, TRACE_REFRACT, 0, 20, 5, 1, 1.5);
    add_cap(sc, TRACE_REFRACT, 0, 20, 5, 1.5, 1.6);
    add_plane(sc, TRACE_DETECT, 30, 100, 1.6, 1.6);
    trace_ray r[5];
    for (int i = 0; i < 5; i++) r[i] = (trace_ray){{0, i - 2.0, -5}, {0, 0, 1}, 1};
    add_rays(sc, r, 5);
    trace_summary sum;
    int rc = tr->run(sc, &o, &sink, &sum);
    double worst = 0;
    for (int i = 0; i < k.n && i < 5; i++) {
        long double h = fabsl((long double)k.h[i].pos[1]), want = 0;
        long double y0 = r[k.h[i].ray].o[1];
        want = cap_exact_x(y0, 20, 1, 1.6L, 30);
        worst = fmax(worst, fabs((double)((long double)k.h[i].pos[1] - want)));
        (void)h;
    }
    CHECK(rc == TRACE_OK && k.n == 5 && sum.interactions == 10 && sum.cut_depth == 0 &&
          worst <= 1e-13,
          "coincident: caps 1 -> 1.5 -> 1.6 sharing vertex and radius bend 5 rays as one "
          "interface 1 -> 1.6 (detector y to %.1e of the exact; %d interactions)", worst,
          (int)sum.interactions);
    tr->scene_free(sc);
}

/* ---- 5. underflow, overflow ---- */

static void tiny(void)
{
    trace_scene *sc = tr->scene_new();
    trace_surface s = {0};
    s.shape = TRACE_AXIAL;
    s.axis[2] = 1;
    s.radius = 1;
    s.aperture = TRACE_AP_DISC;
    s.r_outer = 1e-200;
    trace_material m = mat(TRACE_DETECT, 1, 1);
    int rc = tr->add_surface(sc, &s, &m);
    CHECK(rc == TRACE_EINVAL && strstr(tr->error(sc), "1e-30"),
          "tiny: aperture 1e-200 is refused, not squared to 0 (%s)", tr->error(sc));
    s.r_outer = 0.5;
    s.r_inner = 1e-200;
    rc = tr->add_surface(sc, &s, &m);
    CHECK(rc == TRACE_EINVAL, "tiny: hole 1e-200 is refused (%s)", tr->error(sc));
    s.r_inner = 0;
    s.radius = 1e-310;
    rc = tr->add_surface(sc, &s, &m);
    CHECK(rc == TRACE_EINVAL && strstr(tr->error(sc), "out of range"),
          "tiny: radius 1e-310 is refused (%s)", tr->error(sc));
    trace_source g = {0};
    g.type = TRACE_SRC_GRID;
    g.dir[2] = 1;
    g.radius = 1e-310;
    g.count = 5;
    rc = tr->add_source(sc, &g, NULL);
    CHECK(rc == TRACE_EINVAL, "tiny: a collimated source of radius 1e-310 is refused (%s)",
          tr->error(sc));
    trace_source ga = {0};
    ga.type = TRACE_SRC_GAUSSIAN;
    ga.dir[2] = 1;
    ga.waist = 1e-310;
    ga.wavelength = 1e-3;
    ga.rings = 3;
    rc = tr->add_source(sc, &ga, NULL);
    CHECK(rc == TRACE_EINVAL, "tiny: a Gaussian waist of 1e-310 is refused (%s)",
          tr->error(sc));
    tr->scene_free(sc);

    /* dir 0 0 1e-170 is the +z direction, exactly */
    sc = tr->scene_new();
    hits k = {.n = 0};
    trace_sink sink = {&k, NULL, on_hit, NULL};
    trace_options o = geometry_only();
    add_plane(sc, TRACE_DETECT, 5, 1, 1, 1);
    trace_source c = {0};
    c.type = TRACE_SRC_FAN;
    c.dir[2] = 1e-170;
    c.count = 1;
    rc = tr->add_source(sc, &c, NULL);
    if (rc == TRACE_OK) rc = tr->run(sc, &o, &sink, NULL);
    CHECK(rc == TRACE_OK && k.n == 1 && k.h[0].dir[2] == 1 && k.h[0].pos[2] == 5,
          "tiny: a direction 0 0 1e-170 is +z exactly (rc %d: %s)", rc,
          rc ? tr->error(sc) : "ok");
    tr->scene_free(sc);
}

/* ---- 6. sums that drift ---- */

/* A collimated grid of about n rays of total power 1 onto a detector: emitted and
 * detected are n fl(1/n) to within one rounding (computed here in long double), the
 * balance is exact, the same bits on 1 and 2 threads. */
static void sums(long across)
{
    trace_summary s[2];
    int rc[2];
    for (int th = 0; th < 2; th++) {
        trace_scene *sc = tr->scene_new();
        trace_options o = geometry_only();
        o.threads = th + 1;
        add_plane(sc, TRACE_DETECT, 1, 2, 1, 1);
        trace_source g = {0};
        g.type = TRACE_SRC_GRID;
        g.dir[2] = 1;
        g.radius = 1;
        g.count = across;
        tr->add_source(sc, &g, NULL);
        rc[th] = tr->run(sc, &o, NULL, &s[th]);
        tr->scene_free(sc);
    }
    long double each = 1.0 / (double)s[0].rays, want = each * (long double)s[0].rays;
    double e = fabs((double)(s[0].emitted - want)), dd = fabs((double)(s[0].detected - want));
    CHECK(rc[0] == TRACE_OK && rc[1] == TRACE_OK && e <= DBL_EPSILON && dd <= DBL_EPSILON &&
          s[0].emitted == s[0].detected &&
          !memcmp(&s[0].emitted, &s[1].emitted, 5 * sizeof(double)),
          "sums: %llu rays of power 1: emitted %.17g, detected %.17g (exact n fl(1/n) = "
          "%.17Lg, off by %.1e), same bits on 1 and 2 threads",
          (unsigned long long)s[0].rays, s[0].emitted, s[0].detected, want, fmax(e, dd));
}

/* ---- 4. meshes that leak ---- */

/* Rays aimed at points of a tessellated surface (its vertices, its seam) through an
 * index-matched mesh (refract 1 -> 1: no bending): every ray must cross it exactly
 * `want` times (interactions = want x rays), none slipping through a hole or crack. */
static int mesh_crossings(const sc_surface *f, int level, const trace_ray *r, int n,
                          uint64_t *inter)
{
    double *tri = NULL;
    long ntri = 0;
    char err[SC_ERRMAX];
    if (sc_tessellate(f, level, &tri, &ntri, err)) { printf("# %s\n", err); return -1; }
    trace_scene *sc = tr->scene_new();
    trace_mesh m = {tri, 3 * ntri, NULL, ntri, NULL, NULL, 0, 0};
    trace_material mm = mat(TRACE_REFRACT, 1, 1);
    int rc = tr->add_mesh(sc, &m, &mm);
    if (rc >= 0) rc = add_rays(sc, r, n);
    trace_summary sum;
    trace_options o = geometry_only();
    if (rc >= 0) rc = tr->run(sc, &o, NULL, &sum);
    *inter = rc == TRACE_OK ? sum.interactions : 0;
    tr->scene_free(sc);
    free(tri);
    return rc;
}

/* The vertices of sc_tessellate's sphere at level L (as it computes them, in exact
 * terms: latitude a pi / L, longitude b 2 pi / 2L) and the midpoints of its seam
 * edges; rays from outside toward the centre through each. */
static void leak_sphere(int level, int vertices)
{
    sc_surface f = {0};
    f.shape = SC_SPHERE;
    f.radius = 1;
    int nlon = 2 * level, n = 0, cap = (level + 1) * (vertices ? nlon : 1) + 2 * level + 2;
    trace_ray *r = calloc((size_t)cap, sizeof *r);
    for (int a = 0; a <= level; a++)
        for (int b = 0; b < (vertices ? nlon : 1); b++) {
            long double th = 3.14159265358979323846264338L * a / level;
            long double ph = 2 * 3.14159265358979323846264338L * b / nlon;
            long double p[3] = {sinl(th) * cosl(ph), sinl(th) * sinl(ph), cosl(th)};
            for (int k = 0; k < 2 && !(k == 1 && (a == 0 || a == level)); k++) {
                long double q[3] = {p[0], p[1], p[2]};
                if (k) {                       /* the midpoint of the seam edge below */
                    if (a == level || b) break;
                    long double t2 = 3.14159265358979323846264338L * (a + 0.5L) / level;
                    q[0] = sinl(t2); q[1] = 0; q[2] = cosl(t2);
                }
                for (int j = 0; j < 3; j++) {
                    r[n].o[j] = (double)(3 * q[j]);
                    r[n].d[j] = (double)-q[j];
                }
                r[n].power = 1;
                n++;
            }
        }
    uint64_t inter;
    int rc = mesh_crossings(&f, level, r, n, &inter);
    CHECK(rc == TRACE_OK && inter == 2 * (uint64_t)n,
          "watertight: a sphere tessellated at level %d: %d rays aimed at its %s cross it "
          "twice each (%llu crossings of %d)", level, n,
          vertices ? "vertices, poles and seam" : "poles and seam", (unsigned long long)inter,
          2 * n);
    free(r);
}

/* A cap tessellated at level L: rays along the axis at every vertex inside its rim
 * (hexapolar rings, 6k vertices on ring k, the seam at angle 0) cross it once each. */
static void leak_cap(int level)
{
    sc_surface f = {0};
    f.shape = SC_CAP;
    f.axis[2] = 1;
    f.radius = 20;
    f.aperture = 10;
    int n = 0, cap = 1 + 3 * level * (level + 1);
    trace_ray *r = calloc((size_t)cap, sizeof *r);
    for (int k = 0; k < level; k++)           /* the rim is an open edge: not aimed at */
        for (int j = 0; j < (k ? 6 * k : 1); j++) {
            long double s = 10.0L * k / level, ph = 2 * 3.14159265358979323846264338L * j / (k ? 6 * k : 1);
            r[n] = (trace_ray){{(double)(s * cosl(ph)), (double)(s * sinl(ph)), -5}, {0, 0, 1}, 1};
            n++;
        }
    uint64_t inter;
    int rc = mesh_crossings(&f, level, r, n, &inter);
    CHECK(rc == TRACE_OK && inter == (uint64_t)n,
          "watertight: a cap tessellated at level %d: %d rays along the axis at its "
          "vertices cross it once each (%llu crossings)", level, n,
          (unsigned long long)inter);
    free(r);
}

/* An icosphere (an icosahedron subdivided `level` times, vertices shared by index and
 * put on the unit sphere): rays from outside through every vertex toward the centre
 * cross it twice each (it is closed: what Embree's float test lets slip through at a
 * shared vertex is asked again). */
typedef struct ico {
    double *v;
    uint32_t *f;
    long nv, nf;
    uint64_t *key;
    long *val, cap;
} ico;

static long ico_vertex(ico *m, double x, double y, double z)
{
    double l = sqrt(x * x + y * y + z * z);
    m->v[3 * m->nv] = x / l;
    m->v[3 * m->nv + 1] = y / l;
    m->v[3 * m->nv + 2] = z / l;
    return m->nv++;
}

static long ico_mid(ico *m, long a, long b)
{
    if (a > b) { long t = a; a = b; b = t; }
    uint64_t k = (uint64_t)a << 32 | (uint64_t)b;
    long h = (long)((k * 0x9E3779B97F4A7C15ULL) >> 17) & (m->cap - 1);
    for (; m->val[h] >= 0; h = (h + 1) & (m->cap - 1))
        if (m->key[h] == k) return m->val[h];
    m->key[h] = k;
    const double *p = m->v + 3 * a, *q = m->v + 3 * b;
    return m->val[h] = ico_vertex(m, p[0] + q[0], p[1] + q[1], p[2] + q[2]);
}

static void leak_icosphere(int level)
{
    static const int fi[20][3] = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11},
        {1, 5, 9}, {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2},
        {3, 2, 6}, {3, 6, 8}, {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7},
        {9, 8, 1}};
    double g = (1 + sqrt(5)) / 2;
    double iv[12][3] = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g},
        {0, 1, g}, {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    long maxf = 20L << (2 * level);
    ico m = {0};
    m.v = malloc((size_t)(maxf / 2 + 2) * 3 * sizeof(double));
    m.f = malloc((size_t)maxf * 3 * sizeof(uint32_t));
    for (m.cap = 1; m.cap < 4 * maxf; m.cap *= 2) {}
    m.key = malloc((size_t)m.cap * sizeof *m.key);
    m.val = malloc((size_t)m.cap * sizeof *m.val);
    for (int i = 0; i < 12; i++) ico_vertex(&m, iv[i][0], iv[i][1], iv[i][2]);
    for (int i = 0; i < 20; i++) for (int j = 0; j < 3; j++) m.f[3 * i + j] = (uint32_t)fi[i][j];
    m.nf = 20;
    for (int l = 0; l < level; l++) {
        uint32_t *nf = malloc((size_t)m.nf * 12 * sizeof *nf);
        for (long i = 0; i < m.cap; i++) m.val[i] = -1;
        for (long f = 0; f < m.nf; f++) {
            long a = m.f[3 * f], b = m.f[3 * f + 1], c = m.f[3 * f + 2];
            long ab = ico_mid(&m, a, b), bc = ico_mid(&m, b, c), ca = ico_mid(&m, c, a);
            long t[12] = {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca};
            for (int j = 0; j < 12; j++) nf[12 * f + j] = (uint32_t)t[j];
        }
        memcpy(m.f, nf, (size_t)m.nf * 12 * sizeof *nf);
        m.nf *= 4;
        free(nf);
    }
    trace_ray *r = malloc((size_t)m.nv * sizeof *r);
    for (long i = 0; i < m.nv; i++) {
        const double *p = m.v + 3 * i;
        r[i] = (trace_ray){{3 * p[0], 3 * p[1], 3 * p[2]}, {-p[0], -p[1], -p[2]}, 1};
    }
    trace_scene *sc = tr->scene_new();
    trace_mesh mesh = {m.v, m.nv, m.f, m.nf, NULL, NULL, 0, 0};
    trace_material mm = mat(TRACE_REFRACT, 1, 1);
    int rc = tr->add_mesh(sc, &mesh, &mm);
    if (rc >= 0) rc = add_rays(sc, r, (int)m.nv);
    trace_summary sum = {0}, one = {0};
    trace_options o = geometry_only();
    o.threads = 2;
    if (rc >= 0) rc = tr->run(sc, &o, NULL, &sum);
    o.threads = 1;
    if (rc >= 0) rc = tr->run(sc, &o, NULL, &one);
    int same = sum.interactions == one.interactions && sum.segments == one.segments &&
               !memcmp(&sum.emitted, &one.emitted, 5 * sizeof(double));
    CHECK(rc == TRACE_OK && sum.interactions == 2 * (uint64_t)m.nv && same,
          "watertight: an icosphere of %ld faces: rays through each of its %ld vertices "
          "cross it twice (%llu crossings of %ld), the same on 1 and 2 threads", m.nf, m.nv,
          (unsigned long long)sum.interactions, 2 * m.nv);
    tr->scene_free(sc);
    free(r); free(m.v); free(m.f); free(m.key); free(m.val);
}

int main(void)
{
    tr = tt_api();
    far_cap();
    far_ball();
    tiny_far_cap();
    far_triplet();
    huge();
    coincident_planes();
    coincident_caps();
    tiny();
    leak_sphere(8, 1);
    leak_sphere(40, 1);
    leak_sphere(400, 0);
    leak_cap(16);
    leak_icosphere(SLOW_BUILD ? 5 : 7);
    sums(SLOW_BUILD ? 400 : 3568);   /* 3568 across: 9 998 ... rays (1e7) */
    return unit_failed();
}
