/* im_centroid.c -- laser spots in a frame: background and noise from tile statistics
 * (one pass over the frame), the saturation level (the file's full scale, the
 * caller's, or a pile-up found in the frame), detection by the matched filter for the
 * expected spot (the spot's integrated SNR: a screen on 2x2-binned pixels, then the
 * exact statistic where it points, climbed to its maximum and grown over the region
 * above threshold), the connected pixels above the pixel threshold for the start and
 * the thresholded-moments baseline, refined by a 2-D Gaussian least-squares fit
 * (im_fit.c).  Every outcome is explicit: none (with the best candidate's SNR, the
 * same statistic the threshold is on), one, several (sorted by power, flagged), and
 * per spot saturated and cut-by-the-edge flags. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "im_centroid.h"

#define TILE 16
#define MF_MAXR 24             /* the matched filter's half-width: ceil(2 w), w <= 12 */
#define MF_MAXRB 12            /* ... on the 2x2-binned screen */
#define MF_RING (2 * MF_MAXRB + 1)  /* binned rows the screen holds at once */
#define MF_MAXCAND 4096        /* screen candidates examined per frame at most */
#define MF_MAXREG 20000        /* pixels of one region above threshold at most */

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
    /* the matched filter: the binned screen (padded), its column pass and result;
       the exact statistic per pixel (NaN: not computed), the region mask, and the
       pixels touched (reset after each frame) */
    int bw, bh, pw;            /* bins across, down; padded row length */
    float *bin, *bcol, *tb4, *scr;
    float *tmap;
    uint8_t *rmask;
    int *touched, *reg;
    size_t ntouched, touched_cap, reg_cap;
    float *rmax;               /* the screen's maximum on each of its rows */
};

im_centroider *im_centroider_new(void) { return calloc(1, sizeof(im_centroider)); }

static void release(im_centroider *c)
{
    free(c->mask); free(c->list); free(c->tmean); free(c->tmax); free(c->cmax);
    free(c->csum); free(c->csq);
    free(c->bin); free(c->bcol); free(c->tb4); free(c->scr); free(c->tmap); free(c->rmask);
    free(c->touched); free(c->reg); free(c->rmax);
    c->mask = NULL; c->list = NULL; c->tmean = NULL; c->tmax = NULL; c->cmax = NULL;
    c->csum = NULL; c->csq = NULL;
    c->bin = c->bcol = c->tb4 = c->scr = c->tmap = NULL; c->rmask = NULL;
    c->touched = c->reg = NULL; c->rmax = NULL;
    c->ntouched = c->touched_cap = c->reg_cap = 0;
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
    c->bw = w / 2;
    c->bh = h / 2;
    c->pw = c->bw + 2 * MF_MAXRB;
    /* the screen's binned rows: a ring of MF_RING rows and a row of zeros (the rows
       beyond the frame), their padding columns zero for good; one column-pass row */
    c->bin = calloc((size_t)c->pw * (MF_RING + 1), sizeof(float));
    c->bcol = calloc((size_t)c->pw, sizeof(float));
    c->tb4 = malloc(sizeof(float) * (size_t)(c->bw > 0 ? c->bw : 1));
    c->scr = malloc(sizeof(float) * (size_t)(c->bw > 0 ? c->bw : 1) * (size_t)(c->bh > 0 ? c->bh : 1));
    c->tmap = malloc(sizeof(float) * (size_t)w * h);
    c->rmask = calloc((size_t)w * h, 1);
    c->touched_cap = c->reg_cap = 1024;
    c->touched = malloc(sizeof(int) * c->touched_cap);
    c->reg = malloc(sizeof(int) * c->reg_cap);
    c->rmax = malloc(sizeof(float) * (size_t)(c->bh > 0 ? c->bh : 1));
    if (!c->mask || !c->tmean || !c->tmax || !c->list || !c->cmax || !c->csum || !c->csq ||
        !c->bin || !c->bcol || !c->tb4 || !c->scr || !c->tmap || !c->rmask || !c->touched || !c->reg ||
        !c->rmax) {
        release(c);
        return -1;
    }
    for (size_t i = 0; i < (size_t)w * h; i++) c->tmap[i] = NAN;
    c->tvar = c->tmean + nt;
    c->tbg = c->tvar + nt;
    c->tmp = c->tbg + nt;
    c->w = w;
    c->h = h;
    return 0;
}

