/* tr_packet.h -- private to the trace engine: eight rays side by side through the
 * surfaces a sequential lens names (the candidate sets: tr_packet.c; the step:
 * tr_pk_kernel.h, one source built per instruction set; the choice: tr_isa.c), in
 * vector arithmetic that rounds
 * exactly as the one-ray code does (tr_geom.c's fast shapes, tr_optics.c's Fresnel,
 * tr_trace.c's interaction): the same operations in the same order, where a branch
 * becomes a select.  The engine keeps the books (counts, records, stacks); a ray the
 * packet cannot take one step further is handed back to the one-ray code unchanged. */
#ifndef TR_PACKET_H
#define TR_PACKET_H
#include "tr_int.h"

#pragma GCC visibility push(hidden)

/* Lanes: eight rays in hand, the widest packet (one AVX-512 register of doubles).
 * A narrower instruction set steps them in chunks of its own width (four with AVX2,
 * two with SSE2 or NEON), lane by lane the same arithmetic, so the same bits. */
#define TR_PK 8

/* The double part of the rays' states (lane l is element l of every member),
 * aligned for the widest vector loads. */
typedef struct tr_pk {
    double o[3][TR_PK], d[3][TR_PK];
    double n[TR_PK], len[TR_PK], opl[TR_PK];
    double e[3][TR_PK], jss[TR_PK], jpp[TR_PK], jre[TR_PK], jim[TR_PK];   /* tr_pol */
    double p0[TR_PK];                 /* the source ray's power */
    /* the ray's books since it started, kept here while it runs in the packet */
    double cut[TR_PK];                /* reflected power cut off (reflections off) */
    long long depth[TR_PK], maxd[TR_PK];   /* interactions; the deepest step start */
    long long nseg[TR_PK], nint[TR_PK], nmis[TR_PK], ncutr[TR_PK];
                                      /* segments, interactions, index mismatches,
                                         reflections cut */
} __attribute__((aligned(64))) tr_pk;

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
    long long status[TR_PK], cand[TR_PK];   /* TR_PK_*; the candidate index */
    long long mismatch[TR_PK];        /* REFRACT: the ray's index was not n1 (-1) */
    double t[TR_PK];                  /* distance to the hit */
    double p[TR_PK];                  /* power arriving (jss + jpp before the step) */
    double nrm[3][TR_PK];             /* front unit normal at the hit */
    double jss[TR_PK], jpp[TR_PK], jre[TR_PK], jim[TR_PK];
                                      /* REFRACT: the state in the s/p basis, before T */
    double Rs[TR_PK], Rp[TR_PK], rsp[TR_PK];  /* REFRACT with Fresnel: reflection
                                                 coefficients */
    double rd[3][TR_PK], n1[TR_PK];   /* REFRACT with reflections: reflected direction,
                                         its medium */
} __attribute__((aligned(64))) tr_pk_aux;

/* One step of the lanes in mask `live` (bit l: lane l) against the candidates of s
 * (nc > 0): the depth limit and direction checks of the one-ray code, the nearest hit
 * in double (the first candidate at a tie), its normal, and for REFRACT lanes the
 * rotation into the s/p basis, Fresnel coefficients (applied to the powers if
 * fresnel), the reflected direction (if reflections), the refracted ray and its books
 * (counts, reflected power cut off).  Returns the lanes that refracted and keep enough
 * power to go on; the others' books are the caller's.  in and out must not overlap.
 * Runs the kernel of the instruction set chosen at load (tr_isa.c). */
unsigned tr_pk_step(const tr_pk *in, tr_pk *out, tr_pk_aux *x, const tr_pk_set *s,
                    unsigned live, const tr_pk_opt *o);

/* The same step, one kernel (tr_pk_kernel.h) compiled per instruction set
 * (tr_pk_avx512.c, tr_pk_avx2.c, tr_pk_base.c: SSE2 on x86-64, NEON on arm64). */
typedef unsigned (*tr_pk_step_fn)(const tr_pk *in, tr_pk *out, tr_pk_aux *x,
                                  const tr_pk_set *s, unsigned live, const tr_pk_opt *o);
unsigned tr_pk_step_avx512(const tr_pk *, tr_pk *, tr_pk_aux *, const tr_pk_set *,
                           unsigned, const tr_pk_opt *);
unsigned tr_pk_step_avx2(const tr_pk *, tr_pk *, tr_pk_aux *, const tr_pk_set *,
                         unsigned, const tr_pk_opt *);
unsigned tr_pk_step_base(const tr_pk *, tr_pk *, tr_pk_aux *, const tr_pk_set *,
                         unsigned, const tr_pk_opt *);
unsigned tr_pk_step_base4(const tr_pk *, tr_pk *, tr_pk_aux *, const tr_pk_set *,
                          unsigned, const tr_pk_opt *);   /* tr_pk_sse2x4.c: 4 lanes */

/* 1 if the packets run in this process (0: LENSMAT_ISA=scalar, rays one by one). */
int tr_pk_usable(void);

#pragma GCC visibility pop
#endif
