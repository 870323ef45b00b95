/* tr_seqscan.c -- finds a sequential lens inside any scene when it is built, so that a
 * scene file gets the lens shortcut (tr_hit.c) and the packets (tr_lanes.c) that
 * add_lens's lenses get, with the same bits as Embree.  Owns the rule of what counts
 * as a sequential lens and the hints it leaves on the scene; which surface a ray
 * meets next stays tr_hit.c's.
 *
 * The shortcut's promise: a ray going forward (d_z > 0, never reflected) that leaves a
 * lens surface meets, of everything in the scene, first one of the surfaces of its own
 * z slab or of the next slab -- if it meets any of those; else Embree is asked.  That
 * holds when
 *   - the lens's surfaces are analytic, with the fast shapes the packet knows (conics
 *     without aspheric terms and planes, their frame the world's: axis exactly +z),
 *     on one axis line (the same vertex x and y), of the four known kinds;
 *   - their z ranges (the shapes' padded boxes), merged where they overlap, make slabs
 *     with gaps between them, at most four surfaces in two consecutive slabs (a face
 *     and its mount, then the next face and its mount; or the two faces of a
 *     meniscus, which overlap in z, then the next face);
 *   - nothing else in the scene (meshes, spheres, tilted, decentred or aspheric
 *     surfaces, unknown kinds) reaches into the z range of the slabs taken.
 * Ties: Embree's analytic hits go to the lower surface id at an equal distance
 * (tr_hit.c), and the candidates named here are in id order within a slab (ties
 * between slabs cannot happen: they are disjoint), the first taken at a tie.
 * The run of consecutive slabs with the most refracting conics is taken, if it has
 * two at least (else the scene has no lens: every segment goes through Embree), from
 * its first slab with a refracting surface.  A ray from a source meets that slab first
 * if it starts left of it and right of everything else on that side (entry_z,
 * entry_zmin).  Rays going back (d_z <= 0), reflected rays, rays starting inside the
 * lens or left of something before it, and rays that miss the surfaces named are
 * Embree's, as before.  A scene whose hints add_lens set (a lens alone) keeps them;
 * coincident surfaces turn the shortcut off (tr_scene.c).  Cost: a sort of the
 * surfaces per build. */
#include <math.h>
#include <stddef.h>
#include "tr_eng.h"

/* A tripwire: the lens path knows every field of a material.  A new one (an
 * absorption coefficient, a dispersion) must be taught to tr_packet.c and tr_trace.c
 * alike -- or refused here (lens_kind below) -- before this builds again. */
struct tr_seq_known_material { int kind; double n_front, n_back; };
_Static_assert(sizeof(trace_material) == sizeof(struct tr_seq_known_material),
               "trace_material has a new field: teach tr_seqscan.c whether the lens "
               "path (tr_packet.c) handles it, or refuse such surfaces there");

/* ... and every field of a ray's working state.  The packet carries the doubles of
 * the first seven and nothing else: a lane's other fields stay as they were when it
 * started (tr_lanes.c's lane_ray copies them into every record).  So lambda is right
 * (it never changes); alpha, the absorption of the medium, is not updated by the
 * packet at a refraction, which is why a scene with an absorbing medium goes ray by
 * ray (tr_pool.c, sc->absorbing) -- the lens shortcut itself (tr_hit.c: which surface
 * next) is still exact there, Beer-Lambert being applied by the one-ray code. */
struct tr_seq_known_ray {
    double o[3], d[3];
    double n, len, opl;
    tr_pol pol;
    int depth, last_surf;
    long last_prim;
    uint32_t hist;
    double lambda, alpha;
};
_Static_assert(sizeof(tr_wray) == sizeof(struct tr_seq_known_ray),
               "tr_wray has a new field: teach tr_seqscan.c and tr_packet.c about it (or "
               "find no lens in scenes that use it) before the lens path may run");

typedef struct zr {
    double lo, hi;             /* z range, padded */
    int id;
} zr;

static int by_lo(const void *a, const void *b)
{
    const zr *x = a, *y = b;
    if (x->lo != y->lo) return x->lo < y->lo ? -1 : 1;
    return x->id - y->id;
}

static int by_id(const void *a, const void *b)
{
    return *(const int *)a - *(const int *)b;
}

/* The z range of what f can be hit at: an analytic shape's padded box; a mesh's
 * vertices padded as pad_box pads shapes, and by its eps (a refined hit may lie that
 * far off its triangle). */
