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
 * over the 2 ms budget.  Poisson: GSL below a mean of 10, PTRS above.
 * Dark pixels (no random electrons: outside the spots when the background is not shot
 * noise) take their count straight from its exact discrete law, one table look-up per
 * pixel (dark_tab below): the same statistics as Gaussian-then-floor, ~3x faster. */
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

/* ---- dark pixels: the count drawn from its exact discrete law --------------------- */
/* A pixel whose electrons n are not random (no spot on it, and no background under shot
 * noise) reads count = clamp(floor(c + sigma Z), 0, max), c = bias + 0.5 + n / gain,
 * sigma the read noise in counts, Z normal: P(count <= k) = Phi((k + 1 - c) / sigma)
 * for 0 <= k < max, 1 at max.  That law is tabulated to 63 bits (T[i]: 2^63 P(count <=
 * klo + i), each tail from erfc of its own side, so no cancellation) over c +- 13 sigma
 * (the mass beyond, below 1e-38, joins the end values), and one 64-bit draw u per pixel
 * gives the first i with T[i] > u: a guide on u's top 13 bits answers at once unless a
 * threshold falls inside u's bucket (DK_SEARCH; ~3 % of the draws at sigma 50), when
 * the search compares from there.  Exact to erfc's double precision, where the
 * ziggurat and the floor it replaces resolved ~2^-31; ~1 ns a pixel instead of ~3.
 * Tables live in a small cache keyed by (c, sigma, max): every frame of a scan shares
 * one. */
#define DK_BITS 13
#define DK_SLOTS 8
#define DK_SEARCH 0x8000u
typedef struct dark_tab {
    double c, sigma, maxv;      /* the key */
    int klo, n, refs, cached;
    uint64_t *T;                /* n thresholds, T[n - 1] = 2^63 */
    uint16_t guide[1 << DK_BITS];   /* first i of each bucket of u, | DK_SEARCH */
} dark_tab;

static dark_tab *dark_build(double c, double sigma, double maxv)
{
    const double two63 = 0x1p63;
    double lo = sigma > 0 ? floor(c - 13 * sigma) : floor(c);
    double hi = sigma > 0 ? ceil(c + 13 * sigma) : floor(c);
    int klo = lo < 0 ? 0 : lo > maxv ? (int)maxv : (int)lo;
    int khi = hi < 0 ? 0 : hi > maxv ? (int)maxv : (int)hi;
    dark_tab *d;
    if (khi - klo >= 0x7fff) return NULL;          /* indices must fit the guide's 15 bits */
    if (!(d = malloc(sizeof *d))) return NULL;
    d->c = c; d->sigma = sigma; d->maxv = maxv;
    d->refs = 0; d->cached = 0;
    d->klo = klo;
    d->n = khi - klo + 1;
    d->T = malloc(sizeof *d->T * (size_t)d->n);
    if (!d->T) { free(d); return NULL; }
    uint64_t prev = 0;
    for (int i = 0; i < d->n - 1; i++) {
        double z = (klo + i + 1 - c) / sigma;        /* sigma > 0: n == 1 otherwise */
        uint64_t t = z <= 0 ? (uint64_t)(0.5 * erfc(-z * M_SQRT1_2) * two63)
                            : (1ull << 63) - (uint64_t)(0.5 * erfc(z * M_SQRT1_2) * two63);
        d->T[i] = prev = t < prev ? prev : t;
    }
    d->T[d->n - 1] = 1ull << 63;
    for (int b = 0, i = 0; b < 1 << DK_BITS; b++) {
        uint64_t u0 = (uint64_t)b << (63 - DK_BITS), u1 = u0 + (1ull << (63 - DK_BITS));
        while (d->T[i] <= u0) i++;
        /* DK_SEARCH: a threshold falls inside the bucket, so compare */
        d->guide[b] = (uint16_t)((d->T[i] < u1 ? DK_SEARCH : 0) | (unsigned)i);
    }
    return d;
}

static pthread_mutex_t dk_mu = PTHREAD_MUTEX_INITIALIZER;
static dark_tab *dk_cache[DK_SLOTS];

