/* tr_trace.c -- the recursive trace of one ray: its segments to the surfaces the
 * scene names, what each surface does (refraction, mirrors, TIR, detectors,
 * absorbers) with Fresnel s/p bookkeeping, the reflected rays waiting on a stack, the
 * ray's books (tally) and records (segments, hits).  Nothing here prints. */
#include <math.h>
#include <stddef.h>
#include "tr_eng.h"

void tr_emit_segment(tr_worker *w, tr_out *out, const tr_wray *r, uint64_t ray,
                         const double p1[3], int end, int surf)
{
    if (!w->want_seg) return;
    trace_segment *s = buf_slot(&out->seg);
    if (!s) { w->nomem = 1; return; }
    memset(s, 0, sizeof *s);            /* padding too: records compare bytewise */
    s->ray = ray;
    s->depth = r->depth;
    s->end = end;
    s->surface = surf;
    v_set(s->p0, r->o);
    v_set(s->p1, p1);
    s->power = r->pol.jss + r->pol.jpp;
    s->lambda = r->lambda;
}

/* Is the record's one hole after surface (every other byte a field's)?  Then only it
 * needs zeroing (the condition is a constant: the other branch is not compiled in). */
#define HIT_PAD (offsetof(trace_hit, surface) + sizeof(int))
#define HIT_ONE_HOLE                                                                     \
    (offsetof(trace_hit, depth) == sizeof(uint64_t) &&                                   \
     offsetof(trace_hit, history) == offsetof(trace_hit, depth) + sizeof(int) &&         \
     offsetof(trace_hit, surface) == offsetof(trace_hit, history) + sizeof(uint32_t) &&  \
     offsetof(trace_hit, prim) - HIT_PAD + sizeof(uint64_t) + 2 * sizeof(int) +          \
     sizeof(uint32_t) + sizeof(long) + 17 * sizeof(double) == sizeof(trace_hit))

void tr_emit_hit(tr_worker *w, tr_out *out, const tr_wray *r, uint64_t ray,
                     const tr_hitrec *h, const double p[3])
{
    if (!w->want_hit) return;
    trace_hit *x = buf_slot(&out->hit);
    if (!x) { w->nomem = 1; return; }
    /* padding too: records compare bytewise.  Every field is set below, so only the
     * hole needs it: a memset of the whole record was a `rep stos`, half of this
     * function's time (perf, scripts/bench_trace_out.sh's triplet) */
    if (HIT_ONE_HOLE) memset((char *)x + HIT_PAD, 0, offsetof(trace_hit, prim) - HIT_PAD);
    else memset(x, 0, sizeof *x);
    x->ray = ray;
    x->depth = r->depth;
    x->history = r->hist;
    x->surface = h->surf;
    x->prim = h->prim;
    v_set(x->pos, p);
    v_set(x->dir, r->d);
    v_set(x->normal, h->n);
    v_set(x->s_dir, r->pol.e);
    x->power_s = r->pol.jss;
    x->power_p = r->pol.jpp;
    x->length = r->len;
    x->opl = r->opl;
    x->lambda = r->lambda;
}

/* s unit vector of the plane of incidence (d x n), or the ray's own e at normal
 * incidence. */
static void s_vector(const tr_wray *r, const double n[3], double s[3])
{
    v_cross(r->d, n, s);
    double l = v_norm(s);
    if (!(l >= 1e-12)) { v_set(s, r->pol.e); return; }
    l = 1.0 / l;
    s[0] *= l; s[1] *= l; s[2] *= l;
}

/* Does a ray of power p go on?  Else it is counted as cut off. */
int tr_strong(const tr_worker *w, tr_tally *ty, double p, double p0)
{
    if (p <= 0) return 0;
    if (p < w->o->cutoff * p0) {
        ty->cutoff += p;
        ty->cut_power++;
        return 0;
    }
    return 1;
}

void tr_keep(tr_worker *w, tr_tally *ty, int *sp, const tr_wray *c, double p0)
{
    if (tr_strong(w, ty, c->pol.jss + c->pol.jpp, p0)) (*sp)++;
}

/* The interaction at h: a reflected ray that must wait is pushed on the stack; the
 * ray that goes on now (refracted, or reflected at a mirror or TIR) replaces *r.
 * Returns 1 if *r goes on. */