/* Moves the elements of a[lo..hi] for which (strict ? v < p : v <= p) to the front,
 * without branches (a noisy frame's tile statistics are in random order, so a branch
 * on each comparison is mispredicted half the time); their count. */
static int part_le(double *a, int lo, int hi, double p, int strict)
{
    int st = lo;
    for (int i = lo; i <= hi; i++) {
        double v = a[i], t = a[st];
        int in = strict ? v < p : v <= p;
        a[i] = in ? t : v;
        a[st] = in ? v : t;
        st += in;
    }
    return st - lo;
}

/* k-th smallest of a[0..n) (a is reordered): quickselect on the median of three,
 * each range split three ways (below, equal to, above the pivot), so that equal
 * values - a noiseless frame's tiles - end it at once. */
static double select_k(double *a, int n, int k)
{
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        double x = a[lo], y = a[(lo + hi) / 2], z = a[hi];
        double piv = x < y ? (y < z ? y : (x < z ? z : x)) : (x < z ? x : (y < z ? z : y));
        int nl = part_le(a, lo, hi, piv, 1);
        if (k < lo + nl) { hi = lo + nl - 1; continue; }
        int ne = part_le(a, lo + nl, hi, piv, 0);
        if (k < lo + nl + ne) return piv;
        lo = lo + nl + ne;
    }
    return a[k];
}

/* Column accumulators of one row: the maximum of every sample (a spot anywhere must be
 * seen), sums and sums of squares of every second row (the background statistics need
 * no more).  Written once, compiled per processor (AVX-512, AVX2, baseline). */
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
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

/* ---- the saturation level ------------------------------------------------------ */

/* A camera's ADC narrower than the file (12-bit data in a 16-bit PNG), or a full well
 * reached below the ADC's range, clips at a level under 2^bits - 1 that nothing in the
 * file names.  It shows as a pile-up: the frame's brightest value held by several
 * pixels with hardly any just below it (the top of an unclipped spot is one pixel, at
 * most four tied by symmetry on a noiseless frame, and the values under it spread
 * over the noise).  The pixels are counted in the tiles that reach the band only. */
static double sat_level(const im_centroider *c, const im_frame *f, double bg, double noise,
                        int *how)
{
    double full = (double)((1u << f->bits) - 1);
    size_t nt = (size_t)c->ntx * c->nty;
    unsigned vmax = 0;
    *how = IM_SAT_FULL_SCALE;
    for (size_t t = 0; t < nt; t++) vmax = c->tmax[t] > vmax ? c->tmax[t] : vmax;
    if (vmax >= full || !(vmax > bg + 5 * noise)) return full;
    unsigned k = (unsigned)fmax(1, fmax(ceil(noise), ceil(0.01 * (vmax - bg))));
    unsigned lo = vmax > k ? vmax - k : 0;
    long ntop = 0, nband = 0;
    for (size_t t = 0; t < nt; t++) {
        if (c->tmax[t] < lo) continue;
        int tx = (int)(t % (size_t)c->ntx), ty = (int)(t / (size_t)c->ntx);
        for (int y = ty * TILE; y < ty * TILE + TILE && y < f->height; y++)
            for (int x = tx * TILE; x < tx * TILE + TILE && x < f->width; x++) {
                unsigned v = f->px[(size_t)y * f->width + x];
                ntop += v == vmax;
                nband += v >= lo && v < vmax;
            }
    }
    int known = 0;
    for (int b = 8; b < f->bits; b += 2)
        if (vmax == (1u << b) - 1 || (f->bits == 16 && vmax == ((1u << b) - 1) << (16 - b)))
            known = 1;
    if ((known && ntop >= 3) || (ntop >= 5 && ntop > 2 * nband)) {
        *how = IM_SAT_PILEUP;
        return vmax;
    }
    return full;
}

/* ---- the matched filter -------------------------------------------------------- */

