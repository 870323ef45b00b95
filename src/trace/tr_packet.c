/* tr_packet.c -- one step of eight rays side by side through a sequential lens's
 * candidate surfaces (see tr_packet.h).  Each function here is the vector twin of a
 * one-ray function and says which: the same operations in the same order, a branch
 * becoming a select between lanes, so every lane rounds exactly as that ray would
 * alone (GCC vector extensions: IEEE add, multiply, divide and square root per
 * element, and -ffp-contract=off from the build keeps them unfused).  Eight rays at a
 * time keep the divider and the square-root unit busy instead of waiting on one
 * ray's dependent chain; that is the whole point of this file. */
#include <float.h>
#include <math.h>
#include <string.h>
#include "tr_packet.h"

void tr_pk_set_clear(tr_pk_set *s)
{
    memset(s, 0, sizeof *s);
}

void tr_pk_set_add(tr_pk_set *s, int id, const tr_shape *g, const trace_material *m,
                   int leaving, const tr_shape *from)
{
    int i = s->nc;
    if (i < 0 || i >= 4 || i >= TR_PK) return;
    if (g->fast != TR_FAST_CONIC && g->fast != TR_FAST_PLANE) {
        s->nc = -1;                   /* not for the packet, whatever comes after */
        return;
    }
    s->id[i] = id;
    s->g[i] = g;
    s->leaving[i] = leaving;
    /* a ray starting on `from` lies within |at - from's at| + from's reach of g's
     * vertex: too near for tr_advance (with a margin for its rounding) if that is
     * under (TR_FAR + 1) reaches; then the step need not ask */
    s->farok[i] = 1;
    if (from) {
        double dv[3] = {from->at[0] - g->at[0], from->at[1] - g->at[1],
                        from->at[2] - g->at[2]};
        s->farok[i] = !(v_norm(dv) + from->reach <= 0.99 * (TR_FAR + 1) * g->reach);
    }
    s->anyfar |= s->farok[i];
    s->c[i] = g->c;
    s->ck1[i] = g->ck1;
    s->cone[i] = g->fast == TR_FAST_CONIC;
    s->kind[i] = m->kind;
    s->nf[i] = m->n_front;
    s->nb[i] = m->n_back;
    for (int j = 0; j < 3; j++) {
        s->wn[j][i] = -g->w[j];
        s->at[j][i] = g->at[j];
    }
    s->nc++;
}

/* Eight doubles make one AVX-512 register: what follows is compiled for AVX-512 (the
 * engine calls it only where the processor has it, see tr_lanes.c).  The fused
 * multiply-add it brings stays unused: -ffp-contract=off forbids it. */
#pragma GCC target("avx2,avx512f,avx512vl,avx512dq")

typedef tr_vd vd;
typedef tr_vm vm;