static int interact(tr_worker *w, tr_tally *ty, tr_wray *stack, int *sp, tr_wray *r,
                    const tr_hitrec *h, const tr_surf *f, double p0)
{
    double n1 = f->mat.n_front, n2 = f->mat.n_back, s[3], m[3];
    double a2 = f->alpha_back;                          /* absorption of n2's side */
    if (f->media && h->prim >= 0) {
        n1 = f->media[2 * h->prim]; n2 = f->media[2 * h->prim + 1]; a2 = 0;
    }
    double dn = v_dot(r->d, h->n);
    if (dn > 0) {                                       /* arriving from the back */
        double x = n1; n1 = n2; n2 = x;
        a2 = f->media && h->prim >= 0 ? 0 : f->alpha_front;
    }
    /* m: unit normal pointing back into the incident medium */
    for (int i = 0; i < 3; i++) m[i] = dn > 0 ? -h->n[i] : h->n[i];
    double ci = fabs(dn) < 1.0 ? fabs(dn) : 1.0;   /* fmin(1, |dn|) without the call */
    if (f->mat.kind == TRACE_REFRACT && fabs(r->n - n1) > 1e-9 * n1) ty->mismatch++;
    ty->interactions++;
    s_vector(r, h->n, s);
    tr_pol_rotate(&r->pol, r->d, s);
    r->depth++;
    r->last_surf = h->surf;
    r->last_prim = h->prim;

    if (f->mat.kind == TRACE_MIRROR) {          /* rs = -1, rp = +1 */
        if (r->depth <= 32) r->hist |= 1u << (r->depth - 1);
        for (int i = 0; i < 3; i++) r->d[i] += 2 * ci * m[i];
        v_unit(r->d);
        r->pol.jre = -r->pol.jre;
        r->pol.jim = -r->pol.jim;
        return tr_strong(w, ty, r->pol.jss + r->pol.jpp, p0);
    }
    trace_fresnel_coef fc;
    tr_fresnel(n1, n2, ci, &fc);
    if (fc.tir) {
        double ph = fc.rs_phase - fc.rp_phase, re = r->pol.jre, im = r->pol.jim;
        if (r->depth <= 32) r->hist |= 1u << (r->depth - 1);
        for (int i = 0; i < 3; i++) r->d[i] += 2 * ci * m[i];
        v_unit(r->d);
        if (re != 0 || im != 0) {
            r->pol.jre = cos(ph) * re - sin(ph) * im;
            r->pol.jim = sin(ph) * re + cos(ph) * im;
        }
        ty->tir++;
        return tr_strong(w, ty, r->pol.jss + r->pol.jpp, p0);
    }
    if (w->o->fresnel) {
        /* outside TIR the phases are 0 or pi: rs rp is the product of signed values */
        double rsp = fc.rs * fc.rp * (fc.rs_phase == fc.rp_phase ? 1.0 : -1.0);
        if (w->o->reflections) {
            /* the reflected ray waits on the stack; the refracted one goes first */
            tr_wray *c = &stack[*sp];
            *c = *r;
            if (r->depth <= 32) c->hist |= 1u << (r->depth - 1);
            for (int i = 0; i < 3; i++) c->d[i] = r->d[i] + 2 * ci * m[i];
            v_unit(c->d);
            c->n = n1;
            c->pol.jss = fc.Rs * r->pol.jss;
            c->pol.jpp = fc.Rp * r->pol.jpp;
            c->pol.jre = rsp * r->pol.jre;
            c->pol.jim = rsp * r->pol.jim;
            tr_keep(w, ty, sp, c, p0);
        } else {
            double p = fc.Rs * r->pol.jss + fc.Rp * r->pol.jpp;
            if (p > 0) { ty->cutoff += p; ty->cut_reflection++; }
        }
    }
    double eta = n1 / n2, k = eta * ci - fc.cos_t;
    for (int i = 0; i < 3; i++) r->d[i] = eta * r->d[i] + k * m[i];
    v_unit(r->d);
    r->n = n2;
    r->alpha = a2;
    if (w->o->fresnel) {
        double a = sqrt(fc.Ts * fc.Tp);
        r->pol.jss *= fc.Ts;
        r->pol.jpp *= fc.Tp;
        r->pol.jre *= a;
        r->pol.jim *= a;
    }
    return tr_strong(w, ty, r->pol.jss + r->pol.jpp, p0);
}

