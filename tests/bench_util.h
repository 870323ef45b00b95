/* bench_util.h -- what every benchmark program needs: a monotonic clock in seconds
 * and a comparison of doubles for qsort (medians of repeated runs). */
#ifndef BENCH_UTIL_H
#define BENCH_UTIL_H
#include <time.h>

static inline double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static inline int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

#endif
