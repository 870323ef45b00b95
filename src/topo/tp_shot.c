/* tp_shot.c -- shot noise in the centroids of frames from a camera whose gain is not
 * known: the photon transfer of the spots themselves.  Each located spot's fitted
 * Gaussian predicts every pixel of its window; the residual's variance there is the
 * read (background) noise plus the signal over the gain, var = sr^2 + s / g, so over
 * all spots of a scan sr^2 and 1/g are the least-squares fit of d^2 to them (sr
 * fitted too: the frame's background noise, estimated apart, is a few % off, and the
 * read noise dwarfs the shot noise away from the peak).  The
 * centroid's sigma from the fit used the additive noise alone; for a symmetric spot
 * its x and y are orthogonal to amplitude, width and background, so the sigma with
 * shot noise is the additive one times sqrt(I_add / I_shot), the Fisher information
 * of x summed over the window with each pixel's variance.
 * The samples are unsigned: a background within a few sigmas of zero has its noise
 * clipped there, so each pixel's expected d^2 is scaled by the censored normal's
 * variance ratio (clip_kappa); that clipping was why the gain read 0.80-0.84 of the
 * truth (frames of a bias of 100 counts under 50 counts of read noise). */
#include <math.h>
#include "tp_int.h"
#include "imaging/imaging.h"

/* The window the sums run over: the centroider's (im_fit.c: half-width ceil(2w + 1)
 * about the peak pixel, a constant background).  The fit's five parameters (peak, x,
 * y, width, background) absorb part of each pixel's noise, most at the peak where
 * the shot noise is: with the hat matrix H = J (J'J)^-1 J' of the fit's (equal)
 * weights, E[d_i^2] = sum_j (I - H)_ij^2 var_j = sr^2 (1 - h_ii) + t_i / g, where
 * t_i = sum_j (I - H)_ij^2 s_j = s_i (1 - 2 h_ii) + J_i A B A J_i' (A = (J'J)^-1,
 * B = sum_j s_j J_j' J_j).  Without this correction the gain of 1 e-/count of the
 * synthetic frames came out 2.6. */
#define NP 5

static int inv5(double a[NP][NP], double out[NP][NP])    /* Gauss-Jordan, pivoting */
{
    double m[NP][2 * NP];
    for (int i = 0; i < NP; i++)
        for (int j = 0; j < 2 * NP; j++) m[i][j] = j < NP ? a[i][j] : (j - NP == i);
    for (int c = 0; c < NP; c++) {
        int p = c;
        for (int r = c + 1; r < NP; r++) if (fabs(m[r][c]) > fabs(m[p][c])) p = r;
        if (!(fabs(m[p][c]) > 0)) return -1;
        for (int j = 0; j < 2 * NP; j++) { double t = m[c][j]; m[c][j] = m[p][j]; m[p][j] = t; }
        double d = m[c][c];
        for (int j = 0; j < 2 * NP; j++) m[c][j] /= d;
        for (int r = 0; r < NP; r++) {
            if (r == c) continue;
            double f = m[r][c];
            for (int j = 0; j < 2 * NP; j++) m[r][j] -= f * m[c][j];
        }
    }
    for (int i = 0; i < NP; i++) for (int j = 0; j < NP; j++) out[i][j] = m[i][j + NP];
    return 0;
}

/* Var(max(X, 0)) / Var(X) for X normal with mean z sigmas (the censored normal). */
static double clip_kappa(double z)
{
    if (z > 8) return 1;
    if (z < -8) return 0;
    double P = 0.5 * erfc(-z / sqrt(2)), ph = exp(-0.5 * z * z) * 0.3989422804014327;
    double m = z * P + ph, q = (z * z + 1) * P + z * ph;
    return fmax(0, q - m * m);
}

static void jrow(double i, double j, double x, double y, double amp, double w, double J[NP],
                 double *s)
{
    double dx = i - x, dy = j - y, rr = dx * dx + dy * dy, g = exp(-2 * rr / (w * w));
    *s = amp * g;
    J[0] = g;                                   /* peak */
    J[1] = amp * g * 4 * dx / (w * w);          /* x */
    J[2] = amp * g * 4 * dy / (w * w);          /* y */
    J[3] = amp * g * 4 * rr / (w * w * w);      /* width */
    J[4] = 1;                                   /* background */
}

