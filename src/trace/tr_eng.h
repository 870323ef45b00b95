/* tr_eng.h -- private to the engine's core files: the scene as the trace loop sees it
 * (tr_scene.c builds it on Embree, tr_hit.c answers "which surface next"), a ray's
 * working state and books (tr_trace.c, the recursive trace loop), the lanes of the
 * packet path (tr_lanes.c) and the worker the thread pool hands batches to
 * (tr_pool.c).  The exported table is in tr_engine.c. */
#ifndef TR_ENG_H
#define TR_ENG_H
#include <embree3/rtcore.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "tr_int.h"
#include "tr_packet.h"

#pragma GCC visibility push(hidden)

typedef struct tr_surf {
    int id, is_mesh;
    trace_material mat;
    double alpha_front, alpha_back;   /* absorption of its media (set_absorption) */
    tr_shape shape;            /* analytic surface, or a mesh's underlying one */
    int has_under, refine;
    double *vtx;               /* mesh: nv*3 */
    int shared;                /* mesh: vtx and idx are the caller's (trace_mesh.shared):
                                  not freed here */
    uint32_t *idx;             /* mesh: ntri*3 */
    double *media;             /* mesh: ntri*2 or NULL */
    long nv, ntri;
    double eps;                /* mesh: plane distances below this are "here" */
    int closed;                /* mesh: closed and consistently wound, its normals
                                  outward (1) or inward (-1); 0: not known closed */
    uint32_t *weld;            /* mesh: nv, the first vertex at each one's coordinates */
    uint32_t *vt_start, *vt_tri;   /* mesh: the triangles around each welded vertex
                                  (tr_wt.c): vt_tri[vt_start[w] .. vt_start[w + 1]) */
    uint32_t *perm;            /* mesh in chunks (tr_meshbvh.c): the triangles in
                                  their spatial order, chunk after chunk; NULL: one BVH */
    int ch0;                   /* ... the Embree instance ID of its first chunk */
    int seq[4], nseq;          /* lens: the only surfaces a forward ray can meet next */
    const tr_shape *seqg[4];   /* ... and their shapes */
    tr_pk_set pk;              /* ... laid out for the packet */
    double pad;                /* analytic: its Embree box grows by this; mesh: its
                                  margin (each triangle grows by 2 pad, hits within
                                  2 pad of an edge are decided in double) (tr_build) */
    const double *eoff;        /* ... and moves by minus the scene's eoff */
    int group, gprev, gnext;   /* analytic surfaces at the same place (the same shape,
                                  position, axis and aperture): the group's first
                                  member, the members before and after it in the
                                  order they were added; -1: none (tr_build) */
} tr_surf;

/* Embree sees coordinates in single precision: surfaces reaching beyond TR_EMBREE_MAX
 * (or unbounded) stay out of its BVH and are tested in double on every query, and
 * Embree's rays start where they enter the box of what it holds (see nearest()). */
#define TR_EMBREE_MAX 1e15
/* A scene with meshes and at most this many analytic surfaces (in range, none
 * coincident) asks those in double before each Embree query instead of holding them
 * as user geometry: Embree's traversal of a second BVH and its callback per query
 * cost more than the test (a detector plane: a few ns). */
#define TR_INLINE_MAX 4

