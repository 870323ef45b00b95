/* im_synth.c -- synthetic detector frames: the laser spot (analytic, tracer hits binned
 * by exact pixel-area overlap, or hits splatted with the Gaussian beam profile of the
 * seed's section 46), stray light, dark current, photon shot noise, read noise, the
 * converter's gain, bias, bit depth and saturation.
 *
 * Determinism: every row draws its random numbers from its own generator, seeded from
 * (seed, row) by SplitMix64, so a frame is the same bits whatever the thread count.
 * Generator: xoshiro256**.  Gaussian deviates: Marsaglia and Tsang's ziggurat, inline
 * here with the box index and the value from separate bits (Doornik's fix): GSL's
 * gsl_ran_gaussian_ziggurat through a wrapped gsl_rng costs 2.1 ms per 640x480 frame,
 * over the 2 ms budget.  Poisson: GSL below a mean of 10, PTRS above. */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include "im_int.h"

/* ---- generator -------------------------------------------------------------------- */
typedef struct { uint64_t s[4]; } xo_state;

static inline uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
static inline uint64_t xo_next(xo_state *x)
{
    uint64_t *s = x->s, r = rotl(s[1] * 5, 7) * 9, t = s[1] << 17;
    s[2] ^= s[0]; s[3] ^= s[1]; s[1] ^= s[2]; s[0] ^= s[3]; s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return r;
}
static uint64_t splitmix(uint64_t *z)
{
    uint64_t r = (*z += 0x9e3779b97f4a7c15ull);
    r = (r ^ (r >> 30)) * 0xbf58476d1ce4e5b9ull;
    r = (r ^ (r >> 27)) * 0x94d049bb133111ebull;
    return r ^ (r >> 31);
}
static void xo_seed(xo_state *x, uint64_t seed, uint64_t stream)
{
    uint64_t z = seed ^ (stream * 0xd1b54a32d192ed03ull);
    for (int i = 0; i < 4; i++) x->s[i] = splitmix(&z);
}
static void xo_set(void *st, unsigned long s) { xo_seed(st, s, 0); }
static unsigned long xo_get(void *st) { return (unsigned long)(xo_next(st) >> 32); }
static double xo_double(void *st) { return (double)(xo_next(st) >> 11) * 0x1.0p-53; }
static const gsl_rng_type xo_type = {"xoshiro256**", 0xffffffffUL, 0, sizeof(xo_state),
                                     xo_set, xo_get, xo_double};

/* ---- Gaussian: ziggurat with 128 boxes ------------------------------------------ */
static uint32_t zk[128];
static double zw[128], zf[128];
static pthread_once_t zig_once = PTHREAD_ONCE_INIT;

static void zig_init(void)
{
    const double m1 = 2147483648.0, vn = 9.91256303526217e-3;
    double dn = 3.442619855899, tn = dn, q = vn / exp(-0.5 * dn * dn);
    zk[0] = (uint32_t)((dn / q) * m1);
    zk[1] = 0;
    zw[0] = q / m1;
    zw[127] = dn / m1;
    zf[0] = 1;
    zf[127] = exp(-0.5 * dn * dn);
    for (int i = 126; i >= 1; i--) {
        dn = sqrt(-2 * log(vn / dn + exp(-0.5 * dn * dn)));
        zk[i + 1] = (uint32_t)((dn / tn) * m1);
        tn = dn;
        zf[i] = exp(-0.5 * dn * dn);
        zw[i] = dn / m1;
    }
}

static double zig_slow(xo_state *st, int32_t hz, int iz)
{
    const double r = 3.442619855899;
    for (;;) {
        double x = hz * zw[iz];
        if (iz == 0) {                          /* the tail beyond r */
            double y;
            do {
                x = -log(1 - xo_double(st)) / r;
                y = -log(1 - xo_double(st));
            } while (y + y < x * x);
            return hz > 0 ? r + x : -r - x;
        }
        if (zf[iz] + xo_double(st) * (zf[iz - 1] - zf[iz]) < exp(-0.5 * x * x)) return x;
        uint64_t u = xo_next(st);
        iz = (int)(u & 127);
        hz = (int32_t)(u >> 32);
        uint32_t a = hz < 0 ? (uint32_t)(-(int64_t)hz) : (uint32_t)hz;
        if (a < zk[iz]) return hz * zw[iz];
    }
}

