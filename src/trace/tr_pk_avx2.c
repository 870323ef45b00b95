/* tr_pk_avx2.c -- the packet step (tr_pk_kernel.h) compiled for AVX2: four lanes a register,
 * two chunks a packet.  x86-64 only; tr_isa.c calls it only where the processor has the instructions. */
#if defined(__x86_64__)
#pragma GCC target("avx2")
#define PK_W 4
#define PK_FN tr_pk_step_avx2
#include "tr_pk_kernel.h"
#else
typedef int tr_pk_avx2_none;        /* other processors: nothing here */
#endif
