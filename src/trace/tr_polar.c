/* tr_polar.c -- polarization ray tracing: Chipman's 3x3 polarization ray-tracing matrix
 * P carried by every ray (Chipman, Lam & Young, "Polarized Light and Optical Systems",
 * 2018, ch. 9-10), the complex Fresnel amplitudes of each interface (the phases of TIR
 * kept), thin-film coatings by characteristic matrices in place of bare Fresnel,
 * polarizers and retarders on surfaces, and the detector's Stokes parameters.
 *
 * A scene with polarization on is traced ray by ray (tr_polar_batch) through
 * tr_trace.c's loop, which hands each hit to tr_polar_on_hit here instead of its own
 * on_hit: the same segments, the same choice of surfaces, the same cut-offs, with P
 * beside the ray (the live ray's and one per waiting ray in the worker's tr_polw).
 * The packet path is not taken; the unpolarized loop pays two branches.  The ray's coherency
 * (tr_pol: its s and p powers, which the hits report and the cut-offs test) is
 * recomputed from P at every interface, so powers follow P: polarizers absorb,
 * coatings set R and T.  Conventions: trace.h, "polarization ray tracing". */
#include <complex.h>
#include <math.h>
#include "tr_eng.h"

typedef double complex cplx;

struct tr_polar {
    double xref[3], xalt[3];   /* Stokes frame reference, and the one near it */
    int (*cb)(void *ctx, const trace_polar_hit *ph);   /* the records' sink */
    void *ctx;

    int n;                     /* entries in el */
    trace_polar_surface *el;   /* per surface id (element NONE, no layers: bare) */
};

/* The polarization state of one ray beside its tr_wray: P, the radiometric gain. */
typedef struct pray {
    cplx P[3][3];
    double Q[3][3];            /* the parallel transport matrix: P's geometry alone */
    double g;
    int cx;                    /* P has imaginary parts (else they are all 0) */
} pray;

/* What every ray of one source ray's tree shares: its source coherency as
 * a1 a1^H + a2 a2^H (vectors perpendicular to the source direction, real parts a and
 * imaginary parts ai: zero but for an elliptical source) and the input frame of its
 * Jones matrix. */
typedef struct ptree {
    double a[2][3], ai[2][3];
    int na;                    /* 1: fully polarized (a[1] = 0), else 2 */
    double xin[3], yin[3];
} ptree;

/* A worker's polarization state while it traces a batch (tr_worker.pol): the live
 * ray's, and one per slot of its stack of waiting rays (the same index). */
struct tr_polw {
    pray cur, *stack;
    ptree t;
};

/* ---- set-up ------------------------------------------------------------------------ */

void tr_polar_free(struct tr_polar *p)
{
    if (!p) return;
    free(p->el);
    free(p);
}

static int pfail(trace_scene *sc, const char *msg)
{
    return tr_scene_fail(sc, TRACE_EINVAL, msg);
}

int tr_polar_deliver(const trace_scene *sc, const trace_polar_hit *ph)
{
    return sc->polar && sc->polar->cb ? sc->polar->cb(sc->polar->ctx, ph) : 0;
}

int tr_polarization(trace_scene *sc, int on, const double xref[3],
                    int (*cb)(void *ctx, const trace_polar_hit *ph), void *ctx)
{
    if (!sc) return TRACE_EINVAL;
    if (!on) {
        tr_polar_free(sc->polar);
        sc->polar = NULL;
        return TRACE_OK;
    }
    double x[3] = {1, 0, 0};
    if (xref) {
        v_set(x, xref);
        if (!(isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2])) || v_unit(x))
            return pfail(sc, "the Stokes reference must be a finite, nonzero vector");
    }
    if (!sc->polar && !(sc->polar = calloc(1, sizeof *sc->polar)))
        return tr_scene_fail(sc, TRACE_ENOMEM, "out of memory");
    v_set(sc->polar->xref, x);
    sc->polar->cb = cb;
    sc->polar->ctx = ctx;
    /* the reference for rays near x: z x x (+y for the default +x), or +y */
    double z[3] = {0, 0, 1}, a[3];
    v_cross(z, x, a);
    if (!(v_norm(a) > 1e-6)) { a[0] = 0; a[1] = 1; a[2] = 0; }
    v_unit(a);
    v_set(sc->polar->xalt, a);
    return TRACE_OK;
}