static inline double gauss(xo_state *st)
{
    uint64_t u = xo_next(st);
    int iz = (int)(u & 127);
    int32_t hz = (int32_t)(u >> 32);
    uint32_t a = hz < 0 ? (uint32_t)(-(int64_t)hz) : (uint32_t)hz;
    if (__builtin_expect(a < zk[iz], 1)) return hz * zw[iz];
    return zig_slow(st, hz, iz);
}

/* Poisson deviates.  Small means: GSL.  Means >= 10: Hoermann's transformed rejection
 * with squeeze (PTRS, 1993; as in NumPy), exact and ~20x faster than GSL's gamma
 * recursion there; its constants are kept while the mean stays the same (the
 * background of a whole row). */
typedef struct ptrs {
    double mu, smu, b, a, inv_alpha, vr, log_mu, log_ia;
} ptrs;
static double poisson(gsl_rng *r, ptrs *c, double mu)
{
    if (mu < 10) return (double)gsl_ran_poisson(r, mu);
    if (mu != c->mu) {
        c->mu = mu;
        c->smu = sqrt(mu);
        c->b = 0.931 + 2.53 * c->smu;
        c->a = -0.059 + 0.02483 * c->b;
        c->inv_alpha = 1.1239 + 1.1328 / (c->b - 3.4);
        c->vr = 0.9277 - 3.6224 / (c->b - 2);
        c->log_mu = log(mu);
        c->log_ia = log(c->inv_alpha);
    }
    for (;;) {
        double U = xo_double(r->state) - 0.5, V = xo_double(r->state);
        double us = 0.5 - fabs(U);
        double k = floor((2 * c->a / us + c->b) * U + mu + 0.43);
        if (us >= 0.07 && V <= c->vr) return k;
        if (k < 0 || (us < 0.013 && V > us)) continue;
        if (log(V) + c->log_ia - log(c->a / (us * us) + c->b) <=
            -mu + k * c->log_mu - lgamma(k + 1))
            return k;
    }
}

/* ---- geometry and signal layers ------------------------------------------------ */
typedef struct geom {
    double o[3], ex[3], ey[3], pitch, cx, cy;
} geom;

/* A dense patch of expected signal electrons over [x0,x1) x [y0,y1). */
typedef struct layer {
    int x0, y0, x1, y1;
    double *e;
} layer;

static double dot3(const double *a, const double *b) { return a[0]*b[0] + a[1]*b[1] + a[2]*b[2]; }

static int make_geom(const im_sensor *s, geom *g, char *err, size_t cap)
{
    double n;
    memcpy(g->o, s->origin, sizeof g->o);
    memcpy(g->ex, s->xdir, sizeof g->ex);
    memcpy(g->ey, s->ydir, sizeof g->ey);
    if (dot3(g->ex, g->ex) == 0 && dot3(g->ey, g->ey) == 0) {
        g->ex[0] = 1; g->ey[1] = 1;                  /* default: sensor in the xy plane */
    }
    n = sqrt(dot3(g->ex, g->ex));
    if (!(n > 0) || !isfinite(n)) return im_err(err, cap, IM_EINVAL, "sensor xdir is zero");
    for (int k = 0; k < 3; k++) g->ex[k] /= n;
    n = dot3(g->ey, g->ex);
    for (int k = 0; k < 3; k++) g->ey[k] -= n * g->ex[k];
    n = sqrt(dot3(g->ey, g->ey));
    if (!(n > 1e-12)) return im_err(err, cap, IM_EINVAL, "sensor ydir is zero or along xdir");
    for (int k = 0; k < 3; k++) g->ey[k] /= n;
    g->pitch = s->pitch;
    g->cx = 0.5 * (s->width - 1);
    g->cy = 0.5 * (s->height - 1);
    return IM_OK;
}

