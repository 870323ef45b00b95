/* t_isa.c -- the lens packets give the same bits on every instruction set (issue 13):
 * this program runs itself once per instruction set the processor has, forced with
 * LENSMAT_ISA (avx512, avx2, sse2 or neon, and scalar: rays one by one), each child
 * tracing four lenses (the Cooke triplet with mounts, a singlet, a cemented doublet,
 * a plano-convex lens without mounts) from an off-axis point and from a collimated
 * grid (on two threads), with Fresnel on and off and reflected rays on and off, and
 * writing every hit, every segment and the summary's counts and powers to a file;
 * the files must be equal byte for byte.  Also: the child runs the kernel it was asked for, and an
 * unknown name falls back to the best one. */
#define _DEFAULT_SOURCE 1
#include <stdio.h>
#include <sys/wait.h>
#include <unistd.h>
#include "unit.h"
#include "tt.h"

/* ---- the child: trace everything, dump it ---- */
typedef struct dump { FILE *f; uint64_t nh, ns; } dump;
static int put_hit(void *ctx, const trace_hit *h)
{
    dump *d = ctx;
    d->nh++;
    return fwrite(h, sizeof *h, 1, d->f) != 1;
}
static int put_seg(void *ctx, const trace_segment *g)
{
    dump *d = ctx;
    d->ns++;
    return fwrite(g, sizeof *g, 1, d->f) != 1;
}

static void lens_of(int which, trace_lens_surface *s, trace_lens *l)
{
    static const double single[2][4] = {{50, 0, 1.5168, 12}, {-50, 6, 1, 12}};
    static const double doublet[3][4] = {{61.47, 0, 1.5168, 12.5}, {-44.64, 6, 1.6727, 12.5},
                                         {-129.94, 8.5, 1, 12.5}};
    static const double plano[2][4] = {{INFINITY, 0, 1.7, 0}, {-40, 7, 1, 0}};
    const double (*t)[4] = NULL;
    int n = 0;
    memset(l, 0, sizeof *l);
    if (which == 0) {
        tt_triplet(s, l, 1);
    } else {
        if (which == 1) { t = single; n = 2; }
        if (which == 2) { t = doublet; n = 3; }
        if (which == 3) { t = plano; n = 2; }
        for (int i = 0; i < n; i++) {
            s[i].radius = t[i][0];
            s[i].z = t[i][1];
            s[i].n_right = t[i][2];
            s[i].semi_diameter = t[i][3];
        }
        l->n_object = 1;
        l->nsurf = n;
        l->surf = s;
        l->mounts = which != 3;
    }
    l->z_detector = tt_paraxial_image(l, -INFINITY);
}

static int child(const trace_api *tr, const char *path)
{
    dump d = {fopen(path, "wb"), 0, 0};
    if (!d.f) return 2;
    fprintf(d.f, "%s\n", trace_isa_active());
    for (int lens = 0; lens < 4; lens++)
        for (int v = 0; v < 8; v++) {
            int fresnel = v & 1, reflections = (v >> 1) & 1, grid = v >> 2;
            trace_lens_surface s[TT_NSURF];
            trace_lens l;
            lens_of(lens, s, &l);
            trace_scene *sc = tr->scene_new();
            trace_source src = {0};
            if (grid) {
                src.type = TRACE_SRC_GRID;
                src.at[2] = -5; src.dir[2] = 1; src.up[1] = 1;
                src.radius = lens == 3 ? 9 : 7; src.count = reflections ? 16 : 48;
            } else {
                src.type = TRACE_SRC_CONE;             /* from an off-axis point: skew */
                src.at[1] = 8; src.at[2] = -60; src.dir[1] = -8; src.dir[2] = 60;
                src.half_angle = 0.09; src.rings = reflections ? 6 : 20;
            }
            trace_options o;
            trace_summary sum;
            tr->options_default(&o);
            o.fresnel = fresnel;
            o.reflections = reflections;
            o.threads = grid ? 2 : 1;           /* the grid on two threads */
            trace_sink sink = {&d, put_seg, put_hit, NULL};
            if (tr->add_lens(sc, &l) < 0 || tr->add_source(sc, &src, NULL) ||
                tr->run(sc, &o, &sink, &sum)) {
                fprintf(stderr, "t_isa child: %s\n", tr->error(sc));
                return 2;
            }
            fwrite(&sum.rays, sizeof(uint64_t), 10, d.f);
            fwrite(&sum.max_depth_seen, sizeof(int), 1, d.f);
            fwrite(&sum.emitted, sizeof(double), 5, d.f);
            tr->scene_free(sc);
        }
    fprintf(d.f, "\n%llu hits %llu segments\n", (unsigned long long)d.nh,
            (unsigned long long)d.ns);
    return fclose(d.f) ? 2 : 0;
}

