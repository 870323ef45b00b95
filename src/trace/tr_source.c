/* tr_source.c -- the engine's light sources: every ray of a source is computed from
 * its number alone (so rays stream in batches and any thread can make any ray):
 * explicit rays, opticrt's aimed rays, fans, hexapolar cones, collimated grids and
 * Gaussian laser beams (section 46) as hyperboloids of skew rays. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "tr_int.h"

static int finite3(const double a[3])
{
    return isfinite(a[0]) && isfinite(a[1]) && isfinite(a[2]);
}

/* u, v: orthonormal, perpendicular to the unit w; v from `up` when usable. */
static void perp_frame(const double w[3], const double up[3], double u[3], double v[3])
{
    double k = v_dot(up, w);
    for (int i = 0; i < 3; i++) v[i] = up[i] - k * w[i];
    if (v_unit(v)) {
        double a[3] = {0, 1, 0};
        if (fabs(w[1]) > 0.6) { a[1] = 0; a[0] = 1; }
        k = v_dot(a, w);
        for (int i = 0; i < 3; i++) v[i] = a[i] - k * w[i];
        v_unit(v);
    }
    v_cross(v, w, u);
    v_unit(u);
}

/* rays in rings 0..r-1 of a hexapolar pattern (1 + 6 + 12 + ...) */
static long hex_before(long r) { return r == 0 ? 0 : 1 + 3 * r * (r - 1); }

static void hex_index(long i, long *ring, long *j)
{
    long r = 0;
    if (i > 0) {
        r = (long)floor((3.0 + sqrt(9.0 + 12.0 * (double)(i - 1))) / 6.0);
        while (r > 1 && hex_before(r) > i) r--;
        while (hex_before(r + 1) <= i) r++;
    }
    *ring = r;
    *j = i - hex_before(r);
}

static int init_grid(tr_source *ts, char *err, size_t cap)
{
    long n = ts->s.count;
    double R = ts->s.radius, h = 2 * R / (double)n;
    ts->row_first = malloc((size_t)(n + 1) * sizeof *ts->row_first);
    ts->row_i0 = malloc((size_t)n * sizeof *ts->row_i0);
    if (!ts->row_first || !ts->row_i0) {
        tr_set_err(err, cap, "out of memory for a %ld x %ld grid", n, n);
        return -1;
    }
    long total = 0;
    for (long j = 0; j < n; j++) {
        double y = -R + (j + 0.5) * h, i0 = 0, i1 = -1;
        double xr2 = R * R - y * y;
        ts->row_first[j] = total;
        if (xr2 >= 0) {
            /* x_i = -R + (i + 0.5) h, keep x_i^2 + y^2 <= R^2 */
            double xr = sqrt(xr2);
            i0 = ceil((R - xr) / h - 0.5);
            i1 = floor((R + xr) / h - 0.5);
            while (i0 <= i1) {
                double x = -R + (i0 + 0.5) * h;
                if (x * x + y * y <= R * R) break;
                i0++;
            }
            while (i1 >= i0) {
                double x = -R + (i1 + 0.5) * h;
                if (x * x + y * y <= R * R) break;
                i1--;
            }
        }
        ts->row_i0[j] = (int)i0;
        if (i1 >= i0) total += (long)(i1 - i0 + 1);
    }
    ts->row_first[n] = total;
    ts->nrays = total;
    return 0;
}

static void ray_at(const tr_source *ts, long i, long row, tr_ray0 *r);

