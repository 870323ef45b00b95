/* pub.h -- published lenses for the trace engine's test and bench (t_published.c,
 * bench_published.c): a prescription file of tests/published/ read into a
 * trace_lens with its glasses' indices at d evaluated here from data/glass.txt's
 * Sellmeier coefficients (no paraxial-engine code: the trace tests link the module
 * only), the real chief ray aimed at the centre of the stop with tt.h's independent
 * trace, and spot figures of a collimated field: the RMS radius about the chief ray,
 * unweighted (as lens tracers report it), and power-weighted (Fresnel's s + p powers)
 * about the chief ray and about the power centroid.  Run from the top of the tree. */
#ifndef PUB_H
#define PUB_H
#include <stdio.h>
#include <string.h>
#include <strings.h>
#include "tt.h"
#include "bench_util.h"

#define PUB_MAXS 16
#define PUB_PI 3.14159265358979323846
#define PUB_LAMBDA_D 0.5875618

typedef struct pub_lens {
    trace_lens_surface s[PUB_MAXS];
    trace_lens lens;
    int nsurf;
} pub_lens;

/* n at lambda (um) of catalogue glass `name` (data/glass.txt, models sellmeier and
 * const), a plain number, or "1"; 0 if unknown. */
static double pub_index(const char *name, double lambda)
{
    char *end;
    double v = strtod(name, &end);
    if (*end == '\0' && end != name) return v;
    FILE *f = fopen("data/glass.txt", "r");
    char line[512];
    double n = 0;
    if (!f) return 0;
    while (fgets(line, sizeof line, f)) {
        char nm[64], model[32];
        double c[12];
        int off, k = 0;
        if (line[0] == '#' || sscanf(line, "%63s %31s%n", nm, model, &off) != 2) continue;
        if (strcasecmp(nm, name)) continue;
        char *p = line + off;
        /* LMIN LMAX ND VD, then the coefficients ("-" for a missing nd or vd) */
        for (int skip = 0; skip < 4; skip++) { while (*p == ' ') p++; while (*p && *p != ' ') p++; }
        while (k < 12) {
            double x = strtod(p, &end);
            if (end == p) break;
            c[k++] = x; p = end;
        }
        if (!strcmp(model, "const") && k >= 1) n = c[0];
        else if (!strcmp(model, "sellmeier")) {
            double l2 = lambda * lambda, s = 1;
            for (int i = 0; i + 1 < k; i += 2) s += c[i] * l2 / (l2 - c[i + 1]);
            n = sqrt(s);
        }
        break;
    }
    fclose(f);
    return n;
}

/* A prescription file of lensmat's format (index line, "radius position index"
 * lines, keywords skipped); semi-diameters sd[] (NULL: none, mounts off). */
static int pub_read(const char *path, const double *sd, pub_lens *pl)
{
    FILE *f = fopen(path, "r");
    char line[256];
    double nobj = 1;
    memset(pl, 0, sizeof *pl);
    if (!f) { printf("FAIL cannot open %s\n", path); return -1; }
    while (fgets(line, sizeof line, f)) {
        char a[40], b[40], c[40], *hash = strchr(line, '#');
        if (hash) *hash = '\0';
        int k = sscanf(line, "%39s %39s %39s", a, b, c);
        if (k <= 0) continue;
        if (!strcmp(a, "index") && k >= 2) { nobj = pub_index(b, PUB_LAMBDA_D); continue; }
        if (!strcmp(a, "object") || !strcmp(a, "nearpoint") || !strcmp(a, "wavelength")) continue;
        if (k != 3 || pl->nsurf == PUB_MAXS) { fclose(f); return -1; }
        trace_lens_surface *s = &pl->s[pl->nsurf];
        s->radius = strtod(a, NULL);
        s->z = strtod(b, NULL);
        s->n_right = pub_index(c, PUB_LAMBDA_D);
        s->semi_diameter = sd ? sd[pl->nsurf] : 0;
        if (!(s->n_right > 0)) { printf("FAIL %s: no index for %s\n", path, c); fclose(f); return -1; }
        pl->nsurf++;
    }
    fclose(f);
    pl->lens.n_object = nobj;
    pl->lens.nsurf = pl->nsurf;
    pl->lens.surf = pl->s;
    pl->lens.mounts = sd != NULL;
    pl->lens.z_detector = NAN;
    return 0;
}

/* The collimated ray at field angle theta (y-z plane) that starts on the plane
 * z = z0 at height y0: direction d. */
static void pub_dir(double theta, double d[3])
{
    d[0] = 0; d[1] = sin(theta); d[2] = cos(theta);
}

/* Height where that ray crosses the axis plane of surface `stop` (traced through
 * the surfaces before it with tt.h's independent double trace). */