static int check_ps(trace_scene *sc, const trace_polar_surface *ps)
{
    if (ps->element < TRACE_POL_NONE || ps->element > TRACE_POL_RETARDER)
        return pfail(sc, "unknown polarization element");
    if (ps->element != TRACE_POL_NONE) {
        double a[3] = {ps->axis[0], ps->axis[1], ps->axis[2]};
        if (!(isfinite(a[0]) && isfinite(a[1]) && isfinite(a[2])) || !(v_norm(a) > 0))
            return pfail(sc, "a polarizer or retarder needs a finite, nonzero axis");
        if (!isfinite(ps->retardance)) return pfail(sc, "the retardance must be finite");
    }
    if (ps->nlayer < 0 || ps->nlayer > TRACE_MAXLAYER)
        return pfail(sc, "a coating has 0 to 32 layers");
    for (int i = 0; i < ps->nlayer; i++)
        if (!(ps->layer_n[i] > 0 && isfinite(ps->layer_n[i]) && ps->layer_d[i] >= 0 &&
              isfinite(ps->layer_d[i])))
            return pfail(sc, "a coating layer needs an index > 0 and a thickness >= 0");
    return TRACE_OK;
}

int tr_set_polar(trace_scene *sc, int id, const trace_polar_surface *ps)
{
    if (!sc) return TRACE_EINVAL;
    if (id < 0 || id >= sc->nsurf) return pfail(sc, "no such surface");
    if (!ps) return pfail(sc, "no polarization element given");
    if (sc->surf[id]->mat.kind != TRACE_REFRACT)
        return pfail(sc, "polarizers, retarders and coatings go on refracting surfaces");
    if (check_ps(sc, ps)) return TRACE_EINVAL;
    if (!sc->polar && tr_polarization(sc, 1, NULL, NULL, NULL)) return TRACE_ENOMEM;
    struct tr_polar *p = sc->polar;
    if (id >= p->n) {
        trace_polar_surface *e = realloc(p->el, (size_t)sc->nsurf * sizeof *e);
        if (!e) return tr_scene_fail(sc, TRACE_ENOMEM, "out of memory");
        memset(e + p->n, 0, (size_t)(sc->nsurf - p->n) * sizeof *e);
        p->el = e;
        p->n = sc->nsurf;
    }
    p->el[id] = *ps;
    if (p->el[id].element != TRACE_POL_NONE) v_unit(p->el[id].axis);
    return TRACE_OK;
}

/* ---- one interface ----------------------------------------------------------------- */

/* The amplitude coefficients (Hecht's signs) from n1 into n2 at cos ci of a coating's
 * layers in the order light meets them (rev: the list backwards), by characteristic
 * matrices (Born and Wolf 1.6; the same arithmetic as src/wave's film calculator).
 * The matrices give r and t of the tangential fields; rp = -r and tp = t cos i / cos t
 * of the p admittance n / cos turn them into the fields' amplitudes. */
static cplx cos_in(double n1, double n, double sin1)
{
    double s = n1 / n * sin1, q = 1 - s * s;
    return q >= 0 ? sqrt(q) : I * sqrt(-q);
}

static void film(const trace_polar_surface *ps, int rev, double n1, double n2, double ci,
                 double lambda, cplx *rs, cplx *rp, cplx *ts, cplx *tp)
{
    double sin1 = sqrt(fmax(0, 1 - ci * ci));
    cplx cs = cos_in(n1, n2, sin1);
    for (int pol = 0; pol < 2; pol++) {
        cplx m11 = 1, m12 = 0, m21 = 0, m22 = 1;
        for (int k = 0; k < ps->nlayer; k++) {
            int j = rev ? ps->nlayer - 1 - k : k;
            double nj = ps->layer_n[j];
            cplx cj = cos_in(n1, nj, sin1);
            cplx eta = pol == 0 ? nj * cj : nj / cj;
            cplx dl = 2 * TR_PI * nj * ps->layer_d[j] * cj / lambda;
            cplx a = ccos(dl), b = -I * csin(dl) / eta, c = -I * eta * csin(dl);
            cplx t11 = m11 * a + m12 * c, t12 = m11 * b + m12 * a;
            cplx t21 = m21 * a + m22 * c, t22 = m21 * b + m22 * a;
            m11 = t11; m12 = t12; m21 = t21; m22 = t22;
        }
        cplx e0 = pol == 0 ? n1 * ci : n1 / ci, es = pol == 0 ? n2 * cs : n2 / cs;
        cplx den = e0 * m11 + e0 * es * m12 + m21 + es * m22;
        cplx r = (e0 * m11 + e0 * es * m12 - m21 - es * m22) / den, t = 2 * e0 / den;
        if (pol == 0) { *rs = r; *ts = t; }
        else { *rp = -r; *tp = t * ci / cs; }
    }
}