/* A ray's state from its source ray; its tally starts. */
void tr_ray_start(tr_wray *r, const tr_ray0 *r0, tr_tally *ty, double *p0)
{
    memset(ty, 0, sizeof *ty);
    v_set(r->o, r0->o);
    v_set(r->d, r0->d);
    r->n = r0->n;
    r->len = r->opl = 0;
    r->pol = r0->pol;
    r->depth = 0;
    r->last_surf = -1;
    r->last_prim = -1;
    r->hist = 0;
    r->lambda = r0->lambda;
    r->alpha = r0->alpha;
    *p0 = r0->pol.jss + r0->pol.jpp;
    ty->emitted = *p0;
}

/* A numerical failure of the ray (its first cause kept); a finite power p is counted
 * as cut off so the balance still holds for the rest. */
static void ray_failed(tr_tally *ty, int cause, int surf, double p)
{
    if (!ty->failures) { ty->fail_cause = cause; ty->fail_surf = surf; }
    ty->failures++;
    if (isfinite(p)) ty->cutoff += p;
}

/* Beer-Lambert along a segment of length t in the ray's medium (alpha > 0): its
 * state scaled by exp(-alpha t), the loss counted as absorbed; returns the loss.  The
 * segment's record keeps the power where it starts (emitted before this). */
static double absorb_along(tr_tally *ty, tr_wray *r, double t)
{
    double k = exp(-r->alpha * t), p = r->pol.jss + r->pol.jpp;
    r->pol.jss *= k;
    r->pol.jpp *= k;
    r->pol.jre *= k;
    r->pol.jim *= k;
    double lost = p - (r->pol.jss + r->pol.jpp);
    ty->absorbed += lost;
    return lost;
}

/* One step once the hit h of *r is known: the segment to it and what the surface
 * does.  Returns 1 if *r goes on. */
static inline int on_hit(tr_worker *w, tr_out *out, tr_tally *ty, tr_wray *stack, int *sp,
                         tr_wray *r, const tr_hitrec *h, uint64_t ray, double p0)
{
    double p = r->pol.jss + r->pol.jpp, q[3];
    if (h->far) v_set(q, h->q);
    else for (int i = 0; i < 3; i++) q[i] = r->o[i] + h->t * r->d[i];
    if (!(isfinite(q[0]) && isfinite(q[1]) && isfinite(q[2]) && isfinite(h->n[0]))) {
        ray_failed(ty, TR_FAIL_POINT, h->surf, p);
        return 0;
    }
    const tr_surf *f = w->sc->surf[h->surf];
    ty->segments++;
    r->len += h->t;
    r->opl += r->n * h->t;
    switch (f->mat.kind) {
    case TRACE_ABSORB:                  /* (what the medium took is absorbed too) */
        ty->absorbed += p;
        tr_emit_segment(w, out, r, ray, q, TRACE_END_ABSORB, h->surf);
        return 0;
    case TRACE_DETECT: {
        double s[3];
        s_vector(r, h->n, s);
        tr_pol_rotate(&r->pol, r->d, s);
        tr_emit_segment(w, out, r, ray, q, TRACE_END_DETECT, h->surf);
        if (r->alpha > 0) p -= absorb_along(ty, r, h->t);
        ty->detected += p;
        ty->hits++;
        tr_emit_hit(w, out, r, ray, h, q);
        return 0;
    }
    default:
        tr_emit_segment(w, out, r, ray, q, TRACE_END_NONE, h->surf);
        if (r->alpha > 0) absorb_along(ty, r, h->t);
        v_set(r->o, q);
        return interact(w, ty, stack, sp, r, h, f, p0);
    }
}

