/* t_stokes.c -- the engine's elliptical sources (trace_source.pol = TRACE_ELLIPTIC,
 * src/trace/tr_source.c and tr_polar.c) through its table: a Jones vector of any length
 * in the Stokes frame gives, at a detector straight ahead, the Stokes parameters of the
 * ellipse's closed form S/S0 = (cos 2c cos 2p, cos 2c sin 2p, sin 2c) (computed here
 * from the azimuth and ellipticity, not from the Jones vector), in the frame x' = the
 * reference projected perpendicular to the ray (computed here), for oblique rays, for
 * a reference of (0, 1, 0) and for rays within 25 degrees of the reference (its twin
 * z x ref); without polarization the coherency path's s and p powers are the closed
 * form's |Jx'|^2 and |Jy'|^2 at normal incidence; bad states are refused. */
#include <complex.h>
#include <stdio.h>
#include "unit.h"
#include "tt.h"

static const trace_api *tr;
#define PI 3.14159265358979323846

typedef struct rec { trace_hit h[8]; trace_polar_hit p[8]; int n, np; } rec;
static int keep_hit(void *ctx, const trace_hit *h)
{
    rec *x = ctx;
    if (x->n < 8) x->h[x->n++] = *h;
    return 0;
}
static int keep_pol(void *ctx, const trace_polar_hit *p)
{
    rec *x = ctx;
    if (x->np < 8) x->p[x->np++] = *p;
    return 0;
}

/* The Jones vector of the ellipse (psi, chi), times k, with a common phase g. */
static void jones_of(double psi, double chi, double k, double g, double j[2][2])
{
    double complex a = cos(psi) * cos(chi) - I * sin(psi) * sin(chi);
    double complex b = sin(psi) * cos(chi) + I * cos(psi) * sin(chi);
    a *= k * cexp(I * g);
    b *= k * cexp(I * g);
    j[0][0] = creal(a); j[0][1] = cimag(a);
    j[1][0] = creal(b); j[1][1] = cimag(b);
}

/* One ray from the origin along d (unit) to a detector sphere of radius 10, the state
 * (psi, chi) in the frame of ref; polar: trace P with that reference.  0 or -1. */
static int one(const double d[3], const double ref[3], double psi, double chi, int polar,
               rec *x, char *why)
{
    trace_scene *sc = tr->scene_new();
    trace_ray r = {{0, 0, 0}, {d[0], d[1], d[2]}, 0};
    trace_source s = {0};
    s.type = TRACE_SRC_RAYS;
    s.count = 1;
    s.ray = &r;
    s.power = 2;
    s.pol = TRACE_ELLIPTIC;
    if (ref) memcpy(s.pol_dir, ref, sizeof s.pol_dir);
    jones_of(psi, chi, 3.5, 0.7, s.jones);
    trace_surface f = {0};
    trace_material m = {TRACE_DETECT, 1, 1};
    f.shape = TRACE_SPHERE;
    f.radius = 10;
    trace_options o;
    tr->options_default(&o);
    o.threads = 1;
    trace_sink k = {x, NULL, keep_hit, NULL};
    trace_summary sum;
    x->n = x->np = 0;
    (void)why;
    int rc = tr->add_source(sc, &s, NULL) < 0 || tr->add_surface(sc, &f, &m) < 0 ||
             (polar && tr->polarization(sc, 1, ref, keep_pol, x)) ||
             tr->run(sc, &o, &k, &sum) != TRACE_OK || x->n != 1 || x->np != (polar ? 1 : 0) ||
             fabs(sum.detected - 2) > 1e-13 ? -1 : 0;
    tr->scene_free(sc);
    return rc;
}

/* x' of the Stokes frame for a ray along d (unit), ref (NULL: +x), independently. */
static void frame(const double d[3], const double *ref, double x[3])
{
    double r[3] = {1, 0, 0};
    if (ref) memcpy(r, ref, sizeof r);
    double l = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (int i = 0; i < 3; i++) r[i] /= l;
    if (fabs(r[0] * d[0] + r[1] * d[1] + r[2] * d[2]) > cos(25 * PI / 180)) {
        double a[3] = {-r[1], r[0], 0};   /* z x ref */
        l = sqrt(a[0] * a[0] + a[1] * a[1]);
        if (l < 1e-6) { a[0] = 0; a[1] = 1; l = 1; }
        for (int i = 0; i < 3; i++) r[i] = a[i] / l;
    }
    double c = r[0] * d[0] + r[1] * d[1] + r[2] * d[2];
    for (int i = 0; i < 3; i++) x[i] = r[i] - c * d[i];
    l = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    for (int i = 0; i < 3; i++) x[i] /= l;
}

