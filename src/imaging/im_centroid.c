/* im_centroid.c -- laser spots in a frame: background and noise from tile statistics
 * (one pass over the frame), detection threshold, connected spots (a second pass over
 * the candidate tiles only), intensity-weighted moments as the start and the fallback,
 * refined by a 2-D Gaussian least-squares fit (im_fit.c).  Every outcome is explicit:
 * none (with the best candidate's SNR), one, several (sorted by power, flagged), and per
 * spot saturated and cut-by-the-edge flags. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "im_centroid.h"

#define TILE 16

struct im_centroider {
    int w, h;                  /* frame size the scratch is for */
    uint8_t *mask;             /* w*h: 1 = already in a component */
    int *list;                 /* pixel indices of the components, in order */
    size_t list_cap;
    int ntx, nty;
    double *tmean, *tvar, *tbg, *tmp;
    uint16_t *tmax, *cmax;     /* per tile; per column of the current tile row */
    uint32_t *csum;
    uint64_t *csq;
    im_fit_ws fit;
};

im_centroider *im_centroider_new(void) { return calloc(1, sizeof(im_centroider)); }

static void release(im_centroider *c)
{
    free(c->mask); free(c->list); free(c->tmean); free(c->tmax); free(c->cmax);
    free(c->csum); free(c->csq);
    c->mask = NULL; c->list = NULL; c->tmean = NULL; c->tmax = NULL; c->cmax = NULL;
    c->csum = NULL; c->csq = NULL;
    c->list_cap = 0;
    c->w = c->h = 0;
}

void im_centroider_free(im_centroider *c)
{
    if (!c) return;
    release(c);
    im_fit_ws_free(&c->fit);
    free(c);
}

static int prepare(im_centroider *c, int w, int h)
{
    if (c->w == w && c->h == h) return 0;
    release(c);
    c->ntx = (w + TILE - 1) / TILE;
    c->nty = (h + TILE - 1) / TILE;
    size_t nt = (size_t)c->ntx * c->nty;
    c->mask = calloc((size_t)w * h, 1);
    c->tmean = malloc(sizeof(double) * nt * 4);
    c->tmax = malloc(sizeof(uint16_t) * nt);
    c->list_cap = 4096;
    c->list = malloc(sizeof(int) * c->list_cap);
    c->cmax = malloc(sizeof(uint16_t) * (size_t)w);
    c->csum = malloc(sizeof(uint32_t) * (size_t)w);
    c->csq = malloc(sizeof(uint64_t) * (size_t)w);
    if (!c->mask || !c->tmean || !c->tmax || !c->list || !c->cmax || !c->csum || !c->csq) {
        release(c);
        return -1;
    }
    c->tvar = c->tmean + nt;
    c->tbg = c->tvar + nt;
    c->tmp = c->tbg + nt;
    c->w = w;
    c->h = h;
    return 0;
}

/* k-th smallest of a[0..n) (a is reordered). */
static double select_k(double *a, int n, int k)
{
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        double piv = a[(lo + hi) / 2];
        int i = lo, j = hi;
        while (i <= j) {
            while (a[i] < piv) i++;
            while (a[j] > piv) j--;
            if (i <= j) { double t = a[i]; a[i] = a[j]; a[j] = t; i++; j--; }
        }
        if (k <= j) hi = j;
        else if (k >= i) lo = i;
        else break;
    }
    return a[k];
}

/* Column accumulators of one row: the maximum of every sample (a spot anywhere must be
 * seen), sums and sums of squares of every second row (the background statistics need
 * no more).  Written once, compiled per processor (AVX-512, AVX2, baseline). */
__attribute__((target_clones("arch=skylake-avx512", "avx2", "default")))
static void acc_row(const uint16_t *restrict row, int W, int stats, uint16_t *restrict cmax,
                    uint32_t *restrict csum, uint64_t *restrict csq)
{
    for (int x = 0; x < W; x++) cmax[x] = row[x] > cmax[x] ? row[x] : cmax[x];
    if (!stats) return;
    for (int x = 0; x < W; x++) {
        uint32_t v = row[x];
        csum[x] += v;
        csq[x] += (uint64_t)v * v;
    }
}