int tr_source_init(tr_source *ts, const trace_source *s, char *err, size_t cap)
{
    memset(ts, 0, sizeof *ts);
    ts->s = *s;
    ts->s.ray = NULL;
    if (ts->s.power == 0) ts->s.power = 1;
    if (ts->s.n_medium == 0) ts->s.n_medium = 1;
    if (!(ts->s.power > 0 && isfinite(ts->s.power))) {
        tr_set_err(err, cap, "source power must be positive (got %g)", s->power);
        return -1;
    }
    if (!(ts->s.n_medium > 0 && isfinite(ts->s.n_medium))) {
        tr_set_err(err, cap, "index of the medium must be positive (got %g)",
                   s->n_medium);
        return -1;
    }
    if (!(s->alpha_medium >= 0 && isfinite(s->alpha_medium)) ||
        !(s->lambda >= 0 && isfinite(s->lambda))) {
        tr_set_err(err, cap, "a source's absorption and wavelength must be numbers >= 0");
        return -1;
    }
    if (!(ts->s.power >= TR_LEN_MIN && ts->s.power <= TR_LEN_MAX) ||
        !tr_len_ok(s->radius) || !tr_len_ok(s->waist) || !tr_len_ok(s->wavelength)) {
        tr_set_err(err, cap, "source power, radius, waist and wavelength must be 0 (where "
                   "absent) or %g to %g", TR_LEN_MIN, TR_LEN_MAX);
        return -1;
    }
    if (s->type != TRACE_SRC_RAYS && !finite3(s->at)) {
        tr_set_err(err, cap, "source position is not finite");
        return -1;
    }
    if (s->type != TRACE_SRC_RAYS && s->type != TRACE_SRC_AIMED) {
        double w[3];
        v_set(w, s->dir);
        if (!finite3(w) || v_unit(w)) {
            tr_set_err(err, cap, "source direction is zero or not finite");
            return -1;
        }
        v_set(ts->s.dir, w);
        perp_frame(w, s->up, ts->u, ts->v);
    }
    if (s->count < 0 || s->count > 100000000L) {
        tr_set_err(err, cap, "bad ray count %ld", s->count);
        return -1;
    }
    switch (s->type) {
    case TRACE_SRC_RAYS:
        if (s->count < 1 || !s->ray) {
            tr_set_err(err, cap, "no rays given");
            return -1;
        }
        ts->rays = malloc((size_t)s->count * sizeof *ts->rays);
        if (!ts->rays) { tr_set_err(err, cap, "out of memory"); return -1; }
        for (long i = 0; i < s->count; i++) {
            trace_ray r = s->ray[i];
            if (!finite3(r.o) || !finite3(r.d) || v_unit(r.d) || !isfinite(r.power)) {
                tr_set_err(err, cap, "ray %ld: zero or non-finite direction or origin",
                           i + 1);
                return -1;
            }
            ts->rays[i] = r;
        }
        ts->nrays = s->count;
        break;
    case TRACE_SRC_AIMED:
        if (s->count < 1 || !finite3(s->to0) || !finite3(s->to1)) {
            tr_set_err(err, cap, "aimed rays need a count and two target points");
            return -1;
        }
        for (int e = 0; e < 2; e++) {
            const double *p = e ? s->to1 : s->to0;
            double d[3] = {p[0] - s->at[0], p[1] - s->at[1], p[2] - s->at[2]};
            if (v_unit(d)) {
                tr_set_err(err, cap, "a target point is the source point itself");
                return -1;
            }
        }
        ts->nrays = s->count;
        break;
    case TRACE_SRC_FAN:
    case TRACE_SRC_CONE:
        if (!(s->half_angle >= 0 && s->half_angle < TR_PI)) {
            tr_set_err(err, cap, "half angle must be in [0, pi) radians (got %g)",
                       s->half_angle);
            return -1;
        }
        if (s->type == TRACE_SRC_FAN) {
            if (s->count < 1) { tr_set_err(err, cap, "a fan needs rays"); return -1; }
            ts->nrays = s->count;
        } else {
            if (s->rings < 0 || s->rings > 10000) {
                tr_set_err(err, cap, "bad ring count %d", s->rings);
                return -1;
            }
            ts->nrays = hex_before(s->rings + 1);
        }
        break;
    case TRACE_SRC_GRID:
        if (!(s->radius > 0 && isfinite(s->radius)) || s->count < 1 || s->count > 100000) {
            tr_set_err(err, cap, "a grid needs a positive radius and 1..100000 rays "
                       "across");
            return -1;
        }
        if (init_grid(ts, err, cap)) return -1;
        break;
    case TRACE_SRC_GAUSSIAN:
        if (!(s->waist > 0 && isfinite(s->waist)) ||
            !(s->wavelength > 0 && isfinite(s->wavelength)) ||
            s->rings < 1 || s->rings > 10000 || s->trunc < 0 || !isfinite(s->trunc)) {
            tr_set_err(err, cap, "a Gaussian beam needs a positive waist, wavelength "
                       "and 1..10000 rings");
            return -1;
        }
        if (ts->s.trunc == 0) ts->s.trunc = 2;
        ts->nrays = hex_before(s->rings + 1);
        for (long i = 0; i < ts->nrays; i++) {
            long r, j;
            hex_index(i, &r, &j);
            double rho = ts->s.trunc * s->waist * (double)r / s->rings;
            ts->wsum += exp(-2 * rho * rho / (s->waist * s->waist));
        }
        break;
    default:
        tr_set_err(err, cap, "unknown source type %d", s->type);
        return -1;
    }
    if (ts->nrays < 1) {                /* e.g. a grid whose cells all miss its disc */
        tr_set_err(err, cap, "the source emits no ray");
        return -1;
    }
    if (s->type == TRACE_SRC_GAUSSIAN && !(ts->wsum > 0 && isfinite(ts->wsum))) {
        tr_set_err(err, cap, "the Gaussian beam's ray weights are not finite");
        return -1;
    }
    if (s->pol != TRACE_UNPOLARISED && s->pol != TRACE_LINEAR && s->pol != TRACE_ELLIPTIC &&
        s->pol != TRACE_PARTIAL) {
        tr_set_err(err, cap, "unknown polarisation %d", s->pol);
        return -1;
    }
    if (s->pol == TRACE_LINEAR && (!finite3(s->pol_dir) || v_norm(s->pol_dir) == 0)) {
        tr_set_err(err, cap, "linear polarisation needs a direction");
        return -1;
    }
    if (s->pol == TRACE_ELLIPTIC) {
        double j2 = 0;
        for (int i = 0; i < 2; i++) j2 += s->jones[i][0] * s->jones[i][0] + s->jones[i][1] * s->jones[i][1];
        if (!finite3(s->pol_dir) || !(j2 > 0) || !isfinite(j2)) {
            tr_set_err(err, cap, "a Jones vector must be finite and nonzero (its frame's "
                       "reference finite)");
            return -1;
        }
    }
    if (s->pol == TRACE_PARTIAL) {
        double q = 0;
        for (int i = 0; i < 3; i++) q += s->stokes[i] * s->stokes[i];
        if (!finite3(s->pol_dir) || !finite3(s->stokes) || !(q <= 1 + 1e-12)) {
            tr_set_err(err, cap, "a Stokes vector must be finite with S1^2 + S2^2 + S3^2 "
                       "at most S0^2 (its frame's reference finite)");
            return -1;
        }
    }
    if (s->type == TRACE_SRC_GRID) {   /* direction, power, polarisation: once */
        ray_at(ts, 0, -1, &ts->grid0);
        ts->has_grid0 = 1;
    }
    return 0;
}

