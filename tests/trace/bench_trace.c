/* bench_trace.c -- the trace engine's benchmarks (run by scripts/bench_trace.sh), one
 * "BENCH name value unit" line per figure, baselines measured in the same run:
 *   trace_vs_raw_embree      full optical trace segments/s / bare rtcIntersect1/s on
 *                            the same mesh and the same segments (one thread)
 *   trace_vs_bruteforce_100k speed-up over the seed's per-triangle loop on a 100 000
 *                            triangle cornea (the loop is timed on a subset of the
 *                            segments and scaled; one thread each)
 *   trace_mrays_per_s        triplet workload on all cores
 *   trace_threads_scaling    triplet workload, 2 threads / 1 thread (median of five
 *                            back-to-back pairs)
 *   trace_mem_mb_per_mtri    peak RSS growth per million triangles (child process)
 *   trace_triplet_mrays_per_s, trace_triplet_peak_mb, trace_triplet_rms_spot_um:
 *                            Cooke triplet f/4, Fresnel on, 1e6 rays, one thread
 *                            (median of three runs), peak from getrusage of a
 *                            child process
 *   trace_triplet_vs_bvh     the same trace against the same rays traced one by one
 *                            through Embree (sequential shortcut off), same results
 *   trace_sum_1e8_{rays,error,balance}: 1e8 rays of total power 1, the summed powers
 *                            against n fl(1/n) and the balance (not in quick runs)
 * `bench_trace isa` prints one triplet run's Mrays/s (wall clock, and per second of
 * the tracing thread's CPU time) with the packet kernel of this process (LENSMAT_ISA=<isa>), `bench_trace isas` the kernels this processor runs
 * (scripts/bench_trace_isa.sh: BENCH trace_triplet_<isa>_mrays_per_s).
 * `bench_trace triplet` prints the triplet figures alone, `bench_trace sum` the sums. */
#define _DEFAULT_SOURCE 1      /* wait4 */
#include <embree3/rtcore.h>
#include <stdio.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>
#include "tt.h"
#include "mesh.h"
#include "bench_util.h"

static const trace_api *tr;

static int cmpd(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}
static double median3(double a, double b, double c)
{
    double v[3] = {a, b, c};
    qsort(v, 3, sizeof *v, cmpd);
    return v[1];
}

/* ---------- the triplet workload ---------- */
typedef struct spot { double s2, w, sx, sy; } spot;
static int spot_hit(void *ctx, const trace_hit *h)
{
    spot *s = ctx;
    double w = h->power_s + h->power_p;
    s->s2 += w * (h->pos[0] * h->pos[0] + h->pos[1] * h->pos[1]);
    s->sx += w * h->pos[0];
    s->sy += w * h->pos[1];
    s->w += w;
    return 0;
}

/* The calling thread's CPU time (one thread traces on the caller): a figure that a
 * busy shared machine does not halve, unlike the wall clock. */
static double triplet_cpu_s;
static double cpu_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

/* Returns rays/s; *rms_um: the power-weighted RMS spot radius about its centroid. */
static double triplet_run(int threads, long across, int sequential, double *rms_um,
                          uint64_t *nrays)
{
    trace_lens_surface s[TT_NSURF];
    trace_lens l;
    tt_triplet(s, &l, 1);
    l.z_detector = tt_paraxial_image(&l, -INFINITY);
    trace_scene *sc = tr->scene_new();
    if (tr->add_lens(sc, &l) < 0) { fprintf(stderr, "%s\n", tr->error(sc)); exit(1); }
    trace_source src = {0};
    src.type = TRACE_SRC_GRID;
    src.at[2] = -5; src.dir[2] = 1; src.up[1] = 1;
    src.radius = TT_EPD / 2;
    src.count = across;
    tr->add_source(sc, &src, NULL);
    trace_options o;
    tr->options_default(&o);
    o.threads = threads;
    o.reflections = 0;                 /* sequential: reflected power leaves the bundle */
    o.sequential = sequential;
    spot sp = {0};
    trace_sink sink = {&sp, NULL, spot_hit, NULL};
    trace_summary sum;
    tr->build(sc, NULL);
    double t0 = now(), c0 = cpu_now();
    if (tr->run(sc, &o, &sink, &sum)) { fprintf(stderr, "%s\n", tr->error(sc)); exit(1); }
    double dt = now() - t0;
    triplet_cpu_s = cpu_now() - c0;
    double cx = sp.sx / sp.w, cy = sp.sy / sp.w;
    if (rms_um) *rms_um = 1e3 * sqrt(sp.s2 / sp.w - cx * cx - cy * cy);
    if (nrays) *nrays = sum.rays;
    tr->scene_free(sc);
    return sum.rays / dt;
}

