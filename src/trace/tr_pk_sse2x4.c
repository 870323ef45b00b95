/* tr_pk_sse2x4.c -- the packet step (tr_pk_kernel.h) at four lanes on the instructions
 * every processor of the architecture has (SSE2 on x86-64, NEON on arm64): each
 * four-lane vector is two 128-bit registers, two chunks a packet (issue 23: does a
 * wider chunk of the base instructions beat tr_pk_base.c's two lanes?).  No target
 * pragma: the build's own -march decides. */
#define PK_W 4
#define PK_SPLIT 1   /* 4-lane vectors on 2-lane registers */
#define PK_FN tr_pk_step_base4
#include "tr_pk_kernel.h"