typedef struct mfk {
    double w;                  /* 1/e^2 radius, pixels */
    int R, Rb;                 /* half-widths: pixels, bins */
    double g[MF_MAXR + 1];     /* exp(-2 k^2 / w^2) */
    float gb[MF_MAXRB + 1];    /* the same at the bins' spacing of 2 pixels */
    double gb2;                /* sum over the binned 2-D kernel of its squares */
} mfk;

static void mf_kernel(mfk *k, double w)
{
    k->w = w;
    k->R = (int)ceil(2 * w);
    if (k->R > MF_MAXR) k->R = MF_MAXR;
    k->Rb = (k->R + 1) / 2;
    if (k->Rb > MF_MAXRB) k->Rb = MF_MAXRB;
    for (int i = 0; i <= k->R; i++) k->g[i] = exp(-2.0 * i * i / (w * w));
    /* the screen's taps down to 1 % (a screen need not be exact) */
    while (k->Rb > 1 && exp(-8.0 * k->Rb * k->Rb / (w * w)) < 0.01) k->Rb--;
    double s = 0;
    for (int i = 0; i <= k->Rb; i++) {
        k->gb[i] = (float)exp(-8.0 * i * i / (w * w));
        s += (i ? 2 : 1) * (double)k->gb[i] * k->gb[i];
    }
    k->gb2 = s * s;
}

/* The exact statistic T at pixel (cx, cy) (im_centroid_opt's comment), over the
 * kernel's square clipped to the frame; *amp: the least-squares peak of the centred
 * spot with a free constant background. */
static double mf_at(const im_frame *f, const mfk *k, int cx, int cy, double noise,
                    double *amp)
{
    int W = f->width, H = f->height;
    int x0 = cx - k->R, x1 = cx + k->R, y0 = cy - k->R, y1 = cy + k->R;
    if (x0 < 0) x0 = 0;
    if (y0 < 0) y0 = 0;
    if (x1 > W - 1) x1 = W - 1;
    if (y1 > H - 1) y1 = H - 1;
    double r0 = 0, r2 = 0;
    for (int x = x0; x <= x1; x++) {
        double gx = k->g[abs(x - cx)];
        r0 += gx;
        r2 += gx * gx;
    }
    double S1 = 0, S0 = 0, S2 = 0, Sv = 0, gx[2 * MF_MAXR + 1];
    for (int x = x0; x <= x1; x++) gx[x - x0] = k->g[abs(x - cx)];
    /* four rows at a time: their sums are independent chains (the adds' latency, not
       their number, bounds this loop), each summed in the same order as one at a time */
    int y = y0;
    for (; y + 3 <= y1; y += 4) {
        const uint16_t *r0p = f->px + (size_t)y * W, *r1p = r0p + W, *r2p = r1p + W,
                       *r3p = r2p + W;
        double a1 = 0, av = 0, b1 = 0, bv = 0, c1 = 0, cv = 0, d1 = 0, dv = 0;
        for (int x = x0; x <= x1; x++) {
            double g = gx[x - x0], va = r0p[x], vb = r1p[x], vc = r2p[x], vd = r3p[x];
            a1 += g * va; av += va;
            b1 += g * vb; bv += vb;
            c1 += g * vc; cv += vc;
            d1 += g * vd; dv += vd;
        }
        double q1[4] = {a1, b1, c1, d1}, qv[4] = {av, bv, cv, dv};
        for (int l = 0; l < 4; l++) {
            double gy = k->g[abs(y + l - cy)];
            S1 += gy * q1[l]; S0 += gy * r0; S2 += gy * gy * r2; Sv += qv[l];
        }
    }
    for (; y <= y1; y++) {
        const uint16_t *row = f->px + (size_t)y * W;
        double gy = k->g[abs(y - cy)], r1 = 0, rv = 0;
        for (int x = x0; x <= x1; x++) {
            double v = row[x];
            r1 += gx[x - x0] * v;
            rv += v;
        }
        S1 += gy * r1;
        S0 += gy * r0;
        S2 += gy * gy * r2;
        Sv += rv;
    }
    double n = (double)(x1 - x0 + 1) * (y1 - y0 + 1);
    double num = S1 - S0 * Sv / n, den = S2 - S0 * S0 / n;
    if (!(den > 1e-12)) { if (amp) *amp = 0; return 0; }
    if (amp) *amp = num / den;
    return num / (noise * sqrt(den));
}

