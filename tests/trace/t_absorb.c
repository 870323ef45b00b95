/* t_absorb.c -- the engine's wavelength and absorption (issue 14) through its table:
 * Beer-Lambert inside absorbing media (set_absorption, a source's alpha_medium), at
 * normal and oblique incidence against closed forms, on every path (a sequential lens
 * that would take the packet path gives the general path's bits), the energy balance,
 * every ray's lambda in its records, and the refusals. */
#include <math.h>
#include <stdio.h>
#include "unit.h"
#include "tt.h"

static const trace_api *tr;

typedef struct recs { trace_hit h[64]; int nh; trace_segment s[256]; int ns; } recs;
static int keep_hit(void *ctx, const trace_hit *h)
{
    recs *x = ctx;
    if (x->nh < 64) x->h[x->nh++] = *h;
    return 0;
}
static int keep_seg(void *ctx, const trace_segment *s)
{
    recs *x = ctx;
    if (x->ns < 256) x->s[x->ns++] = *s;
    return 0;
}

static int balance_ok(const trace_summary *s)
{
    double e = s->emitted - (s->detected + s->absorbed + s->escaped + s->cutoff);
    return fabs(e) <= 1e-14 * s->emitted;
}

static void plane(trace_scene *sc, double z, double nx, double nz, int kind, double n1,
                  double n2)
{
    trace_surface s = {0};
    trace_material m = {kind, n1, n2};
    s.shape = TRACE_PLANE;
    s.at[2] = z;
    s.axis[0] = nx;
    s.axis[2] = nz;
    s.r_outer = 100;
    if (tr->add_surface(sc, &s, &m) < 0) printf("add_surface: %s\n", tr->error(sc));
}

static void one_ray(trace_scene *sc, double dx, double dz, double lambda, double alpha)
{
    trace_ray r = {{0, 0, -1}, {dx, 0, dz}, 1};
    trace_source s = {0};
    s.type = TRACE_SRC_RAYS;
    s.count = 1;
    s.ray = &r;
    s.lambda = lambda;
    s.alpha_medium = alpha;
    tr->add_source(sc, &s, NULL);
}

static int run(trace_scene *sc, int reflections, int sequential, recs *x, trace_summary *sum)
{
    trace_options o;
    trace_sink k = {x, keep_seg, keep_hit, NULL};
    tr->options_default(&o);
    o.reflections = reflections;
    o.sequential = sequential;
    o.cutoff = 0;
    x->nh = x->ns = 0;
    return tr->run(sc, &o, &k, sum);
}

/* A slab n = 1.5, thickness L, alpha inside: one ray at incidence angle th. */
static void slab(double th)
{
    const double n = 1.5, L = 7, a = 0.03;
    trace_scene *sc = tr->scene_new();
    plane(sc, 0, 0, 1, TRACE_REFRACT, 1, n);
    plane(sc, L, 0, 1, TRACE_REFRACT, n, 1);
    plane(sc, 50, 0, 1, TRACE_DETECT, 1, 1);
    CHECK(tr->set_absorption(sc, 0, 0, a) == TRACE_OK &&
          tr->set_absorption(sc, 1, a, 0) == TRACE_OK, "set_absorption accepted");
    one_ray(sc, sin(th), cos(th), 0.5461, 0);
    static recs x;
    trace_summary sum;
    int rc = run(sc, 0, 1, &x, &sum);
    trace_fresnel_coef f1, f2;
    double st = sin(th) / n, ct = sqrt(1 - st * st);
    tr->fresnel(1, n, cos(th), &f1);
    tr->fresnel(n, 1, ct, &f2);
    double path = L / ct, k = exp(-a * path);
    double want = 0.5 * (f1.Ts * f2.Ts + f1.Tp * f2.Tp) * k;
    double absorbed = 0.5 * (f1.Ts + f1.Tp) * (1 - k);
    CHECK(rc == 0 && x.nh == 1 && fabs(sum.detected - want) <= 1e-14 * want &&
          fabs(sum.absorbed - absorbed) <= 1e-13 * absorbed && balance_ok(&sum),
          "slab at %.0f deg: detected %.15g = T1 T2 exp(-alpha L/cos) %.15g, absorbed %.6g",
          th * 180 / 3.14159265358979, sum.detected, want, sum.absorbed);
    CHECK(x.nh == 1 && x.h[0].lambda == 0.5461 && x.ns == 3 && x.s[0].lambda == 0.5461 &&
          x.s[2].lambda == 0.5461, "the ray's wavelength is in its hit and every segment");
    /* a segment's power is where it starts: the one inside the slab starts at T1 */
    CHECK(x.ns == 3 && fabs(x.s[1].power - 0.5 * (f1.Ts + f1.Tp)) < 1e-15 &&
          fabs(x.s[2].power - want) < 1e-15,
          "segment powers are those where each segment starts");
    tr->scene_free(sc);
}