/* Pass 1: per-tile mean, variance and maximum; the frame is read once, row by row. */
static void tile_stats(im_centroider *c, const im_frame *f)
{
    int W = f->width, ntx = c->ntx;
    uint16_t *cmax = c->cmax;
    uint32_t *csum = c->csum;
    uint64_t *csq = c->csq;
    for (int ty = 0; ty < c->nty; ty++) {
        int y0 = ty * TILE, y1 = y0 + TILE < f->height ? y0 + TILE : f->height;
        memset(cmax, 0, sizeof *cmax * (size_t)W);
        memset(csum, 0, sizeof *csum * (size_t)W);
        memset(csq, 0, sizeof *csq * (size_t)W);
        for (int y = y0; y < y1; y++)
            acc_row(f->px + (size_t)y * W, W, y1 - y0 == 1 || ((y - y0) & 1) == 0,
                    cmax, csum, csq);
        int nrows = y1 - y0 == 1 ? 1 : (y1 - y0 + 1) / 2;
        for (int tx = 0; tx < ntx; tx++) {
            int x0 = tx * TILE, x1 = x0 + TILE < W ? x0 + TILE : W;
            uint64_t s = 0, q = 0;
            unsigned m = 0;
            for (int x = x0; x < x1; x++) {
                s += csum[x]; q += csq[x];
                m = cmax[x] > m ? cmax[x] : m;
            }
            double n = (double)(x1 - x0) * nrows, mean = s / n;
            size_t t = (size_t)ty * ntx + tx;
            c->tmax[t] = (uint16_t)m;
            c->tmean[t] = mean;
            c->tvar[t] = fmax(0, q / n - mean * mean) * n / (n > 1 ? n - 1 : 1);
        }
    }
}

/* Local background of every tile: median of the means of its 3x3 neighbourhood, so a
 * spot filling a tile or two does not raise its own background. */
static void local_background(im_centroider *c, double floor)
{
    for (int ty = 0; ty < c->nty; ty++)
        for (int tx = 0; tx < c->ntx; tx++) {
            double v[9];
            size_t t = (size_t)ty * c->ntx + tx;
            /* A tile whose peak is not even `floor` above its own mean holds no spot
             * pixel above threshold (its mean is at or above the local background
             * unless the background falls steeply): its own mean will do. */
            if (c->tmax[t] - c->tmean[t] <= floor) { c->tbg[t] = c->tmean[t]; continue; }
            int n = 0;
            for (int dy = -1; dy <= 1; dy++)
                for (int dx = -1; dx <= 1; dx++) {
                    int x = tx + dx, y = ty + dy;
                    if (x >= 0 && y >= 0 && x < c->ntx && y < c->nty)
                        v[n++] = c->tmean[(size_t)y * c->ntx + x];
                }
            c->tbg[(size_t)ty * c->ntx + tx] = select_k(v, n, n / 2);
        }
}

typedef struct comp {
    int start, npix;           /* its pixels: list[start .. start+npix) */
    int peak_i;                /* brightest pixel */
    double peak, bg, thr;
    double sum;                /* counts above background over its pixels */
    int edge, nsat;
} comp;

static int grow(im_centroider *c, size_t need)
{
    if (need <= c->list_cap) return 0;
    size_t cap = c->list_cap * 2;
    while (cap < need) cap *= 2;
    int *l = realloc(c->list, sizeof(int) * cap);
    if (!l) return -1;
    c->list = l;
    c->list_cap = cap;
    return 0;
}

/* Flood fill (8-connected) from pixel `seed` over pixels above thr; pixels appended to
 * c->list from *used on. */