static void to_pixel(const geom *g, const double p[3], double *x, double *y)
{
    double d[3] = {p[0] - g->o[0], p[1] - g->o[1], p[2] - g->o[2]};
    *x = dot3(d, g->ex) / g->pitch + g->cx;
    *y = dot3(d, g->ey) / g->pitch + g->cy;
}

static int layer_alloc(layer *L, double x0, double y0, double x1, double y1, int W, int H)
{
    L->x0 = (int)fmax(0, floor(x0 + 0.5));
    L->y0 = (int)fmax(0, floor(y0 + 0.5));
    L->x1 = (int)fmin(W, floor(x1 + 0.5) + 1);
    L->y1 = (int)fmin(H, floor(y1 + 0.5) + 1);
    L->e = NULL;
    if (!(x0 <= x1) || !(y0 <= y1)) { L->x1 = L->x0; L->y1 = L->y0; }
    if (L->x1 <= L->x0 || L->y1 <= L->y0) { L->x1 = L->x0; L->y1 = L->y0; return 0; }
    L->e = calloc((size_t)(L->x1 - L->x0) * (L->y1 - L->y0), sizeof *L->e);
    return L->e ? 0 : -1;
}

/* Share of pixel i of a 1-D Gaussian exp(-2 (x-c)^2 / w^2) normalised to 1. */
static double gauss_share(int i, double c, double w)
{
    double k = M_SQRT2 / w;
    return 0.5 * (erf(k * (i + 0.5 - c)) - erf(k * (i - 0.5 - c)));
}
/* Overlap of [a, b] with pixel i's [i-0.5, i+0.5]. */
static double overlap(int i, double a, double b)
{
    double lo = fmax(a, i - 0.5), hi = fmin(b, i + 0.5);
    return hi > lo ? hi - lo : 0;
}

static int add_analytic(const im_sensor *s, const im_spot_src *sp, layer *L,
                        char *err, size_t cap)
{
    double r = 6 * sp->w + 2, gain = s->gain > 0 ? s->gain : 1;
    if (!(sp->w > 0) || !isfinite(sp->w) || !isfinite(sp->x) || !isfinite(sp->y) ||
        !isfinite(sp->peak) || sp->peak < 0)
        return im_err(err, cap, IM_EINVAL, "analytic spot: width must be > 0, peak >= 0, "
                      "all finite");
    if (layer_alloc(L, sp->x - r, sp->y - r, sp->x + r, sp->y + r, s->width, s->height))
        return im_err(err, cap, IM_ENOMEM, "out of memory");
    int nx = L->x1 - L->x0, ny = L->y1 - L->y0;
    if (!nx) return IM_OK;
    double *gx = malloc(sizeof(double) * (size_t)(nx + ny)), *gy = gx + nx;
    if (!gx) return im_err(err, cap, IM_ENOMEM, "out of memory");
    double a = sp->peak * gain;                     /* electrons at the centre */
    if (sp->integrate) {
        double norm = sp->w * sqrt(M_PI / 2);
        for (int i = 0; i < nx; i++) gx[i] = norm * gauss_share(L->x0 + i, sp->x, sp->w);
        for (int j = 0; j < ny; j++) gy[j] = norm * gauss_share(L->y0 + j, sp->y, sp->w);
    } else {
        double k = 2 / (sp->w * sp->w);
        for (int i = 0; i < nx; i++) { double d = L->x0 + i - sp->x; gx[i] = exp(-k * d * d); }
        for (int j = 0; j < ny; j++) { double d = L->y0 + j - sp->y; gy[j] = exp(-k * d * d); }
    }
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) L->e[(size_t)j * nx + i] = a * gx[i] * gy[j];
    free(gx);
    return IM_OK;
}