#define W TR_PK
static inline vd splat(double a)
{
    vd r;
    for (int i = 0; i < W; i++) r[i] = a;
    return r;
}
static inline vm msplat(long long a)
{
    vm r;
    for (int i = 0; i < W; i++) r[i] = a;
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
static inline vd load(const double a[4]) { vd v; memcpy(&v, a, sizeof v); return v; }
static inline vm finite(vd x) { return vabs(x) <= DBL_MAX; }
static inline vd vsqrt(vd x)
{
    vd r;
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
    vm ok = (l > 0) & finite(l);
    vd r = 1.0 / l;
    for (int i = 0; i < 3; i++) a[i] = sel(ok, a[i] * r, a[i]);
}

/* tr_in_aperture */
static inline vm in_aperture(const tr_shape *g, vd x, vd y)
{
    if (g->aperture == TRACE_AP_RECT) return (vabs(x) <= g->hw) & (vabs(y) <= g->hh);
    vd s2 = x * x + y * y;
    vm ok = s2 >= g->r_inner2;
    if (g->r_outer2 > 0) ok &= ~(s2 > g->r_outer2);
    return ok;
}

/* tr_axial_ok */
static inline vm axial_ok(const tr_shape *g, const vd p[3])
{
    vm ok = mask_all();
    if (g->c != 0) ok &= ~((1.0 - g->ck1 * p[2]) <= 0);
    if (g->r_outer2 == 0 && g->aperture == TRACE_AP_DISC && g->c != 0)
        ok &= ~((1.0 - g->k1 * g->c * g->c * (p[0] * p[0] + p[1] * p[1])) < 0);
    return ok & in_aperture(g, p[0], p[1]);
}

/* tr_conic_hit with tr_quad_roots: the roots in ascending order, the first one in
 * front on the vertex branch and the aperture wins. */
static vm conic_hit(const tr_shape *g, int leaving, int farok, const vd o[3],
                    const vd d[3], vd *t, vd p[3], vm *farout)
{
    vd lo[3] = {o[0] - g->at[0], o[1] - g->at[1], o[2] - g->at[2]};
    double c = g->c, k1 = g->k1;
    vd t0 = splat(0);
    vm far = mask_none();
    if (!leaving && farok) {             /* tr_advance: a far start */
        t0 = -(lo[0] * d[0] + lo[1] * d[1] + lo[2] * d[2]) - g->reach;
        far = t0 > TR_FAR * g->reach;
        if (any(far))
            for (int j = 0; j < 3; j++) lo[j] = sel(far, lo[j] + t0 * d[j], lo[j]);
    }
    vd A = c * (d[0] * d[0] + d[1] * d[1] + k1 * d[2] * d[2]);
    vd B = c * (lo[0] * d[0] + lo[1] * d[1] + k1 * lo[2] * d[2]) - d[2];
    vd ra, rb;
    vm va, vb;
    if (leaving) {                       /* roots 0 and -2B/A */
        va = A != 0;
        ra = rb = -2.0 * B / A;
        vb = mask_none();
    } else {
        vd C = c * (lo[0] * lo[0] + lo[1] * lo[1] + k1 * lo[2] * lo[2]) - 2.0 * lo[2];
        vd disc = B * B - A * C;
        vd q = -(B + with_sign(vsqrt(disc), B));
        vd r0 = q / A, r1 = C / q;       /* each where it is defined */
        vm real = ~(disc < 0), hasA = A != 0, hasq = q != 0, both = hasA & hasq;
        vm swap = both & (r0 > r1);
        ra = sel(hasA, sel(swap, r1, r0), r1);
        rb = sel(swap, r0, r1);
        va = real & (hasA | hasq);
        vb = real & both;
    }
    vd pa[3], pb[3];
    for (int j = 0; j < 3; j++) pa[j] = lo[j] + ra * d[j];
    vm oka = va & (ra > 0) & axial_ok(g, pa);
    int anyfar = !leaving && farok && any(far);
    *farout = far;
    *t = anyfar ? sel(far, t0 + ra, ra) : ra;
    for (int j = 0; j < 3; j++) p[j] = pa[j];
    vm need = vb & ~oka;
    if (!any(need)) return oka;            /* the usual case: no lane looks further */
    for (int j = 0; j < 3; j++) pb[j] = lo[j] + rb * d[j];
    vm okb = need & (rb > 0) & axial_ok(g, pb);
    if (anyfar) { ra = sel(far, t0 + ra, ra); rb = sel(far, t0 + rb, rb); }
    *t = sel(oka, ra, rb);
    for (int j = 0; j < 3; j++) p[j] = sel(oka, pa[j], pb[j]);
    return oka | okb;
}

/* tr_plane_hit */
static vm plane_hit(const tr_shape *g, int leaving, int farok, const vd o[3],
                    const vd d[3], vd *t, vd p[3], vm *far)
{
    if (leaving) return mask_none();
    vd lo[3] = {o[0] - g->at[0], o[1] - g->at[1], o[2] - g->at[2]};
    vd tt = -lo[2] / d[2];
    *t = tt;
    p[0] = lo[0] + tt * d[0];
    p[1] = lo[1] + tt * d[1];
    p[2] = splat(0);
    *far = mask_none();
    if (farok)
        *far = (-(lo[0] * d[0] + lo[1] * d[1] + lo[2] * d[2]) - g->reach) > TR_FAR * g->reach;
    return (d[2] != 0) & (tt > 0) & in_aperture(g, p[0], p[1]);
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

/* seq_hit: the nearest candidate, the first one at a tie. */
static void nearest(const tr_pk_set *s, const vd o[3], const vd d[3], pick *k)
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
        vm up = ok & (t < best);
        best = sel(up, t, best);
        k->k = seli(up, msplat(i), k->k);
        if (s->farok[i]) k->far = seli(up, far, k->far);
        if (cone || (s->farok[i] && any(up & far)))   /* a plane's point: far starts */
            for (int j = 0; j < 3; j++) k->p[j] = sel(up, p[j], k->p[j]);
    }
    k->t = best;
    vm ix = k->k & 3;                      /* lanes without a hit leave the packet */
    k->conic = __builtin_shuffle(load(s->cone), ix) != 0;
    k->kind = __builtin_shuffle(load(s->kind), ix);
    k->c = __builtin_shuffle(load(s->c), ix);
    k->ck1 = __builtin_shuffle(load(s->ck1), ix);
    k->nf = __builtin_shuffle(load(s->nf), ix);
    k->nb = __builtin_shuffle(load(s->nb), ix);
    for (int j = 0; j < 3; j++) k->wn[j] = __builtin_shuffle(load(s->wn[j]), ix);
}