/* Fresnel at an interface, as tr_optics.c's tr_fresnel decides it (the same cos t and
 * TIR test, so the same refracted direction), with the amplitudes complex: Hecht's
 * forms, under TIR cos t = i kappa.  Computed here rather than by calling tr_fresnel:
 * a further caller makes link-time optimisation stop inlining it (and tr_find_hit)
 * into the unpolarized loop, which then ran 8 % slower ray by ray. */
typedef struct pfres { int tir; double cos_t; } pfres;
static void fresnel_of(double n1, double n2, double ci, pfres *f, cplx a[4])
{
    double eta = n1 / n2, c2 = (1.0 - eta * eta) + eta * eta * ci * ci;
    if (c2 <= 0) {
        double kap = sqrt(-c2);
        f->tir = 1;
        f->cos_t = 0;
        a[0] = cexp(-2 * I * atan2(n2 * kap, n1 * ci));
        a[1] = cexp(-2 * I * atan2(n1 * kap, n2 * ci));
        a[2] = a[3] = 0;
        return;
    }
    double ct = sqrt(c2), ds = n1 * ci + n2 * ct, dp = n2 * ci + n1 * ct;
    f->tir = 0;
    f->cos_t = ct;
    if (ds == 0 || dp == 0) { a[0] = -1; a[1] = 1; a[2] = a[3] = 0; return; }
    a[0] = (n1 * ci - n2 * ct) / ds;
    a[1] = (n2 * ci - n1 * ct) / dp;
    a[2] = 2 * n1 * ci / ds;
    a[3] = 2 * n1 * ci / dp;
}

/* The interface's amplitudes: a coating's, else the bare Fresnel ones; 1 if complex. */
static int amplitudes(const trace_polar_surface *ps, int rev, double n1, double n2,
                      double ci, double lambda, pfres *fc, cplx a[4])
{
    fresnel_of(n1, n2, ci, fc, a);
    if (ps && ps->nlayer > 0 && ci > 0) {
        film(ps, rev, n1, n2, ci, lambda > 0 ? lambda : 0.5875618, &a[0], &a[1], &a[2], &a[3]);
        if (fc->tir) a[2] = a[3] = 0;
        return 1;
    }
    return fc->tir;
}

/* M = O_out diag(as, ap, 1) O_in^T, O = [s, k x s, k]. */
static void prt_of(const double kin[3], const double kout[3], const double s[3], cplx as,
                   cplx ap, cplx M[3][3])
{
    double pin[3], pout[3];
    v_cross(kin, s, pin);
    v_cross(kout, s, pout);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            M[i][j] = as * s[i] * s[j] + ap * pout[i] * pin[j] + kout[i] * kin[j];
}

/* Q = O_out O_in^T Q, O = [s, k x s, k]: the interface's parallel transport (Chipman,
 * Lam & Young ch. 11; Yun, McClain & Chipman, Appl. Opt. 50, 2866 (2011)), P's matrix
 * with every Fresnel amplitude 1 -- the rotation about s that takes kin to kout and
 * carries transverse vectors without turning them about the ray.  Q^T P is what the
 * path does to the field beyond the geometry: its retardance is the path's proper
 * retardance, the same whatever local frames are chosen.  (With Hecht's signs an
 * ideal mirror, rs = -1 and rp = +1, is then a half-wave: the book's convention.) */
static void transport(const double kin[3], const double kout[3], const double s[3],
                      double Q[3][3])
{
    double pin[3], pout[3], T[3][3], R[3][3];
    v_cross(kin, s, pin);
    v_cross(kout, s, pout);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            T[i][j] = s[i] * s[j] + pout[i] * pin[j] + kout[i] * kin[j];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            R[i][j] = T[i][0] * Q[0][j] + T[i][1] * Q[1][j] + T[i][2] * Q[2][j];
    memcpy(Q, R, sizeof R);
}

