/* bench_polar.c -- what polarization ray tracing costs (scripts/bench_wave.sh): the
 * Cooke triplet of tt.h at f/4 with mounts, Fresnel on, reflections off, a collimated
 * grid to the paraxial image, one thread, a hit sink summing the spot's power.  Traced
 * unpolarized on the engine's fastest path (packets where the processor has them),
 * unpolarized with every segment by Embree (sequential 0), and with polarization on
 * (P per ray, a Stokes record per hit; ray by ray, with the lens shortcut's choice of
 * surfaces).  Rounds alternate; medians of the thread's CPU time.  BENCH
 * trace_polar_cost: polarized over unpolarized, same scene, same rays.  With the
 * argument `unpolarized` it times only the first (run under LENSMAT_ISA=scalar it is
 * the unpolarized ray-by-ray loop that tr_polar.c mirrors). */
#include <stdio.h>
#include <time.h>
#include "tt.h"

static const trace_api *tr;

typedef struct acc { double p, s0; long n; } acc;
static int on_hit(void *ctx, const trace_hit *h)
{
    acc *a = ctx;
    a->p += h->power_s + h->power_p;
    a->n++;
    return 0;
}
static int on_pol(void *ctx, const trace_polar_hit *p)
{
    ((acc *)ctx)->s0 += p->stokes[0];
    return 0;
}

static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

/* mode 0: unpolarized; 1: unpolarized, every segment by Embree (sequential 0);
 * 2: polarization on.  Returns the CPU seconds; *a the sums. */
static double run(int mode, long across, acc *a, uint64_t *rays)
{
    trace_lens_surface s[TT_NSURF];
    trace_lens l;
    tt_triplet(s, &l, 1);
    l.mounts = 1;
    l.z_detector = tt_paraxial_image(&l, -INFINITY);
    trace_scene *sc = tr->scene_new();
    if (tr->add_lens(sc, &l) < 0) { fprintf(stderr, "%s\n", tr->error(sc)); exit(1); }
    trace_source src = {0};
    src.type = TRACE_SRC_GRID;
    src.at[2] = -5; src.dir[2] = 1; src.up[1] = 1;
    src.radius = TT_EPD / 2;
    src.count = across;
    tr->add_source(sc, &src, NULL);
    memset(a, 0, sizeof *a);
    if (mode == 2) tr->polarization(sc, 1, NULL, on_pol, a);
    trace_options o;
    tr->options_default(&o);
    o.threads = 1;
    o.reflections = 0;
    o.sequential = mode != 1;
    trace_sink sink = {a, NULL, on_hit, NULL};
    trace_summary sum;
    tr->build(sc, NULL);
    double c0 = cpu_now();
    if (tr->run(sc, &o, &sink, &sum)) { fprintf(stderr, "%s\n", tr->error(sc)); exit(1); }
    double dt = cpu_now() - c0;
    *rays = sum.rays;
    tr->scene_free(sc);
    return dt;
}

static int cmp(const void *x, const void *y)
{
    double a = *(const double *)x, b = *(const double *)y;
    return a < b ? -1 : a > b;
}

int main(int argc, char **argv)
{
    long across = 400;
    int only = argc > 1 && !strcmp(argv[1], "unpolarized");
    enum { R = 5 };
    double t[3][R];
    acc a[3];
    uint64_t rays = 0;
    tr = tt_api();
    for (int k = 0; k < R; k++)
        for (int m = 0; m < (only ? 1 : 3); m++) t[m][k] = run(m, across, &a[m], &rays);
    if (only) {
        qsort(t[0], R, sizeof t[0][0], cmp);
        printf("BENCH trace_unpolar_%s_mrays_per_s %.3g Mrays/s\n", trace_isa_active(),
               rays / t[0][R / 2] / 1e6);
        return 0;
    }
    for (int m = 0; m < 3; m++) qsort(t[m], R, sizeof t[m][0], cmp);
    double u = t[0][R / 2], b = t[1][R / 2], p = t[2][R / 2];
    /* the same rays and powers either way (the polarized s and p from P) */
    double dp = fabs(a[2].p - a[0].p) / a[0].p, ds = fabs(a[2].s0 - a[0].p) / a[0].p;
    printf("# triplet f/4, %llu rays, mounts, Fresnel, reflections off, 1 thread, CPU time, "
           "medians of %d; kernel %s; hits %ld/%ld, power agrees to %.1e, S0 to %.1e\n",
           (unsigned long long)rays, R, trace_isa_active(), a[0].n, a[2].n, dp, ds);
    printf("BENCH trace_polar_mrays_per_s %.3g Mrays/s\n", rays / p / 1e6);
    printf("BENCH trace_unpolar_mrays_per_s %.3g Mrays/s\n", rays / u / 1e6);
    printf("BENCH trace_unpolar_bvh_mrays_per_s %.3g Mrays/s\n", rays / b / 1e6);
    printf("BENCH trace_polar_cost %.3g ratio\n", p / u);
    printf("BENCH trace_polar_vs_bvh %.3g ratio\n", p / b);
    return a[0].n == a[2].n && dp < 1e-12 && ds < 1e-12 ? 0 : 1;
}