/* The rest of a ray's tree from *r (live: *r itself goes on; else the stack). */
void tr_trace_rest(tr_worker *w, tr_out *out, tr_tally *ty, tr_wray *stack, int sp,
                       tr_wray *rp, int live, uint64_t ray, double p0)
{
    const trace_scene *sc = w->sc;
    const trace_options *o = w->o;
    tr_wray r = *rp;
    for (;;) {
        if (!live) {
            if (sp == 0) break;
            r = stack[--sp];
            if (__builtin_expect(w->pol != NULL, 0)) tr_polar_pop(w, sp);   /* its P */
        }
        double p = r.pol.jss + r.pol.jpp, q[3];
        tr_hitrec h;
        if (r.depth > ty->max_depth) ty->max_depth = r.depth;
        if (!(isfinite(r.d[0]) && isfinite(r.d[1]) && isfinite(r.d[2]) && isfinite(p))) {
            ray_failed(ty, isfinite(p) ? TR_FAIL_DIR : TR_FAIL_POWER, r.last_surf, p);
            live = 0;                   /* never handed to Embree */
            continue;
        }
        if (r.depth >= o->max_depth) { ty->cutoff += p; ty->cut_depth++; live = 0; continue; }
        if (!tr_find_hit(sc, o, r.o, r.d, r.last_surf, r.last_prim, r.hist, &h)) {
            for (int i = 0; i < 3; i++) q[i] = r.o[i] + o->escape_length * r.d[i];
            ty->segments++;
            ty->escaped += p;
            tr_emit_segment(w, out, &r, ray, q, TRACE_END_ESCAPE, -1);
            live = 0;
            continue;
        }
        if (__builtin_expect(w->pol != NULL, 0)) {   /* polarization: tr_polar.c */
            /* (on copies: the addresses of r, h and sp never leave this loop, so they
             * stay in registers for the unpolarized trace) */
            tr_wray pr = r;
            tr_hitrec ph = h;
            int psp = sp;
            live = tr_polar_on_hit(w, out, ty, stack, &psp, &pr, &ph, ray, p0);
            r = pr;
            sp = psp;
        } else {
            live = on_hit(w, out, ty, stack, &sp, &r, &h, ray, p0);
        }
    }
}

void tr_trace_one(tr_worker *w, const tr_ray0 *r0, uint64_t ray, tr_tally *ty)
{
    tr_wray r;
    double p0;
    tr_ray_start(&r, r0, ty, &p0);
    tr_trace_rest(w, &w->out, ty, w->stack, 0, &r, 1, ray, p0);
}

void tr_trace_batch_rays(tr_worker *w)
{
    int k = 0;
    for (uint64_t i = 0; i < w->count; i++) {
        tr_ray0 r;
        tr_scene_ray(w->sc, &k, w->first + i, &r);
        tr_trace_one(w, &r, w->first + i, &w->tally[0]);
        tr_fold(w, i, &w->tally[0]);
    }
}

/* A traced ray's tally (ray i of the batch) into the batch's powers and counts. */
void tr_fold(tr_worker *w, uint64_t i, const tr_tally *t)
{
    trace_summary *s = w->counts;
    tr_power *pw = &w->power[i];
    pw->emitted = t->emitted;
    pw->detected = t->detected;
    pw->absorbed = t->absorbed;
    pw->escaped = t->escaped;
    pw->cutoff = t->cutoff;
    s->rays++;
    s->segments += t->segments;
    s->interactions += t->interactions;
    s->tir += t->tir;
    s->hits += t->hits;
    s->cut_depth += t->cut_depth;
    s->cut_power += t->cut_power;
    s->cut_reflection += t->cut_reflection;
    s->medium_mismatch += t->mismatch;
    s->failures += t->failures;
    if (t->failures && !w->fail.cause)
        w->fail = (tr_failure){w->first + i, t->fail_cause, t->fail_surf};
    if (t->max_depth > s->max_depth_seen) s->max_depth_seen = t->max_depth;
}

/* Source ray number g (the source index *k moves forward only). */
void tr_scene_ray(const trace_scene *sc, int *k, uint64_t g, tr_ray0 *r)
{
    while (*k + 1 < sc->nsrc && sc->src[*k + 1].first <= g) (*k)++;
    while (sc->src[*k].first + (uint64_t)sc->src[*k].nrays <= g) (*k)++;
    tr_source_ray(&sc->src[*k], (long)(g - sc->src[*k].first), r);
}