static double triplet(int threads, long across, double *rms_um, uint64_t *nrays)
{
    return triplet_run(threads, across, 1, rms_um, nrays);
}

/* ---------- a refracting mesh scene and its segments ---------- */
typedef struct segs { float *o, *d; long n, cap; } segs;
static int keep_seg(void *ctx, const trace_segment *s)
{
    segs *g = ctx;
    if (g->n == g->cap || s->end == TRACE_END_ESCAPE) return 0;
    for (int i = 0; i < 3; i++) {
        g->o[3 * g->n + i] = (float)s->p0[i];
        g->d[3 * g->n + i] = (float)(s->p1[i] - s->p0[i]);
    }
    g->n++;
    return 0;
}

static trace_scene *glass_scene(const tmesh *m, double n, long across, double radius,
                                double z0)
{
    trace_scene *sc = tr->scene_new();
    trace_mesh mesh = {m->v, m->nv, m->t, m->nt, NULL, NULL, 0, 0};
    trace_material g = {TRACE_REFRACT, 1.0, n};
    if (tr->add_mesh(sc, &mesh, &g) < 0) { fprintf(stderr, "%s\n", tr->error(sc)); exit(1); }
    trace_source src = {0};
    src.type = TRACE_SRC_GRID;
    src.at[2] = z0; src.dir[2] = 1; src.up[1] = 1;
    src.radius = radius;
    src.count = across;
    tr->add_source(sc, &src, NULL);
    return sc;
}

/* full trace, one thread, no output: segments per second */
static double trace_segments_per_s(trace_scene *sc, uint64_t *nseg)
{
    trace_options o;
    tr->options_default(&o);
    o.threads = 1;
    o.cutoff = 1e-3;
    trace_summary sum;
    tr->build(sc, NULL);
    double t0 = now();
    tr->run(sc, &o, NULL, &sum);
    double dt = now() - t0;
    if (nseg) *nseg = sum.segments;
    return sum.segments / dt;
}

static segs collect_segments(trace_scene *sc, long max)
{
    segs g = {malloc((size_t)max * 3 * sizeof(float)), malloc((size_t)max * 3 * sizeof(float)),
              0, max};
    trace_options o;
    tr->options_default(&o);
    o.threads = 1;
    o.cutoff = 1e-3;
    trace_sink sink = {&g, keep_seg, NULL, NULL};
    tr->run(sc, &o, &sink, NULL);
    return g;
}

/* bare Embree: the same triangles, the same flags, rtcIntersect1 per segment */
static double raw_queries_per_s(const tmesh *m, const segs *g)
{
    RTCDevice dev = rtcNewDevice(NULL);
    RTCScene scn = rtcNewScene(dev);
    rtcSetSceneFlags(scn, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scn, RTC_BUILD_QUALITY_MEDIUM);
    RTCGeometry geo = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *v = rtcSetNewGeometryBuffer(geo, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                       12, (size_t)m->nv);
    unsigned *ix = rtcSetNewGeometryBuffer(geo, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                           12, (size_t)m->nt);
    for (long i = 0; i < 3 * m->nv; i++) v[i] = (float)m->v[i];
    memcpy(ix, m->t, (size_t)m->nt * 12);
    rtcCommitGeometry(geo);
    rtcAttachGeometry(scn, geo);
    rtcReleaseGeometry(geo);
    rtcCommitScene(scn);
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    long hits = 0;
    double t0 = now();
    for (long i = 0; i < g->n; i++) {
        struct RTCRayHit rh;
        rh.ray.org_x = g->o[3 * i]; rh.ray.org_y = g->o[3 * i + 1]; rh.ray.org_z = g->o[3 * i + 2];
        rh.ray.dir_x = g->d[3 * i]; rh.ray.dir_y = g->d[3 * i + 1]; rh.ray.dir_z = g->d[3 * i + 2];
        rh.ray.tnear = 1e-4f; rh.ray.tfar = INFINITY; rh.ray.time = 0;
        rh.ray.mask = 0xFFFFFFFFu; rh.ray.id = 0; rh.ray.flags = 0;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scn, &ctx, &rh);
        hits += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    }
    double dt = now() - t0;
    rtcReleaseScene(scn);
    rtcReleaseDevice(dev);
    if (hits == 0) fprintf(stderr, "bench: raw Embree found no hits\n");
    return g->n / dt;
}

