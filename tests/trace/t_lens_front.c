/* t_lens_front.c -- what the lens dialogue relies on in the engine's lens calls:
 * lenses whose consecutive surfaces cross within their semi-diameters are refused
 * (with the surfaces, the height and the edge thickness), touching ones are not;
 * a fan's heights are where the rays meet the first surface (fraction 1 is the rim
 * and is not vignetted), checked against an independent trace aimed at that point;
 * and collimated rays start near the lens, so a triplet with a 7331 mm radius keeps
 * its near-axis accuracy. */
#include <stdio.h>
#include "unit.h"
#include "tt.h"

/* The singlet of --example: R 50 / -50, n 1.5168, semi-diameter 12, thickness t. */
static void singlet(trace_lens_surface s[2], trace_lens *l, double t)
{
    s[0] = (trace_lens_surface){50, 0, 1.5168, 12};
    s[1] = (trace_lens_surface){-50, t, 1, 12};
    l->n_object = 1;
    l->nsurf = 2;
    l->surf = s;
    l->mounts = 1;
    l->z_detector = NAN;
}

static void crossing(const trace_api *tr)
{
    trace_lens_surface s[2];
    trace_lens l;
    char err[256];
    double h[1] = {1};
    trace_fan_ray out[1];
    /* t = 1: the sags (1.4618 each at 12) cross where 2 sag(h) = 1, h = sqrt(49.75) */
    singlet(s, &l, 1);
    trace_scene *sc = tr->scene_new();
    int rc = tr->add_lens(sc, &l);
    CHECK(rc == TRACE_EINVAL && strstr(tr->error(sc), "surfaces 1 and 2 cross at height "
          "7.05337") && strstr(tr->error(sc), "edge thickness at the semi-diameter 12 is "
          "-1.92271"), "crossing surfaces refused by add_lens: %d '%s'", rc, tr->error(sc));
    tr->scene_free(sc);
    rc = tr->lens_fan(&l, -INFINITY, 0, 50, 1, h, out, err, sizeof err);
    CHECK(rc == TRACE_EINVAL && strstr(err, "cross at height 7.05337"),
          "crossing surfaces refused by lens_fan: %d '%s'", rc, err);
    /* both at z = 0: they touch on the axis and cross at once */
    singlet(s, &l, 0);
    sc = tr->scene_new();
    rc = tr->add_lens(sc, &l);
    CHECK(rc == TRACE_EINVAL && strstr(tr->error(sc), "cross at height 0:"),
          "surfaces touching on the axis refused: '%s'", tr->error(sc));
    tr->scene_free(sc);
    /* the limit: t = 2 sag(12) exactly touches at the rim (edge thickness 0) */
    double sag = 50 - sqrt(2500 - 144);
    singlet(s, &l, 2 * sag + 1e-9);
    sc = tr->scene_new();
    rc = tr->add_lens(sc, &l);
    CHECK(rc >= 0, "edge thickness 1e-9 accepted: %s", rc < 0 ? tr->error(sc) : "");
    tr->scene_free(sc);
    singlet(s, &l, 2 * sag - 1e-9);
    sc = tr->scene_new();
    rc = tr->add_lens(sc, &l);
    CHECK(rc == TRACE_EINVAL, "edge thickness -1e-9 refused (%s)", tr->error(sc));
    tr->scene_free(sc);
    /* a cemented pair (same radius, same z) does not cross */
    trace_lens_surface c[3] = {{30, 0, 1.5, 10}, {-30, 6, 1.6, 10}, {-30, 6, 1, 10}};
    trace_lens lc = {1, 3, c, 1, NAN};
    sc = tr->scene_new();
    rc = tr->add_lens(sc, &lc);
    CHECK(rc >= 0, "a cemented interface (equal surfaces) accepted: %s",
          rc < 0 ? tr->error(sc) : "");
    tr->scene_free(sc);
}

/* Fan heights are heights on surface 1: check against an independent trace of the ray
 * aimed from the object at the surface point (h, sag(h)). */
static void aiming(const trace_api *tr)
{
    trace_lens_surface s[2];
    trace_lens l;
    char err[256];
    singlet(s, &l, 8);
    double zobj = -200, zp = tt_paraxial_image(&l, zobj);
    enum { N = 6 };
    double h[N] = {1e-5, 3, 6, 9, 11.9999, 12};
    trace_fan_ray out[N];
    int rc = tr->lens_fan(&l, zobj, 0, zp, N, h, out, err, sizeof err);
    CHECK(rc == TRACE_OK, "fan from z = -200 traced: %s", rc ? err : "");
    if (rc) return;
    for (int i = 0; i < N; i++) {
        double z1 = 50 - sqrt(2500 - h[i] * h[i]);
        double o[3] = {0, 0, zobj}, d[3] = {0, h[i], z1 - zobj}, p[3], dd[3];
        double dl = sqrt(d[1] * d[1] + d[2] * d[2]);
        d[1] /= dl;
        d[2] /= dl;
        int miss = tt_real_trace(&l, o, d, zp, p, dd);
        double zc = p[2] - p[1] * dd[2] / dd[1];
        CHECK(out[i].status == 0 && !miss, "object -200, height %g on surface 1: traced "
              "(status %d)", h[i], out[i].status);
        CHECK(fabs(out[i].h - h[i]) <= 1e-13 * 12, "height %g: met surface 1 at %.17g",
              h[i], out[i].h);
        CHECK(fabs(out[i].z_cross - zc) <= 1e-11 * fabs(zc), "height %g: axis crossing "
              "%.15g, independent trace %.15g", h[i], out[i].z_cross, zc);
    }
    /* collimated: the rim ray too */
    double hc[2] = {6, 12};
    zp = tt_paraxial_image(&l, -INFINITY);
    rc = tr->lens_fan(&l, -INFINITY, 0, zp, 2, hc, out, err, sizeof err);
    CHECK(rc == TRACE_OK && out[1].status == 0 && fabs(out[1].h - 12) < 1e-13,
          "collimated rim ray (12) traced: status %d, h %.17g", out[1].status, out[1].h);
}

/* The triplet with its second radius 7331 mm: collimated near-axis rays meet the
 * paraxial focus as the independent trace started just left of the lens says. */
static void far_radius(const trace_api *tr)
{
    trace_lens_surface s[TT_NSURF];
    trace_lens l;
    char err[256];
    tt_triplet(s, &l, 1);
    s[1].radius = 7331;
    double zp = tt_paraxial_image(&l, -INFINITY);
    double h[2] = {1e-4, 1e-3};
    trace_fan_ray out[2];
    int rc = tr->lens_fan(&l, -INFINITY, 0, zp, 2, h, out, err, sizeof err);
    CHECK(rc == TRACE_OK, "triplet R2 = 7331 traced: %s", rc ? err : "");
    if (rc) return;
    for (int i = 0; i < 2; i++) {
        double o[3] = {0, h[i], -0.01}, d[3] = {0, 0, 1}, p[3], dd[3];
        tt_real_trace(&l, o, d, zp, p, dd);
        double zc = p[2] - p[1] * dd[2] / dd[1];
        double rel = fabs(out[i].z_cross - zc) / (zp - s[TT_NSURF - 1].z);
        CHECK(out[i].status == 0 && rel < 1e-12, "h %g: crossing %.17g, independent "
              "%.17g (%.2e of the back focus)", h[i], out[i].z_cross, zc, rel);
    }
}

int main(void)
{
    const trace_api *tr = tt_api();
    crossing(tr);
    aiming(tr);
    far_radius(tr);
    return unit_failed();
}
