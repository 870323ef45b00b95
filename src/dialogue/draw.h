/* draw.h -- the pictures of the --trace dialogue: trace.c remembers the lens and
 * object it just traced (lm_draw_remember) and its "draw" choice asks for pictures of
 * them (lm_draw_last), with the questions and texts of the --draw dialogue. */
#ifndef DRAW_H
#define DRAW_H
#include "ask.h"
#include "../trace/trace.h"

void lm_draw_remember(const trace_lens *l, double z_obj, double frac);
int  lm_draw_last(lm_io *io);

#endif