/* A polarizer's or retarder's matrix for a ray along k (unit). */
static void element_of(const trace_polar_surface *ps, const double k[3], cplx M[3][3])
{
    double f[3], sl[3], c = v_dot(ps->axis, k);
    for (int i = 0; i < 3; i++) f[i] = ps->axis[i] - c * k[i];
    int ok = v_norm(f) > 1e-12;
    if (ok) v_unit(f);
    v_cross(k, f, sl);
    cplx af = 1, as = 0;
    if (ps->element == TRACE_POL_RETARDER) {
        af = cexp(-I * ps->retardance / 2);
        as = cexp(I * ps->retardance / 2);
    }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            M[i][j] = ok ? af * f[i] * f[j] + as * sl[i] * sl[j] + k[i] * k[j]
                         : k[i] * k[j];   /* an axis along the ray passes nothing */
}

/* P = A P, *cx: P complex; acx: A complex.  Written out in real arithmetic: while
 * no TIR, coating or retarder has been met every factor is real (a third of the
 * work), and C's complex product would test every result for NaN. */
static void mul(cplx A[3][3], int acx, cplx P[3][3], int *cx)
{
    double ar[3][3], ai[3][3], pr[3][3], pi[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) { ar[i][j] = creal(A[i][j]); pr[i][j] = creal(P[i][j]); }
    if (!acx && !*cx) {
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                P[i][j] = ar[i][0] * pr[0][j] + ar[i][1] * pr[1][j] + ar[i][2] * pr[2][j];
        return;
    }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) { ai[i][j] = cimag(A[i][j]); pi[i][j] = cimag(P[i][j]); }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double re = 0, im = 0;
            for (int k = 0; k < 3; k++) {
                re += ar[i][k] * pr[k][j] - ai[i][k] * pi[k][j];
                im += ar[i][k] * pi[k][j] + ai[i][k] * pr[k][j];
            }
            P[i][j] = CMPLX(re, im);
        }
    *cx = 1;
}

/* s unit vector of the plane of incidence (d x n), or e at normal incidence. */
static void s_vector(const double d[3], const double n[3], const double e[3], double s[3])
{
    v_cross(d, n, s);
    double l = v_norm(s);
    if (!(l >= 1e-12)) { v_set(s, e); return; }
    l = 1.0 / l;
    s[0] *= l; s[1] *= l; s[2] *= l;
}

/* Some unit vector perpendicular to the unit vector k. */
static void any_perp(const double k[3], double e[3])
{
    double a[3] = {0, 0, 0};
    int i = fabs(k[0]) < fabs(k[1]) ? (fabs(k[0]) < fabs(k[2]) ? 0 : 2)
                                    : (fabs(k[1]) < fabs(k[2]) ? 1 : 2);
    a[i] = 1;
    v_cross(k, a, e);
    v_unit(e);
}

int tr_prt_interface(const double kin[3], const double nrm[3], double n1, double n2,
                     const trace_polar_surface *ps, double lambda, int reflect,
                     double P[3][3][2], double kout[3])
{
    double dn = v_dot(kin, nrm), m[3], s[3], e[3];
    for (int i = 0; i < 3; i++) m[i] = dn > 0 ? -nrm[i] : nrm[i];
    double ci = fabs(dn) < 1.0 ? fabs(dn) : 1.0;
    pfres fc;
    cplx a[4], M[3][3];
    any_perp(kin, e);
    s_vector(kin, nrm, e, s);
    (void)amplitudes(ps, dn > 0, n1, n2, ci, lambda, &fc, a);
    int tir = 0;
    if (reflect || fc.tir) {
        for (int i = 0; i < 3; i++) kout[i] = kin[i] + 2 * ci * m[i];
        v_unit(kout);
        prt_of(kin, kout, s, a[0], a[1], M);
        tir = fc.tir && !reflect;
        if (tir) memset(M, 0, sizeof M);
    } else {
        double eta = n1 / n2, k = eta * ci - fc.cos_t;
        for (int i = 0; i < 3; i++) kout[i] = eta * kin[i] + k * m[i];
        v_unit(kout);
        prt_of(kin, kout, s, a[2], a[3], M);
        if (ps && ps->element != TRACE_POL_NONE) {
            cplx J[3][3];
            trace_polar_surface q = *ps;
            v_unit(q.axis);
            element_of(&q, kout, J);
            int cx = 1;
            mul(J, 1, M, &cx);
        }
    }
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) { P[i][j][0] = creal(M[i][j]); P[i][j][1] = cimag(M[i][j]); }
    return tir;
}

/* ---- the ray's state from P -------------------------------------------------------- */

/* The coherency of ray r in the basis (s, d x s) from P and the tree's source
 * coherency. */
