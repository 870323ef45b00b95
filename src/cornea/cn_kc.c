/* cn_kc.c -- what a topographer reads off the reconstructed surface (cn_zern.c):
 * masked maps (elevation against the best-fit sphere, axial and tangential power)
 * and the keratoconus indices as clinical software reports them -- Kmax and where,
 * central K, I-S, Sim K and AST on the 3 mm ring, SRAX, KISA% -- with the screen
 * against the published thresholds (sources in doc/topography.md) and each index's
 * sd from the Zernike coefficients' covariance (Monte Carlo draws).  The same
 * indices of an analytic surface (the truth of a simulation) for tests and benches. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cn_int.h"

#define KN 337.5                /* (1.3375 - 1) * 1000: D per 1/mm */
#define DEG (M_PI / 180)

/* A surface the indices read: axial power (D) at (x, y), 0 or -1. */
typedef struct kc_surf {
    const cn_zfit *z;           /* the reconstruction, or */
    cn_surf s;                  /* an analytic surface, seen from a frame: */
    double O[3];                /* the frame's origin in the surface's eye frame */
    double E[3][3];             /* E[k]: the frame's axis k in the eye frame */
    double g0x, g0y;            /* its slope at the origin (taken out, as cn_zlocal) */
    double ox, oy;              /* the frame's origin about the rig's nominal apex */
} kc_surf;

/* The analytic surface's slopes in a frame (the reconstruction's, cn_recon.c: the
 * reference model's eye frame when that fits, else the instrument's axes): the
 * surface met along the frame's z line through (x, y), its normal turned back into
 * the frame.  Taken in the surface's own frame instead, a 2 deg tilted, decentred
 * coned eye's true Kmax sat 0.45 mm from a correct measurement in the instrument's. */
static int model_slope(const kc_surf *k, double x, double y, double *fx, double *fy)
{
    double p[3], d[3], z = 0, zx = 0, zy = 0;
    for (int i = 0; i < 3; i++) {
        p[i] = k->O[i] + x * k->E[0][i] + y * k->E[1][i];
        d[i] = k->E[2][i];
    }
    double t = -p[2] / d[2];
    for (int it = 0; it < 40; it++) {   /* Newton on p_z + t d_z - sag(p_xy + t d_xy) */
        if (cn_sag(&k->s, p[0] + t * d[0], p[1] + t * d[1], &z, &zx, &zy)) return -1;
        double g = p[2] + t * d[2] - z, dg = d[2] - zx * d[0] - zy * d[1];
        if (!(fabs(dg) > 1e-9)) return -1;
        t -= g / dg;
        if (fabs(g / dg) < 1e-14) break;
    }
    if (cn_sag(&k->s, p[0] + t * d[0], p[1] + t * d[1], &z, &zx, &zy)) return -1;
    double ne[3] = {-zx, -zy, 1}, n[3];
    for (int i = 0; i < 3; i++) n[i] = k->E[i][0] * ne[0] + k->E[i][1] * ne[1] + k->E[i][2] * ne[2];
    if (!(n[2] > 1e-9)) return -1;
    *fx = -n[0] / n[2];
    *fy = -n[1] / n[2];
    return 0;
}

/* Axial curvature of the analytic surface about its normal at the origin. */
static int model_axial(const kc_surf *k, double x, double y, double *axial)
{
    double r = hypot(x, y), ex = 1, ey = 0, ax, ay, bx, by, cx, cy;
    const double h = 1e-4;
    if (r > 0) { ex = x / r; ey = y / r; }
    if (model_slope(k, x, y, &ax, &ay) || model_slope(k, x + h * ex, y + h * ey, &bx, &by) ||
        model_slope(k, x - h * ex, y - h * ey, &cx, &cy))
        return -1;
    ax -= k->g0x;
    ay -= k->g0y;
    double zr = ax * ex + ay * ey, zrr = ((bx - cx) * ex + (by - cy) * ey) / (2 * h);
    *axial = r > 1e-6 ? zr / (r * sqrt(1 + ax * ax + ay * ay)) : zrr / pow(1 + zr * zr, 1.5);
    return 0;
}

