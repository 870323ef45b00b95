/* tr_isa.c -- which packet step this process runs (tr_packet.h): the widest kernel
 * the processor can execute, chosen once when the module loads, or the one the
 * environment variable LENSMAT_ISA names (avx512, avx2, sse2 on x86-64; neon on
 * arm64; scalar: no packets, rays one by one).  Every choice gives the same bits;
 * the variable is there to measure and test each.  A name this processor cannot run
 * falls to the best it can below it; an unknown name (or "auto") means the best. */
#include <stdlib.h>
#include <string.h>
#include "tr_packet.h"

typedef struct tr_isa {
    const char *name;
    tr_pk_step_fn step;          /* NULL: rays one by one */
} tr_isa;

static const tr_isa isas[] = {
#if defined(__x86_64__)
    {"avx512", tr_pk_step_avx512},
    {"avx2", tr_pk_step_avx2},
    {"sse2", tr_pk_step_base},
    {"sse2x4", tr_pk_step_base4},
#elif defined(__aarch64__)
    {"neon", tr_pk_step_base},
    {"neonx4", tr_pk_step_base4},
#else
    {"generic", tr_pk_step_base},
#endif
    {"scalar", NULL},
};
enum { NISA = sizeof isas / sizeof isas[0] };

static int chosen = NISA - 1;
static tr_pk_step_fn step_fn;

/* 1 if this processor (and its operating system) runs isas[i]. */
static int isa_usable(int i)
{
#if defined(__x86_64__)
    __builtin_cpu_init();
    if (isas[i].step == tr_pk_step_avx512)
        return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
               __builtin_cpu_supports("avx512dq");
    if (isas[i].step == tr_pk_step_avx2) return __builtin_cpu_supports("avx2");
#endif
    return i >= 0 && i < NISA;
}

/* At load, before any trace runs (so no thread ever sees the choice change). */
__attribute__((constructor)) static void isa_choose(void)
{
    const char *want = getenv("LENSMAT_ISA");
    int i = 0;
    if (want && *want)
        for (int k = 0; k < NISA; k++)
            if (!strcmp(isas[k].name, want)) i = k;
    while (!isa_usable(i)) i++;            /* "scalar", the last, always is */
    chosen = i;
    step_fn = isas[i].step;
}

int tr_pk_usable(void)
{
    return step_fn != NULL;
}

unsigned tr_pk_step(const tr_pk *in, tr_pk *out, tr_pk_aux *x, const tr_pk_set *s,
                    unsigned live, const tr_pk_opt *o)
{
    return step_fn(in, out, x, s, live, o);
}

const char *trace_isa_name(int i, int *usable)
{
    if (i < 0 || i >= NISA) return NULL;
    if (usable) *usable = isa_usable(i);
    return isas[i].name;
}

const char *trace_isa_active(void)
{
    return isas[chosen].name;
}