static void unit3(double d[3])
{
    double l = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int i = 0; i < 3; i++) d[i] /= l;
}

int main(void)
{
    tr = tt_api();
    char why[256];
    rec x;
    static const double states[][2] = {{0, 0}, {35, -15}, {-70, 30}, {120, 45}, {10, -45}};
    double dirs[][3] = {{0, 0, 1}, {0.3, -0.2, 0.93}, {0.95, 0.2, 0.1}, {0, 1, 0}};
    const double yref[3] = {0, 1, 0};
    for (int di = 0; di < 4; di++) {
        unit3(dirs[di]);
        for (int ri = 0; ri < 2; ri++) {
            const double *ref = ri ? yref : NULL;
            double worst = 0, fx = 0;
            int ok = 1;
            for (int k = 0; k < 5; k++) {
                double p = states[k][0] * PI / 180, c = states[k][1] * PI / 180;
                if (one(dirs[di], ref, p, c, 1, &x, why)) { ok = 0; break; }
                const trace_polar_hit *h = &x.p[0];
                double want[4] = {2, 2 * cos(2 * c) * cos(2 * p), 2 * cos(2 * c) * sin(2 * p),
                                  2 * sin(2 * c)}, xr[3];
                for (int i = 0; i < 4; i++) worst = fmax(worst, fabs(h->stokes[i] - want[i]));
                frame(dirs[di], ref, xr);
                for (int i = 0; i < 3; i++) fx = fmax(fx, fabs(h->xref[i] - xr[i]));
            }
            CHECK(ok && worst < 1e-13 && fx < 1e-15,
                  "dir %d, ref %s: 5 elliptical states' Stokes = the (azimuth, ellipticity) "
                  "closed form (worst %.2g), frame x' as computed here (%.2g)", di,
                  ri ? "+y" : "+x", worst, fx);
        }
    }
    /* the coherency path (no polarization), normal incidence on the detector: the s
     * basis is the source's x' (the ray meets nothing before), so power_s = P (1 + S1)/2 */
    double worst = 0;
    int ok = 1;
    for (int k = 0; k < 5; k++) {
        double p = states[k][0] * PI / 180, c = states[k][1] * PI / 180;
        if (one(dirs[1], NULL, p, c, 0, &x, why)) { ok = 0; break; }
        double s1 = cos(2 * c) * cos(2 * p);
        worst = fmax(worst, fabs(x.h[0].power_s - (1 + s1)) + fabs(x.h[0].power_p - (1 - s1)));
    }
    CHECK(ok && worst < 1e-13, "without polarization: power_s, power_p = P (1 +- S1)/2 (%.2g)",
          worst);

    /* refusals */
    trace_scene *sc = tr->scene_new();
    trace_ray r = {{0, 0, 0}, {0, 0, 1}, 0};
    trace_source s = {0};
    s.type = TRACE_SRC_RAYS;
    s.count = 1;
    s.ray = &r;
    s.pol = TRACE_ELLIPTIC;
    why[0] = 0;
    int zero = tr->add_source(sc, &s, NULL);
    snprintf(why, sizeof why, "%s", tr->error(sc));
    CHECK(zero < 0 && strstr(why, "Jones vector"), "a zero Jones vector is refused (%s)", why);
    s.jones[0][0] = NAN;
    CHECK(tr->add_source(sc, &s, NULL) < 0, "a NaN Jones vector is refused");
    s.jones[0][0] = 1;
    s.pol_dir[1] = INFINITY;
    CHECK(tr->add_source(sc, &s, NULL) < 0, "an infinite frame reference is refused");
    s.pol_dir[1] = 0;
    s.pol = TRACE_PARTIAL + 1;
    CHECK(tr->add_source(sc, &s, NULL) < 0, "an unknown polarization kind is refused");
    s.pol = TRACE_PARTIAL;
    s.stokes[0] = 0.6; s.stokes[1] = 0.8; s.stokes[2] = 1e-3;
    CHECK(tr->add_source(sc, &s, NULL) < 0, "a Stokes vector longer than 1 is refused (%s)",
          tr->error(sc));
    s.stokes[2] = NAN;
    CHECK(tr->add_source(sc, &s, NULL) < 0, "a NaN Stokes vector is refused");
    s.stokes[2] = 0;
    CHECK(tr->add_source(sc, &s, NULL) >= 0, "Stokes (0.6, 0.8, 0): fully polarized, taken");
    s.pol = TRACE_ELLIPTIC;
    CHECK(tr->add_source(sc, &s, NULL) >= 0, "Jones (1, 0) is taken");
    tr->scene_free(sc);
    return unit_failed();
}