void tr_source_free(tr_source *ts)
{
    free(ts->rays);
    free(ts->row_first);
    free(ts->row_i0);
    memset(ts, 0, sizeof *ts);
}

static void dir_at(const tr_source *ts, double th, double phi, double d[3])
{
    double st = sin(th), ct = cos(th), cp = cos(phi), sp = sin(phi);
    for (int i = 0; i < 3; i++)
        d[i] = ct * ts->s.dir[i] + st * (cp * ts->u[i] + sp * ts->v[i]);
}

/* The Jones frame's x' for a ray along d (TRACE_ELLIPTIC, TRACE_PARTIAL): the reference pol_dir (zero:
 * +x) projected perpendicular to d, or for d within 25 degrees of it z x ref (+y if
 * that is zero) projected -- tr_polar.c's rule for the Stokes frame. */
static void jones_frame(const double ref0[3], const double d[3], double x[3])
{
    double ref[3] = {ref0[0], ref0[1], ref0[2]}, alt[3];
    if (v_unit(ref)) { ref[0] = 1; ref[1] = ref[2] = 0; }
    alt[0] = -ref[1];                    /* z x ref */
    alt[1] = ref[0];
    alt[2] = 0;
    if (!(v_norm(alt) > 1e-6)) { alt[0] = 0; alt[1] = 1; alt[2] = 0; }
    v_unit(alt);
    const double *r = fabs(v_dot(ref, d)) > 0.90630778703665 ? alt : ref;
    double c = v_dot(r, d);
    for (int i = 0; i < 3; i++) x[i] = r[i] - c * d[i];
    v_unit(x);
}

