/* bench_threads.c -- how the trace scales from one thread to two (issue 23), on the
 * lens path (the Cooke triplet of tt.h, 800 x 800 collimated grid, Fresnel on, the
 * packets and the sequential shortcut) and on the BVH path (a glass sphere of 80 000
 * triangles, 300 x 300 grid, every segment through Embree).  Each run is timed by the
 * wall clock and by the process's CPU time (getrusage: every thread, the pool's
 * included), so a machine shared with other work cannot make the figure look better
 * or worse than it is:
 *   wall scaling  = wall(1 thread) / wall(2 threads): what a user waits, on this
 *                   machine at this moment;
 *   CPU scaling   = 2 x (rays per CPU-second on 2 threads) / (on 1 thread): the wall
 *                   scaling two threads would give with a core each (1.8 or more: the
 *                   threads do not slow each other down; lower: they contend, or the
 *                   work does not split).
 * Each pair is run back to back, order alternating, five pairs, medians.  Prints
 *   BENCH trace_threads_scaling_lens       CPU scaling, lens path
 *   BENCH trace_threads_scaling_lens_wall  wall scaling, lens path
 *   BENCH trace_threads_scaling_bvh        CPU scaling, BVH path
 *   BENCH trace_threads_scaling_bvh_wall   wall scaling, BVH path
 * and a comment line per path with the CPU-seconds per thread and the share of the
 * two cores the 2-thread run got (under 90 %: the machine was busy; the line says so). */
#include <stdio.h>
#include <sys/resource.h>
#include <unistd.h>
#include "tt.h"
#include "mesh.h"
#include "bench_util.h"

static const trace_api *tr;

static double cpu_s(void)
{
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_utime.tv_sec + ru.ru_stime.tv_sec +
           1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}


typedef struct run { double wall, cpu, rays; } run;   /* rays: segments traced */

static run timed(trace_scene *sc, int threads)
{
    trace_options o;
    trace_summary sum;
    run r;
    tr->options_default(&o);
    o.threads = threads;
    o.reflections = 0;
    tr->build(sc, NULL);
    double t0 = now(), c0 = cpu_s();
    if (tr->run(sc, &o, NULL, &sum)) { fprintf(stderr, "%s\n", tr->error(sc)); exit(1); }
    r.wall = now() - t0;
    r.cpu = cpu_s() - c0;
    r.rays = (double)sum.segments;
    return r;
}

static trace_scene *lens_scene(void)
{
    trace_scene *sc = tt_triplet_grid(tr, 800, TT_EPD / 2);
    if (!sc) { fprintf(stderr, "bench_threads: the triplet scene was refused\n"); exit(1); }
    return sc;
}

static trace_scene *bvh_scene(tmesh *m)
{
    tm_sphere(m, 1, 100);
    trace_scene *sc = tr->scene_new();
    trace_mesh mesh = {m->v, m->nv, m->t, m->nt, NULL, NULL, 0, 0};
    trace_material g = {TRACE_REFRACT, 1.0, 1.5};
    if (tr->add_mesh(sc, &mesh, &g) < 0) { fprintf(stderr, "%s\n", tr->error(sc)); exit(1); }
    trace_source src = {0};
    src.type = TRACE_SRC_GRID;
    src.at[2] = -3; src.dir[2] = 1; src.up[1] = 1;
    src.radius = 0.999;
    src.count = 300;
    tr->add_source(sc, &src, NULL);
    return sc;
}

static void scaling(const char *name, trace_scene *sc)
{
    double w[5], c[5], per1 = 0, per2 = 0, share[5];
    timed(sc, 1);                                   /* warm up, build */
    for (int i = 0; i < 5; i++) {
        run a, b;
        if (i % 2) { b = timed(sc, 2); a = timed(sc, 1); }
        else { a = timed(sc, 1); b = timed(sc, 2); }
        w[i] = a.wall / b.wall;
        c[i] = 2 * (b.rays / b.cpu) / (a.rays / a.cpu);
        share[i] = b.cpu / (2 * b.wall);
        per1 += a.cpu / 5;
        per2 += b.cpu / 2 / 5;
    }
    qsort(w, 5, sizeof *w, cmp);
    qsort(c, 5, sizeof *c, cmp);
    qsort(share, 5, sizeof *share, cmp);
    printf("# %s: CPU-seconds per thread %.3f (1 thread), %.3f (each of 2); the 2-thread "
           "runs got %.0f %% of two cores%s\n", name, per1, per2, 100 * share[2],
           share[2] < 0.9 ? ": the machine was busy, the wall figure is the machine's, "
           "the CPU figure the trace's" : "");
    printf("BENCH trace_threads_scaling_%s %.2f x\n", name, c[2]);
    printf("BENCH trace_threads_scaling_%s_wall %.2f x\n", name, w[2]);
}

int main(void)
{
    tr = tt_api();
    char load[64] = "?";
    FILE *f = fopen("/proc/loadavg", "r");
    if (f) { if (!fgets(load, sizeof load, f)) load[0] = '\0'; fclose(f); }
    load[strcspn(load, "\n")] = '\0';
    printf("# bench_threads: load %s on %ld cores\n", load, sysconf(_SC_NPROCESSORS_ONLN));
    trace_scene *sc = lens_scene();
    scaling("lens", sc);
    tr->scene_free(sc);
    tmesh m = {0};
    sc = bvh_scene(&m);
    scaling("bvh", sc);
    tr->scene_free(sc);
    return 0;
}