static void sync(tr_wray *r, const pray *q, const ptree *t, const double s[3])
{
    double f[3];
    v_cross(r->d, s, f);
    double ss = 0, pp = 0, spr = 0, spi = 0;
    for (int j = 0; j < t->na; j++) {
        double sr = 0, si = 0, qr = 0, qi = 0;
        for (int i = 0; i < 3; i++) {
            double er = 0, ei = 0;
            for (int k = 0; k < 3; k++) {   /* (the ai terms are exact zeros but for
                                               an elliptical source) */
                er += creal(q->P[i][k]) * t->a[j][k] - cimag(q->P[i][k]) * t->ai[j][k];
                ei += cimag(q->P[i][k]) * t->a[j][k] + creal(q->P[i][k]) * t->ai[j][k];
            }
            sr += s[i] * er; si += s[i] * ei;
            qr += f[i] * er; qi += f[i] * ei;
        }
        ss += sr * sr + si * si;
        pp += qr * qr + qi * qi;
        spr += sr * qr + si * qi;      /* Es conj(Ep) */
        spi += si * qr - sr * qi;
    }
    v_set(r->pol.e, s);
    r->pol.jss = q->g * ss;
    r->pol.jpp = q->g * pp;
    r->pol.jre = q->g * spr;
    r->pol.jim = q->g * spi;
}

static double power(const tr_wray *r) { return r->pol.jss + r->pol.jpp; }

/* The Stokes frame's x' for a ray along k. */
static void frame_x(const struct tr_polar *pl, const double k[3], double x[3])
{
    const double *ref = fabs(v_dot(pl->xref, k)) > 0.90630778703665 ? pl->xalt : pl->xref;
    double c = v_dot(ref, k);          /* (cos 25 degrees) */
    for (int i = 0; i < 3; i++) x[i] = ref[i] - c * k[i];
    v_unit(x);
}

