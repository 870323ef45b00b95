/* tr_packet.c -- the packet's candidate sets (see tr_packet.h): the surfaces a ray
 * may meet after one surface of a sequential lens, their figures laid out for the
 * packet step (tr_pk_kernel.h) to pick a lane's own.  Built with the scene. */
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
