/* tr_pk_kernel.h -- the packet step (see tr_packet.h), written once for any vector
 * width.  A file that includes it defines PK_W (lanes per vector: 8, 4 or 2) and PK_FN
 * (the step's name) and sets the instruction set it is compiled for
 * (tr_pk_avx512.c, tr_pk_avx2.c, tr_pk_base.c); the eight lanes of a packet go
 * through in chunks of PK_W.
 *
 * Each function here is the vector twin of a one-ray function and says which: the
 * same operations in the same order, a branch becoming a select between lanes, so
 * every lane rounds exactly as that ray would alone, whatever the width (GCC vector
 * extensions: IEEE add, multiply, divide and square root per element, and
 * -ffp-contract=off from the build keeps them unfused, so the fused multiply-add
 * AVX-512 brings stays unused).  A test on `any` lane only skips work whose result
 * every lane would discard.  Several rays at a time keep the divider and the
 * square-root unit busy instead of waiting on one ray's dependent chain; that is the
 * whole point of the packets. */
#include <float.h>
#include <math.h>
#include <string.h>
#include "tr_packet.h"

#if !defined(PK_W) || !defined(PK_FN) || TR_PK % PK_W
#error "define PK_W (dividing TR_PK) and PK_FN before including tr_pk_kernel.h"
#endif

/* GCC notes that wide vectors pass differently with and without AVX; they never
 * leave this file (the step takes pointers), so the note is moot. */
#pragma GCC diagnostic ignored "-Wpsabi"

typedef double vd __attribute__((vector_size(8 * PK_W)));
typedef long long vm __attribute__((vector_size(8 * PK_W)));   /* lane masks */

#define W PK_W
static inline vd splat(double a)
{
    vd r = {a};
    for (int i = 1; i < W; i++) r[i] = a;
    return r;
}
static inline vm msplat(long long a)
{
    vm r = {a};
    for (int i = 1; i < W; i++) r[i] = a;
    return r;
}
static inline vm mask_all(void) { return msplat(-1); }
static inline vm mask_none(void) { return msplat(0); }
static inline vd sel(vm m, vd a, vd b) { return (vd)((m & (vm)a) | (~m & (vm)b)); }
static inline vm seli(vm m, vm a, vm b) { return (m & a) | (~m & b); }
static inline vm sign_bits(void) { return (vm)splat(-0.0); }
static inline vd vabs(vd x) { return (vd)((vm)x & ~sign_bits()); }
/* copysign(x, y) for x >= +0 (or NaN) */
static inline vd with_sign(vd x, vd y) { return (vd)((vm)x | ((vm)y & sign_bits())); }
static inline int any(vm m)
{
    long long a = 0;
    for (int i = 0; i < W; i++) a |= m[i];
    return a != 0;
}
static inline vd ld(const double *a) { vd v; memcpy(&v, a, sizeof v); return v; }
static inline vm ldm(const long long *a) { vm v; memcpy(&v, a, sizeof v); return v; }
static inline void st(double *a, vd v) { memcpy(a, &v, sizeof v); }
static inline void stm(long long *a, vm v) { memcpy(a, &v, sizeof v); }
/* t[ix] per lane, ix in 0..3 (a candidate's figure, tr_pk_set's tables) */
static inline vd pick4(const double t[TR_PK], vm ix)
{
#if PK_W >= 4
    return __builtin_shuffle(ld(t), ix);
#else
    return __builtin_shuffle(ld(t), ld(t + PK_W), ix);
#endif
}
/* The comparisons of doubles.  Four lanes on 2-lane registers (PK_SPLIT, tr_pk_sse2x4.c):
 * GCC lowers a comparison it has no instruction for element by element (scalar
 * compares and branches, though it splits the arithmetic into 2-lane halves), so
 * there each is two 2-lane comparisons; elsewhere the operator itself. */
#if PK_SPLIT
typedef double vd2 __attribute__((vector_size(16)));
typedef long long vm2 __attribute__((vector_size(16)));
#define PK_CMP(name, op)                                                              \
    static inline vm name(vd a, vd b)                                                 \
    {                                                                                 \
        vd2 a0, a1, b0, b1;                                                           \
        vm r;                                                                         \
        memcpy(&a0, &a, 16); memcpy(&a1, (char *)&a + 16, 16);                        \
        memcpy(&b0, &b, 16); memcpy(&b1, (char *)&b + 16, 16);                        \
        vm2 r0 = a0 op b0, r1 = a1 op b1;                                             \
        memcpy(&r, &r0, 16); memcpy((char *)&r + 16, &r1, 16);                        \
        return r;                                                                     \
    }