static int push(int **a, size_t *cap, size_t n, int v)
{
    if (n >= *cap) {
        size_t nc = *cap * 2;
        int *b = realloc(*a, sizeof(int) * nc);
        if (!b) return -1;
        *a = b;
        *cap = nc;
    }
    (*a)[n] = v;
    return 0;
}

/* T at pixel p, computed once per frame (tmap caches it; touched lists it). */
static int tval(im_centroider *c, const im_frame *f, const mfk *k, double noise, int p,
                double *t)
{
    if (isnan(c->tmap[p])) {
        if (push(&c->touched, &c->touched_cap, c->ntouched, p)) return -1;
        c->ntouched++;
        c->tmap[p] = (float)mf_at(f, k, p % f->width, p / f->width, noise, NULL);
    }
    *t = c->tmap[p];
    return 0;
}

/* From pixel p up the statistic to its local maximum (8 neighbours). */
static int climb(im_centroider *c, const im_frame *f, const mfk *k, double noise, int *pp)
{
    int p = *pp, W = f->width, H = f->height;
    double tp;
    if (tval(c, f, k, noise, p, &tp)) return -1;
    for (int it = 0; it < 256; it++) {
        int best = p, x = p % W, y = p / W;
        double tb = tp;
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++) {
                int xx = x + dx, yy = y + dy;
                double t;
                if ((!dx && !dy) || xx < 0 || yy < 0 || xx >= W || yy >= H) continue;
                if (tval(c, f, k, noise, yy * W + xx, &t)) return -1;
                if (t > tb) { tb = t; best = yy * W + xx; }
            }
        if (best == p) break;
        p = best;
        tp = tb;
    }
    *pp = p;
    return 0;
}

/* The region about p where T stays above thr (8-connected, at most MF_MAXREG
 * pixels), marked in rmask; its size. */
static long region(im_centroider *c, const im_frame *f, const mfk *k, double noise, int p,
                   double thr)
{
    int W = f->width, H = f->height;
    size_t head = 0, tail = 0;
    c->rmask[p] = 1;
    if (push(&c->reg, &c->reg_cap, tail++, p)) return -1;
    while (head < tail) {
        int q = c->reg[head++], x = q % W, y = q / W;
        for (int dy = -1; dy <= 1; dy++)
            for (int dx = -1; dx <= 1; dx++) {
                int xx = x + dx, yy = y + dy, r = yy * W + xx;
                double t;
                if (xx < 0 || yy < 0 || xx >= W || yy >= H || c->rmask[r]) continue;
                if (tail >= MF_MAXREG) continue;
                if (tval(c, f, k, noise, r, &t)) return -1;
                if (!(t > thr)) continue;
                c->rmask[r] = 1;
                if (push(&c->reg, &c->reg_cap, tail++, r)) return -1;
            }
    }
    return (long)tail;
}

/* The screen's kernels, written once and compiled per processor.  Each output value
 * is one expression evaluated left to right, g0 a + g1 (b1 + c1) + g2 (b2 + c2) + ...,
 * with no contraction (-ffp-contract=off): the same float whatever the vector width,
 * the same as a pass per tap over whole rows gives.  Eight lanes at a time in GCC's
 * vector extension, the tail one by one. */
#define IM_VN 16                /* lanes: one AVX-512 register, two AVX2, four SSE2 */
typedef float im_v8f __attribute__((vector_size(4 * IM_VN), aligned(4)));
#define v8_load(p) (*(const im_v8f *)(p))
#define v8_store(p, v) (*(im_v8f *)(p) = (v))
typedef uint32_t im_v8u __attribute__((vector_size(4 * IM_VN), aligned(2), may_alias));
typedef int32_t im_v8i __attribute__((vector_size(4 * IM_VN)));
#define v8u_load(p) (*(const im_v8u *)(const void *)(p))