/* Solve the 5 x 5 system m (destroyed) for its inverse; 0 or -1. */
static int inv5(double m[5][5], double out[5][5])
{
    double a[5][10];
    for (int i = 0; i < 5; i++)
        for (int j = 0; j < 10; j++) a[i][j] = j < 5 ? m[i][j] : (j - 5 == i);
    for (int c = 0; c < 5; c++) {
        int p = c;
        for (int r = c + 1; r < 5; r++) if (fabs(a[r][c]) > fabs(a[p][c])) p = r;
        if (!(fabs(a[p][c]) > 1e-300)) return -1;
        for (int j = 0; j < 10; j++) { double t = a[c][j]; a[c][j] = a[p][j]; a[p][j] = t; }
        double d = a[c][c];
        for (int j = 0; j < 10; j++) a[c][j] /= d;
        for (int r = 0; r < 5; r++) {
            if (r == c) continue;
            double f = a[r][c];
            for (int j = 0; j < 10; j++) a[r][j] -= f * a[c][j];
        }
    }
    for (int i = 0; i < 5; i++) for (int j = 0; j < 5; j++) out[i][j] = a[i][j + 5];
    return 0;
}

/* The measured slopes about (x, y), fitted locally (the curvatures come from the
 * data where they are, not from a global surface alone: a cone 0.8 mm wide near the
 * zone's edge can be beyond what the Zernike orders follow to the noise): the
 * departure of the measured slopes from the Zernike surface's, fx - Zx = a0 + a1 dx
 * + a2 dy, fy - Zy = b0 + a2 dx + a3 dy (one Hessian), each spot weighted by its
 * slope's 1 / sigma^2 and a Gaussian kernel of sd kr / 2 (cut at 1.5 kr), then the
 * Zernike surface's slopes and Hessian at (x, y) added back.  The trend taken out is
 * what keeps the kernel from biasing the curvature: a linear fit of a sphere's own
 * slopes reads its axial power high by about 1.5 (kr / 2)^2 / R^2 inside the data
 * and more where the kernel is cut by the zone's edge (a 9.5 mm zone of 770 spots,
 * kr 0.77 mm: central K +0.21 D and Kmax +0.73 D at the edge on R 7.8, +0.40 and
 * +0.98 D on R 6.5).  p = (a0, b0, a1, a2, a3); V its covariance (the sandwich of
 * the kernel weights; the trend is taken as known).  0, or -1 with fewer than 8
 * spots in reach. */
static int local_fit(const cn_zfit *z, double x, double y, double p[5], double V[5][5],
                     double tr[5])
{
    double M[5][5] = {{0}}, S[5][5] = {{0}}, b[5] = {0}, Mi[5][5];
    double s2 = 0.25 * z->kr * z->kr, cut = 2.25 * z->kr * z->kr;
    int nn = 0;
    for (int i = 0; i < z->npts; i++) {
        double dx = z->xy[2 * i] - x, dy = z->xy[2 * i + 1] - y, d2 = dx * dx + dy * dy;
        if (d2 > cut || !(z->wt[i] > 0)) continue;
        double k = exp(-d2 / (2 * s2)), w = k * z->wt[i], w2 = k * k * z->wt[i];
        double ru[5] = {1, 0, dx, dy, 0}, rv[5] = {0, 1, 0, dx, dy};
        double eu = z->sl[2 * i] - z->zsl[2 * i], ev = z->sl[2 * i + 1] - z->zsl[2 * i + 1];
        for (int a = 0; a < 5; a++) {
            b[a] += w * (ru[a] * eu + rv[a] * ev);
            for (int c = 0; c < 5; c++) {
                M[a][c] += w * (ru[a] * ru[c] + rv[a] * rv[c]);
                S[a][c] += w2 * (ru[a] * ru[c] + rv[a] * rv[c]);
            }
        }
        nn++;
    }
    if (nn < 8 || inv5(M, Mi)) return -1;
    for (int a = 0; a < 5; a++) {
        p[a] = 0;
        for (int c = 0; c < 5; c++) p[a] += Mi[a][c] * b[c];
    }
    {   /* the trend back: the Zernike surface's slopes and Hessian at (x, y) */
        const double h = 1e-3;
        double f, gx, gy, ax, ay, bx, by, cx, cy, ex, ey;
        if (cn_zsag(z, x, y, &f, &gx, &gy) || cn_zsag(z, x + h, y, &f, &ax, &ay) ||
            cn_zsag(z, x - h, y, &f, &bx, &by) || cn_zsag(z, x, y + h, &f, &cx, &cy) ||
            cn_zsag(z, x, y - h, &f, &ex, &ey))
            return -1;
        double t[5] = {gx, gy, (ax - bx) / (2 * h), 0.5 * ((ay - by) + (cx - ex)) / (2 * h),
                       (cy - ey) / (2 * h)};
        for (int a = 0; a < 5; a++) p[a] += t[a];
        if (tr) memcpy(tr, t, sizeof t);
    }
    double T[5][5];
    for (int a = 0; a < 5; a++)
        for (int c = 0; c < 5; c++) {
            T[a][c] = 0;
            for (int q = 0; q < 5; q++) T[a][c] += Mi[a][q] * S[q][c];
        }
    for (int a = 0; a < 5; a++)
        for (int c = 0; c < 5; c++) {
            V[a][c] = 0;
            for (int q = 0; q < 5; q++) V[a][c] += T[a][q] * Mi[q][c];
        }
    return 0;
}

