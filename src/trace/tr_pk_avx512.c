/* tr_pk_avx512.c -- the packet step (tr_pk_kernel.h) compiled for AVX-512: eight lanes, one register.
 * x86-64 only; tr_isa.c calls it only where the processor has the instructions. */
#if defined(__x86_64__)
#pragma GCC target("avx2,avx512f,avx512vl,avx512dq")
#define PK_W 8
#define PK_FN tr_pk_step_avx512
#include "tr_pk_kernel.h"
#else
typedef int tr_pk_avx512_none;        /* other processors: nothing here */
#endif