static int add_hits(const im_sensor *s, const geom *g, const im_spot_src *sp, layer *L,
                    char *err, size_t cap)
{
    const double hc = 6.62607015e-34 * 299792458.0;
    double lam = s->wavelength > 0 ? s->wavelength : 632.8e-9;
    double qe = s->qe > 0 ? s->qe : 1;
    double per_w = s->exposure * lam / hc * qe;      /* electrons per watt */
    double blam = sp->beam_lambda > 0 ? sp->beam_lambda : lam * 1e3;   /* mm */
    int gauss = sp->kind == IM_SPOT_HITS_GAUSS;
    double theta = 0, side = sp->hit_size / g->pitch;
    double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
    size_t k;
    if (!sp->hits && sp->nhits) return im_err(err, cap, IM_EINVAL, "hits missing");
    if (gauss) {
        if (!(sp->waist > 0))
            return im_err(err, cap, IM_EINVAL, "Gaussian splat: the waist must be > 0");
        theta = sp->mirror_d > 0 ? blam / sp->mirror_d : blam / (M_PI * sp->waist);
    } else if (!(side >= 0) || !isfinite(side)) {
        return im_err(err, cap, IM_EINVAL, "hit footprint size must be >= 0");
    }
    /* Footprint radius of hit k, in pixels. */
#define RADIUS(h) (gauss ? 4 * sqrt(sp->waist * sp->waist + theta * theta * (h)->path * \
                                    (h)->path) / g->pitch + 1 : side / 2 + 1)
    for (k = 0; k < sp->nhits; k++) {
        const im_hit *h = &sp->hits[k];
        double x, y, r;
        if (!(h->power > 0) || !isfinite(h->power)) continue;
        to_pixel(g, h->p, &x, &y);
        r = RADIUS(h);
        if (!isfinite(x) || !isfinite(y) || !isfinite(r)) continue;
        x0 = fmin(x0, x - r); x1 = fmax(x1, x + r);
        y0 = fmin(y0, y - r); y1 = fmax(y1, y + r);
    }
    if (layer_alloc(L, x0, y0, x1, y1, s->width, s->height))
        return im_err(err, cap, IM_ENOMEM, "out of memory");
    int nx = L->x1 - L->x0;
    if (!nx) return IM_OK;
    double *ox = malloc(sizeof(double) * (size_t)(s->width + s->height)), *oy = ox + s->width;
    if (!ox) return im_err(err, cap, IM_ENOMEM, "out of memory");
    for (k = 0; k < sp->nhits; k++) {
        const im_hit *h = &sp->hits[k];
        double x, y, r, e;
        if (!(h->power > 0) || !isfinite(h->power)) continue;
        to_pixel(g, h->p, &x, &y);
        r = RADIUS(h);
        if (!isfinite(x) || !isfinite(y) || !isfinite(r)) continue;
        int i0 = (int)fmax(L->x0, floor(x - r)), i1 = (int)fmin(L->x1 - 1, ceil(x + r));
        int j0 = (int)fmax(L->y0, floor(y - r)), j1 = (int)fmin(L->y1 - 1, ceil(y + r));
        if (i0 > i1 || j0 > j1) continue;
        e = h->power * per_w;
        if (gauss) {
            double w = sqrt(sp->waist * sp->waist + theta * theta * h->path * h->path) / g->pitch;
            for (int i = i0; i <= i1; i++) ox[i] = gauss_share(i, x, w);
            for (int j = j0; j <= j1; j++) oy[j] = gauss_share(j, y, w);
        } else if (side > 0) {
            for (int i = i0; i <= i1; i++) ox[i] = overlap(i, x - side / 2, x + side / 2) / side;
            for (int j = j0; j <= j1; j++) oy[j] = overlap(j, y - side / 2, y + side / 2) / side;
        } else {                                     /* a point: the pixel it falls in */
            int pi = (int)floor(x + 0.5), pj = (int)floor(y + 0.5);
            for (int i = i0; i <= i1; i++) ox[i] = i == pi;
            for (int j = j0; j <= j1; j++) oy[j] = j == pj;
        }
        for (int j = j0; j <= j1; j++) {
            double *row = L->e + (size_t)(j - L->y0) * nx - L->x0, ey = e * oy[j];
            if (ey == 0) continue;
            for (int i = i0; i <= i1; i++) row[i] += ey * ox[i];
        }
    }