static void z_range(const tr_surf *f, double *lo, double *hi)
{
    if (!f->is_mesh) {
        *lo = f->shape.lo[2];
        *hi = f->shape.hi[2];
        return;
    }
    double a = INFINITY, b = -INFINITY, m[3] = {INFINITY, INFINITY, INFINITY},
           M[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (long v = 0; v < f->nv; v++)
        for (int j = 0; j < 3; j++) {
            m[j] = fmin(m[j], f->vtx[3 * v + j]);
            M[j] = fmax(M[j], f->vtx[3 * v + j]);
        }
    double d[3] = {M[0] - m[0], M[1] - m[1], M[2] - m[2]};
    a = m[2];
    b = M[2];
    double pad = 1e-6 * v_norm(d) + 1e-6 * fmax(fabs(a), fabs(b)) + 4 * f->eps;
    if (f->has_under && f->refine == TRACE_REFINE_FULL) pad += 1e-6 * f->shape.scale;
    *lo = a - pad;
    *hi = b + pad;
}

/* Could f be a surface of a lens on the axis (x, y)? */
static int lens_kind(const tr_surf *f, double x, double y)
{
    if (f->is_mesh || f->group >= 0) return 0;
    if (f->shape.fast != TR_FAST_CONIC && f->shape.fast != TR_FAST_PLANE) return 0;
    if (f->mat.kind < TRACE_REFRACT || f->mat.kind > TRACE_DETECT) return 0;
    return f->shape.at[0] == x && f->shape.at[1] == y;
}

/* A refracting conic: what makes a lens (two at least). */
static int power_surface(const tr_surf *f)
{
    return f->shape.fast == TR_FAST_CONIC && f->mat.kind == TRACE_REFRACT;
}

typedef struct axp { double x, y; int id; } axp;

static int by_axis(const void *a, const void *b)
{
    const axp *p = a, *q = b;
    if (p->x != q->x) return p->x < q->x ? -1 : 1;
    if (p->y != q->y) return p->y < q->y ? -1 : 1;
    return p->id - q->id;
}

/* The axis line the most refracting conics share (ties: the one named first), 1; or 0
 * if no line has two. */
static int pick_axis(const trace_scene *sc, double *ax, double *ay)
{
    axp *a = malloc((size_t)sc->nsurf * sizeof *a);
    int na = 0, best = 0, bfirst = 0;
    if (!a) return 0;
    for (int i = 0; i < sc->nsurf; i++) {
        const tr_surf *f = sc->surf[i];
        if (lens_kind(f, f->shape.at[0], f->shape.at[1]) && power_surface(f))
            a[na++] = (axp){f->shape.at[0], f->shape.at[1], i};
    }
    qsort(a, (size_t)na, sizeof *a, by_axis);
    for (int i = 0, j; i < na; i = j) {
        for (j = i; j < na && a[j].x == a[i].x && a[j].y == a[i].y; j++) {}
        if (j - i > best || (j - i == best && a[i].id < bfirst)) {
            best = j - i;
            bfirst = a[i].id;
            *ax = a[i].x;
            *ay = a[i].y;
        }
    }
    free(a);
    return best >= 2;
}

/* Does [lo, hi] meet any of the disjoint intervals u[0..nu) (ascending)? */
static int blocked(const zr *u, int nu, double lo, double hi)
{
    int a = 0, b = nu;                    /* the first with u.hi >= lo */
    while (a < b) {
        int m = a + (b - a) / 2;
        if (u[m].hi >= lo) b = m; else a = m + 1;
    }
    return a < nu && u[a].lo <= hi;
}

/* Forget every hint (add_lens's of an earlier scene, this file's of an earlier build). */
static void clear_hints(trace_scene *sc)
{
    for (int i = 0; i < sc->nsurf; i++) {
        sc->surf[i]->nseq = 0;
        tr_pk_set_clear(&sc->surf[i]->pk);
    }
    sc->nentry = 0;
    tr_pk_set_clear(&sc->entry_pk);
    sc->entry_zmin = -INFINITY;
}

void tr_seq_detect(trace_scene *sc)
{
    double ax = 0, ay = 0;
    int n = sc->nsurf;
    zr *z = NULL;
    int *slab = NULL;          /* slab k: members z[slab[k] .. slab[k+1]) */
    clear_hints(sc);
    if (n < 2 || sc->ngroup || !pick_axis(sc, &ax, &ay)) goto none;
    z = malloc((size_t)n * sizeof *z);
    slab = malloc((size_t)(n + 1) * sizeof *slab);
    if (!z || !slab) goto none;               /* no hints: Embree alone, same bits */
    int nl = 0, nb = 0;
    for (int i = 0; i < n; i++) {             /* lens candidates first, the rest after */
        const tr_surf *f = sc->surf[i];
        if (lens_kind(f, ax, ay)) z[nl++].id = i;
    }
    for (int i = 0; i < n; i++)
        if (!lens_kind(sc->surf[i], ax, ay)) { z[nl + nb].id = i; nb++; }
    for (int i = 0; i < n; i++) z_range(sc->surf[z[i].id], &z[i].lo, &z[i].hi);
    qsort(z, (size_t)nl, sizeof *z, by_lo);
    /* slabs: lens candidates whose ranges overlap, transitively */
    int ns = 0;
    double shi = -INFINITY;
    for (int i = 0; i < nl; i++) {
        if (i == 0 || z[i].lo > shi) { slab[ns++] = i; shi = z[i].hi; }
        else shi = fmax(shi, z[i].hi);
    }
    slab[ns] = nl;
    /* what else the scene holds, as disjoint z intervals (u, in place after z[nl]) */
    qsort(z + nl, (size_t)nb, sizeof *z, by_lo);
    zr *u = z + nl;
    int nu = 0;
    for (int i = 0; i < nb; i++) {
        if (nu && !(u[i].lo > u[nu - 1].hi)) u[nu - 1].hi = fmax(u[nu - 1].hi, u[i].hi);
        else u[nu++] = u[i];
    }
    /* the best run of consecutive good slabs (nothing else in them or between them,
     * at most four members in two consecutive ones: the candidates a surface names):
     * the most refracting conics, the first at a tie */
    int best0 = -1, best1 = -1, bestp = 0, k0 = 0, p = 0;
    shi = -INFINITY;                          /* now: the previous slab's hi */
    for (int k = 0; k < ns; k++) {
        double lo = z[slab[k]].lo, hi = -INFINITY;
        for (int i = slab[k]; i < slab[k + 1]; i++) hi = fmax(hi, z[i].hi);
        int ok = slab[k + 1] - slab[k] <= 4 && !blocked(u, nu, lo, hi);
        if (ok && k > k0 && (blocked(u, nu, shi, lo) ||          /* a gap blocked, or */
                             slab[k + 1] - slab[k - 1] > 4))      /* too many to name */
            k0 = k, p = 0;
        shi = hi;
        if (!ok) { k0 = k + 1; p = 0; continue; }
        for (int i = slab[k]; i < slab[k + 1]; i++) p += power_surface(sc->surf[z[i].id]);
        if (p > bestp || (p == bestp && k0 == best0)) { bestp = p; best0 = k0; best1 = k; }
    }
    if (bestp < 2) goto none;
    /* the entry is the first slab with a refracting surface: a detector or a mirror
     * left of the lens (behind the sources) is better left to Embree than made the
     * slab the sources' rays must start left of */
    for (;;) {
        int refr = 0;
        for (int i = slab[best0]; i < slab[best0 + 1]; i++)
            refr |= sc->surf[z[i].id]->mat.kind == TRACE_REFRACT;
        if (refr) break;
        best0++;
    }
    /* the hints: a refracting surface of slab k may meet slab k's and slab k+1's
     * members next, each slab's in id order (ties go to the lower id, as in Embree) */
    for (int k = best0; k <= best1; k++) {
        int cand[4], nc = 0;
        for (int kk = k; kk <= k + 1 && kk <= best1; kk++) {
            int m0 = nc;
            for (int i = slab[kk]; i < slab[kk + 1]; i++) cand[nc++] = z[i].id;
            qsort(cand + m0, (size_t)(nc - m0), sizeof *cand, by_id);
        }
        for (int i = slab[k]; i < slab[k + 1]; i++)
            if (sc->surf[z[i].id]->mat.kind == TRACE_REFRACT)
                tr_scene_set_seq(sc, z[i].id, cand, nc);
    }
    int e[4], ne = 0;
    for (int i = slab[best0]; i < slab[best0 + 1]; i++) e[ne++] = z[i].id;
    qsort(e, (size_t)ne, sizeof *e, by_id);
    double run_lo = z[slab[best0]].lo, zmin = -INFINITY;
    tr_scene_set_entry(sc, e, ne, run_lo);
    for (int i = 0; i < n; i++)               /* everything left of the lens */
        if (z[i].hi < run_lo) zmin = fmax(zmin, z[i].hi);
    sc->entry_zmin = zmin;
    sc->seq_nsurf = sc->nsurf;
    free(z);
    free(slab);
    return;
none:
    free(z);
    free(slab);
    clear_hints(sc);
    sc->seq_nsurf = -1;
}