/* The hit's record: P, gain, Stokes, the Jones matrix's retardance and diattenuation. */
static void emit_polar(tr_worker *w, tr_out *out, const tr_wray *r, const pray *q,
                       const ptree *t, uint64_t ray, int surf, const double pos[3])
{
    if (!w->want_hit) return;
    trace_polar_hit *h = buf_slot(&out->pol);
    if (!h) { w->nomem = 1; return; }
    memset(h, 0, sizeof *h);
    h->ray = ray;
    h->depth = r->depth;
    h->surface = surf;
    v_set(h->pos, pos);
    const struct tr_polar *pl = w->sc->polar;
    double x[3], y[3];
    frame_x(pl, r->d, x);
    v_cross(r->d, x, y);
    v_set(h->xref, x);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            h->prt[i][j][0] = creal(q->P[i][j]);
            h->prt[i][j][1] = cimag(q->P[i][j]);
        }
    h->gain = q->g;
    for (int j = 0; j < t->na; j++) {
        cplx ex = 0, ey = 0;
        for (int i = 0; i < 3; i++) {
            double er = 0, ei = 0;
            for (int k = 0; k < 3; k++) {
                er += creal(q->P[i][k]) * t->a[j][k] - cimag(q->P[i][k]) * t->ai[j][k];
                ei += cimag(q->P[i][k]) * t->a[j][k] + creal(q->P[i][k]) * t->ai[j][k];
            }
            cplx E = CMPLX(er, ei);
            ex += x[i] * E;
            ey += y[i] * E;
        }
        double xx = creal(ex * conj(ex)), yy = creal(ey * conj(ey));
        cplx xy = conj(ex) * ey;
        h->stokes[0] += q->g * (xx + yy);
        h->stokes[1] += q->g * (xx - yy);
        h->stokes[2] += q->g * 2 * creal(xy);
        h->stokes[3] += q->g * 2 * cimag(xy);
    }
    /* J = [Q xin, Q yin]^T P [xin yin] (= [xin yin]^T Q^T P [xin yin]): the Jones matrix
     * in the source's frame and that frame carried along the path by parallel
     * transport, so no turn of the frames (the Stokes frames' projection of one
     * reference, or any other choice) shows up as retardance; its singular values and
     * the unitary factor's trace */
    double qx[3], qy[3];
    for (int i = 0; i < 3; i++) {
        qx[i] = q->Q[i][0] * t->xin[0] + q->Q[i][1] * t->xin[1] + q->Q[i][2] * t->xin[2];
        qy[i] = q->Q[i][0] * t->yin[0] + q->Q[i][1] * t->yin[1] + q->Q[i][2] * t->yin[2];
    }
    const double *ob[2] = {qx, qy}, *ib[2] = {t->xin, t->yin};
    cplx J[2][2];
    for (int a = 0; a < 2; a++)
        for (int b = 0; b < 2; b++) {
            cplx v = 0;
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++) v += ob[a][i] * q->P[i][j] * ib[b][j];
            J[a][b] = v;
        }
    /* H = J^H J */
    double h11 = creal(conj(J[0][0]) * J[0][0] + conj(J[1][0]) * J[1][0]);
    double h22 = creal(conj(J[0][1]) * J[0][1] + conj(J[1][1]) * J[1][1]);
    cplx h12 = conj(J[0][0]) * J[0][1] + conj(J[1][0]) * J[1][1];
    double tr = h11 + h22, det = h11 * h22 - creal(h12 * conj(h12));
    double disc = sqrt(fmax(0, tr * tr / 4 - det));
    double lmax = tr / 2 + disc, lmin = fmax(0, tr / 2 - disc);
    h->diattenuation = lmax + lmin > 0 ? (lmax - lmin) / (lmax + lmin) : NAN;
    h->retardance = NAN;
    if (lmax > 0 && lmin > 1e-24 * lmax) {
        /* sqrt(H) = (H + sqrt(det) I) / sqrt(tr + 2 sqrt(det)); U = J sqrt(H)^-1 */
        double sd = sqrt(fmax(0, det)), k = 1 / sqrt(tr + 2 * sd);
        cplx r11 = (h11 + sd) * k, r22 = (h22 + sd) * k, r12 = h12 * k, r21 = conj(h12) * k;
        cplx rd = r11 * r22 - r12 * r21;
        cplx i11 = r22 / rd, i22 = r11 / rd, i12 = -r12 / rd, i21 = -r21 / rd;
        cplx u11 = J[0][0] * i11 + J[0][1] * i21, u22 = J[1][0] * i12 + J[1][1] * i22;
        cplx u12 = J[0][0] * i12 + J[0][1] * i22, u21 = J[1][0] * i11 + J[1][1] * i21;
        /* U's eigenvalues e^{ia}, e^{ib}: |tr U| = 2 cos((a - b) / 2) and
         * |tr^2 - 4 det| = |(u11 - u22)^2 + 4 u12 u21| = 4 sin^2((a - b) / 2), both over
         * |det U|; atan2 of the pair keeps every digit near 0 and pi (acos of the
         * cosine alone loses half of them there) */
        cplx dd = (u11 - u22) * (u11 - u22) + 4 * u12 * u21;
        h->retardance = 2 * atan2(sqrt(cabs(dd)), cabs(u11 + u22));
    }
}

/* ---- the interaction (tr_trace.c's on_hit and interact, with P) ---------------------
 * tr_trace_rest (tr_trace.c) runs the loop for both kinds of run: with w->pol set it
 * calls tr_polar_on_hit instead of its own on_hit, and tr_polar_pop as it takes a
 * waiting ray off the stack; the next hit is found by the one call there. */

static const trace_polar_surface *el_of(const trace_scene *sc, int id)
{
    const struct tr_polar *p = sc->polar;
    return id < p->n ? &p->el[id] : NULL;
}