void cn_zlocal_vertex(cn_zfit *z)
{
    double p[5], V[5][5], f;
    for (int i = 0; i < z->npts; i++)
        if (cn_zsag(z, z->xy[2 * i], z->xy[2 * i + 1], &f, &z->zsl[2 * i], &z->zsl[2 * i + 1]))
            z->zsl[2 * i] = z->zsl[2 * i + 1] = 0;
    z->l0x = z->l0y = 0;
    if (!local_fit(z, 0, 0, p, V, NULL)) { z->l0x = p[0]; z->l0y = p[1]; }
}

/* Axial and tangential curvature (1/mm) at (x, y) from the local fit, about the
 * normal at the vertex, and the axial one's sd.  Within one kernel radius of the
 * vertex f_r / r of the local fit loses its precision as r -> 0: there the axial
 * curvature is the Zernike surface's own (its slope is smooth to the vertex) plus
 * the local fit's departure from it as tangential curvature (the axial's limit at
 * r -> 0; the whole tangential curvature in its place put a cone's flank 0.11 D above
 * the true Kmax at 0.76 mm from the vertex on a 9.5 mm zone, t_zone). */
int cn_zlocal(const cn_zfit *z, double x, double y, double *axial, double *tang,
              double *sd_axial)
{
    double p[5], V[5][5], tr[5], r = hypot(x, y), ex = 1, ey = 0;
    if (local_fit(z, x, y, p, V, tr)) return -1;
    if (r > 0) { ex = x / r; ey = y / r; }
    double sx = p[0] - z->l0x, sy = p[1] - z->l0y;
    double fr = sx * ex + sy * ey, q = 1 + sx * sx + sy * sy;
    double g[3] = {ex * ex, 2 * ex * ey, ey * ey};
    double frr = g[0] * p[2] + g[1] * p[3] + g[2] * p[4], vt = 0;
    for (int a = 0; a < 3; a++)
        for (int c = 0; c < 3; c++) vt += g[a] * V[a + 2][c + 2] * g[c];
    double t15 = pow(1 + fr * fr, 1.5);
    *tang = frr / t15;
    if (r > z->kr) {
        double vr = ex * ex * V[0][0] + 2 * ex * ey * V[0][1] + ey * ey * V[1][1];
        *axial = fr / (r * sqrt(q));
        if (sd_axial) *sd_axial = sqrt(vr) / (r * sqrt(q));
    } else {
        double zx = tr[0] - z->g0x, zy = tr[1] - z->g0y, zr = zx * ex + zy * ey;
        double zrr = g[0] * tr[2] + g[1] * tr[3] + g[2] * tr[4];
        double za = r > 1e-6 ? zr / (r * sqrt(1 + zx * zx + zy * zy)) : zrr;
        *axial = za + (*tang - zrr / pow(1 + zr * zr, 1.5));
        if (sd_axial) *sd_axial = sqrt(vt) / t15;
    }
    return isfinite(*axial) && isfinite(*tang) ? 0 : -1;
}

