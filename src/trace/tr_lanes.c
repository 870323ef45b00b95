/* tr_lanes.c -- the packet orchestration: eight rays at a time through a sequential
 * lens on the packet step (tr_pk_kernel.h), each lane's books and records kept as the
 * one-ray code (tr_trace.c) would keep them, a lane that leaves the shortcut finished
 * by the one-ray code; and the choice, per batch, between packets and rays one by one
 * (the same bits either way; with LENSMAT_ISA=scalar always one by one). */
#include <math.h>
#include "tr_eng.h"

/* Lane l of a packet from a starting ray (its books are empty), and a ray's doubles
 * back from lane l. */
static void pk_put(tr_pk *p, int l, const tr_wray *r, double p0)
{
    for (int i = 0; i < 3; i++) {
        p->o[i][l] = r->o[i];
        p->d[i][l] = r->d[i];
        p->e[i][l] = r->pol.e[i];
    }
    p->n[l] = r->n;
    p->len[l] = r->len;
    p->opl[l] = r->opl;
    p->jss[l] = r->pol.jss;
    p->jpp[l] = r->pol.jpp;
    p->jre[l] = r->pol.jre;
    p->jim[l] = r->pol.jim;
    p->p0[l] = p0;
    p->cut[l] = 0;
    p->depth[l] = p->maxd[l] = r->depth;
    p->nseg[l] = p->nint[l] = p->nmis[l] = p->ncutr[l] = 0;
}

static void pk_get(const tr_pk *p, int l, tr_wray *r)
{
    for (int i = 0; i < 3; i++) {
        r->o[i] = p->o[i][l];
        r->d[i] = p->d[i][l];
        r->pol.e[i] = p->e[i][l];
    }
    r->n = p->n[l];
    r->len = p->len[l];
    r->opl = p->opl[l];
    r->pol.jss = p->jss[l];
    r->pol.jpp = p->jpp[l];
    r->pol.jre = p->jre[l];
    r->pol.jim = p->jim[l];
    r->depth = (int)p->depth[l];
}

/* The ray of lane l as packet p holds it, having left surface `last`. */
static tr_wray *lane_ray(const tr_lane *L, const tr_pk *p, int l, int last, tr_wray *r)
{
    *r = L->r;
    pk_get(p, l, r);
    r->last_surf = last;
    r->last_prim = -1;
    return r;
}

/* The books lane l kept in packet p go back to its tally (they were empty when it
 * entered the packet, so the sums are exact). */
static void lane_tally(tr_lane *L, const tr_pk *p, int l)
{
    tr_tally *ty = L->ty;
    if (p->maxd[l] > ty->max_depth) ty->max_depth = (int)p->maxd[l];
    ty->segments += (uint32_t)p->nseg[l];
    ty->interactions += (uint32_t)p->nint[l];
    ty->mismatch += (uint32_t)p->nmis[l];
    ty->cut_reflection += (uint32_t)p->ncutr[l];
    ty->cutoff += p->cut[l];
}

/* Lane l leaves the packet as p holds it (having left surface `last`) to go on alone:
 * its ray and books go back to L. */
static void lane_leave(tr_lane *L, const tr_pk *p, int l, int last)
{
    lane_ray(L, p, l, last, &L->r);
    lane_tally(L, p, l);
}

/* Lane l is finished here (the one-ray code takes its reflected rays, if any). */
static void lane_end(tr_lane *L)
{
    L->live = 0;
    L->state = L->sp ? LANE_SLOW : LANE_DONE;
}

/* What on_hit and interact record for lane l's step from in (having left `last`) to
 * out, and the books of a lane that stops here.  Returns 1 if it goes on. */
