/* dsu.h -- what the design engine's tests share: the two modules' tables, a problem
 * from a text in memory, and a thin-lens / thick-lens paraxial model of the tests'
 * own (ABCD matrices, written here, never the engine's) for the closed forms. */
#ifndef DSU_H
#define DSU_H
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "design/design.h"
#include "trace/trace.h"
#include "unit.h"

static const ds_api *ds;
static const trace_api *tr;

static void dsu_init(void)
{
    ds = ds_get_api(DS_ABI);
    tr = trace_get_api(TRACE_ABI);
    if (!ds || !tr) { printf("FAIL no design or trace table\n"); exit(1); }
}

/* A problem from text (merit lines inside); NULL (and a FAIL line) if refused. */
static ds_problem *dsu_problem(const char *text, char *err, size_t cap)
{
    ds_problem *p = NULL;
    if (ds->read(text, strlen(text), "test.rx", NULL, 0, NULL, tr, &p, err, cap) != DS_OK)
        return NULL;
    return p;
}

static inline char *dsu_slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    char *b = malloc(1 << 20);
    size_t n = b ? fread(b, 1, (1 << 20) - 1, f) : 0;
    fclose(f);
    if (b) b[n] = '\0';
    return b;
}

/* The tests' own paraxial model: surfaces (curvature c, thickness t after, index n
 * after) from an object at infinity in air; efl and back focus by y-nu tracing. */
static void dsu_yn(int ns, const double *c, const double *t, const double *n,
                   double *efl, double *bfd)
{
    double y = 1, nu = 0, n0 = 1;
    for (int i = 0; i < ns; i++) {
        nu = nu - y * c[i] * (n[i] - n0);
        n0 = n[i];
        if (i + 1 < ns) y += t[i] * nu / n0;
    }
    *efl = -1 / nu;               /* unit height in, slope nu/n' out (n' = 1 behind) */
    *bfd = -y / (nu / n0) ;
}
#endif