static int power(const kc_surf *k, double x, double y, double *ax)
{
    double a, t;
    int rc = k->z ? cn_zlocal(k->z, x, y, &a, &t, NULL) : model_axial(k, x, y, &a);
    *ax = KN * a;
    return rc;
}

static int power_sd(const kc_surf *k, double x, double y, double *ax, double *sd)
{
    double a, t, sa = NAN;
    int rc = k->z ? cn_zlocal(k->z, x, y, &a, &t, &sa) : model_axial(k, x, y, &a);
    *ax = KN * a;
    *sd = KN * sa;
    return rc;
}

/* Mean axial power on a ring of radius r (72 points); its second harmonic too. */
static int ring(const kc_surf *k, double r, double *mean, double *amp, double *steep)
{
    enum { N = 72 };
    double sum = 0, a = 0, b = 0, p;
    int n = 0;
    for (int j = 0; j < N; j++) {
        double phi = 2 * M_PI * j / N;
        if (power(k, r * cos(phi), r * sin(phi), &p)) continue;   /* a gap in the data */
        sum += p;
        a += p * cos(2 * phi);
        b += p * sin(2 * phi);
        n++;
    }
    if (n < N / 2) return -1;
    *mean = sum / n;
    if (amp) *amp = hypot(a, b) * 2.0 / n;
    if (steep) {
        double st = 0.5 * atan2(b, a) / DEG;
        *steep = st < 0 ? st + 180 : st;
    }
    return 0;
}

/* The mean axial power of each semi-meridian (1 deg steps, 0.5 mm to lim), and the
 * steepest of the upper (0-179) and lower (180-359) halves. */
static void semi_meridians(const kc_surf *k, double lim, double sm[360], int *au, int *al)
{
    double bu = -INFINITY, bl = -INFINITY, p;
    *au = 0;
    *al = 180;
    for (int dg = 0; dg < 360; dg++) {
        double a = dg * DEG, sum = 0;
        int nn = 0;
        for (double r = 0.5; r <= lim; r += 0.1)
            if (!power(k, r * cos(a), r * sin(a), &p)) { sum += p; nn++; }
        sm[dg] = nn ? sum / nn : -INFINITY;
        if (dg < 180) { if (sm[dg] > bu) { bu = sm[dg]; *au = dg; } }
        else if (sm[dg] > bl) { bl = sm[dg]; *al = dg; }
    }
}