/* ---------- the seed's per-triangle loop (intlnp + baryt, double) ---------- */
static int brute_nearest(const tmesh *m, const double o[3], const double d[3], double *tbest)
{
    int found = -1;
    *tbest = INFINITY;
    for (long k = 0; k < m->nt; k++) {
        const double *a = m->v + 3 * m->t[3 * k], *b = m->v + 3 * m->t[3 * k + 1],
                     *c = m->v + 3 * m->t[3 * k + 2];
        double e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        double e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                       e1[0] * e2[1] - e1[1] * e2[0]};
        double den = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
        if (den == 0) continue;
        double t = (n[0] * (a[0] - o[0]) + n[1] * (a[1] - o[1]) + n[2] * (a[2] - o[2])) / den;
        if (!(t > 1e-9) || t >= *tbest) continue;
        double p[3] = {o[0] + t * d[0] - a[0], o[1] + t * d[1] - a[1], o[2] + t * d[2] - a[2]};
        /* barycentric coordinates */
        double d00 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
        double d01 = e1[0] * e2[0] + e1[1] * e2[1] + e1[2] * e2[2];
        double d11 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
        double d20 = p[0] * e1[0] + p[1] * e1[1] + p[2] * e1[2];
        double d21 = p[0] * e2[0] + p[1] * e2[1] + p[2] * e2[2];
        double dn = d00 * d11 - d01 * d01;
        double v = (d11 * d20 - d01 * d21) / dn, w = (d00 * d21 - d01 * d20) / dn;
        if (v < 0 || w < 0 || v + w > 1) continue;
        *tbest = t;
        found = (int)k;
    }
    return found;
}

/* A cornea: a spherical cap R 7.8 mm, 5.5 mm semi-diameter, as an n x n grid. */
static void cornea(tmesh *m, long n)
{
    double R = 7.8, s = 5.5;
    for (long j = 0; j <= n; j++)
        for (long i = 0; i <= n; i++) {
            double x = -s + 2 * s * i / n, y = -s + 2 * s * j / n;
            double r2 = (x * x + y * y) / 2;      /* squeeze the square into the cap */
            double z = R - sqrt(R * R - r2);
            tm_vertex(m, x / sqrt(2), y / sqrt(2), z);
        }
    for (long j = 0; j < n; j++)
        for (long i = 0; i < n; i++) {
            long a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
            tm_tri(m, a, c, b);       /* normals toward -z: front (air) side */
            tm_tri(m, b, c, d);
        }
}