/* A source starting in an absorbing medium: detected exp(-alpha d). */
static void source_medium(void)
{
    trace_scene *sc = tr->scene_new();
    plane(sc, 9, 0, 1, TRACE_DETECT, 1, 1);
    one_ray(sc, 0, 1, 0, 0.1);              /* from z = -1: 10 to the detector */
    static recs x;
    trace_summary sum;
    int rc = run(sc, 1, 1, &x, &sum);
    CHECK(rc == 0 && fabs(sum.detected - exp(-1.0)) < 1e-15 && balance_ok(&sum) &&
          x.nh == 1 && x.h[0].lambda == 0, "a source in an absorbing medium: exp(-alpha d) "
          "= %.15g, lambda 0 when none named", sum.detected);
    tr->scene_free(sc);
}

/* A sequential lens (add_lens: the packet path's kind of scene) with an absorbing
 * glass: the same bits as the general path (sequential off), and less than without. */
static void lens_paths(void)
{
    trace_lens_surface s[TT_NSURF];
    trace_lens l;
    double det[3][2];
    for (int pass = 0; pass < 3; pass++) {
        trace_scene *sc = tr->scene_new();
        tt_triplet(s, &l, 1);
        l.z_detector = 60;
        int id = tr->add_lens(sc, &l);
        if (pass < 2)
            for (int i = 0; i < TT_NSURF; i++)   /* the glasses between 1-2, 3-4, 5-6 */
                tr->set_absorption(sc, id + i, i % 2 ? 0.02 : 0, i % 2 ? 0 : 0.02);
        trace_source src = {0};
        src.type = TRACE_SRC_GRID;
        src.at[2] = -5;
        src.dir[2] = 1;
        src.radius = 6;
        src.count = 40;
        src.lambda = 0.5875618;
        tr->add_source(sc, &src, NULL);
        static recs x;
        trace_summary sum;
        int rc = run(sc, 1, pass != 1, &x, &sum);
        CHECK(rc == 0 && balance_ok(&sum), "triplet pass %d: traced, balance holds", pass);
        det[pass][0] = sum.detected;
        det[pass][1] = sum.absorbed;
        tr->scene_free(sc);
    }
    CHECK(det[0][0] == det[1][0] && det[0][1] == det[1][1],
          "absorbing triplet: the lens shortcut gives the general path's bits (detected "
          "%.17g, absorbed %.17g)", det[0][0], det[0][1]);
    CHECK(det[0][0] < det[2][0] && det[0][1] > det[2][1],
          "absorbing triplet detects less than the clear one (%.6g < %.6g)", det[0][0],
          det[2][0]);
}

static void refusals(void)
{
    trace_scene *sc = tr->scene_new();
    plane(sc, 0, 0, 1, TRACE_REFRACT, 1, 1.5);
    CHECK(tr->set_absorption(sc, 0, -1, 0) == TRACE_EINVAL, "negative alpha refused: %s",
          tr->error(sc));
    CHECK(tr->set_absorption(sc, 0, NAN, 0) == TRACE_EINVAL &&
          tr->set_absorption(sc, 0, 0, INFINITY) == TRACE_EINVAL, "non-finite alpha refused");
    CHECK(tr->set_absorption(sc, 1, 0.1, 0) == TRACE_EINVAL, "no such surface refused");
    trace_ray r = {{0, 0, -1}, {0, 0, 1}, 1};
    trace_source s = {0};
    s.type = TRACE_SRC_RAYS; s.count = 1; s.ray = &r; s.lambda = -0.5;
    CHECK(tr->add_source(sc, &s, NULL) == TRACE_EINVAL, "negative wavelength refused: %s",
          tr->error(sc));
    tr->scene_free(sc);
}

int main(void)
{
    tr = tt_api();
    slab(0);
    slab(0.6);
    source_medium();
    lens_paths();
    refusals();
    return unit_failed();
}