static int pub_at_stop(const pub_lens *pl, int stop, double theta, double z0, double y0,
                       double *y)
{
    trace_lens l = pl->lens;
    double o[3] = {0, y0, z0}, d[3], p[3], dd[3];
    pub_dir(theta, d);
    l.nsurf = stop;
    if (tt_real_trace(&l, o, d, pl->s[stop].z, p, dd)) return -1;
    *y = p[1];
    return 0;
}

/* y0 on z = z0 of the real chief ray (through the stop's centre): secant from the
 * paraxial entrance pupil at z_enp.  Returns the residual height at the stop. */
static double pub_aim_chief(const pub_lens *pl, int stop, double theta, double z0,
                            double z_enp, double *y0)
{
    double a = -(z_enp - z0) * tan(theta), b = a + 0.01, fa, fb;
    if (pub_at_stop(pl, stop, theta, z0, a, &fa) || pub_at_stop(pl, stop, theta, z0, b, &fb))
        return INFINITY;
    for (int i = 0; i < 40 && fb != 0 && fb != fa; i++) {
        double c = b - fb * (b - a) / (fb - fa), fc;
        if (pub_at_stop(pl, stop, theta, z0, c, &fc)) return INFINITY;
        a = b; fa = fb; b = c; fb = fc;
        if (fabs(fb) < 1e-13) break;
    }
    *y0 = b;
    return fb;
}

/* The rays of a field: the chief ray first (ray 0), then a square grid of across x
 * across cell centres over the disc of radius r_pupil on the entrance-pupil plane
 * z_enp centred where the chief ray crosses it (cells outside the disc dropped), all
 * parallel to the field direction, started on z = z0.  Returns the count (ray[]
 * malloc'd), or -1. */
static long pub_field_rays(double theta, double z0, double y0_chief, double z_enp,
                           double r_pupil, long across, trace_ray **out)
{
    double d[3], cell = 2 * r_pupil / across;
    pub_dir(theta, d);
    double tl = (z_enp - z0) / d[2], yc = y0_chief + tl * d[1];   /* chief at the pupil */
    trace_ray *r = malloc(sizeof *r * (size_t)(across * across + 1));
    long n = 0;
    if (!r) return -1;
    memset(r, 0, sizeof *r);
    r[0].o[1] = y0_chief; r[0].o[2] = z0;
    memcpy(r[0].d, d, sizeof d);
    n = 1;
    for (long i = 0; i < across; i++)
        for (long j = 0; j < across; j++) {
            double px = -r_pupil + (i + 0.5) * cell, py = -r_pupil + (j + 0.5) * cell;
            if (px * px + py * py > r_pupil * r_pupil) continue;
            trace_ray *q = &r[n++];
            q->o[0] = px - tl * d[0];
            q->o[1] = yc + py - tl * d[1];
            q->o[2] = z0;
            memcpy(q->d, d, sizeof d);
            q->power = 0;
        }
    *out = r;
    return n;
}

/* Spot sums about the chief ray's hit (ray 0, which arrives first: hits come in ray
 * order), the chief ray itself left out. */
typedef struct pub_spot {
    int have_chief;
    double cx, cy;                    /* the chief ray's hit */
    double n, s2;                     /* unweighted: count, sum |p - c|^2 */
    double w, ws2, wx, wy;            /* power-weighted: sum w, w |p - c|^2, w (p - c) */
    long hits;
} pub_spot;

static int pub_spot_hit(void *ctx, const trace_hit *h)
{
    pub_spot *s = ctx;
    if (h->ray == 0) { s->have_chief = 1; s->cx = h->pos[0]; s->cy = h->pos[1]; return 0; }
    if (!s->have_chief) return 1;      /* vignetted chief ray: no reference */
    double x = h->pos[0] - s->cx, y = h->pos[1] - s->cy, w = h->power_s + h->power_p;
    s->n += 1; s->s2 += x * x + y * y;
    s->w += w; s->ws2 += w * (x * x + y * y); s->wx += w * x; s->wy += w * y;
    s->hits++;
    return 0;
}

typedef struct pub_result {
    double rays_per_s;
    double rms_chief_um;              /* unweighted, about the chief ray */
    double rms_power_chief_um;        /* power-weighted, about the chief ray */
    double rms_power_centroid_um;     /* power-weighted, about the power centroid */
    double transmitted;               /* detected / emitted power */
    long rays, hits;                  /* grid rays (chief excluded), their hits */
    double chief_y;                   /* the chief ray's image height */
} pub_result;

/* Trace the field through the lens onto the detector plane z_det (Fresnel on,
 * reflections off: sequential), `threads` threads.  rays != NULL: those nrays rays
 * (chief first); rays == NULL: on axis, the chief ray (the axis) and then the
 * engine's collimated grid source of nrays x nrays cells over the disc of radius
 * r_grid (the workload of bench_trace's triplet figure). */