#undef RADIUS
    free(ox);
    return IM_OK;
}

typedef struct plan {
    const im_sensor *s;
    layer *L;
    int nl;
    double base;          /* expected electrons per pixel without the spot */
    double gain, fw, read, bias, maxv;
    uint64_t seed;
    im_frame *f;
    int next_row, rows_per;
} plan;

static int check_sensor(const im_sensor *s, char *err, size_t cap)
{
    if (!s) return im_err(err, cap, IM_EINVAL, "no sensor");
    if (s->width < 1 || s->height < 1 || (long)s->width * s->height > IM_MAX_PIXELS)
        return im_err(err, cap, IM_EINVAL, "sensor size %dx%d: must be at least 1x1 and at "
                      "most %ld pixels", s->width, s->height, (long)IM_MAX_PIXELS);
    if (s->bits != 8 && s->bits != 12 && s->bits != 16)
        return im_err(err, cap, IM_EINVAL, "sensor bit depth %d: 8, 12 or 16", s->bits);
    if (!(s->pitch > 0) || !isfinite(s->pitch))
        return im_err(err, cap, IM_EINVAL, "pixel pitch must be > 0");
    if (!(s->exposure >= 0) || !(s->qe >= 0) || s->qe > 1 || !(s->gain >= 0) ||
        !(s->full_well >= 0) || !(s->background >= 0) || !(s->dark_current >= 0) ||
        !(s->read_noise >= 0) || !isfinite(s->bias) || !isfinite(s->exposure) ||
        !isfinite(s->gain) || !isfinite(s->background) || !isfinite(s->dark_current) ||
        !isfinite(s->read_noise) || !isfinite(s->full_well))
        return im_err(err, cap, IM_EINVAL, "sensor: exposure, gain, full well, background, "
                      "dark current and read noise must be finite and >= 0, qe in 0..1");
    return IM_OK;
}

static int build_layers(const im_sensor *s, const im_spot_src *spots, int nspots,
                        layer **out, char *err, size_t cap)
{
    geom g;
    int rc = make_geom(s, &g, err, cap);
    layer *L;
    *out = NULL;
    if (rc) return rc;
    if (nspots < 0 || (nspots && !spots)) return im_err(err, cap, IM_EINVAL, "bad spot list");
    L = calloc((size_t)nspots + 1, sizeof *L);
    if (!L) return im_err(err, cap, IM_ENOMEM, "out of memory");
    for (int k = 0; k < nspots && !rc; k++) {
        switch (spots[k].kind) {
        case IM_SPOT_ANALYTIC: rc = add_analytic(s, &spots[k], &L[k], err, cap); break;
        case IM_SPOT_HITS_BIN:
        case IM_SPOT_HITS_GAUSS: rc = add_hits(s, &g, &spots[k], &L[k], err, cap); break;
        default: rc = im_err(err, cap, IM_EINVAL, "spot %d: unknown kind %d", k, spots[k].kind);
        }
    }
    if (rc) {
        for (int k = 0; k < nspots; k++) free(L[k].e);
        free(L);
        return rc;
    }
    *out = L;
    return IM_OK;
}

static void free_layers(layer *L, int n)
{
    if (!L) return;
    for (int k = 0; k < n; k++) free(L[k].e);
    free(L);
}

/* Expected signal electrons of row j into e[0..W) (base included). */
static void row_expected(const plan *p, int j, double *e)
{
    int W = p->s->width;
    for (int i = 0; i < W; i++) e[i] = p->base;
    for (int k = 0; k < p->nl; k++) {
        const layer *L = &p->L[k];
        if (!L->e || j < L->y0 || j >= L->y1) continue;
        const double *src = L->e + (size_t)(j - L->y0) * (L->x1 - L->x0);
        for (int i = L->x0; i < L->x1; i++) e[i] += src[i - L->x0];
    }
}