static dark_tab *dark_get(double c, double sigma, double maxv)
{
    dark_tab *d = NULL;
    pthread_mutex_lock(&dk_mu);
    for (int k = 0; k < DK_SLOTS && !d; k++)
        if (dk_cache[k] && dk_cache[k]->c == c && dk_cache[k]->sigma == sigma &&
            dk_cache[k]->maxv == maxv)
            d = dk_cache[k];
    if (!d && (d = dark_build(c, sigma, maxv))) {
        for (int k = 0; k < DK_SLOTS; k++)       /* an empty slot, or an unused table's */
            if (!dk_cache[k] || !dk_cache[k]->refs) {
                if (dk_cache[k]) { free(dk_cache[k]->T); free(dk_cache[k]); }
                dk_cache[k] = d;
                d->cached = 1;
                break;
            }
    }
    if (d) d->refs++;
    pthread_mutex_unlock(&dk_mu);
    return d;
}

static void dark_put(dark_tab *d)
{
    if (!d) return;
    pthread_mutex_lock(&dk_mu);
    int gone = --d->refs == 0 && !d->cached;
    pthread_mutex_unlock(&dk_mu);
    if (gone) { free(d->T); free(d); }
}

/* Eight xoshiro256** streams side by side, in two sets of four (lane l of a[i] is word
 * i of stream l, of b[i] of stream 4 + l; two sets: one chain is latency-bound): the
 * dark pixels' draws, written once with GCC vector extensions and cloned per
 * processor; integer arithmetic only, so every clone gives the same bits. */
#define XO_LANES 8
typedef uint64_t u64x4 __attribute__((vector_size(32)));
typedef struct { u64x4 a[4], b[4]; } xo8_state;

static void xo8_seed(xo8_state *x, uint64_t seed, uint64_t stream)
{
    for (int l = 0; l < XO_LANES; l++) {
        xo_state t;
        xo_seed(&t, seed, stream + (uint64_t)l);
        for (int i = 0; i < 4; i++) {
            if (l < 4) x->a[i][l] = t.s[i];
            else x->b[i][l - 4] = t.s[i];
        }
    }
}

#define XO8_STEP(s0, s1, s2, s3, dst) do {                                             \
        u64x4 m_ = (s1 << 2) + s1;                      /* s1 * 5 */                   \
        m_ = (m_ << 7) | (m_ >> 57);                                                    \
        u64x4 r_ = (m_ << 3) + m_, t_ = s1 << 17;       /* rotl(s1 * 5, 7) * 9 */      \
        memcpy(dst, &r_, sizeof r_);                                                    \
        s2 ^= s0; s3 ^= s1; s1 ^= s2; s0 ^= s3; s2 ^= t_;                               \
        s3 = (s3 << 45) | (s3 >> 19);                                                   \
    } while (0)

__attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
static void xo8_fill(xo8_state *x, uint64_t *out, int nblk)
{
    u64x4 a0 = x->a[0], a1 = x->a[1], a2 = x->a[2], a3 = x->a[3];
    u64x4 b0 = x->b[0], b1 = x->b[1], b2 = x->b[2], b3 = x->b[3];
    for (int k = 0; k < nblk; k++) {
        XO8_STEP(a0, a1, a2, a3, out + XO_LANES * k);
        XO8_STEP(b0, b1, b2, b3, out + XO_LANES * k + 4);
    }
    x->a[0] = a0; x->a[1] = a1; x->a[2] = a2; x->a[3] = a3;
    x->b[0] = b0; x->b[1] = b1; x->b[2] = b2; x->b[3] = b3;
}

/* The count for a 64-bit draw. */
static inline int dark_count(const dark_tab *d, uint64_t u)
{
    u >>= 1;
    unsigned g = d->guide[u >> (63 - DK_BITS)];
    if (__builtin_expect(!(g & DK_SEARCH), 1)) return d->klo + (int)g;
    unsigned k = g & ~DK_SEARCH;
    while (d->T[k] <= u) k++;
    return d->klo + (int)k;
}

/* n dark pixels of a row, from the eight streams (each chunk's draws in lane order;
 * the last block's unused lanes are dropped). */