static int lane_books(tr_worker *w, tr_lane *L, int l, const tr_pk *in, const tr_pk *out,
                      const tr_pk_aux *x, const int *id, int last, unsigned calm)
{
    tr_tally *ty = L->ty;
    tr_wray s;
    int surf = id[x->cand[l] & 3], st = (int)x->status[l];
    double q[3] = {out->o[0][l], out->o[1][l], out->o[2][l]}, p = x->p[l];
    if (st == TR_PK_SCALAR) {                 /* the one-ray code takes this step */
        lane_leave(L, in, l, last);
        L->state = LANE_SLOW;
        return 0;
    }
    if (st == TR_PK_ABSORB || st == TR_PK_DETECT) {    /* the ray ends: books only */
        lane_tally(L, out, l);
        ty->segments++;
        if (w->want_seg || w->want_hit) {
            lane_ray(L, st == TR_PK_ABSORB ? in : out, l, last, &s);
            v_set(s.o, (double[3]){in->o[0][l], in->o[1][l], in->o[2][l]});
        }
        if (st == TR_PK_ABSORB) {
            ty->absorbed += p;
            tr_emit_segment(w, &L->out, &s, L->ray, q, TRACE_END_ABSORB, surf);
        } else {
            tr_hitrec h = {surf, -1, x->t[l], {x->nrm[0][l], x->nrm[1][l], x->nrm[2][l]},
                           0, {0, 0, 0}};
            ty->detected += p;
            ty->hits++;
            tr_emit_segment(w, &L->out, &s, L->ray, q, TRACE_END_DETECT, surf);
            tr_emit_hit(w, &L->out, &s, L->ray, &h, q);
        }
        lane_end(L);
        return 0;
    }
    if (w->want_seg)                           /* REFRACT */
        tr_emit_segment(w, &L->out, lane_ray(L, in, l, last, &s), L->ray, q, TRACE_END_NONE,
                     surf);
    if (w->o->fresnel && w->o->reflections) {
        tr_wray *c = lane_ray(L, out, l, surf, &L->stack[L->sp]);
        if (c->depth <= 32) c->hist |= 1u << (c->depth - 1);
        for (int i = 0; i < 3; i++) c->d[i] = x->rd[i][l];
        c->n = x->n1[l];
        c->pol.jss = x->Rs[l] * x->jss[l];
        c->pol.jpp = x->Rp[l] * x->jpp[l];
        c->pol.jre = x->rsp[l] * x->jre[l];
        c->pol.jim = x->rsp[l] * x->jim[l];
        tr_keep(w, ty, &L->sp, c, L->p0);
    }
    if (calm & (1u << l)) return 1;
    lane_leave(L, out, l, surf);              /* too weak to go on */
    tr_strong(w, ty, out->jss[l] + out->jpp[l], L->p0);
    lane_end(L);
    return 0;
}

/* buf_move for a lane's hits, out of line (the lanes loop copies a lane's one hit
 * itself: below). */
static __attribute__((noinline)) int hits_move(tr_buf *b, tr_buf *a)
{
    return buf_move(b, a);
}

/* Rays i0 .. i0+TR_LANES-1 of the worker side by side while each stays on the lens
 * shortcut, step by step in a packet (tr_pk_kernel.h); a lane that leaves it (no
 * candidate hit, depth limit, a ray going back, TIR, reflections waiting) is finished
 * alone afterwards by trace_rest from where it left.  Every lane computes exactly what
 * trace_one would; its records wait in the lane's buffers and are passed on in ray
 * order. */