static long rss_kb(void)
{
    long pages = 0, resident = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (f) { if (fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0; fclose(f); }
    return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

/* child: build a ~1M-triangle mesh; print peak growth per million triangles */
static void mem_child(void)
{
    tmesh m = {0};
    tm_sphere(&m, 1, 354);
    long base = rss_kb();
    trace_scene *sc = tr->scene_new();
    trace_mesh mesh = {m.v, m.nv, m.t, m.nt, NULL, NULL, 0, 0};
    trace_material g = {TRACE_REFRACT, 1.0, 1.5};
    tr->add_mesh(sc, &mesh, &g);
    tr->build(sc, NULL);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("BENCH trace_mem_mb_per_mtri %.1f MB/Mtri\n",
           (ru.ru_maxrss - base) / 1024.0 / (m.nt / 1e6));
    tr->scene_free(sc);
}

static long child_peak_kb(void (*fn)(void *), void *arg, FILE **out)
{
    int fd[2];
    fflush(stdout);
    if (pipe(fd)) return -1;
    pid_t p = fork();
    if (p == 0) {
        close(fd[0]);
        dup2(fd[1], 1);
        fn(arg);
        fflush(stdout);
        _exit(0);
    }
    close(fd[1]);
    *out = fdopen(fd[0], "r");
    int st;
    struct rusage ru;
    char buf[256];
    size_t n = fread(buf, 1, sizeof buf - 1, *out);
    buf[n] = '\0';
    fclose(*out);
    *out = NULL;
    wait4(p, &st, 0, &ru);
    fputs(buf, stdout);
    return ru.ru_maxrss;
}

static void triplet_child(void *arg)
{
    double rms;
    uint64_t n;
    (void)arg;
    /* median of three runs of the same trace: one run on this shared 2-core machine
     * swings by 30 % with what else is running */
    double r[3], q[3];
    for (int i = 0; i < 3; i++) {               /* pairs back to back, for the ratio */
        r[i] = triplet(1, 1128, &rms, &n);
        q[i] = r[i] / triplet_run(1, 400, 0, NULL, NULL);
    }
    printf("BENCH trace_triplet_mrays_per_s %.3f Mrays/s\n", median3(r[0], r[1], r[2]) / 1e6);
    printf("BENCH trace_triplet_vs_bvh %.2f ratio\n", median3(q[0], q[1], q[2]));
    printf("BENCH trace_triplet_rms_spot_um %.3f um\n", rms);
    printf("BENCH trace_triplet_rays %llu rays\n", (unsigned long long)n);
}
static void mem_fn(void *arg) { (void)arg; mem_child(); }

/* Issue 13: the triplet figure of the packet kernel this process runs (LENSMAT_ISA
 * forces one; scripts/bench_trace_isa.sh runs this for each instruction set the
 * processor has, in rounds, and takes the medians): one thread, one run. */
static void triplet_isa(void)
{
    uint64_t n;
    double r = triplet(1, 1128, NULL, &n);
    printf("%s %.4f %.4f\n", trace_isa_active(), r / 1e6, n / triplet_cpu_s / 1e6);
}

/* Issue 9's 1e8-ray row (too long for make check, which runs 1e7 in t_extreme): a
 * collimated grid of about 1e8 rays of total power 1 onto a detector, on all cores:
 * how far the summed powers are from n fl(1/n) (exact, in long double), and the
 * balance; both must stay at rounding level (a plain sum drifted to 2e-9). */
static void sum_1e8(void)
{
    trace_scene *sc = tr->scene_new();
    trace_options o;
    tr->options_default(&o);
    o.fresnel = 0;
    o.reflections = 0;
    trace_surface p = {0};
    p.shape = TRACE_PLANE;
    p.at[2] = 1;
    p.axis[2] = 1;
    p.aperture = TRACE_AP_DISC;
    p.r_outer = 2;
    trace_material m = {TRACE_DETECT, 1, 1};
    tr->add_surface(sc, &p, &m);
    trace_source g = {0};
    g.type = TRACE_SRC_GRID;
    g.dir[2] = 1;
    g.radius = 1;
    g.count = 11284;
    tr->add_source(sc, &g, NULL);
    trace_summary s;
    if (tr->run(sc, &o, NULL, &s) != TRACE_OK) {
        printf("# sum_1e8: %s\n", tr->error(sc));
        tr->scene_free(sc);
        return;
    }
    long double each = 1.0 / (double)s.rays, want = each * (long double)s.rays;
    double e = fmax(fabs((double)(s.emitted - want)), fabs((double)(s.detected - want)));
    double bal = s.emitted - (s.detected + s.absorbed + s.escaped + s.cutoff);
    printf("BENCH trace_sum_1e8_rays %llu rays\n", (unsigned long long)s.rays);
    printf("BENCH trace_sum_1e8_error %.2e power\n", e);
    printf("BENCH trace_sum_1e8_balance %.2e power\n", fabs(bal));
    tr->scene_free(sc);
}

int main(int argc, char **argv)
{
    tr = tt_api();
    int quick = argc > 1 && !strcmp(argv[1], "quick");
    FILE *f = NULL;
    if (argc > 1 && !strcmp(argv[1], "triplet")) {     /* the triplet figures alone */
        triplet_child(NULL);
        return 0;
    }
    if (argc > 1 && !strcmp(argv[1], "isa")) {         /* this process's kernel */
        triplet_isa();
        return 0;
    }
    if (argc > 1 && !strcmp(argv[1], "isas")) {        /* those this processor runs */
        int ok;
        for (int i = 0; trace_isa_name(i, &ok); i++)
            if (ok) printf("%s\n", trace_isa_name(i, NULL));
        return 0;
    }
    if (argc > 1 && !strcmp(argv[1], "sum")) {         /* the 1e8-ray sums alone */
        sum_1e8();
        return 0;
    }
    if (!quick) sum_1e8();

    /* Cooke triplet, one thread, in a child for its peak memory */
    long peak = child_peak_kb(triplet_child, NULL, &f);
    printf("BENCH trace_triplet_peak_mb %.1f MB\n", peak / 1024.0);

    /* all cores and scaling on the same workload.  The speed of this machine drifts
     * by tens of percent over seconds, so the scaling is the median of five ratios of
     * back-to-back 1- and 2-thread runs (taken in alternating order), not a ratio of
     * medians taken seconds apart. */
    long across = quick ? 400 : 800;
    double ratio2[5], ra;
    for (int i = 0; i < 5; i++) {
        double a, b;
        if (i % 2) { b = triplet(2, across, NULL, NULL); a = triplet(1, across, NULL, NULL); }
        else { a = triplet(1, across, NULL, NULL); b = triplet(2, across, NULL, NULL); }
        ratio2[i] = b / a;
    }
    qsort(ratio2, 5, sizeof *ratio2, cmpd);
    double rall[3];
    for (int i = 0; i < 3; i++) rall[i] = triplet(0, across, NULL, NULL);
    ra = median3(rall[0], rall[1], rall[2]);
    printf("BENCH trace_mrays_per_s %.3f Mrays/s\n", ra / 1e6);
    printf("BENCH trace_threads_scaling %.2f x\n", ratio2[2]);

    /* full trace vs bare Embree on a glass geodesic sphere (80 000 triangles) */
    tmesh ball = {0};
    tm_sphere(&ball, 1, 100);
    trace_scene *sc = glass_scene(&ball, 1.5, quick ? 150 : 300, 0.999, -3);
    double tf[3], ratio[3];
    uint64_t nseg;
    trace_segments_per_s(sc, &nseg);                       /* warm up, count */
    segs g = collect_segments(sc, (long)nseg);
    /* pairs measured back to back, so a busy machine hits both alike */
    for (int i = 0; i < 3; i++) {
        tf[i] = trace_segments_per_s(sc, NULL);
        ratio[i] = tf[i] / raw_queries_per_s(&ball, &g);
    }
    double full = median3(tf[0], tf[1], tf[2]);
    printf("BENCH trace_vs_raw_embree %.3f ratio\n", median3(ratio[0], ratio[1], ratio[2]));
    printf("BENCH trace_segments_per_s %.3f Msegments/s\n", full / 1e6);
    tr->scene_free(sc);
    free(g.o); free(g.d);

    /* brute force on a 100 000-triangle cornea: the seed's loop on a subset */
    tmesh cor = {0};
    cornea(&cor, 224);
    sc = glass_scene(&cor, 1.376, quick ? 100 : 200, 3.8, -5);
    for (int i = 0; i < 3; i++) tf[i] = trace_segments_per_s(sc, &nseg);
    g = collect_segments(sc, (long)nseg);
    long nb = g.n < 200 ? g.n : 200, found = 0;
    double t0 = now();
    for (long i = 0; i < nb; i++) {
        long k = i * (g.n / nb);
        double o[3] = {g.o[3 * k], g.o[3 * k + 1], g.o[3 * k + 2]};
        double d[3] = {g.d[3 * k], g.d[3 * k + 1], g.d[3 * k + 2]}, t;
        found += brute_nearest(&cor, o, d, &t) >= 0;
    }
    double brute = nb / (now() - t0);
    full = median3(tf[0], tf[1], tf[2]);

    printf("BENCH trace_vs_bruteforce_100k %.0f ratio\n", full / brute);
    fprintf(stderr, "bench_trace: brute force (%ld triangles) timed on %ld of %ld "
            "segments (%ld hits) and scaled: %.1f queries/s vs %.0f segments/s traced\n",
            cor.nt, nb, g.n, found, brute, full);
    tr->scene_free(sc);
    free(g.o); free(g.d);

    /* memory per million triangles, in a child */
    child_peak_kb(mem_fn, NULL, &f);
    return 0;
}