static void dark_fill(const dark_tab *d, xo8_state *x, uint16_t *out, int n)
{
    enum { CHUNK = 256 };
    uint64_t u[CHUNK];
    if (d->n == 1) {
        for (int i = 0; i < n; i++) out[i] = (uint16_t)d->klo;
        return;
    }
    for (int at = 0; at < n; at += CHUNK) {
        int m = n - at < CHUNK ? n - at : CHUNK;
        xo8_fill(x, u, (m + XO_LANES - 1) / XO_LANES);
        for (int i = 0; i < m; i++) out[at + i] = (uint16_t)dark_count(d, u[i]);
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
    dark_tab *dk;         /* the dark pixels' law; NULL: every pixel drawn in full */
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

/* Expected signal electrons of row j into e[x0..x1) (base included). */
static void row_expected(const plan *p, int j, double *e, int x0, int x1)
{
    for (int i = x0; i < x1; i++) e[i] = p->base;
    for (int k = 0; k < p->nl; k++) {
        const layer *L = &p->L[k];
        if (!L->e || j < L->y0 || j >= L->y1) continue;
        const double *src = L->e + (size_t)(j - L->y0) * (L->x1 - L->x0);
        int a = L->x0 > x0 ? L->x0 : x0, b = L->x1 < x1 ? L->x1 : x1;
        for (int i = a; i < b; i++) e[i] += src[i - L->x0];
    }
}

/* Pixels [x0, x1) of a row drawn in full: Poisson electrons when shot noise is on, the
 * full well, the converter, Gaussian read noise, the floor. */
static void full_span(const plan *p, xo_state *st, const double *e, uint16_t *out,
                      int x0, int x1)
{
    const im_sensor *s = p->s;
    gsl_rng r = {&xo_type, st};
    ptrs pc = {-1, 0, 0, 0, 0, 0, 0, 0};
    double inv = 1 / p->gain, rn = p->read * inv, off = p->bias + 0.5;
    for (int i = x0; i < x1; i++) {
        double n = e[i], v;
        if (p->dk && n == p->base) { out[i] = (uint16_t)dark_count(p->dk, xo_next(st)); continue; }
        if (s->shot_noise && n > 0) n = poisson(&r, &pc, n);
        if (p->fw > 0 && n > p->fw) n = p->fw;
        v = off + n * inv;
        if (rn > 0) v += rn * gauss(st);
        out[i] = (uint16_t)(v < 1 ? 0 : v >= p->maxv ? p->maxv : v);   /* floor */
    }
}

/* Row j: with a dark table, only the span the spots' layers cover is drawn in full. */
static void make_row(const plan *p, int j, double *e)
{
    const int W = p->s->width;
    xo_state st;
    xo8_state dst;
    uint16_t *out = p->f->px + (size_t)j * W;
    xo_seed(&st, p->seed, (uint64_t)j + 1);
    if (!p->dk) {
        row_expected(p, j, e, 0, W);
        full_span(p, &st, e, out, 0, W);
        return;
    }
    int xa = W, xb = 0;
    for (int k = 0; k < p->nl; k++) {
        const layer *L = &p->L[k];
        if (!L->e || j < L->y0 || j >= L->y1) continue;
        if (L->x0 < xa) xa = L->x0;
        if (L->x1 > xb) xb = L->x1;
    }
    /* the dark streams: 8 per row, numbered apart from the rows' own (1 .. height) */
    xo8_seed(&dst, p->seed, (1ull << 40) + XO_LANES * (uint64_t)j);
    if (xa >= xb) { dark_fill(p->dk, &dst, out, W); return; }
    row_expected(p, j, e, xa, xb);
    dark_fill(p->dk, &dst, out, xa);
    full_span(p, &st, e, out, xa, xb);
    dark_fill(p->dk, &dst, out + xb, W - xb);
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

/* The dark pixels' table when their electrons are certain: no shot noise, or nothing
 * but the spots to be shot noise.  NULL (every pixel in full) otherwise. */
static dark_tab *plan_dark(const plan *p)
{
    if ((p->s->shot_noise && p->base > 0) || 26 * p->read / p->gain > 0x7000) return NULL;
    double n = p->fw > 0 && p->base > p->fw ? p->fw : p->base;
    return dark_get(p->bias + 0.5 + n / p->gain, p->read / p->gain, p->maxv);
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
    p.dk = plan_dark(&p);
    p.f = im_frame_new_raw(s->width, s->height, s->bits);   /* every sample is written */
    if (!p.f) {
        dark_put(p.dk);
        free_layers(L, nspots);
        return im_err(err, cap, IM_ENOMEM, "out of memory");
    }
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
    dark_put(p.dk);
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
        row_expected(&p, j, row, 0, s->width);
        for (int i = 0; i < s->width; i++) row[i] /= p.gain;
    }
    free_layers(L, nspots);
    return IM_OK;
}
