/* tr_pk_base.c -- the packet step (tr_pk_kernel.h) for the instructions every
 * processor of the architecture has: SSE2 on x86-64, NEON (Advanced SIMD) on arm64,
 * two lanes of doubles a register, four chunks a packet.  No target pragma: the
 * build's own -march decides. */
#define PK_W 2
#define PK_FN tr_pk_step_base
#include "tr_pk_kernel.h"