struct trace_scene {
    char err[512];
    tr_surf **surf;
    int nsurf, capsurf;
    tr_source *src;
    int nsrc, capsrc;
    uint64_t nrays;
    RTCDevice dev;
    RTCScene scn;
    int built;
    double build_ms;
    int *far, nfar;            /* surfaces outside Embree's range, tested in double */
    int inl[TR_INLINE_MAX], ninline;   /* a mesh scene's few analytic surfaces, asked
                                  in double before Embree, not as its user geometry
                                  (tr_build, tr_hit.c) */
    int nembree;               /* surfaces Embree holds */
    long chunk;                /* a mesh of more triangles than this goes to Embree in
                                  chunks of this many (tr_meshbvh.c); 0: never */
    int *ch_surf, nch;         /* each chunk's mesh; chunk k is Embree instance
                                  ch_base + k */
    int ch_base;
    int ngroup;                /* surfaces in a group of coincident ones */
    int nclosed;               /* closed meshes */
    double elo[3], ehi[3];     /* ... their box, grown by epad */
    double nlo[3], nhi[3];     /* ... grown by its diagonal: a ray starting in there
                                  hands Embree its own origin */
    double epad;               /* how far a float ray may stray from the double one */
    double emag;               /* the largest coordinate Embree holds (less eoff) */
    double slo[3], shi[3];     /* where rays may start: sources, and surfaces that
                                  pass rays on (not detectors, absorbers); sglobal:
                                  anywhere in the n box (a far surface or source) */
    int sglobal;
    int wt_all;                /* LENSMAT_TRACE_EXACT: every mesh hit by tr_wt_ring */
    double eoff[3];            /* Embree's coordinates are the world's minus this (the
                                  centre of its box): a scene far from the origin keeps
                                  single precision's digits for its own size */
    int seq_nsurf;             /* the lens hints hold while nsurf == seq_nsurf */
    int absorbing;             /* some medium absorbs: the packet path is not taken
                                  (it does not apply Beer-Lambert; see tr_pool.c) */
    int entry[4], nentry;      /* lens: what a forward ray from left of it meets first */
    const tr_shape *entryg[4];
    tr_pk_set entry_pk;
    double entry_z;            /* ... if it starts at z < entry_z */
    double entry_zmin;         /* ... and z > entry_zmin (what lies left of the lens:
                                  -inf for none, tr_seqscan.c) */
    struct tr_polar *polar;    /* polarization ray tracing (tr_polar.c); NULL: off */
};

/* tr_wt.c: adjacency and the watertight test in double (see there). */
int    tr_wt_adjacency(tr_surf *f);
int    tr_wt_hit(const tr_surf *f, long prim, const double o[3], const double d[3],
                 double *t);
double tr_wt_margin(const tr_surf *f, long prim, double pad);
#define TR_WT_KMAX 0.1
/* Is barycentric distance m from an edge within tr_wt_margin(f, prim, pad)?  The same
 * test without its square root or division (every mesh hit asks it). */
static inline int tr_wt_near(const tr_surf *f, long prim, double m, double pad)
{
    const uint32_t *ix = f->idx + 3 * prim;
    const double *a = f->vtx + 3 * ix[0], *b = f->vtx + 3 * ix[1], *c = f->vtx + 3 * ix[2];
    double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    double e3[3] = {c[0] - b[0], c[1] - b[1], c[2] - b[2]}, n[3];
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    double l2 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
    double l = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
    if (l > l2) l2 = l;
    l = e3[0] * e3[0] + e3[1] * e3[1] + e3[2] * e3[2];
    if (l > l2) l2 = l;
    double n2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2], k = 3 * pad;
    /* m < min(KMAX, 3 pad lmax / |n|)  <=>  m < KMAX and m^2 |n|^2 < (3 pad)^2 lmax^2 */
    return m < TR_WT_KMAX && m * m * n2 < k * k * l2;
}
int    tr_wt_ring(const tr_surf *f, long prim, const double o[3], const double d[3],
                  long skip, double tmin, long *best, double *t, uint32_t *ex, int *nex,
                  int cap);

typedef struct tr_hitrec {
    int surf;
    long prim;
    double t, n[3];                  /* n: unit normal pointing into the front side */
    int far;                         /* 1: the hit point is q (a far start), else o + t d */
    double q[3];
} tr_hitrec;

static inline double tr_now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

typedef struct tr_tally {
    double emitted, detected, absorbed, escaped, cutoff;
    uint32_t segments, interactions, tir, hits, cut_depth, cut_power, cut_reflection,
             mismatch, failures;
    int max_depth;
    int fail_cause, fail_surf;   /* the ray's first numerical failure (TR_FAIL_*) */
} tr_tally;

/* Why a ray failed numerically (every failure makes the run an error, see tr_pool.c). */
enum { TR_FAIL_NONE, TR_FAIL_POINT, TR_FAIL_DIR, TR_FAIL_POWER };

/* The first failure of a batch, of a run: which ray, why, where. */
typedef struct tr_failure {
    uint64_t ray;
    int cause, surf;
} tr_failure;

/* The powers of one ray's tally: summed ray by ray, in ray order, so that the sums
 * keep their bits whatever the thread count (the counts are summed in any order). */