/* The indices of one surface (no sd). */
static int indices(const kc_surf *k, double zone, cn_kc *o)
{
    double p;
    o->zone_r = zone;
    /* Kmax: a 0.05 mm grid within 0.9 of the zone and its edge (the axial map of
       a cone off the centre peaks beyond the cone, often at the zone's edge), then
       polar steps about the best (0.0025 mm radially, 0.0025 mm along the arc) */
    double lim = 0.9 * zone, best = -INFINITY, bx = 0, by = 0;
    for (double y = -lim; y <= lim; y += 0.05)
        for (double x = -lim; x <= lim; x += 0.05) {
            if (hypot(x, y) > lim || (k->z && !cn_zcovered(k->z, x, y))) continue;
            if (!power(k, x, y, &p) && p > best) { best = p; bx = x; by = y; }
        }
    for (int j = 0; j < 720; j++) {
        double x = lim * cos(j * M_PI / 360), y = lim * sin(j * M_PI / 360);
        if ((!k->z || cn_zcovered(k->z, x, y)) && !power(k, x, y, &p) && p > best) { best = p; bx = x; by = y; }
    }
    if (!isfinite(best)) return -1;
    double r0 = hypot(bx, by), t0 = atan2(by, bx);
    for (int pass = 0; pass < 2; pass++) {
        double span = pass ? 0.005 : 0.05;
        double rc = r0, tc = t0;
        for (int i = -20; i <= 20; i++)
            for (int j = -20; j <= 20; j++) {
                double r = fmin(rc + i * span / 20, lim), t = tc + j * span / 20 / fmax(rc, 0.05);
                if (r < 0) continue;
                double x = r * cos(t), y = r * sin(t);
                if (!power(k, x, y, &p) && p > best) { best = p; bx = x; by = y; r0 = r; t0 = t; }
            }
    }
    o->kmax = best;
    o->kmax_x = bx + k->ox;
    o->kmax_y = by + k->oy;
    /* central K: the rings of 2, 3, 4 mm diameter inside the data */
    double s = 0, m;
    o->ck_rings = 0;
    for (int d = 2; d <= 4; d++)
        if (d / 2.0 <= lim && !ring(k, d / 2.0, &m, NULL, NULL)) { s += m; o->ck_rings++; }
    o->ck = o->ck_rings ? s / o->ck_rings : NAN;
    /* I-S: five points 30 deg apart about straight down and straight up */
    o->is_r = fmin(3.0, lim);
    double inf = 0, sup = 0;
    int ni = 0, ns = 0;
    for (int j = -2; j <= 2; j++) {
        double a = (90 + 30 * j) * DEG;
        if (!power(k, o->is_r * cos(a), o->is_r * sin(a), &p)) { sup += p; ns++; }
        if (!power(k, o->is_r * cos(a + M_PI), o->is_r * sin(a + M_PI), &p)) { inf += p; ni++; }
    }
    if (ni < 3 || ns < 3) return -1;
    o->is = inf / ni - sup / ns;
    /* Sim K on the 3 mm ring (or the zone's, if smaller) */
    double amp, st, hr = fmin(1.5, lim);
    if (ring(k, hr, &m, &amp, &st)) return -1;
    o->simk1 = m - amp;
    o->simk2 = m + amp;
    o->simk_axis = st;
    o->ast = 2 * amp;
    /* SRAX: the steepest semi-meridian above and below the horizontal (mean axial
       power from 0.5 mm to the zone's edge, 1 deg steps); the angle between them
       less 180 */
    double sm[360], bu, bl;
    int au, al;
    semi_meridians(k, lim, sm, &au, &al);
    bu = sm[au];
    bl = sm[al];
    /* each half's steepest semi-meridian must be one: a cone straight below steepens
       the two semi-meridians either side of it alike, and the upper half's flanks
       alike, and which of two equals wins is noise (the bench's cone read 35 deg
       against the truth's 145 with the same surface): no other semi-meridian of the
       half, 20 deg or more away, within 0.05 D of it; else SRAX (and KISA) is not
       defined on these data */
    o->srax = fabs(180 - fabs((double)(al - au)));
    for (int dg = 0; dg < 360; dg++) {
        int half = dg < 180, far = half ? abs(dg - au) >= 20 : abs(dg - al) >= 20;
        if (far && sm[dg] > (half ? bu : bl) - 0.05) { o->srax = NAN; break; }
    }
    /* KISA% (Rabinowitz & Rasheed 1999) */
    o->kisa = o->ck * o->is * o->ast * o->srax * 100 / 300;
    return 0;
}

