/* bench_paraxial.c -- figures of the paraxial engine (scripts/bench_paraxial.sh):
 * surfaces per second building a 10 000-surface system (listing-order and
 * double-double products, steps kept) plus its first-order analysis with every
 * condition estimate; and |det - 1| of a 10 000-surface periodic relay whose entries
 * stay bounded, for the accurate matrix and for the listing-order one.  Prints BENCH
 * lines; the median of `runs` timings. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "paraxial/paraxial.h"
#include "bench_util.h"

#define NSURF 10000

/* A 10 000-surface random system and its full analysis; returns seconds. */
static double one_run(double *sink)
{
    px_system s;
    px_first f;
    px_conj cj;
    double t0 = now(), z = 0;
    unsigned x = 12345;
    px_system_init(&s, 1);
    for (int i = 0; i < NSURF; i++) {
        double u, r;
        x = x * 1103515245u + 12345u;
        u = (x >> 8) / 16777216.0;
        r = (50 + 450 * u) * (i % 2 ? 1 : -1);
        px_system_translate(&s, z);
        px_system_refract(&s, r, 1 + u);
        z += 0.1 + 2 * u;
    }
    px_first_order(&s, &f);
    px_conjugate(&s, -100, &cj);
    *sink += f.power.cond + cj.d2.cond;
    px_system_free(&s);
    return now() - t0;
}

int main(int argc, char **argv)
{
    int runs = argc > 1 ? atoi(argv[1]) : 21;
    double *t = malloc(sizeof *t * (runs > 0 ? runs : 1)), sink = 0, f = 37.3;
    px_system s;
    px_first fo;
    if (!t || runs < 1) return 1;
    for (int i = 0; i < runs; i++) t[i] = one_run(&sink);
    qsort(t, runs, sizeof *t, cmp);
    printf("BENCH paraxial_surfaces_per_s %.0f surfaces/s\n", NSURF / t[runs / 2]);

    px_system_init(&s, 1);                   /* relay: thin lenses f = 37.3, 2f apart */
    for (int i = 0; i < NSURF / 2; i++) {
        px_system_translate(&s, i * 2 * f);
        px_system_refract(&s, f, 1.5);
        px_system_refract(&s, -f, 1.0);
    }
    px_first_order(&s, &fo);
    printf("BENCH paraxial_det_drift %.3g abs\n", fabs(fo.det - 1));
    printf("BENCH paraxial_det_drift_listing %.3g abs\n", fabs(px_det(s.m) - 1));
    px_system_free(&s);
    free(t);
    return sink < 0;   /* keep the work */
}