static void set_pol(const tr_source *ts, tr_ray0 *r)
{
    double e[3], k;
    if (ts->s.pol == TRACE_ELLIPTIC) {   /* the coherency J J^H in (x', d x x') */
        const double (*j)[2] = ts->s.jones;
        double a = j[0][0] * j[0][0] + j[0][1] * j[0][1];
        double b = j[1][0] * j[1][0] + j[1][1] * j[1][1], w = r->power / (a + b);
        jones_frame(ts->s.pol_dir, r->d, r->pol.e);
        r->pol.jss = w * a;
        r->pol.jpp = w * b;
        r->pol.jre = w * (j[0][0] * j[1][0] + j[0][1] * j[1][1]);   /* Jx conj(Jy) */
        r->pol.jim = w * (j[0][1] * j[1][0] - j[0][0] * j[1][1]);
        return;
    }
    if (ts->s.pol == TRACE_PARTIAL) {    /* Jx conj(Jy) = (S2 - i S3) / 2 */
        const double *st = ts->s.stokes, w = 0.5 * r->power;
        jones_frame(ts->s.pol_dir, r->d, r->pol.e);
        r->pol.jss = w * (1 + st[0]);
        r->pol.jpp = w * (1 - st[0]);
        r->pol.jre = w * st[1];
        r->pol.jim = -w * st[2];
        return;
    }
    if (ts->s.pol == TRACE_LINEAR) v_set(e, ts->s.pol_dir);
    else { e[0] = 1; e[1] = 0; e[2] = 0; }
    k = v_dot(e, r->d);
    for (int i = 0; i < 3; i++) e[i] -= k * r->d[i];
    if (v_unit(e)) {                       /* e parallel to d: any perpendicular */
        double a[3] = {0, 1, 0};
        if (fabs(r->d[1]) > 0.6) { a[1] = 0; a[2] = 1; }
        k = v_dot(a, r->d);
        for (int i = 0; i < 3; i++) e[i] = a[i] - k * r->d[i];
        v_unit(e);
    }
    v_set(r->pol.e, e);
    r->pol.jre = r->pol.jim = 0;
    if (ts->s.pol == TRACE_LINEAR) { r->pol.jss = r->power; r->pol.jpp = 0; }
    else r->pol.jss = r->pol.jpp = 0.5 * r->power;
}

/* GRID: the last row whose first ray is <= i */
static long grid_row(const tr_source *ts, long i)
{
    long lo = 0, hi = ts->s.count - 1;
    while (lo < hi) {
        long mid = (lo + hi + 1) / 2;
        if (ts->row_first[mid] <= i) lo = mid; else hi = mid - 1;
    }
    return lo;
}