/* out[x] = g[0] mid[x] + sum_j g[j] (up[j][x] + dn[j][x]), j = 1 .. R (the column
 * pass: up, dn the rows j above and below). */
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
static void f_col(float *restrict out, const float *mid, const float *const *up,
                  const float *const *dn, const float *g, int R, int n)
{
    int x = 0;
    for (; x + IM_VN <= n; x += IM_VN) {
        im_v8f a = g[0] * v8_load(mid + x);
        for (int j = 1; j <= R; j++) a = a + g[j] * (v8_load(up[j] + x) + v8_load(dn[j] + x));
        v8_store(out + x, a);
    }
    for (; x < n; x++) {
        float a = g[0] * mid[x];
        for (int j = 1; j <= R; j++) a = a + g[j] * (up[j][x] + dn[j][x]);
        out[x] = a;
    }
}
/* out[x] = (g[0] in[x] + sum_j g[j] (in[x - j] + in[x + j])) norm (the row pass, in
 * read from -R to n + R). */
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
static void f_row(float *restrict out, const float *in, const float *g, int R, float norm,
                  int n)
{
    int x = 0;
    for (; x + IM_VN <= n; x += IM_VN) {
        im_v8f a = g[0] * v8_load(in + x);
        for (int j = 1; j <= R; j++) a = a + g[j] * (v8_load(in + x - j) + v8_load(in + x + j));
        v8_store(out + x, a * norm);
    }
    for (; x < n; x++) {
        float a = g[0] * in[x];
        for (int j = 1; j <= R; j++) a = a + g[j] * (in[x - j] + in[x + j]);
        out[x] = a * norm;
    }
}
/* (finite values only: GCC vectorises the max when told so) */
#if defined(__GNUC__) && !defined(__clang__)
#define IM_FINITE __attribute__((optimize("finite-math-only", "no-signed-zeros")))
#else
#define IM_FINITE
#endif
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default"))) IM_FINITE
static float row_max(const float *restrict a, int n)
{
    float m = a[0];
    for (int x = 1; x < n; x++) m = a[x] > m ? a[x] : m;
    return m;
}
/* o[x] = (four pixels of rows a and b summed) - tb[x]: the sum exact in integers
 * (signed: under 2^18, and a signed conversion is one instruction), then one rounding
 * to float and one in the subtraction. */
__attribute__((target_clones("arch=x86-64-v4", "avx2", "default")))
static void bin_row(const uint16_t *restrict a, const uint16_t *restrict b,
                    const float *restrict tb, float *restrict o, int n)
{
    int x = 0;
    /* eight pixel pairs a vector: a pair read as one 32-bit word, its halves added */
    for (; x + IM_VN <= n; x += IM_VN) {
        im_v8u pa = v8u_load(a + 2 * x), pb = v8u_load(b + 2 * x);
        im_v8u t = ((pa & 0xffff) + (pa >> 16)) + ((pb & 0xffff) + (pb >> 16));
        v8_store(o + x, __builtin_convertvector((im_v8i)t, im_v8f) - v8_load(tb + x));
    }
    for (; x < n; x++)
        o[x] = (float)((int32_t)a[2 * x] + a[2 * x + 1] + b[2 * x] + b[2 * x + 1]) - tb[x];
}
/* The screen's binned row by (ring row by % MF_RING): four pixels summed less four
 * times their tile's local background (c->tb4 holds it for the tile row *tbrow). */
static void screen_bin(im_centroider *c, const im_frame *f, int by, int *tbrow)
{
    int W = f->width, bw = c->bw, ty = (2 * by) / TILE;
    if (ty != *tbrow) {
        const double *tb = c->tbg + (size_t)ty * c->ntx;
        for (int bx = 0; bx < bw; bx++) c->tb4[bx] = (float)(4 * tb[(2 * bx) / TILE]);
        *tbrow = ty;
    }
    const uint16_t *a = f->px + (size_t)(2 * by) * W;
    bin_row(a, a + W, c->tb4, c->bin + (size_t)(by % MF_RING) * c->pw + MF_MAXRB, bw);
}