/* seq_normal: tr_conic_normal_local turned to the front, or a plane's -w. */
static void normal(const pick *k, vd n[3])
{
    vd nl[3];
    nl[0] = -k->c * k->p[0];
    nl[1] = -k->c * k->p[1];
    nl[2] = 1.0 - k->ck1 * k->p[2];
    vd l = 1.0 / vsqrt(nl[0] * nl[0] + nl[1] * nl[1] + nl[2] * nl[2]);
    for (int j = 0; j < 3; j++) n[j] = sel(k->conic, -(nl[j] * l), k->wn[j]);
}

/* s_vector then tr_pol_rotate: the state of rays d in the s/p basis of normal n. */
static void rotate(const tr_pk *in, const vd n[3], vd e[3], vd j[4])
{
    vd s[3], f[3];
    cross(in->d, n, s);
    vd l = vsqrt(dot(s, s));
    vm small = ~(l >= 1e-12);
    vd il = 1.0 / l;
    for (int i = 0; i < 3; i++) s[i] = sel(small, in->e[i], s[i] * il);
    vm iso = (in->jss == in->jpp) & (in->jre == 0) & (in->jim == 0);
    cross(in->d, in->e, f);
    vd c = dot(in->e, s), sn = dot(f, s);
    vm same = iso | ((c == 1.0) & (sn == 0.0));
    vd a = in->jss, b = in->jpp, re = in->jre, im = in->jim;
    vd cc = c * c, ss = sn * sn, cs = c * sn;
    vd jss = cc * a + 2.0 * cs * re + ss * b;
    vd jpp = ss * a - 2.0 * cs * re + cc * b;
    vd jre = cs * (b - a) + (cc - ss) * re;
    vd jim = (cc + ss) * im;
    jss = sel(jss < 0, splat(0), jss);
    jpp = sel(jpp < 0, splat(0), jpp);
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

static void fresnel(vd n1, vd n2, vd ci, fres *f)
{
    vd eta = n1 / n2;
    vd c2 = (1.0 - eta * eta) + eta * eta * ci * ci;
    f->ct = vsqrt(c2);
    vd ds = n1 * ci + n2 * f->ct, dp = n2 * ci + n1 * f->ct;
    f->bad = (c2 <= 0) | (ds == 0) | (dp == 0);
    vd is = 1.0 / ds, ip = 1.0 / dp;
    vd rs = (n1 * ci - n2 * f->ct) * is;
    vd rp = (n2 * ci - n1 * f->ct) * ip;
    vm ns = rs < 0, np = rp < 0;
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

unsigned tr_pk_step(const tr_pk *in, tr_pk *out, tr_pk_aux *x, const tr_pk_set *st,
                    unsigned live, const tr_pk_opt *o)
{
    pick k;
    vd n[3], q[3], e[3], j[4];
    vm on;
    for (int l = 0; l < W; l++) on[l] = live & (1u << l) ? -1 : 0;
    /* trace_rest's depth limit and seq_cands's direction checks */
    vm go = on & (in->depth < o->max_depth) & (in->d[2] > 0);
    if (o->entry) go &= in->o[2] < o->entry_z;
    nearest(st, in->o, in->d, &k);
    normal(&k, n);
    x->t = k.t;
    x->p = in->jss + in->jpp;
    for (int i = 0; i < 3; i++) {
        q[i] = in->o[i] + k.t * in->d[i];
        x->nrm[i] = n[i];
    }
    if (st->anyfar && any(k.far)) {        /* on_hit: a far start's point (tr_advance) */
        vm ix = k.k & 3;
        for (int i = 0; i < 3; i++)
            q[i] = sel(k.far, __builtin_shuffle(load(st->at[i]), ix) + k.p[i], q[i]);
    }
    vm fin = finite(q[0]) & finite(q[1]) & finite(q[2]) & finite(n[0]);
    out->len = in->len + k.t;
    out->opl = in->opl + in->n * k.t;
    for (int i = 0; i < 3; i++) out->o[i] = q[i];
    rotate(in, n, e, j);

    /* interact: the indices seen from the incident side, m back into it */
    vd dn = dot(in->d, n), m[3];
    vm back = dn > 0;
    vd n1 = sel(back, k.nb, k.nf), n2 = sel(back, k.nf, k.nb);
    for (int i = 0; i < 3; i++) m[i] = sel(back, -n[i], n[i]);
    vd adn = vabs(dn);
    vd ci = sel(adn < 1.0, adn, splat(1.0));
    fres f;
    fresnel(n1, n2, ci, &f);
    x->jss = j[0]; x->jpp = j[1]; x->jre = j[2]; x->jim = j[3];
    x->Rs = f.Rs; x->Rp = f.Rp; x->rsp = f.rsp;
    x->n1 = n1;
    if (o->reflections) {
        for (int i = 0; i < 3; i++) x->rd[i] = in->d[i] + 2.0 * ci * m[i];
        unit(x->rd);
    }
    vd eta = n1 / n2, kk = eta * ci - f.ct, d[3];
    for (int i = 0; i < 3; i++) d[i] = eta * in->d[i] + kk * m[i];
    unit(d);
    vd a = vsqrt(f.Ts * f.Tp);

    /* what each lane did */
    vm hit = go & (k.k >= 0) & fin;
    vm refr = hit & (k.kind == TRACE_REFRACT) & ~f.bad;
    vm det = hit & (k.kind == TRACE_DETECT), abso = hit & (k.kind == TRACE_ABSORB);
    vm rot = refr | det;
    x->status = seli(refr, msplat(TR_PK_REFRACT), seli(det, msplat(TR_PK_DETECT),
                seli(abso, msplat(TR_PK_ABSORB), seli(on, msplat(TR_PK_SCALAR),
                                                      msplat(TR_PK_IDLE)))));
    x->cand = k.k;
    x->mismatch = refr & (vabs(in->n - n1) > 1e-9 * n1);
    for (int i = 0; i < 3; i++) {
        out->e[i] = sel(rot, e[i], in->e[i]);
        out->d[i] = sel(refr, d[i], in->d[i]);
    }
    out->n = sel(refr, n2, in->n);
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
    out->nmis = in->nmis + (x->mismatch & 1);
    out->cut = in->cut;
    out->ncutr = in->ncutr;
    if (o->fresnel && !o->reflections) {
        vd pr = f.Rs * x->jss + f.Rp * x->jpp;
        vm lost = refr & (pr > 0);
        out->cut = sel(lost, in->cut + pr, in->cut);
        out->ncutr = in->ncutr + (lost & 1);
    }
    vd pw = out->jss + out->jpp;
    vm strong = refr & ~(pw <= 0) & ~(pw < o->cutoff * in->p0);
    unsigned calm = 0;
    for (int l = 0; l < W; l++) calm |= strong[l] ? 1u << l : 0;
    return calm;
}
