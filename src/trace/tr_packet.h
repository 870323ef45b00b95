/* tr_packet.h -- private to the trace engine: eight rays side by side through the
 * surfaces a sequential lens names (tr_packet.c), in vector arithmetic that rounds
 * exactly as the one-ray code does (tr_geom.c's fast shapes, tr_optics.c's Fresnel,
 * tr_trace.c's interaction): the same operations in the same order, where a branch
 * becomes a select.  The engine keeps the books (counts, records, stacks); a ray the
 * packet cannot take one step further is handed back to the one-ray code unchanged. */
#ifndef TR_PACKET_H
#define TR_PACKET_H
#include "tr_int.h"

#pragma GCC visibility push(hidden)

/* GCC notes that wide vectors pass differently with and without AVX; they never
 * cross this module's boundary (tr_pk_step takes pointers), so the note is moot. */
#pragma GCC diagnostic ignored "-Wpsabi"

#define TR_PK 8                  /* lanes: one AVX-512 register of doubles */
typedef double tr_vd __attribute__((vector_size(8 * TR_PK)));
typedef long long tr_vm __attribute__((vector_size(8 * TR_PK)));   /* lane masks */

/* The double part of the rays' states (lane l is element l of every member). */
typedef struct tr_pk {
    tr_vd o[3], d[3];
    tr_vd n, len, opl;
    tr_vd e[3], jss, jpp, jre, jim;   /* tr_pol */
    tr_vd p0;                         /* the source ray's power */
    /* the ray's books since it started, kept here while it runs in the packet */
    tr_vd cut;                        /* reflected power cut off (reflections off) */
    tr_vm depth, maxd;                /* interactions; the deepest step start */
    tr_vm nseg, nint, nmis, ncutr;    /* segments, interactions, index mismatches,
                                         reflections cut */
} tr_pk;

/* The trace options a step needs; entry: the rays come from the source (the first
 * surface's candidates), and must start at z < entry_z. */
typedef struct tr_pk_opt {
    int fresnel, reflections, max_depth, entry;
    double cutoff, entry_z;
} tr_pk_opt;

/* The surfaces the rays may meet after one surface (a lens's hint): only fast shapes
 * (TR_FAST_CONIC, TR_FAST_PLANE).  Their figures are laid out a packet wide, for the
 * packet to pick a lane's own with one shuffle.  Built with the scene. */
typedef struct tr_pk_set {
    int nc;                      /* how many; -1: some candidate is not a fast shape */
    int id[4];                   /* their surface ids */
    const tr_shape *g[4];
    int leaving[4];              /* the rays start on it */
    int farok[4];                /* a ray may start far from it (tr_advance): 0 when
                                    the rays start on a surface too near for that */
    int anyfar;                  /* some farok[] is 1 */
    double c[TR_PK], ck1[TR_PK], cone[TR_PK], kind[TR_PK], nf[TR_PK], nb[TR_PK],
           wn[3][TR_PK],         /* curvature terms, material kind and indices, -w */
           at[3][TR_PK];         /* vertices */
} tr_pk_set;

/* Empty s, then add the candidates in order (surface id, shape g, material m); from:
 * the surface the rays start on (NULL: anywhere, from the sources). */
void tr_pk_set_clear(tr_pk_set *s);
void tr_pk_set_add(tr_pk_set *s, int id, const tr_shape *g, const trace_material *m,
                   int leaving, const tr_shape *from);

/* What happened to each lane in a step. */
enum {
    TR_PK_IDLE,      /* not in the step */
    TR_PK_REFRACT,   /* refracted at a TRACE_REFRACT candidate: out holds the new ray */
    TR_PK_DETECT,    /* ended on a detector: out holds the hit (o = hit point) */
    TR_PK_ABSORB,    /* ended on an absorber: out holds the hit (o = hit point) */
    TR_PK_SCALAR     /* anything else (no hit, TIR, grazing, non-finite, other kinds):
                        the one-ray code takes the step from the lane's input state */
};

/* The rest of a step's results, for the engine's books. */
typedef struct tr_pk_aux {
    tr_vm status, cand;          /* TR_PK_*; the candidate index */
    tr_vm mismatch;              /* REFRACT: the ray's index was not n1 (-1) */
    tr_vd t;                     /* distance to the hit */
    tr_vd p;                     /* power arriving (jss + jpp before the step) */
    tr_vd nrm[3];                /* front unit normal at the hit */
    tr_vd jss, jpp, jre, jim;    /* REFRACT: the state in the s/p basis, before T */
    tr_vd Rs, Rp, rsp;           /* REFRACT with Fresnel: reflection coefficients */
    tr_vd rd[3], n1;             /* REFRACT with reflections: reflected direction, its
                                    medium */
} tr_pk_aux;

/* One step of the lanes in mask `live` (bit l: lane l) against the candidates of s
 * (nc > 0): the depth limit and direction checks of the one-ray code, the nearest hit
 * in double (the first candidate at a tie), its normal, and for REFRACT lanes the
 * rotation into the s/p basis, Fresnel coefficients (applied to the powers if
 * fresnel), the reflected direction (if reflections), the refracted ray and its books
 * (counts, reflected power cut off).  Returns the lanes that refracted and keep enough
 * power to go on; the others' books are the caller's.  in and out must not overlap.
 * Needs AVX-512 (the caller checks). */
unsigned tr_pk_step(const tr_pk *in, tr_pk *out, tr_pk_aux *x, const tr_pk_set *s,
                    unsigned live, const tr_pk_opt *o);

#pragma GCC visibility pop
#endif