/* The screen: 2x2 bins less four times their tile's local background, filtered by
 * the kernel at the bins' spacing (columns, then rows; zero beyond the frame), in
 * SNR units of the bins' noise (2 sigma).  Only where it points is T computed.  One
 * pass down the frame: the binned rows live in a ring of 2 Rb + 1 rows and the column
 * pass in one row, so the frame is read once and only the result leaves the cache;
 * every value is computed by the same operations in the same order as a filter over
 * whole binned planes would (the same floats). */
static void screen(im_centroider *c, const im_frame *f, const mfk *k, double noise)
{
    int bw = c->bw, bh = c->bh, pw = c->pw, Rb = k->Rb, M = MF_MAXRB, tbrow = -1;
    const float *zero = c->bin + (size_t)MF_RING * pw;
    int c0 = M - Rb, cw = bw + 2 * Rb;    /* the columns the row pass reads */
    float norm = (float)(1 / (2 * noise * sqrt(k->gb2)));
    /* bottom up: the frame's last rows, the ones pass 1 read last, are still cached */
    for (int by = bh - 1; by >= bh - Rb && by >= 0; by--) screen_bin(c, f, by, &tbrow);
    for (int by = bh - 1; by >= 0; by--) {
        if (by - Rb >= 0) screen_bin(c, f, by - Rb, &tbrow);
        const float *up[MF_MAXRB + 1], *dn[MF_MAXRB + 1];
        for (int j = 1; j <= Rb; j++) {
            up[j] = (by - j >= 0 ? c->bin + (size_t)((by - j) % MF_RING) * pw : zero) + c0;
            dn[j] = (by + j < bh ? c->bin + (size_t)((by + j) % MF_RING) * pw : zero) + c0;
        }
        f_col(c->bcol + c0, c->bin + (size_t)(by % MF_RING) * pw + c0, up, dn, k->gb, Rb, cw);
        f_row(c->scr + (size_t)by * bw, c->bcol + M, k->gb, Rb, norm, bw);
        c->rmax[by] = row_max(c->scr + (size_t)by * bw, bw);
    }
}