static void screen(cn_kc *o)
{
    /* thresholds: central K 47.2-48.7 probable, > 48.7 keratoconus; I-S 1.4-1.8
       probable, > 1.8 keratoconus; SRAX > 21 deg abnormal; KISA% 60-100 suspect,
       > 100 keratoconus (doc/topography.md names the sources) */
    size_t l = 0;
    o->screen = CN_KC_NORMAL;
    o->why[0] = 0;
#define FLAG(lvl, ...) do { if ((lvl) > o->screen) o->screen = (lvl); \
        if (l < sizeof o->why) l += snprintf(o->why + l, sizeof o->why - l, __VA_ARGS__); } while (0)
    /* central K counts only with a sign of the cone's asymmetry (I-S or KISA% past
       its suspect limit): on its own it cannot tell a steep regular cornea from a
       cone (the R 6.5 test sphere, 51.92 D all over, screened KERATOCONUS), which
       is the specificity KISA% (K times I-S, AST, SRAX) was built for; a steep
       central K without one is said, not screened */
    int asym = o->is > 1.4 || o->kisa > 60;
    if (o->ck > 47.2 && !asym)
        FLAG(CN_KC_NORMAL, "central K %.2f D %s, on a regular surface (I-S %.2f D <= 1.4, "
             "KISA%% not past 60): steep, not a cone's sign alone; ", o->ck,
             o->ck > 48.7 ? "> 48.7" : "in 47.2-48.7", o->is);
    else if (o->ck > 48.7) FLAG(CN_KC_KERATOCONUS, "central K %.2f D > 48.7; ", o->ck);
    else if (o->ck > 47.2) FLAG(CN_KC_SUSPECT, "central K %.2f D in 47.2-48.7; ", o->ck);
    if (o->is > 1.8) FLAG(CN_KC_KERATOCONUS, "I-S %.2f D > 1.8; ", o->is);
    else if (o->is > 1.4) FLAG(CN_KC_SUSPECT, "I-S %.2f D in 1.4-1.8; ", o->is);
    /* SRAX alone is not screened: without astigmatism the steepest axes are noise
       (a sphere's came out 133 deg); it enters through KISA, times AST */
    if (o->kisa > 100) FLAG(CN_KC_KERATOCONUS, "KISA %.0f %% > 100; ", o->kisa);
    else if (o->kisa > 60) FLAG(CN_KC_SUSPECT, "KISA %.0f %% in 60-100; ", o->kisa);
    else if (isnan(o->kisa) && l < sizeof o->why)
        l += snprintf(o->why + l, sizeof o->why - l, "no KISA: SRAX not defined (two "
                      "steepest semi-meridians alike within 0.05 D); ");
#undef FLAG
    if (l >= 2 && l < sizeof o->why) o->why[l - 2] = 0;
}

int cn_kc_model_in(int model, const cn_params *p, const cn_bump *bump, const cn_params *frame,
                   double zone_r, cn_kc *k)
{
    kc_surf s = {0};
    memset(k, 0, sizeof *k);
    cn_surface(model, p, &s.s);
    if (bump) s.s.bump = *bump;
    /* the frame in the eye frame (cn_to_eye: eye = Mp^T (x - Dp), frame = Mf^T (x - Df)):
       its origin Mp^T (Df - Dp), its axis k Mp^T Mf b_k */
    static const double zero[3] = {0, 0, 0};
    cn_params prot = *p, frot = *frame;
    double Df[3], Mf[3][3];
    for (int i = 0; i < 3; i++) {
        Df[i] = frame->p[CN_DX + i];
        prot.p[CN_DX + i] = frot.p[CN_DX + i] = 0;
    }
    cn_to_eye(p, zero, Df, s.O);
    for (int j = 0; j < 3; j++) {       /* Mf[j][k] = (Mf^T b_j)_k */
        double b[3] = {j == 0, j == 1, j == 2};
        cn_to_eye(&frot, zero, b, Mf[j]);
    }
    for (int c = 0; c < 3; c++) {
        double a[3] = {Mf[0][c], Mf[1][c], Mf[2][c]};   /* Mf b_c, in the rig */
        cn_to_eye(&prot, zero, a, s.E[c]);
    }
    s.ox = Df[0];
    s.oy = Df[1];
    if (model_slope(&s, 0, 0, &s.g0x, &s.g0y)) return CN_EINVAL;
    if (indices(&s, zone_r, k)) return CN_EINVAL;
    screen(k);
    return CN_OK;
}

int cn_kc_model(int model, const cn_params *p, const cn_bump *bump, double zone_r, cn_kc *k)
{
    return cn_kc_model_in(model, p, bump, p, zone_r, k);
}