static int pub_trace(const trace_api *tr, const pub_lens *pl, double z_det,
                     const trace_ray *rays, long nrays, double r_grid, int threads,
                     pub_result *res)
{
    trace_lens l = pl->lens;
    trace_ray axis = {{0, 0, -5}, {0, 0, 1}, 1};
    l.z_detector = z_det;
    trace_scene *sc = tr->scene_new();
    if (!sc) return -1;
    if (tr->add_lens(sc, &l) < 0) { printf("FAIL add_lens: %s\n", tr->error(sc)); tr->scene_free(sc); return -1; }
    trace_source src = {0};
    src.type = TRACE_SRC_RAYS;
    src.ray = rays ? rays : &axis;
    src.count = rays ? nrays : 1;
    src.power = rays ? src.count : 1e-12;  /* each ray power 1; the lone axis ray next
                                              to the grid (power 1 in all) weighs nothing */
    if (tr->add_source(sc, &src, NULL) != TRACE_OK) { tr->scene_free(sc); return -1; }
    if (!rays) {
        trace_source g = {0};
        g.type = TRACE_SRC_GRID;
        g.at[2] = -5; g.dir[2] = 1; g.up[1] = 1;
        g.radius = r_grid;
        g.count = nrays;
        if (tr->add_source(sc, &g, NULL) != TRACE_OK) { tr->scene_free(sc); return -1; }
    }
    trace_options o;
    tr->options_default(&o);
    o.threads = threads;
    o.reflections = 0;
    pub_spot sp = {0};
    trace_sink sink = {&sp, NULL, pub_spot_hit, NULL};
    trace_summary sum;
    tr->build(sc, NULL);
    double t0 = now();
    int rc = tr->run(sc, &o, &sink, &sum);
    double dt = now() - t0;
    tr->scene_free(sc);
    if (rc != TRACE_OK || !sp.have_chief || sp.n == 0) return -1;
    double mx = sp.wx / sp.w, my = sp.wy / sp.w;
    res->rays_per_s = sum.rays / dt;
    res->rms_chief_um = 1e3 * sqrt(sp.s2 / sp.n);
    res->rms_power_chief_um = 1e3 * sqrt(sp.ws2 / sp.w);
    res->rms_power_centroid_um = 1e3 * sqrt(sp.ws2 / sp.w - mx * mx - my * my);
    res->transmitted = sum.detected / sum.emitted;
    res->rays = sum.rays - 1;
    res->hits = sp.hits;
    res->chief_y = sp.cy;
    return 0;
}

static int pub_trace_field(const trace_api *tr, const pub_lens *pl, double z_det,
                           const trace_ray *rays, long nrays, int threads, pub_result *res)
{
    return pub_trace(tr, pl, z_det, rays, nrays, 0, threads, res);
}

/* Sasian's triplet: the prescription file, the published semi-diameters (ray-optics'
 * listing: the bundle of its 0, 14 and 20 degree fields), stop surface 3, entrance
 * pupil 11.68 mm behind surface 1 (paraxial; pub_enp computes it), EPD 12.5, 20 deg,
 * image plane 41.2365 past the last surface (the prescription's). */
#define PUB_SASIAN "tests/published/sasian_triplet.txt"
static const double pub_sasian_sd[6] = {10.009, 8.9482, 4.7919, 4.7761, 8.0217, 8.3321};
#define PUB_SASIAN_STOP 2
#define PUB_SASIAN_EPD 12.5
#define PUB_SASIAN_FIELD 20.0
#define PUB_SASIAN_IMAGE 41.2365

/* Paraxial entrance pupil: z of the image of the stop's centre in object space.
 * The y-nu rays (y = 1, u = 0) and (y = 0, u = 1) at surface 1, traced to the stop,
 * combine into the chief ray (yb, 1) that meets the stop on the axis; in object
 * space it crosses the axis at z1 - yb. */
static double pub_enp(const pub_lens *pl, int stop)
{
    double h[2];
    for (int r = 0; r < 2; r++) {
        double y = r ? 0 : 1, u = r ? 1 : 0, n = pl->lens.n_object, z = pl->s[0].z;
        for (int i = 0; i < stop; i++) {
            const trace_lens_surface *s = &pl->s[i];
            if (i) { y += u * (s->z - z); z = s->z; }
            double c = (isfinite(s->radius) && s->radius != 0) ? 1 / s->radius : 0;
            u = (n * u - y * (s->n_right - n) * c) / s->n_right;
            n = s->n_right;
        }
        y += u * (pl->s[stop].z - z);
        h[r] = y;
    }
    /* chief ray (yb, 1): yb h0 + h1 = 0 at the stop; it crosses the axis at -yb */
    return pl->s[0].z - (-h[1] / h[0]);
}

#endif