static void make_row(const plan *p, int j, double *e)
{
    const im_sensor *s = p->s;
    xo_state st;
    gsl_rng r = {&xo_type, &st};
    ptrs pc = {-1, 0, 0, 0, 0, 0, 0, 0};
    uint16_t *out = p->f->px + (size_t)j * s->width;
    double inv = 1 / p->gain, rn = p->read * inv, off = p->bias + 0.5;
    xo_seed(&st, p->seed, (uint64_t)j + 1);
    row_expected(p, j, e);
    for (int i = 0; i < s->width; i++) {
        double n = e[i], v;
        if (s->shot_noise && n > 0) n = poisson(&r, &pc, n);
        if (p->fw > 0 && n > p->fw) n = p->fw;
        v = off + n * inv;
        if (rn > 0) v += rn * gauss(&st);
        out[i] = (uint16_t)(v < 1 ? 0 : v >= p->maxv ? p->maxv : v);   /* floor */
    }
}

static void *worker(void *arg)
{
    plan *p = arg;
    double *e = malloc(sizeof(double) * (size_t)p->s->width);
    if (!e) return (void *)1;
    for (;;) {
        int j0 = __atomic_fetch_add(&p->next_row, p->rows_per, __ATOMIC_RELAXED);
        if (j0 >= p->s->height) break;
        for (int j = j0; j < j0 + p->rows_per && j < p->s->height; j++) make_row(p, j, e);
    }
    free(e);
    return NULL;
}

static void plan_init(plan *p, const im_sensor *s, layer *L, int nl, uint64_t seed)
{
    double qe = s->qe > 0 ? s->qe : 1;
    memset(p, 0, sizeof *p);
    p->s = s;
    p->L = L;
    p->nl = nl;
    p->base = qe * s->background * s->exposure + s->dark_current * s->exposure;
    p->gain = s->gain > 0 ? s->gain : 1;
    p->fw = s->full_well;
    p->read = s->read_noise;
    p->bias = s->bias;
    p->maxv = (double)((1u << s->bits) - 1);
    p->seed = seed;
}

int im_synth(const im_sensor *s, const im_spot_src *spots, int nspots, uint64_t seed,
             int threads, im_frame **out, char *err, size_t cap)
{
    layer *L;
    plan p;
    int rc;
    *out = NULL;
    pthread_once(&zig_once, zig_init);
    if ((rc = check_sensor(s, err, cap)) || (rc = build_layers(s, spots, nspots, &L, err, cap)))
        return rc;
    plan_init(&p, s, L, nspots, seed);
    p.f = im_frame_new(s->width, s->height, s->bits);
    if (!p.f) { free_layers(L, nspots); return im_err(err, cap, IM_ENOMEM, "out of memory"); }
    p.rows_per = 16;
    if (threads < 1) threads = 1;
    if (threads > 64) threads = 64;
    pthread_t tid[64];
    int started = 0;
    for (int t = 1; t < threads; t++)
        if (pthread_create(&tid[started], NULL, worker, &p) == 0) started++;
    void *bad = worker(&p);
    for (int t = 0; t < started; t++) {
        void *r;
        pthread_join(tid[t], &r);
        if (r) bad = r;
    }
    free_layers(L, nspots);
    if (bad) { im_frame_free(p.f); return im_err(err, cap, IM_ENOMEM, "out of memory"); }
    *out = p.f;
    return IM_OK;
}

int im_synth_expected(const im_sensor *s, const im_spot_src *spots, int nspots,
                      double *counts, char *err, size_t cap)
{
    layer *L;
    plan p;
    int rc;
    if ((rc = check_sensor(s, err, cap)) || (rc = build_layers(s, spots, nspots, &L, err, cap)))
        return rc;
    if (!counts) { free_layers(L, nspots); return im_err(err, cap, IM_EINVAL, "no output"); }
    plan_init(&p, s, L, nspots, 0);
    for (int j = 0; j < s->height; j++) {
        double *row = counts + (size_t)j * s->width;
        row_expected(&p, j, row);
        for (int i = 0; i < s->width; i++) row[i] /= p.gain;
    }
    free_layers(L, nspots);
    return IM_OK;
}
