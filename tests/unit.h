/* unit.h -- the smallest test framework that works: CHECK prints one PASS or FAIL
 * line per check (tests/run.sh counts them); main returns unit_failed(). */
#ifndef UNIT_H
#define UNIT_H
#include <stdio.h>

static int unit_fails;

#define CHECK(cond, ...) do {                                                  \
        if (cond) { printf("PASS "); printf(__VA_ARGS__); printf("\n"); }      \
        else { unit_fails++; printf("FAIL %s:%d: ", __FILE__, __LINE__);       \
               printf(__VA_ARGS__); printf("  [%s]\n", #cond); }               \
    } while (0)

static inline int unit_failed(void) { return unit_fails != 0; }

#endif