/* The radius of the largest circle about the frame's origin that the data fill: the
 * least, over 36 sectors of 10 deg, of the farthest spot in the sector.  The frame
 * is the instrument's axis (cn_recon.c), so a decentred eye's data are a disc off
 * it: there its far side sets the zone (the data's own radius put I-S's points
 * beyond the data on an eye 0.2 mm off the axis). */
static double filled_radius(const cn_zfit *z)
{
    double far[36] = {0}, r = INFINITY;
    for (int i = 0; i < z->npts; i++) {
        double x = z->xy[2 * i], y = z->xy[2 * i + 1], a = atan2(y, x) + M_PI;
        int sct = (int)(a / (2 * M_PI) * 36);
        if (sct < 0) sct = 0;
        if (sct > 35) sct = 35;
        far[sct] = fmax(far[sct], hypot(x, y));
    }
    for (int j = 0; j < 36; j++) r = fmin(r, far[j]);
    return fmin(r, z->rho);
}

int cn_kc_of(const cn_zfit *z, cn_kc *k)
{
    kc_surf s = {.z = z, .ox = z->ref.p[CN_DX], .oy = z->ref.p[CN_DY]};
    memset(k, 0, sizeof *k);
    /* the data's radius, or where a ring or I-S's points fall off the data there
       (an eye off the instrument's axis: its data a disc off the frame's origin) the
       radius the data fill all round */
    if (indices(&s, z->rho, k) && indices(&s, filled_radius(z), k)) return CN_EINVAL;
    screen(k);
    /* sd from the local fits' covariances: Kmax's at its point; the mean of N
       powers (rings, I-S's five points) as independent points (the kernels of the
       ring's points hardly overlap); the location from the peak's sharpness,
       sd_loc ~ sqrt(2 sd_K / |P''|) (the distance at which the peak falls by 2 sd) */
    double p, sd, pe, sdd;
    power_sd(&s, k->kmax_x - s.ox, k->kmax_y - s.oy, &p, &k->sd_kmax);
    /* along the flattest direction through the peak (a toric's ridge: the
       location is then poorly defined, and says so) */
    double x0 = k->kmax_x - s.ox, y0 = k->kmax_y - s.oy, hh = 0.1, curv = INFINITY;
    for (int d = 0; d < 8; d++) {
        double dx = hh * cos(d * M_PI / 8), dy = hh * sin(d * M_PI / 8), pa, pb;
        if (!power(&s, x0 + dx, y0 + dy, &pa) && !power(&s, x0 - dx, y0 - dy, &pb))
            curv = fmin(curv, -(pa + pb - 2 * p) / (hh * hh));
    }
    k->sd_kmax_loc = curv > 0 && isfinite(curv) ? sqrt(2 * k->sd_kmax / curv) : INFINITY;
    double v = 0;
    int nv = 0;
    for (int j = -2; j <= 2; j++) {
        double a = (90 + 30 * j) * DEG;
        if (!power_sd(&s, k->is_r * cos(a), k->is_r * sin(a), &pe, &sdd)) { v += sdd * sdd; nv++; }
        if (!power_sd(&s, -k->is_r * cos(a), -k->is_r * sin(a), &pe, &sdd)) { v += sdd * sdd; nv++; }
    }
    k->sd_is = nv ? sqrt(v) / 5 : INFINITY;
    v = 0;
    nv = 0;
    double hr = fmin(1.5, 0.9 * k->zone_r);
    for (int j = 0; j < 72; j++) {
        double a = 2 * M_PI * j / 72;
        if (!power_sd(&s, hr * cos(a), hr * sin(a), &pe, &sdd)) { v += sdd * sdd; nv++; }
    }
    /* 72 points of about kr apart or closer share spots: count ring length / kr */
    double indep = fmin(72, fmax(1, 2 * M_PI * hr / z->kr));
    k->sd_simk = nv ? sqrt(v / nv) / sqrt(indep) : INFINITY;
    k->sd_ck = k->sd_simk;
    k->sd_ast = 2 * k->sd_simk;
    /* SRAX's sd: an argmax has no derivative, so from how sharp each half's steepest
       semi-meridian is against its own noise: the semi-meridians within sqrt(2) sd
       (a difference of two means) of the half's maximum span +-w about it, and w / sqrt(3)
       (a uniform spread over them) is that direction's sd; SRAX's is the two halves'
       in quadrature.  A semi-meridian's mean's sd: the power's sd at its middle over
       the root of the independent kernels along it, (lim - 0.5) / kr. */
    k->sd_srax = NAN;
    if (isfinite(k->srax)) {
        double lim = 0.9 * k->zone_r, sm[360], rm = 0.5 * (0.5 + lim), w2 = 0;
        double nind = fmax(1, (lim - 0.5) / z->kr);
        int am[2];
        semi_meridians(&s, lim, sm, &am[0], &am[1]);
        for (int h = 0; h < 2; h++) {
            double a = am[h] * DEG, sdm = INFINITY, w = 0;
            if (!power_sd(&s, rm * cos(a), rm * sin(a), &pe, &sdd)) sdm = sdd / sqrt(nind);
            for (int dg = h * 180; dg < h * 180 + 180; dg++)
                if (sm[dg] >= sm[am[h]] - sqrt(2.0) * sdm) w = fmax(w, abs(dg - am[h]));
            w2 += w * w / 3 + 1.0 / 12;     /* + the 1 deg grid's own spread */
        }
        k->sd_srax = sqrt(w2);
    }
    (void)sd;
    double rel = 0;
    if (k->ck) rel += pow(k->sd_ck / k->ck, 2);
    if (k->is) rel += pow(k->sd_is / k->is, 2);
    if (k->ast) rel += pow(k->sd_ast / k->ast, 2);
    if (k->srax > 0 && isfinite(k->sd_srax)) rel += pow(k->sd_srax / k->srax, 2);
    k->sd_kisa = fabs(k->kisa) * sqrt(rel);
    return CN_OK;
}