static int interact(tr_worker *w, tr_tally *ty, tr_wray *stack, int *sp, tr_wray *r,
                    const tr_hitrec *h, const tr_surf *f, double p0)
{
    struct tr_polw *pw = w->pol;
    pray *q = &pw->cur;
    const ptree *t = &pw->t;
    double n1 = f->mat.n_front, n2 = f->mat.n_back, s[3], m[3], kin[3];
    double a2 = f->alpha_back;
    if (f->media && h->prim >= 0) {
        n1 = f->media[2 * h->prim]; n2 = f->media[2 * h->prim + 1]; a2 = 0;
    }
    double dn = v_dot(r->d, h->n);
    if (dn > 0) {
        double x = n1; n1 = n2; n2 = x;
        a2 = f->media && h->prim >= 0 ? 0 : f->alpha_front;
    }
    for (int i = 0; i < 3; i++) m[i] = dn > 0 ? -h->n[i] : h->n[i];
    double ci = fabs(dn) < 1.0 ? fabs(dn) : 1.0;
    if (f->mat.kind == TRACE_REFRACT && fabs(r->n - n1) > 1e-9 * n1) ty->mismatch++;
    ty->interactions++;
    s_vector(r->d, h->n, r->pol.e, s);
    v_set(kin, r->d);
    r->depth++;
    r->last_surf = h->surf;
    r->last_prim = h->prim;
    cplx M[3][3];

    if (f->mat.kind == TRACE_MIRROR) {          /* rs = -1, rp = +1 */
        if (r->depth <= 32) r->hist |= 1u << (r->depth - 1);
        for (int i = 0; i < 3; i++) r->d[i] += 2 * ci * m[i];
        v_unit(r->d);
        prt_of(kin, r->d, s, -1, 1, M);
        mul(M, 0, q->P, &q->cx);
        transport(kin, r->d, s, q->Q);
        sync(r, q, t, s);
        return tr_strong(w, ty, power(r), p0);
    }
    const trace_polar_surface *ps = el_of(w->sc, h->surf);
    pfres fc;
    cplx a[4];
    int acx = amplitudes(ps, dn > 0, n1, n2, ci, r->lambda, &fc, a);
    if (fc.tir) {
        if (r->depth <= 32) r->hist |= 1u << (r->depth - 1);
        for (int i = 0; i < 3; i++) r->d[i] += 2 * ci * m[i];
        v_unit(r->d);
        prt_of(kin, r->d, s, a[0], a[1], M);
        mul(M, acx, q->P, &q->cx);
        transport(kin, r->d, s, q->Q);
        sync(r, q, t, s);
        ty->tir++;
        return tr_strong(w, ty, power(r), p0);
    }
    if (w->o->fresnel) {
        /* the reflected ray waits on the stack (its P in the same slot of pw->stack) */
        tr_wray tmp, *c = w->o->reflections ? &stack[*sp] : &tmp;
        pray tq, *cq = w->o->reflections ? &pw->stack[*sp] : &tq;
        *c = *r;
        *cq = *q;
        if (r->depth <= 32) c->hist |= 1u << (r->depth - 1);
        for (int i = 0; i < 3; i++) c->d[i] = kin[i] + 2 * ci * m[i];
        v_unit(c->d);
        c->n = n1;
        prt_of(kin, c->d, s, a[0], a[1], M);
        mul(M, acx, cq->P, &cq->cx);
        transport(kin, c->d, s, cq->Q);
        sync(c, cq, t, s);
        if (w->o->reflections) {
            tr_keep(w, ty, sp, c, p0);
        } else {
            double p = power(c);
            if (p > 0) { ty->cutoff += p; ty->cut_reflection++; }
        }
    }
    double eta = n1 / n2, k = eta * ci - fc.cos_t;
    for (int i = 0; i < 3; i++) r->d[i] = eta * r->d[i] + k * m[i];
    v_unit(r->d);
    r->n = n2;
    r->alpha = a2;
    if (w->o->fresnel) {
        prt_of(kin, r->d, s, a[2], a[3], M);
        q->g *= ci > 0 ? n2 * fc.cos_t / (n1 * ci) : 0;
    } else {
        prt_of(kin, r->d, s, 1, 1, M);
        acx = 0;
    }
    mul(M, acx, q->P, &q->cx);
    transport(kin, r->d, s, q->Q);
    if (ps && ps->element != TRACE_POL_NONE) {
        sync(r, q, t, s);
        double before = power(r);
        element_of(ps, r->d, M);
        mul(M, ps->element == TRACE_POL_RETARDER, q->P, &q->cx);
        sync(r, q, t, s);
        double lost = before - power(r);
        if (lost > 0) ty->absorbed += lost;
    } else {
        sync(r, q, t, s);
    }
    return tr_strong(w, ty, power(r), p0);
}

static double absorb_along(tr_tally *ty, tr_wray *r, pray *q, double len)
{
    double k = exp(-r->alpha * len), p = power(r);
    q->g *= k;
    r->pol.jss *= k;
    r->pol.jpp *= k;
    r->pol.jre *= k;
    r->pol.jim *= k;
    double lost = p - power(r);
    ty->absorbed += lost;
    return lost;
}

