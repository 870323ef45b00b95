/* engine.h -- the seam to engines that need big libraries (Embree, OpenCV, libgpiod).
 * Such an engine is built as a module build/lib/lensmat-NAME.so and loaded with
 * dlopen the first time a dialogue needs it, so a session that never uses it never
 * pays for its libraries.  A module exports one function that returns its table of
 * entry points (declared in the engine's own header). */
#ifndef ENGINE_H
#define ENGINE_H

/* Find module `name` (e.g. "trace") and return its symbol `sym`, or NULL after
 * printing why on stderr.  Looked for in $LENSMAT_LIBDIR, then EXEDIR/lib and
 * EXEDIR/build/lib (EXEDIR: the folder of the running lensmat). */
void *lm_engine_symbol(const char *name, const char *sym);

#endif