void tp_shot_add(tp_shot *sh, const im_frame *f, double x, double y, double amp, double w,
                 double bg, double noise)
{
    if (!(w > 0) || !(amp > 0) || !(noise > 0)) return;
    int h = (int)ceil(2 * w + 1);
    if (h < 3) h = 3;
    if (h > 25) h = 25;
    int px = (int)floor(x + 0.5), py = (int)floor(y + 0.5);
    int x0 = px - h, x1 = px + h, y0 = py - h, y1 = py + h;
    if (x0 < 0 || y0 < 0 || x1 >= f->width || y1 >= f->height) return;   /* cut */
    double sat = (double)((1u << f->bits) - 1);
    double JJ[NP][NP] = {{0}}, B[NP][NP] = {{0}}, A[NP][NP], J[NP], sv;
    for (int j = y0; j <= y1; j++)
        for (int i = x0; i <= x1; i++) {
            if (f->px[(size_t)j * (size_t)f->width + (size_t)i] >= sat) return;   /* not linear */
            jrow(i, j, x, y, amp, w, J, &sv);
            for (int a = 0; a < NP; a++)
                for (int b = 0; b < NP; b++) {
                    JJ[a][b] += J[a] * J[b];
                    B[a][b] += sv * J[a] * J[b];
                }
        }
    if (inv5(JJ, A)) return;
    /* the read noise before the clip at zero: the frame's measured noise is the
       clipped one, sqrt(kappa) of it at the background's level */
    double sr = noise;
    for (int it = 0; it < 3; it++) sr = noise / sqrt(fmax(0.25, clip_kappa((bg + 0.5) / sr)));
    double ABA[NP][NP], T[NP][NP];
    for (int a = 0; a < NP; a++)
        for (int b = 0; b < NP; b++) {
            T[a][b] = 0;
            for (int k = 0; k < NP; k++) T[a][b] += A[a][k] * B[k][b];
        }
    for (int a = 0; a < NP; a++)
        for (int b = 0; b < NP; b++) {
            ABA[a][b] = 0;
            for (int k = 0; k < NP; k++) ABA[a][b] += T[a][k] * A[k][b];
        }
    for (int j = y0; j <= y1; j++)
        for (int i = x0; i <= x1; i++) {
            double v = f->px[(size_t)j * (size_t)f->width + (size_t)i];
            jrow(i, j, x, y, amp, w, J, &sv);
            double hii = 0, q = 0;
            for (int a = 0; a < NP; a++)
                for (int b = 0; b < NP; b++) {
                    hii += J[a] * A[a][b] * J[b];
                    q += J[a] * ABA[a][b] * J[b];
                }
            double d = v - bg - sv, t = sv * (1 - 2 * hii) + q;
            double x1 = 1 - hii;
            /* A pixel whose mean is within a few noise sigmas of zero has its read
               noise clipped by the unsigned samples (a bias of 100 counts under 50
               counts of noise: 2.3 % of the background at 0, its variance 4 % low);
               without this the regression gave the missing variance to the shot
               term and read the gain 0.80-0.84 of the truth.  Each pixel's expected
               d^2 is scaled by the censored normal's variance over the normal's. */
            double kap = clip_kappa((bg + sv + 0.5) / sr);
            x1 *= kap;
            t *= kap;
            sh->s11 += x1 * x1;
            sh->s12 += x1 * t;
            sh->s22 += t * t;
            sh->s1y += x1 * d * d;
            sh->s2y += t * d * d;
            sh->q[0] += x1 * x1 * x1 * x1;
            sh->q[1] += x1 * x1 * x1 * t;
            sh->q[2] += x1 * x1 * t * t;
            sh->q[3] += x1 * t * t * t;
            sh->q[4] += t * t * t * t;
        }
    sh->n++;
}

double tp_shot_gain(const tp_shot *sh)
{
    double det = sh->s11 * sh->s22 - sh->s12 * sh->s12;
    if (sh->n < 3 || !(det > 0)) return NAN;
    double ginv = (sh->s11 * sh->s2y - sh->s12 * sh->s1y) / det;
    return ginv > 0 ? 1 / ginv : INFINITY;       /* no excess: no shot noise seen */
}

/* The gain's standard error: 1/g's from the regression's sandwich with each squared
 * residual's variance 2 E[d^2]^2 (normal residuals; E[d^2] the fitted model, so the
 * errors of the pixels at the peak, larger, count for more), times g^2.  With 2000
 * spots of peak 1000 counts over a read noise of 50 counts it is about 0.05 at
 * 1 e-/count and 0.5 at 4 (the shot noise then a tenth of the read noise). */
double tp_shot_gain_se(const tp_shot *sh)
{
    double det = sh->s11 * sh->s22 - sh->s12 * sh->s12;
    if (sh->n < 3 || !(det > 0)) return NAN;
    double a = (sh->s22 * sh->s1y - sh->s12 * sh->s2y) / det;
    double b = (sh->s11 * sh->s2y - sh->s12 * sh->s1y) / det;
    if (!(b > 0)) return NAN;
    /* M = 2 sum x x' (a x1 + b t)^2 */
    const double *q = sh->q;
    double m11 = 2 * (a * a * q[0] + 2 * a * b * q[1] + b * b * q[2]);
    double m12 = 2 * (a * a * q[1] + 2 * a * b * q[2] + b * b * q[3]);
    double m22 = 2 * (a * a * q[2] + 2 * a * b * q[3] + b * b * q[4]);
    /* (X'X)^-1 row 2: (-s12, s11) / det */
    double r1 = -sh->s12 / det, r2 = sh->s11 / det;
    double vb = r1 * r1 * m11 + 2 * r1 * r2 * m12 + r2 * r2 * m22;
    return vb > 0 ? sqrt(vb) / (b * b) : NAN;
}

double tp_shot_factor(double amp, double w, double noise, double gain)
{
    if (!(gain > 0) || isinf(gain) || !(w > 0) || !(noise > 0)) return 1;
    int r = (int)ceil(2 * w + 1);
    double i_add = 0, i_shot = 0;
    for (int j = -r; j <= r; j++)           /* a spot centred on a pixel: the ratio */
        for (int i = -r; i <= r; i++) {     /* hardly depends on the phase */
            double rr = (double)(i * i + j * j);
            double s = amp * exp(-2 * rr / (w * w));
            double dsdx = s * 4 * i / (w * w);
            i_add += dsdx * dsdx / (noise * noise);
            i_shot += dsdx * dsdx / (noise * noise + s / gain);
        }
    return i_shot > 0 ? sqrt(i_add / i_shot) : 1;
}
