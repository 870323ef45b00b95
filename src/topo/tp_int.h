/* tp_int.h -- the topography pipeline's internal declarations (one file per job:
 * tp_pattern.c, tp_loop.c; the table in tp_api.c). */
#ifndef TP_INT_H
#define TP_INT_H
#include "topo.h"

int tp_pattern(int pattern, int n, double zone, rg_target *t);
int tp_measure(tp_run *r, char *err, size_t cap);
void tp_counts(const tp_run *r, int counts[6]);
#endif