/* ---- the parent ---- */
static int run_child(const char *self, const char *isa, const char *path)
{
    pid_t p = fork();
    if (p < 0) return -1;
    if (p == 0) {
        setenv("LENSMAT_ISA", isa, 1);
        execl(self, self, "child", path, (char *)NULL);
        _exit(127);
    }
    int st;
    if (waitpid(p, &st, 0) != p) return -1;
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static char *slurp(const char *path, long *n)
{
    FILE *f = fopen(path, "rb");
    char *b = NULL;
    *n = -1;
    if (!f) return NULL;
    if (fseek(f, 0, SEEK_END) == 0 && (*n = ftell(f)) >= 0 && fseek(f, 0, SEEK_SET) == 0 &&
        (b = malloc((size_t)*n + 1)) && fread(b, 1, (size_t)*n, f) == (size_t)*n) {
        b[*n] = '\0';
    } else {
        free(b);
        b = NULL;
    }
    fclose(f);
    return b;
}

int main(int argc, char **argv)
{
    const trace_api *tr = tt_api();
    if (argc == 3 && !strcmp(argv[1], "child")) return child(tr, argv[2]);
    char dir[] = "/tmp/lensmat-t_isa-XXXXXX", ref[64], path[64];
    if (!mkdtemp(dir)) { printf("FAIL no temporary folder\n"); return 1; }
    const char *best = NULL;
    char *want = NULL;
    long nwant = 0;
    int ok, nisa = 0;
    for (int i = 0; trace_isa_name(i, &ok); i++) {
        const char *isa = trace_isa_name(i, NULL);
        if (!ok) {
            printf("# %s: this processor cannot run it, not tested\n", isa);
            continue;
        }
        nisa++;
        snprintf(path, sizeof path, "%s/%s", dir, isa);
        int rc = run_child("/proc/self/exe", isa, path);
        long n;
        char *got = slurp(path, &n);
        CHECK(rc == 0 && got, "LENSMAT_ISA=%s: the child traced the lenses (exit %d)", isa,
              rc);
        if (!got) continue;
        size_t nl = strcspn(got, "\n");
        CHECK(nl == strlen(isa) && !strncmp(got, isa, nl),
              "LENSMAT_ISA=%s: the child ran the %.*s kernel", isa, (int)nl, got);
        if (!best) {
            best = isa;
            snprintf(ref, sizeof ref, "%s", path);
            want = got;
            nwant = n;
            CHECK(n > 200000, "%s: %ld bytes of hits, segments and summaries", isa, n);
            continue;
        }
        /* the bodies after each file's first line (the kernel's name) */
        size_t wl = strcspn(want, "\n");
        const char *a = got + nl, *b = want + wl;
        long na = n - (long)nl, nb = nwant - (long)wl, m = na < nb ? na : nb, at = 0;
        while (at < m && a[at] == b[at]) at++;
        if (na == nb && at == na)
            CHECK(1, "%s gives the same %ld bytes as %s (hits, segments, summaries)", isa,
                  na, best);
        else
            CHECK(0, "%s gives %ld bytes, %s %ld: the first difference is at byte %ld",
                  isa, na, best, nb, at);
        free(got);
        unlink(path);
    }
    CHECK(nisa >= 2, "%d instruction sets tested (scalar and at least one packet kernel)",
          nisa);
    /* an unknown name: the best this processor runs */
    snprintf(path, sizeof path, "%s/unknown", dir);
    int rc = run_child("/proc/self/exe", "no-such-isa", path);
    long n;
    char *got = slurp(path, &n);
    CHECK(rc == 0 && got && best && !strncmp(got, best, strlen(best)) &&
          got[strlen(best)] == '\n', "LENSMAT_ISA=no-such-isa runs the best kernel (%s)",
          best ? best : "?");
    free(got);
    free(want);
    unlink(path);
    unlink(ref);
    rmdir(dir);
    return unit_failed();
}