typedef struct tr_power {
    double emitted, detected, absorbed, escaped, cutoff;
} tr_power;

typedef struct tr_wray {
    double o[3], d[3];
    double n, len, opl;
    tr_pol pol;
    int depth, last_surf;
    long last_prim;
    uint32_t hist;
    double lambda;               /* the source's wavelength, into every record */
    double alpha;                /* absorption of the medium it travels in (0: none) */
} tr_wray;

typedef struct tr_buf {
    void *p;
    size_t n, cap, size;
} tr_buf;

/* Room for one more record at the end of b (NULL: out of memory). */
static inline void *buf_slot(tr_buf *b)
{
    if (b->n == b->cap) {
        size_t cap = b->cap ? 2 * b->cap : 1024;
        void *p = realloc(b->p, cap * b->size);
        if (!p) return NULL;
        b->p = p;
        b->cap = cap;
    }
    return (char *)b->p + b->n++ * b->size;
}

/* Append all of a's records to b and empty a. */
static inline int buf_move(tr_buf *b, tr_buf *a)
{
    if (a->n == 0) return 0;
    if (b->n + a->n > b->cap) {
        size_t cap = b->cap ? b->cap : 1024;
        while (cap < b->n + a->n) cap *= 2;
        void *p = realloc(b->p, cap * b->size);
        if (!p) return -1;
        b->p = p;
        b->cap = cap;
    }
    memcpy((char *)b->p + b->n * b->size, a->p, a->n * a->size);
    b->n += a->n;
    a->n = 0;
    return 0;
}

/* Where a ray's records go: the worker's buffers, or a lane's until its turn. */
typedef struct tr_out {
    tr_buf seg, hit;
    tr_buf pol;                  /* polarization runs: a trace_polar_hit per hit */
} tr_out;

/* Rays traced side by side on the lens shortcut (tr_packet.c): TR_PK rays' arithmetic
 * in vector registers, one step at a time. */
#define TR_LANES TR_PK

typedef struct tr_lane {
    tr_wray r;                   /* its doubles live in the packet while it runs */
    tr_tally *ty;
    uint64_t ray;
    double p0;
    int sp, live;
    int state;                   /* LANE_RUN, LANE_DONE, LANE_SLOW */
    tr_wray *stack;
    tr_out out;
} tr_lane;
enum { LANE_RUN, LANE_DONE, LANE_SLOW };

typedef struct tr_worker {
    const trace_scene *sc;
    const trace_options *o;
    uint64_t first, count;       /* the batch in hand: global ray numbers */
    tr_tally tally[TR_LANES];    /* the rays in hand (trace_lanes: one per lane) */
    tr_power *power;             /* the batch's powers, one per ray (its slot's) */
    trace_summary *counts;       /* the batch's counts (its slot's) */
    int want_seg, want_hit;
    tr_failure fail;             /* the batch's first failure (cause 0: none) */
    tr_out out;
    tr_wray *stack;
    tr_lane lane[TR_LANES];
    int nomem;
    struct tr_polw *pol;         /* polarization runs: P per ray (tr_polar.c), else NULL */
} tr_worker;

/* ---- the scene (tr_scene.c) ---- */
trace_scene *tr_scene_new(void);
void tr_scene_free(trace_scene *sc);
const char *tr_scene_error(const trace_scene *sc);
int tr_add_surface(trace_scene *sc, const trace_surface *s, const trace_material *m);
int tr_add_mesh(trace_scene *sc, const trace_mesh *mesh, const trace_material *m);
int tr_add_source(trace_scene *sc, const trace_source *s, uint64_t *first);
int tr_set_absorption(trace_scene *sc, int id, double alpha_front, double alpha_back);
int tr_build(trace_scene *sc, double *ms);
/* ---- a sequential lens inside any scene (tr_seqscan.c): the lens hints ---- */
void tr_seq_detect(trace_scene *sc);
/* ---- a mesh's Embree geometry (tr_meshbvh.c) ---- */
#define TR_CHUNK_TRI 131072
int tr_mesh_attach(trace_scene *sc, tr_surf *f);
/* The mesh triangle behind Embree's primID in the instance instID (a chunk), or in
 * the mesh itself (instID invalid). */
