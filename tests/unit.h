/* unit.h -- the smallest test framework that works: CHECK prints one PASS or FAIL
 * line per check (tests/run.sh counts them); main returns unit_failed(). */
#ifndef UNIT_H
#define UNIT_H
#include <stdio.h>
#include <stdlib.h>

static int unit_fails;

#define CHECK(cond, ...) do {                                                  \
        if (cond) { printf("PASS "); printf(__VA_ARGS__); printf("\n"); }      \
        else { unit_fails++; printf("FAIL %s:%d: ", __FILE__, __LINE__);       \
               printf(__VA_ARGS__); printf("  [%s]\n", #cond); }               \
    } while (0)

static inline int unit_failed(void) { return unit_fails != 0; }

/* A whole file (up to 1 MiB), NUL-terminated, in a static buffer that the next call
 * reuses; NULL if it cannot be opened. */
static inline char *unit_slurp(const char *path)
{
    static char buf[1 << 20];
    FILE *f = fopen(path, "rb");
    size_t n;
    if (!f) return NULL;
    n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = 0;
    fclose(f);
    return buf;
}

/* A fresh folder /tmp/NAME.XXXXXX in dir (cap bytes); 0, or -1.  unit_rmtree removes
 * it and what it holds. */
static inline int unit_tmpdir(char *dir, size_t cap, const char *name)
{
    snprintf(dir, cap, "/tmp/%s.XXXXXX", name);
    return mkdtemp(dir) ? 0 : -1;
}
static inline void unit_rmtree(const char *dir)
{
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd)) {}
}

#endif