typedef struct comp {
    int start, npix;           /* its pixels: list[start .. start+npix) */
    int peak_i;                /* brightest pixel */
    double peak, bg, thr;
    double sum;                /* counts above background over its pixels */
    int edge, nsat;
    int mf_p;                  /* where the matched filter peaks */
    double T, amp;             /* its value there and the amplitude it implies */
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

/* The threshold at which noise alone gives `pfa` false spots per frame: the expected
 * Euler characteristic of the excursion set of a smooth Gaussian field of unit
 * variance above u over area A is A lambda u exp(-u^2/2) / (2 pi)^(3/2) (Adler), with
 * lambda = 2 / w^2 for the filter's correlation exp(-r^2 / w^2); above ~4 it counts
 * the local maxima.  640x480, w = 3 px: 0.08 false spots per frame at u = 5, 1e-4 at
 * 6.23 (1e-3 at 5.84). */
double im_false_alarm_threshold(int width, int height, double w, double pfa)
{
    double k = (double)width * height * (2 / (w * w)) / pow(2 * M_PI, 1.5);
    double lo = 4, hi = 10;
    if (k * lo * exp(-lo * lo / 2) <= pfa) return lo;
    for (int i = 0; i < 60; i++) {
        double u = 0.5 * (lo + hi);
        if (k * u * exp(-u * u / 2) > pfa) lo = u; else hi = u;
    }
    return 0.5 * (lo + hi);
}

static int by_power(const void *a, const void *b)
{
    const im_spot *x = a, *y = b;
    return x->power < y->power ? 1 : x->power > y->power ? -1 : 0;
}
static int comp_by_T(const void *a, const void *b)
{
    const comp *x = a, *y = b;
    return x->T < y->T ? 1 : x->T > y->T ? -1 : x->mf_p - y->mf_p;
}

int im_centroid(im_centroider *ctx, const im_frame *f, const im_centroid_opt *opt_in,
                im_spot *spots, int cap, im_centroid_result *res, char *err, size_t errcap)
{
    im_centroid_opt opt = opt_in ? *opt_in : (im_centroid_opt){0};
    im_centroider *c = ctx ? ctx : im_centroider_new();
    im_centroid_result r;
    comp *comps = NULL;
    int *cand = NULL;          /* screen bins to climb from */
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
    if (opt.min_pixels <= 0) opt.min_pixels = 1;
    if (opt.spot_w == 0) opt.spot_w = 3;
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
    if (!(opt.spot_w >= 0.5 && opt.spot_w <= 12)) {
        rc = im_err(err, errcap, IM_EINVAL, "centroid: the expected spot radius %g px is "
                    "not within 0.5 .. 12", opt.spot_w);
        goto out;
    }
    if (opt.threshold <= 0) opt.threshold = im_false_alarm_threshold(f->width, f->height,
                                                                     opt.spot_w, 1e-4);
    r.threshold = opt.threshold;
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
    if (opt.saturation > 0) {
        sat = opt.saturation;
        r.sat_source = IM_SAT_GIVEN;
    } else sat = sat_level(c, f, r.background, noise, &r.sat_source);
    r.saturation = sat;
    local_background(c, 0.7 * opt.threshold * noise);

    /* Pass 2: the matched filter.  The screen's local maxima above threshold - 2
     * (a spot at the threshold reads 0.8-0.95 of its T on the binned grid, with a
     * correlation of ~0.9: one in a thousand would fall under it) and its highest
     * bin always (so that "none" quotes a computed T); from each the exact T climbed
     * to its maximum; a maximum above threshold and in no region yet opens one. */
    mfk K;
    mf_kernel(&K, opt.spot_w);
    int W = f->width, H = f->height;
    double ts = fmax(opt.threshold - 2, 0.5 * opt.threshold);
    int ncand = 0, best_p = 0;
    double best = -INFINITY;
    size_t ccap = 0;
    if (c->bw >= 4 && c->bh >= 4) {
        screen(c, f, &K, noise);
        int bw = c->bw, bh = c->bh, top = 0, toprow = 0;
        float topv = -INFINITY;
        for (int by = 0; by < bh; by++) {
            float m = c->rmax[by];
            if (m > topv) { topv = m; toprow = by; }
            if (!(m > ts)) continue;
            for (int bx = 0; bx < bw; bx++) {
                int b = by * bw + bx;
                float v = c->scr[b];
                if (!(v > ts)) continue;
                int lm = 1;
                for (int dy = -1; dy <= 1 && lm; dy++)
                    for (int dx = -1; dx <= 1; dx++) {
                        int xx = bx + dx, yy = by + dy;
                        if ((!dx && !dy) || xx < 0 || yy < 0 || xx >= bw || yy >= bh) continue;
                        float u = c->scr[yy * bw + xx];
                        if (u > v || (u == v && yy * bw + xx < b)) { lm = 0; break; }
                    }
                if (!lm || ncand >= MF_MAXCAND) continue;
                if ((size_t)ncand >= ccap) {
                    size_t nc = ccap ? 2 * ccap : 64;
                    int *cc = realloc(cand, sizeof *cc * nc);
                    if (!cc) { rc = im_err(err, errcap, IM_ENOMEM, "out of memory"); goto out; }
                    cand = cc;
                    ccap = nc;
                }
                cand[ncand++] = b;
            }
        }
        for (int bx = 0; bx < bw; bx++)
            if (c->scr[(size_t)toprow * bw + bx] == topv) { top = toprow * bw + bx; break; }
        if ((size_t)ncand >= ccap) {
            int *cc = realloc(cand, sizeof *cc * (ccap + 1));
            if (!cc) { rc = im_err(err, errcap, IM_ENOMEM, "out of memory"); goto out; }
            cand = cc;
        }
        cand[ncand++] = top;
    }
    /* a frame too small for the screen: every pixel a candidate */
    int nstart = ncand ? ncand : W * H;
    for (int q = 0; q < nstart; q++) {
        int p;
        if (ncand) {
            int bx = cand[q] % c->bw, by = cand[q] / c->bw;
            double tb = -INFINITY, t;
            p = 2 * by * W + 2 * bx;
            for (int dy = 0; dy < 2; dy++)
                for (int dx = 0; dx < 2; dx++) {
                    int pp = (2 * by + dy) * W + 2 * bx + dx;
                    if (tval(c, f, &K, noise, pp, &t)) goto nomem;
                    if (t > tb) { tb = t; p = pp; }
                }
        } else p = q;
        if (climb(c, f, &K, noise, &p)) goto nomem;
        double tp = c->tmap[p];
        if (tp > best || (tp == best && p < best_p)) { best = tp; best_p = p; }
        if (!(tp > opt.threshold) || c->rmask[p]) continue;
        long nreg = region(c, f, &K, noise, p, opt.threshold);
        if (nreg < 0) goto nomem;
        if (nreg < opt.min_pixels) continue;
        if (ncomp == capcomp) {
            int nc = capcomp ? 2 * capcomp : 16;
            comp *cc = realloc(comps, sizeof *cc * (size_t)nc);
            if (!cc) goto nomem;
            comps = cc;
            capcomp = nc;
        }
        comp *k = &comps[ncomp++];
        memset(k, 0, sizeof *k);
        k->mf_p = p;
        k->T = tp;
        mf_at(f, &K, p % W, p / W, noise, &k->amp);
    }
    /* Each spot's connected pixels above the pixel threshold, from its brightest
     * pixel near the filter's peak (none for a spot found by its integrated SNR
     * alone: its fit starts from the filter's estimate). */
    for (int s = 0; s < ncomp; s++) {
        comp *k = &comps[s];
        int p = k->mf_p, x = p % W, y = p / W, t = (y / TILE) * c->ntx + x / TILE;
        int seed = p;
        for (int dy = -2; dy <= 2; dy++)
            for (int dx = -2; dx <= 2; dx++) {
                int xx = x + dx, yy = y + dy;
                if (xx < 0 || yy < 0 || xx >= W || yy >= H) continue;
                if (f->px[yy * W + xx] > f->px[seed]) seed = yy * W + xx;
            }
        k->bg = c->tbg[t];
        k->thr = k->bg + opt.threshold * noise;
        if (f->px[seed] > k->thr && !c->mask[seed]) {
            if (flood(c, f, seed, k->thr, sat, &used, k)) goto nomem;
        } else {
            k->start = (int)used;
            k->npix = 0;
            k->peak_i = p;
            k->peak = f->px[p];
        }
    }
    r.ndetected = ncomp;
    if (ncomp == 0) {
        r.outcome = IM_FOUND_NONE;
        r.best_snr = best > -INFINITY ? best : 0;
        r.best_x = best_p % W;
        r.best_y = best_p / W;
        goto out;
    }
    qsort(comps, (size_t)ncomp, sizeof *comps, comp_by_T);
    int nfit = ncomp < opt.max_spots ? ncomp : opt.max_spots;
    if (nfit > cap) nfit = cap;
    for (int s = 0; s < nfit; s++) {
        comp *k = &comps[s];
        im_spot_in in = {
            .f = f, .list = c->list + k->start, .npix = k->npix, .peak_i = k->peak_i,
            .peak = k->peak, .bg = k->bg, .thr = k->thr, .noise = noise, .gain = opt.gain,
            .sat = sat, .window = opt.window, .method = opt.method, .edge = k->edge,
            .plane = opt.plane, .w_hint = opt.spot_w, .a_hint = k->amp,
            .x_hint = k->mf_p % f->width, .y_hint = k->mf_p / f->width, .snr_mf = k->T,
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
        r.best_snr = comps[0].T;
        r.best_x = comps[0].mf_p % f->width;
        r.best_y = comps[0].mf_p / f->width;
    }
    goto out;
nomem:
    rc = im_err(err, errcap, IM_ENOMEM, "out of memory");
out:
    if (c->mask)
        for (size_t i = 0; i < used; i++) c->mask[c->list[i]] = 0;
    if (c->tmap)
        for (size_t i = 0; i < c->ntouched; i++) {
            c->tmap[c->touched[i]] = NAN;
            c->rmask[c->touched[i]] = 0;
        }
    c->ntouched = 0;
    free(cand);
    free(comps);
    if (res) *res = r;
    if (!ctx) im_centroider_free(c);
    return rc;
}