static inline long tr_mesh_prim(const trace_scene *sc, unsigned inst, unsigned prim)
{
    if (inst == RTC_INVALID_GEOMETRY_ID) return prim;
    const tr_surf *f = sc->surf[sc->ch_surf[inst - (unsigned)sc->ch_base]];
    return f->perm[(size_t)(inst - (unsigned)f->ch0) * (size_t)sc->chunk + prim];
}
/* ---- the next hit (tr_hit.c) ---- */
/* Embree's callbacks (tr_build attaches them). */
void tr_user_intersect(const struct RTCIntersectFunctionNArguments *a);
void tr_user_occluded(const struct RTCOccludedFunctionNArguments *a);
void tr_mesh_filter(const struct RTCFilterFunctionNArguments *a);
/* The next surface a ray meets: the lens shortcut (the same hits, bit for bit), else
 * Embree; 0 if none. */
int tr_find_hit(const trace_scene *sc, const trace_options *o, const double org[3],
                const double d[3], int last, long last_prim, uint32_t hist,
                tr_hitrec *h);

/* ---- the trace loop (tr_trace.c) ---- */
void tr_emit_segment(tr_worker *w, tr_out *out, const tr_wray *r, uint64_t ray,
                     const double p1[3], int end, int surf);
void tr_emit_hit(tr_worker *w, tr_out *out, const tr_wray *r, uint64_t ray,
                 const tr_hitrec *h, const double p[3]);
int tr_strong(const tr_worker *w, tr_tally *ty, double p, double p0);
void tr_keep(tr_worker *w, tr_tally *ty, int *sp, const tr_wray *c, double p0);
void tr_ray_start(tr_wray *r, const tr_ray0 *r0, tr_tally *ty, double *p0);
void tr_trace_rest(tr_worker *w, tr_out *out, tr_tally *ty, tr_wray *stack, int sp,
                   tr_wray *rp, int live, uint64_t ray, double p0);
void tr_trace_one(tr_worker *w, const tr_ray0 *r0, uint64_t ray, tr_tally *ty);
/* A whole batch ray by ray (the general path: every medium, absorption included). */
void tr_trace_batch_rays(tr_worker *w);
void tr_fold(tr_worker *w, uint64_t i, const tr_tally *t);
void tr_scene_ray(const trace_scene *sc, int *k, uint64_t g, tr_ray0 *r);

/* ---- polarization ray tracing (tr_polar.c) ---- */
void tr_polar_batch(tr_worker *w);      /* a batch ray by ray, P per ray */
/* tr_trace_rest's steps when w->pol is set: a hit (instead of its on_hit), and the
 * waiting ray taken off stack slot sp.  Never inlined: the unpolarized loop keeps the
 * code (and the inlining of tr_find_hit) it had. */
__attribute__((noinline))
int tr_polar_on_hit(tr_worker *w, tr_out *out, tr_tally *ty, tr_wray *stack, int *sp,
                    tr_wray *r, const tr_hitrec *h, uint64_t ray, double p0);
__attribute__((noinline)) void tr_polar_pop(tr_worker *w, int sp);
void tr_polar_free(struct tr_polar *p);
int tr_polarization(trace_scene *sc, int on, const double xref[3],
                    int (*cb)(void *ctx, const trace_polar_hit *ph), void *ctx);
/* The record sink polarization() was given (NULL: none). */
int tr_polar_deliver(const trace_scene *sc, const trace_polar_hit *ph);
int tr_set_polar(trace_scene *sc, int id, const trace_polar_surface *ps);
int tr_prt_interface(const double k_in[3], const double nrm[3], double n1, double n2,
                     const trace_polar_surface *ps, double lambda, int reflect,
                     double P[3][3][2], double k_out[3]);

/* ---- the packet orchestration (tr_lanes.c) ---- */
void tr_trace_batch(tr_worker *w);

/* ---- the run (tr_pool.c) ---- */
void tr_options_default(trace_options *o);
int tr_run(trace_scene *sc, const trace_options *oin, const trace_sink *sink,
           trace_summary *sum);
int tr_run_batches(trace_scene *sc, const trace_options *oin, const trace_batch_sink *sink,
                   trace_summary *sum);

#pragma GCC visibility pop
#endif