static void tr_trace_lanes(tr_worker *w, uint64_t i0, int *k)
{
    const trace_scene *sc = w->sc;
    const trace_options *o = w->o;
    int cur = 0, last = -1, each = w->want_seg || o->reflections;
    unsigned run = (1u << TR_LANES) - 1;
    tr_ray0 r0[TR_LANES];
    tr_pk pk[2];
    tr_pk_aux x;
    tr_pk_opt po = {o->fresnel, o->reflections, o->max_depth, 1, o->cutoff, sc->entry_z};
    uint64_t g = w->first + i0;
    tr_scene_ray(sc, k, g, &r0[0]);             /* moves *k to the first ray's source */
    const tr_source *src = &sc->src[*k];
    if (g + TR_LANES <= src->first + (uint64_t)src->nrays)
        tr_source_rays(src, (long)(g - src->first), TR_LANES, r0);
    else
        for (int l = 1; l < TR_LANES; l++) tr_scene_ray(sc, k, g + (uint64_t)l, &r0[l]);
    for (int l = 0; l < TR_LANES; l++) {
        tr_lane *L = &w->lane[l];
        L->ray = g + (uint64_t)l;
        L->ty = &w->tally[l];
        tr_ray_start(&L->r, &r0[l], L->ty, &L->p0);
        pk_put(&pk[0], l, &L->r, L->p0);
        L->sp = 0;
        L->live = 1;
        L->state = LANE_RUN;
        if (!(L->r.o[2] > sc->entry_zmin)) {     /* something lies between it and the */
            run &= ~(1u << l);                   /* lens: Embree from its start */
            L->state = LANE_SLOW;
        }
    }
    while (run) {
        const tr_pk *in = &pk[cur];
        tr_pk *out = &pk[cur ^ 1];
        const tr_pk_set *set = last >= 0 ? &sc->surf[last]->pk : &sc->entry_pk;
        if (set->nc <= 0) break;
        po.entry = last < 0;
        unsigned calm = tr_pk_step(in, out, &x, set, run, &po);
        unsigned next = calm;
        for (int l = 0; l < TR_LANES; l++)
            if ((run & (1u << l)) && (each || !(calm & (1u << l))) &&
                !lane_books(w, &w->lane[l], l, in, out, &x, set->id, last, calm))
                next &= ~(1u << l);
        last = -1;
        for (int l = 0; l < TR_LANES; l++) {     /* all on from the same surface */
            if (!(next & (1u << l))) continue;
            int surf = set->id[x.cand[l] & 3];
            if (last < 0) last = surf;
            if (surf == last) continue;
            lane_leave(&w->lane[l], out, l, surf);
            w->lane[l].state = LANE_SLOW;
            next &= ~(1u << l);
        }
        run = next;
        cur ^= 1;
    }
    for (int l = 0; l < TR_LANES; l++) {
        tr_lane *L = &w->lane[l];
        if (run & (1u << l)) {                   /* stopped by a surface not for packets */
            lane_leave(L, &pk[cur], l, last);
            L->state = LANE_SLOW;
        }
        if (buf_move(&w->out.seg, &L->out.seg)) w->nomem = 1;
        if (L->out.hit.n == 1 && w->out.hit.n < w->out.hit.cap) {
            /* mostly the lane's one hit at the detector: a copy of known size (padding
             * too), not memcpy's variable-length call */
            trace_hit *to = (trace_hit *)w->out.hit.p + w->out.hit.n++;
            memcpy(to, L->out.hit.p, sizeof(trace_hit));
            L->out.hit.n = 0;
        } else if (L->out.hit.n && hits_move(&w->out.hit, &L->out.hit)) {
            w->nomem = 1;
        }
        if (L->state == LANE_SLOW)
            tr_trace_rest(w, &w->out, L->ty, L->stack, L->sp, &L->r, L->live, L->ray, L->p0);
        tr_fold(w, i0 + (uint64_t)l, L->ty);
    }
}

/* Trace the worker's batch: rays first .. first+count-1, records to w->out in ray
 * order, the powers of each ray to w->power and the counts to w->counts. */
void tr_trace_batch(tr_worker *w)
{
    const trace_scene *sc = w->sc;
    const trace_options *o = w->o;
    int k = 0;
    uint64_t i = 0;
    if (o->sequential && !o->float_hits && sc->seq_nsurf == sc->nsurf && sc->nentry > 0 &&
        tr_pk_usable())
        for (; i + TR_LANES <= w->count; i += TR_LANES) tr_trace_lanes(w, i, &k);
    for (; i < w->count; i++) {
        tr_ray0 r;
        tr_scene_ray(sc, &k, w->first + i, &r);
        tr_trace_one(w, &r, w->first + i, &w->tally[0]);
        tr_fold(w, i, &w->tally[0]);
    }
}