int tr_polar_on_hit(tr_worker *w, tr_out *out, tr_tally *ty, tr_wray *stack, int *sp,
                    tr_wray *r, const tr_hitrec *h, uint64_t ray, double p0)
{
    pray *q = &w->pol->cur;
    double p = power(r), x[3];
    if (h->far) v_set(x, h->q);
    else for (int i = 0; i < 3; i++) x[i] = r->o[i] + h->t * r->d[i];
    if (!(isfinite(x[0]) && isfinite(x[1]) && isfinite(x[2]) && isfinite(h->n[0]))) {
        if (!ty->failures) { ty->fail_cause = TR_FAIL_POINT; ty->fail_surf = h->surf; }
        ty->failures++;
        if (isfinite(p)) ty->cutoff += p;
        return 0;
    }
    const tr_surf *f = w->sc->surf[h->surf];
    ty->segments++;
    r->len += h->t;
    r->opl += r->n * h->t;
    switch (f->mat.kind) {
    case TRACE_ABSORB:
        ty->absorbed += p;
        tr_emit_segment(w, out, r, ray, x, TRACE_END_ABSORB, h->surf);
        return 0;
    case TRACE_DETECT: {
        double s[3];
        s_vector(r->d, h->n, r->pol.e, s);
        sync(r, q, &w->pol->t, s);
        tr_emit_segment(w, out, r, ray, x, TRACE_END_DETECT, h->surf);
        if (r->alpha > 0) absorb_along(ty, r, q, h->t);
        ty->detected += power(r);
        ty->hits++;
        emit_polar(w, out, r, q, &w->pol->t, ray, h->surf, x);
        tr_emit_hit(w, out, r, ray, h, x);
        return 0;
    }
    default:
        tr_emit_segment(w, out, r, ray, x, TRACE_END_NONE, h->surf);
        if (r->alpha > 0) absorb_along(ty, r, q, h->t);
        v_set(r->o, x);
        return interact(w, ty, stack, sp, r, h, f, p0);
    }
}

void tr_polar_pop(tr_worker *w, int sp)
{
    w->pol->cur = w->pol->stack[sp];
}

/* A source ray's tree: P = I, its coherency's factors and input frame. */
static void tree_start(tr_worker *w, const tr_ray0 *r0)
{
    struct tr_polw *pw = w->pol;
    double f[3];
    memset(pw->cur.P, 0, sizeof pw->cur.P);
    memset(pw->cur.Q, 0, sizeof pw->cur.Q);
    for (int i = 0; i < 3; i++) pw->cur.P[i][i] = pw->cur.Q[i][i] = 1;
    pw->cur.g = 1;
    pw->cur.cx = 0;
    v_cross(r0->d, r0->pol.e, f);
    /* J = [[a, c], [c*, b]] in (e, f), c = <Es Ep*>: J = v1 v1^H + v2 v2^H with
     * v1 = (sqrt a, c* / sqrt a), v2 = (0, sqrt(b - |c|^2 / a)) (Cholesky); with c = 0
     * the two fields of before, e and f */
    double a = r0->pol.jss, b = r0->pol.jpp, cr = r0->pol.jre, ci = r0->pol.jim;
    double sa = sqrt(a), c2 = cr * cr + ci * ci, ur = 0, ui = 0, rest = b;
    if (c2 > 0 && sa > 0) {
        ur = cr / sa;
        ui = -ci / sa;
        rest = b - c2 / a;
        if (rest < 1e-12 * (a + b)) rest = 0;   /* a fully polarized state */
    }
    pw->t.na = rest > 0 ? 2 : 1;
    for (int i = 0; i < 3; i++) {
        pw->t.a[0][i] = ur != 0 ? sa * r0->pol.e[i] + ur * f[i] : sa * r0->pol.e[i];
        pw->t.ai[0][i] = ui * f[i];
        pw->t.a[1][i] = sqrt(rest) * f[i];
        pw->t.ai[1][i] = 0;
    }
    frame_x(w->sc->polar, r0->d, pw->t.xin);
    v_cross(r0->d, pw->t.xin, pw->t.yin);
}

void tr_polar_batch(tr_worker *w)
{
    struct tr_polw pw;
    if (!(pw.stack = malloc(((size_t)w->o->max_depth + 4) * sizeof *pw.stack))) {
        w->nomem = 1;
        return;
    }
    w->pol = &pw;
    int k = 0;
    for (uint64_t i = 0; i < w->count; i++) {
        tr_ray0 r0;
        tr_wray r;
        double p0;
        tr_scene_ray(w->sc, &k, w->first + i, &r0);
        tr_ray_start(&r, &r0, &w->tally[0], &p0);
        tree_start(w, &r0);
        tr_trace_rest(w, &w->out, &w->tally[0], w->stack, 0, &r, 1, w->first + i, p0);
        tr_fold(w, i, &w->tally[0]);
    }
    w->pol = NULL;
    free(pw.stack);
}