#else
#define PK_CMP(name, op) static inline vm name(vd a, vd b) { return a op b; }
#endif
PK_CMP(lt, <)
PK_CMP(le, <=)
PK_CMP(gt, >)
PK_CMP(ge, >=)
PK_CMP(eq, ==)
PK_CMP(ne, !=)
static inline vm finite(vd x) { return le(vabs(x), splat(DBL_MAX)); }
static inline vd vsqrt(vd x)
{
    vd r = x;
    for (int i = 0; i < W; i++) r[i] = sqrt(x[i]);
    return r;
}
static inline vd dot(const vd a[3], const vd b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
static inline void cross(const vd a[3], const vd b[3], vd c[3])
{
    vd x = a[1] * b[2] - a[2] * b[1];
    vd y = a[2] * b[0] - a[0] * b[2];
    vd z = a[0] * b[1] - a[1] * b[0];
    c[0] = x; c[1] = y; c[2] = z;
}
/* v_unit: lanes whose length is 0 or not finite keep their vector */
static inline void unit(vd a[3])
{
    vd l = vsqrt(dot(a, a));
    vm ok = gt(l, splat(0)) & finite(l);
    vd r = 1.0 / l;
    for (int i = 0; i < 3; i++) a[i] = sel(ok, a[i] * r, a[i]);
}

/* One chunk of a packet (lanes base .. base + W - 1) in registers. */
typedef struct vpk {
    vd o[3], d[3], n, len, opl, e[3], jss, jpp, jre, jim, p0, cut;
    vm depth, maxd, nseg, nint, nmis, ncutr;
} vpk;

static inline void pk_load(const tr_pk *p, int b, vpk *v)
{
    for (int i = 0; i < 3; i++) {
        v->o[i] = ld(p->o[i] + b);
        v->d[i] = ld(p->d[i] + b);
        v->e[i] = ld(p->e[i] + b);
    }
    v->n = ld(p->n + b); v->len = ld(p->len + b); v->opl = ld(p->opl + b);
    v->jss = ld(p->jss + b); v->jpp = ld(p->jpp + b);
    v->jre = ld(p->jre + b); v->jim = ld(p->jim + b);
    v->p0 = ld(p->p0 + b); v->cut = ld(p->cut + b);
    v->depth = ldm(p->depth + b); v->maxd = ldm(p->maxd + b);
    v->nseg = ldm(p->nseg + b); v->nint = ldm(p->nint + b);
    v->nmis = ldm(p->nmis + b); v->ncutr = ldm(p->ncutr + b);
}

static inline void pk_store(const vpk *v, tr_pk *p, int b)
{
    for (int i = 0; i < 3; i++) {
        st(p->o[i] + b, v->o[i]);
        st(p->d[i] + b, v->d[i]);
        st(p->e[i] + b, v->e[i]);
    }
    st(p->n + b, v->n); st(p->len + b, v->len); st(p->opl + b, v->opl);
    st(p->jss + b, v->jss); st(p->jpp + b, v->jpp);
    st(p->jre + b, v->jre); st(p->jim + b, v->jim);
    st(p->p0 + b, v->p0); st(p->cut + b, v->cut);
    stm(p->depth + b, v->depth); stm(p->maxd + b, v->maxd);
    stm(p->nseg + b, v->nseg); stm(p->nint + b, v->nint);
    stm(p->nmis + b, v->nmis); stm(p->ncutr + b, v->ncutr);
}

/* tr_in_aperture */
static inline vm in_aperture(const tr_shape *g, vd x, vd y)
{
    if (g->aperture == TRACE_AP_RECT) return le(vabs(x), splat(g->hw)) & le(vabs(y), splat(g->hh));
    vd s2 = x * x + y * y;
    vm ok = ge(s2, splat(g->r_inner2));
    if (g->r_outer2 > 0) ok &= ~gt(s2, splat(g->r_outer2));
    return ok;
}

/* tr_axial_ok */
static inline vm axial_ok(const tr_shape *g, const vd p[3])
{
    vm ok = mask_all();
    if (g->c != 0) ok &= ~le(1.0 - g->ck1 * p[2], splat(0));
    if (g->r_outer2 == 0 && g->aperture == TRACE_AP_DISC && g->c != 0)
        ok &= ~lt(1.0 - g->k1 * g->c * g->c * (p[0] * p[0] + p[1] * p[1]), splat(0));
    return ok & in_aperture(g, p[0], p[1]);
}

/* tr_conic_hit with tr_quad_roots: the roots in ascending order, the first one in
 * front on the vertex branch and the aperture wins. */
static inline vm conic_hit(const tr_shape *g, int leaving, int farok, const vd o[3],
                           const vd d[3], vd *t, vd p[3], vm *farout)
{
    vd lo[3] = {o[0] - g->at[0], o[1] - g->at[1], o[2] - g->at[2]};
    double c = g->c, k1 = g->k1;
    vd t0 = splat(0);
    vm far = mask_none();
    if (!leaving && farok) {             /* tr_advance: a far start */
        t0 = -(lo[0] * d[0] + lo[1] * d[1] + lo[2] * d[2]) - g->reach;
        far = gt(t0, splat(TR_FAR * g->reach));
        if (any(far))
            for (int j = 0; j < 3; j++) lo[j] = sel(far, lo[j] + t0 * d[j], lo[j]);
    }
    vd A = c * (d[0] * d[0] + d[1] * d[1] + k1 * d[2] * d[2]);
    vd B = c * (lo[0] * d[0] + lo[1] * d[1] + k1 * lo[2] * d[2]) - d[2];
    vd ra, rb;
    vm va, vb;
    if (leaving) {                       /* roots 0 and -2B/A */
        va = ne(A, splat(0));
        ra = rb = -2.0 * B / A;
        vb = mask_none();
    } else {
        vd C = c * (lo[0] * lo[0] + lo[1] * lo[1] + k1 * lo[2] * lo[2]) - 2.0 * lo[2];
        vd disc = B * B - A * C;
        vd q = -(B + with_sign(vsqrt(disc), B));
        vd r0 = q / A, r1 = C / q;       /* each where it is defined */
        vm real = ~lt(disc, splat(0)), hasA = ne(A, splat(0)), hasq = ne(q, splat(0));
        vm both = hasA & hasq, swap = both & gt(r0, r1);
        ra = sel(hasA, sel(swap, r1, r0), r1);
        rb = sel(swap, r0, r1);
        va = real & (hasA | hasq);
        vb = real & both;
    }
    vd pa[3], pb[3];
    for (int j = 0; j < 3; j++) pa[j] = lo[j] + ra * d[j];
    vm oka = va & gt(ra, splat(0)) & axial_ok(g, pa);
    int anyfar = !leaving && farok && any(far);
    *farout = far;
    *t = anyfar ? sel(far, t0 + ra, ra) : ra;
    for (int j = 0; j < 3; j++) p[j] = pa[j];
    vm need = vb & ~oka;
    if (!any(need)) return oka;            /* the usual case: no lane looks further */
    for (int j = 0; j < 3; j++) pb[j] = lo[j] + rb * d[j];
    vm okb = need & gt(rb, splat(0)) & axial_ok(g, pb);
    if (anyfar) { ra = sel(far, t0 + ra, ra); rb = sel(far, t0 + rb, rb); }
    *t = sel(oka, ra, rb);
    for (int j = 0; j < 3; j++) p[j] = sel(oka, pa[j], pb[j]);
    return oka | okb;
}

/* tr_plane_hit */
static inline vm plane_hit(const tr_shape *g, int leaving, int farok, const vd o[3],
                           const vd d[3], vd *t, vd p[3], vm *far)
{
    if (leaving) {                       /* a plane is not met again */
        *t = splat(INFINITY);
        p[0] = p[1] = p[2] = splat(0);
        *far = mask_none();
        return mask_none();
    }
    vd lo[3] = {o[0] - g->at[0], o[1] - g->at[1], o[2] - g->at[2]};
    vd tt = -lo[2] / d[2];
    *t = tt;
    p[0] = lo[0] + tt * d[0];
    p[1] = lo[1] + tt * d[1];
    p[2] = splat(0);
    *far = mask_none();
    if (farok)
        *far = gt(-(lo[0] * d[0] + lo[1] * d[1] + lo[2] * d[2]) - g->reach,
                  splat(TR_FAR * g->reach));
    return ne(d[2], splat(0)) & gt(tt, splat(0)) & in_aperture(g, p[0], p[1]);
}

/* The chosen candidate of each lane and what the step needs of it. */
typedef struct pick {
    vd t, p[3];            /* distance and the local hit point */
    vm far;                /* a far start: the hit point is at + p (tr_advance) */
    vm k;                  /* candidate index, -1: none */
    vm conic;              /* lanes whose candidate is a conic */
    vd kind;               /* its material (trace_material_kind) */
    vd c, ck1, nf, nb;     /* its curvature terms and indices */
    vd wn[3];              /* a plane's front normal (-w) */
} pick;

/* seq_hit: the nearest candidate, the first one at a tie.  A plane's local point is
 * kept only for far starts: elsewhere no lane reads it (normal() takes -w). */
static inline void nearest(const tr_pk_set *s, const vd o[3], const vd d[3], pick *k)
{
    vd best = splat(INFINITY), t, p[3];
    vm far;
    k->k = msplat(-1);
    k->far = mask_none();
    for (int j = 0; j < 3; j++) k->p[j] = splat(0);
    for (int i = 0; i < s->nc; i++) {
        int cone = s->g[i]->fast == TR_FAST_CONIC;
        vm ok = cone ? conic_hit(s->g[i], s->leaving[i], s->farok[i], o, d, &t, p, &far)
                     : plane_hit(s->g[i], s->leaving[i], s->farok[i], o, d, &t, p, &far);
        vm up = ok & lt(t, best);
        best = sel(up, t, best);
        k->k = seli(up, msplat(i), k->k);
        if (s->farok[i]) k->far = seli(up, far, k->far);
        if (cone || (s->farok[i] && any(up & far)))   /* a plane's point: far starts */
            for (int j = 0; j < 3; j++) k->p[j] = sel(up, p[j], k->p[j]);
    }
    k->t = best;
    vm ix = k->k & 3;                      /* lanes without a hit leave the packet */
    k->conic = ne(pick4(s->cone, ix), splat(0));
    k->kind = pick4(s->kind, ix);
    k->c = pick4(s->c, ix);
    k->ck1 = pick4(s->ck1, ix);
    k->nf = pick4(s->nf, ix);
    k->nb = pick4(s->nb, ix);
    for (int j = 0; j < 3; j++) k->wn[j] = pick4(s->wn[j], ix);
}

/* seq_normal: tr_conic_normal_local turned to the front, or a plane's -w. */
static inline void normal(const pick *k, vd n[3])
{
    vd nl[3];
    nl[0] = -k->c * k->p[0];
    nl[1] = -k->c * k->p[1];
    nl[2] = 1.0 - k->ck1 * k->p[2];
    vd l = 1.0 / vsqrt(nl[0] * nl[0] + nl[1] * nl[1] + nl[2] * nl[2]);
    for (int j = 0; j < 3; j++) n[j] = sel(k->conic, -(nl[j] * l), k->wn[j]);
}

/* s_vector then tr_pol_rotate: the state of rays d in the s/p basis of normal n. */
static inline void rotate(const vpk *in, const vd n[3], vd e[3], vd j[4])
{
    vd s[3], f[3];
    cross(in->d, n, s);
    vd l = vsqrt(dot(s, s));
    vm small = ~ge(l, splat(1e-12));
    vd il = 1.0 / l;
    for (int i = 0; i < 3; i++) s[i] = sel(small, in->e[i], s[i] * il);
    vm iso = eq(in->jss, in->jpp) & eq(in->jre, splat(0)) & eq(in->jim, splat(0));
    cross(in->d, in->e, f);
    vd c = dot(in->e, s), sn = dot(f, s);
    vm same = iso | (eq(c, splat(1.0)) & eq(sn, splat(0.0)));
    vd a = in->jss, b = in->jpp, re = in->jre, im = in->jim;
    vd cc = c * c, ss = sn * sn, cs = c * sn;
    vd jss = cc * a + 2.0 * cs * re + ss * b;
    vd jpp = ss * a - 2.0 * cs * re + cc * b;
    vd jre = cs * (b - a) + (cc - ss) * re;
    vd jim = (cc + ss) * im;
    jss = sel(lt(jss, splat(0)), splat(0), jss);
    jpp = sel(lt(jpp, splat(0)), splat(0), jpp);
    j[0] = sel(same, a, jss);
    j[1] = sel(same, b, jpp);
    j[2] = sel(same, re, jre);
    j[3] = sel(same, im, jim);
    for (int i = 0; i < 3; i++) e[i] = s[i];
}

/* tr_fresnel's coefficients outside TIR and grazing (those lanes are flagged). */
typedef struct fres {
    vd ct, Rs, Rp, Ts, Tp, rsp;
    vm bad;                /* TIR or grazing: the one-ray code handles these */
} fres;

static inline void fresnel(vd n1, vd n2, vd ci, fres *f)
{
    vd eta = n1 / n2;
    vd c2 = (1.0 - eta * eta) + eta * eta * ci * ci;
    f->ct = vsqrt(c2);
    vd ds = n1 * ci + n2 * f->ct, dp = n2 * ci + n1 * f->ct;
    f->bad = le(c2, splat(0)) | eq(ds, splat(0)) | eq(dp, splat(0));
    vd is = 1.0 / ds, ip = 1.0 / dp;
    vd rs = (n1 * ci - n2 * f->ct) * is;
    vd rp = (n2 * ci - n1 * f->ct) * ip;
    vm ns = lt(rs, splat(0)), np = lt(rp, splat(0));
    rs = sel(ns, -rs, rs);
    rp = sel(np, -rp, rp);
    f->Rs = rs * rs;
    f->Rp = rp * rp;
    vd q = 4.0 * n1 * n2 * ci * f->ct;
    f->Ts = q * is * is;
    f->Tp = q * ip * ip;
    vd rr = rs * rp;
    f->rsp = sel(ns == np, rr, -rr);
}

/* The step for lanes b .. b + W - 1 (on: the live ones); returns their calm bits
 * (bit i: lane b + i).  Inlined into the step, so that the step's return clears the
 * upper halves of the vector registers (vzeroupper) before the one-ray code runs:
 * returning from a tail-called chunk left them dirty, and the SSE code after it ran
 * a third slower (issue 13). */
static inline __attribute__((always_inline)) unsigned chunk(const tr_pk *pin, tr_pk *pout, tr_pk_aux *x,
                             const tr_pk_set *cs, vm on, const tr_pk_opt *o, int b)
{
    vpk vi, vo;
    const vpk *in = &vi;
    vpk *out = &vo;
    pick k;
    vd n[3], q[3], e[3], j[4];
    pk_load(pin, b, &vi);
    /* trace_rest's depth limit and seq_cands's direction checks */
    vm go = on & (in->depth < o->max_depth) & gt(in->d[2], splat(0));
    if (o->entry) go &= lt(in->o[2], splat(o->entry_z));
    nearest(cs, in->o, in->d, &k);
    normal(&k, n);
    st(x->t + b, k.t);
    st(x->p + b, in->jss + in->jpp);
    for (int i = 0; i < 3; i++) {
        q[i] = in->o[i] + k.t * in->d[i];
        st(x->nrm[i] + b, n[i]);
    }
    if (cs->anyfar && any(k.far)) {        /* on_hit: a far start's point (tr_advance) */
        vm ix = k.k & 3;
        for (int i = 0; i < 3; i++)
            q[i] = sel(k.far, pick4(cs->at[i], ix) + k.p[i], q[i]);
    }
    vm fin = finite(q[0]) & finite(q[1]) & finite(q[2]) & finite(n[0]);
    out->len = in->len + k.t;
    out->opl = in->opl + in->n * k.t;
    for (int i = 0; i < 3; i++) out->o[i] = q[i];
    rotate(in, n, e, j);

    /* interact: the indices seen from the incident side, m back into it */
    vd dn = dot(in->d, n), m[3];
    vm back = gt(dn, splat(0));
    vd n1 = sel(back, k.nb, k.nf), n2 = sel(back, k.nf, k.nb);
    for (int i = 0; i < 3; i++) m[i] = sel(back, -n[i], n[i]);
    vd adn = vabs(dn);
    vd ci = sel(lt(adn, splat(1.0)), adn, splat(1.0));
    fres f;
    fresnel(n1, n2, ci, &f);
    st(x->jss + b, j[0]); st(x->jpp + b, j[1]); st(x->jre + b, j[2]); st(x->jim + b, j[3]);
    st(x->Rs + b, f.Rs); st(x->Rp + b, f.Rp); st(x->rsp + b, f.rsp);
    st(x->n1 + b, n1);
    if (o->reflections) {
        vd rd[3];
        for (int i = 0; i < 3; i++) rd[i] = in->d[i] + 2.0 * ci * m[i];
        unit(rd);
        for (int i = 0; i < 3; i++) st(x->rd[i] + b, rd[i]);
    }
    vd eta = n1 / n2, kk = eta * ci - f.ct, d[3];
    for (int i = 0; i < 3; i++) d[i] = eta * in->d[i] + kk * m[i];
    unit(d);
    vd a = vsqrt(f.Ts * f.Tp);

    /* what each lane did */
    vm hit = go & (k.k >= 0) & fin;
    vm refr = hit & eq(k.kind, splat(TRACE_REFRACT)) & ~f.bad;
    vm det = hit & eq(k.kind, splat(TRACE_DETECT)), abso = hit & eq(k.kind, splat(TRACE_ABSORB));
    vm rot = refr | det;
    stm(x->status + b, seli(refr, msplat(TR_PK_REFRACT), seli(det, msplat(TR_PK_DETECT),
                       seli(abso, msplat(TR_PK_ABSORB), seli(on, msplat(TR_PK_SCALAR),
                                                             msplat(TR_PK_IDLE))))));
    stm(x->cand + b, k.k);
    vm mismatch = refr & gt(vabs(in->n - n1), 1e-9 * n1);
    stm(x->mismatch + b, mismatch);
    for (int i = 0; i < 3; i++) {
        out->e[i] = sel(rot, e[i], in->e[i]);
        out->d[i] = sel(refr, d[i], in->d[i]);
    }
    out->n = sel(refr, n2, in->n);
    vd pj[2] = {j[0], j[1]};               /* x's state, before T */
    if (o->fresnel) {
        j[0] = sel(refr, j[0] * f.Ts, j[0]);
        j[1] = sel(refr, j[1] * f.Tp, j[1]);
        j[2] = sel(refr, j[2] * a, j[2]);
        j[3] = sel(refr, j[3] * a, j[3]);
    }
    out->jss = sel(rot, j[0], in->jss);
    out->jpp = sel(rot, j[1], in->jpp);
    out->jre = sel(rot, j[2], in->jre);
    out->jim = sel(rot, j[3], in->jim);

    /* the books: on_hit, interact, strong */
    vm one = refr & 1;
    out->p0 = in->p0;
    out->maxd = seli(go & (in->depth > in->maxd), in->depth, in->maxd);
    out->depth = in->depth + one;
    out->nseg = in->nseg + one;
    out->nint = in->nint + one;
    out->nmis = in->nmis + (mismatch & 1);
    out->cut = in->cut;
    out->ncutr = in->ncutr;
    if (o->fresnel && !o->reflections) {
        vd pr = f.Rs * pj[0] + f.Rp * pj[1];
        vm lost = refr & gt(pr, splat(0));
        out->cut = sel(lost, in->cut + pr, in->cut);
        out->ncutr = in->ncutr + (lost & 1);
    }
    vd pw = out->jss + out->jpp;
    vm strong = refr & ~le(pw, splat(0)) & ~lt(pw, o->cutoff * in->p0);
    pk_store(out, pout, b);
    unsigned calm = 0;
    for (int l = 0; l < W; l++) calm |= strong[l] ? 1u << l : 0;
    return calm;
}

unsigned PK_FN(const tr_pk *in, tr_pk *out, tr_pk_aux *x, const tr_pk_set *s,
               unsigned live, const tr_pk_opt *o)
{
    unsigned calm = 0;
    for (int b = 0; b < TR_PK; b += W) {
        unsigned mine = (live >> b) & ((1u << W) - 1);
        if (!mine) {                       /* no live lane here: nothing to do */
            for (int l = 0; l < W; l++) x->status[b + l] = TR_PK_IDLE;
            continue;
        }
        vm bit = {1};
        for (int l = 0; l < W; l++) bit[l] = 1LL << l;
        vm on = (msplat(mine) & bit) != 0;
        calm |= chunk(in, out, x, s, on, o, b) << b;
    }
    return calm;
}