static int flood(im_centroider *c, const im_frame *f, int seed, double thr, double sat,
                 size_t *used, comp *k)
{
    int W = f->width, H = f->height;
    size_t head = *used, tail = *used;
    if (grow(c, tail + 1)) return -1;
    c->mask[seed] = 1;
    c->list[tail++] = seed;
    k->start = (int)head;
    k->peak_i = seed;
    k->peak = f->px[seed];
    k->sum = 0;
    k->edge = 0;
    k->nsat = 0;
    while (head < tail) {
        int p = c->list[head++], x = p % W, y = p / W;
        double v = f->px[p];
        k->sum += v - k->bg;
        if (v > k->peak) { k->peak = v; k->peak_i = p; }
        if (v >= sat) k->nsat++;
        if (x == 0 || y == 0 || x == W - 1 || y == H - 1) k->edge = 1;
        for (int dy = -1; dy <= 1; dy++) {
            int yy = y + dy;
            if (yy < 0 || yy >= H) continue;
            for (int dx = -1; dx <= 1; dx++) {
                int xx = x + dx, q = yy * W + xx;
                if (xx < 0 || xx >= W || c->mask[q] || f->px[q] <= thr) continue;
                if (grow(c, tail + 1)) return -1;
                c->mask[q] = 1;
                c->list[tail++] = q;
            }
        }
    }
    k->npix = (int)(tail - (size_t)k->start);
    *used = tail;
    return 0;
}

static int by_power(const void *a, const void *b)
{
    const im_spot *x = a, *y = b;
    return x->power < y->power ? 1 : x->power > y->power ? -1 : 0;
}
static int comp_by_sum(const void *a, const void *b)
{
    const comp *x = a, *y = b;
    return x->sum < y->sum ? 1 : x->sum > y->sum ? -1 : 0;
}