/* Ray i; row: its grid row if known, else -1. */
/* GRID: the origin of ray i (in row `row` if known, else -1). */
static void grid_origin(const tr_source *ts, long i, long row, double o[3])
{
    const trace_source *s = &ts->s;
    long n = s->count, lo = row >= 0 ? row : grid_row(ts, i);
    double h = 2 * s->radius / (double)n;
    double y = -s->radius + (lo + 0.5) * h;
    double x = -s->radius + ((double)ts->row_i0[lo] + (double)(i - ts->row_first[lo])
                             + 0.5) * h;
    for (int k = 0; k < 3; k++) o[k] = s->at[k] + x * ts->u[k] + y * ts->v[k];
}

static void ray_at(const tr_source *ts, long i, long row, tr_ray0 *r)
{
    const trace_source *s = &ts->s;
    if (ts->has_grid0) {   /* a collimated grid: its rays differ only in their origin */
        *r = ts->grid0;
        grid_origin(ts, i, row, r->o);
        return;
    }
    double each = s->power / (double)ts->nrays;
    v_set(r->o, s->at);
    r->power = each;
    r->n = s->n_medium;
    r->lambda = s->lambda;
    r->alpha = s->alpha_medium;
    switch (s->type) {
    case TRACE_SRC_RAYS:
        v_set(r->o, ts->rays[i].o);
        v_set(r->d, ts->rays[i].d);
        if (ts->rays[i].power > 0) r->power = ts->rays[i].power;
        break;
    case TRACE_SRC_AIMED: {
        double t = ts->nrays > 1 ? (double)i / (double)(ts->nrays - 1) : 0;
        for (int k = 0; k < 3; k++)
            r->d[k] = ((1 - t) * s->to0[k] + t * s->to1[k]) - s->at[k];
        break;
    }
    case TRACE_SRC_FAN: {
        double a = ts->nrays > 1 ?
            -s->half_angle + 2 * s->half_angle * (double)i / (double)(ts->nrays - 1) : 0;
        dir_at(ts, fabs(a), a < 0 ? TR_PI / 2 + TR_PI : TR_PI / 2, r->d);
        break;
    }
    case TRACE_SRC_CONE: {
        long ring, j;
        hex_index(i, &ring, &j);
        double th = s->rings ? s->half_angle * (double)ring / s->rings : 0;
        double phi = ring ? 2 * TR_PI * (double)j / (6.0 * ring) : 0;
        dir_at(ts, th, phi, r->d);
        break;
    }
    case TRACE_SRC_GRID:
        grid_origin(ts, i, row, r->o);
        v_set(r->d, s->dir);
        break;
    case TRACE_SRC_GAUSSIAN: {
        long ring, j;
        hex_index(i, &ring, &j);
        double w0 = s->waist, rho = s->trunc * w0 * (double)ring / s->rings;
        double phi = ring ? 2 * TR_PI * (double)j / (6.0 * ring) : 0;
        double th0 = s->wavelength / (TR_PI * w0);     /* far-field half angle */
        double cx = cos(phi), sy = sin(phi), g = th0 * rho / w0;
        for (int k = 0; k < 3; k++) {
            r->o[k] = s->at[k] + rho * (cx * ts->u[k] + sy * ts->v[k]);
            /* skew: transverse slope th0 rho / w0 along the azimuthal direction */
            r->d[k] = s->dir[k] + g * (-sy * ts->u[k] + cx * ts->v[k]);
        }
        r->power = s->power * exp(-2 * rho * rho / (w0 * w0)) / ts->wsum;
        break;
    }
    }
    v_unit(r->d);
    set_pol(ts, r);
}

void tr_source_ray(const tr_source *ts, long i, tr_ray0 *r)
{
    ray_at(ts, i, -1, r);
}

void tr_source_rays(const tr_source *ts, long i, long n, tr_ray0 *r)
{
    if (ts->s.type != TRACE_SRC_GRID) {
        for (long k = 0; k < n; k++) ray_at(ts, i + k, -1, &r[k]);
        return;
    }
    long row = grid_row(ts, i);
    for (long k = 0; k < n; k++) {
        while (row + 1 < ts->s.count && ts->row_first[row + 1] <= i + k) row++;
        ray_at(ts, i + k, row, &r[k]);
    }
}