int cn_zmap(int kind, const cn_zfit *z, double hmax, int n, double *grid, double *aux)
{
    if (n < 2 || !(hmax > 0) || kind < CN_ZMAP_ELEVATION || kind > CN_ZMAP_TANGENTIAL)
        return CN_EINVAL;
    double cell = 2 * hmax / n, a11 = 0, a12 = 0, a22 = 0, b1 = 0, b2 = 0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            double x = -hmax + (i + 0.5) * cell, y = hmax - (j + 0.5) * cell;
            double *g = &grid[(size_t)j * n + i];
            *g = NAN;
            if (!cn_zcovered(z, x, y)) continue;
            if (kind == CN_ZMAP_ELEVATION) {
                double f;
                if (cn_zsag(z, x, y, &f, NULL, NULL)) continue;
                double rho = x * x + y * y + f * f;
                a11 += 4 * f * f; a12 += -2 * f; a22 += 1;
                b1 += 2 * f * rho; b2 += -rho;
                *g = f;
            } else {
                double ax, tg;
                if (cn_zlocal(z, x, y, &ax, &tg, NULL)) continue;
                *g = KN * (kind == CN_ZMAP_AXIAL ? ax : tg);
            }
        }
    if (kind != CN_ZMAP_ELEVATION) { if (aux) *aux = NAN; return CN_OK; }
    /* the best-fit sphere, centre on the axis (as cn_map) */
    double det = a11 * a22 - a12 * a12;
    if (!(fabs(det) > 0)) return CN_EINVAL;
    double zc = (b1 * a22 - a12 * b2) / det, kk = (a11 * b2 - a12 * b1) / det;
    double rb = sqrt(zc * zc - kk);
    if (!isfinite(rb)) return CN_EINVAL;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            double *g = &grid[(size_t)j * n + i];
            if (isnan(*g)) continue;
            double x = -hmax + (i + 0.5) * cell, y = hmax - (j + 0.5) * cell;
            double q = rb * rb - x * x - y * y;
            *g = q > 0 ? (zc - sqrt(q) - *g) * 1000 : NAN;
        }
    if (aux) *aux = rb;
    return CN_OK;
}