int im_centroid(im_centroider *ctx, const im_frame *f, const im_centroid_opt *opt_in,
                im_spot *spots, int cap, im_centroid_result *res, char *err, size_t errcap)
{
    im_centroid_opt opt = opt_in ? *opt_in : (im_centroid_opt){0};
    im_centroider *c = ctx ? ctx : im_centroider_new();
    im_centroid_result r;
    comp *comps = NULL;
    int ncomp = 0, capcomp = 0, rc = IM_OK;
    size_t used = 0, nt;
    double noise, sat;
    memset(&r, 0, sizeof r);
    if (res) memset(res, 0, sizeof *res);
    if (!c) return im_err(err, errcap, IM_ENOMEM, "out of memory");
    if (!f || !f->px || f->width < 1 || f->height < 1 ||
        (f->bits != 8 && f->bits != 12 && f->bits != 16)) {
        rc = im_err(err, errcap, IM_EINVAL, "centroid: no frame, or a zero-size one");
        goto out;
    }
    if (cap < 0 || (cap > 0 && !spots)) {
        rc = im_err(err, errcap, IM_EINVAL, "centroid: bad spot buffer");
        goto out;
    }
    if (opt.threshold <= 0) opt.threshold = 5;
    if (opt.min_pixels <= 0) opt.min_pixels = 3;
    if (opt.max_spots <= 0) opt.max_spots = 16;
    if (opt.method < IM_CM_GAUSS || opt.method > IM_CM_MOMENTS_BG) {
        rc = im_err(err, errcap, IM_EINVAL, "centroid: unknown method %d", opt.method);
        goto out;
    }
    if (!isfinite(opt.threshold) || !(opt.gain >= 0) || !(opt.read_noise >= 0) ||
        !(opt.window >= 0) || !(opt.saturation >= 0) || !isfinite(opt.gain) ||
        !isfinite(opt.read_noise) || !isfinite(opt.window)) {
        rc = im_err(err, errcap, IM_EINVAL, "centroid: options must be finite and >= 0");
        goto out;
    }
    sat = opt.saturation > 0 ? opt.saturation : (double)((1u << f->bits) - 1);
    if (prepare(c, f->width, f->height)) {
        rc = im_err(err, errcap, IM_ENOMEM, "out of memory");
        goto out;
    }
    nt = (size_t)c->ntx * c->nty;

    /* Pass 1: background and noise. */
    tile_stats(c, f);
    memcpy(c->tmp, c->tmean, sizeof(double) * nt);
    r.background = select_k(c->tmp, (int)nt, (int)nt / 2);
    memcpy(c->tmp, c->tvar, sizeof(double) * nt);
    noise = opt.read_noise > 0 ? opt.read_noise : sqrt(select_k(c->tmp, (int)nt, (int)nt / 2));
    if (!(noise > 0)) noise = 0.5;            /* a noiseless frame: quantisation only */
    r.noise = noise;
    local_background(c, 0.7 * opt.threshold * noise);

    /* Pass 2: connected spots in the tiles whose maximum is above threshold. */
    int best_t = 0;
    double best = -INFINITY;
    for (size_t t = 0; t < nt; t++) {
        double snr = (c->tmax[t] - c->tbg[t]) / noise;
        if (snr > best) { best = snr; best_t = (int)t; }
        if (snr <= opt.threshold) continue;
        int tx = (int)(t % c->ntx), ty = (int)(t / c->ntx);
        int x0 = tx * TILE, y0 = ty * TILE;
        int x1 = x0 + TILE < f->width ? x0 + TILE : f->width;
        int y1 = y0 + TILE < f->height ? y0 + TILE : f->height;
        double thr = c->tbg[t] + opt.threshold * noise;
        for (int y = y0; y < y1; y++)
            for (int x = x0; x < x1; x++) {
                int p = y * f->width + x;
                if (f->px[p] <= thr || c->mask[p]) continue;
                if (ncomp == capcomp) {
                    int nc = capcomp ? 2 * capcomp : 16;
                    comp *cc = realloc(comps, sizeof *cc * (size_t)nc);
                    if (!cc) { rc = im_err(err, errcap, IM_ENOMEM, "out of memory"); goto out; }
                    comps = cc;
                    capcomp = nc;
                }
                comp *k = &comps[ncomp];
                k->bg = c->tbg[t];
                k->thr = thr;
                if (flood(c, f, p, thr, sat, &used, k)) {
                    rc = im_err(err, errcap, IM_ENOMEM, "out of memory");
                    goto out;
                }
                if (k->npix >= opt.min_pixels || k->nsat > 0) ncomp++;
            }
    }
    r.ndetected = ncomp;
    if (ncomp == 0) {
        /* The best candidate: the brightest pixel of the tile with the highest peak. */
        int tx = best_t % c->ntx, ty = best_t / c->ntx, bi = 0;
        double bv = -1;
        for (int y = ty * TILE; y < ty * TILE + TILE && y < f->height; y++)
            for (int x = tx * TILE; x < tx * TILE + TILE && x < f->width; x++)
                if (f->px[y * f->width + x] > bv) { bv = f->px[y * f->width + x]; bi = y * f->width + x; }
        r.outcome = IM_FOUND_NONE;
        r.best_snr = (bv - c->tbg[best_t]) / noise;
        r.best_x = bi % f->width;
        r.best_y = bi / f->width;
        goto out;
    }
    qsort(comps, (size_t)ncomp, sizeof *comps, comp_by_sum);
    int nfit = ncomp < opt.max_spots ? ncomp : opt.max_spots;
    if (nfit > cap) nfit = cap;
    for (int s = 0; s < nfit; s++) {
        comp *k = &comps[s];
        im_spot_in in = {
            .f = f, .list = c->list + k->start, .npix = k->npix, .peak_i = k->peak_i,
            .peak = k->peak, .bg = k->bg, .thr = k->thr, .noise = noise, .gain = opt.gain,
            .sat = sat, .window = opt.window, .method = opt.method, .edge = k->edge,
            .plane = opt.plane,
        };
        im_spot_locate(&c->fit, &in, &spots[s]);
        if (ncomp > 1) spots[s].flags |= IM_SF_SEVERAL;
    }
    qsort(spots, (size_t)nfit, sizeof *spots, by_power);
    r.nspots = nfit;
    r.outcome = ncomp > 1 ? IM_FOUND_SEVERAL : IM_FOUND_ONE;
    if (nfit > 0) {
        r.best_snr = spots[0].snr;
        r.best_x = spots[0].x;
        r.best_y = spots[0].y;
    } else {
        r.best_snr = (comps[0].peak - comps[0].bg) / noise;
        r.best_x = comps[0].peak_i % f->width;
        r.best_y = comps[0].peak_i / f->width;
    }
out:
    if (c->mask)
        for (size_t i = 0; i < used; i++) c->mask[c->list[i]] = 0;
    free(comps);
    if (res) *res = r;
    if (!ctx) im_centroider_free(c);
    return rc;
}
