/* engine.h -- the seam to engines that need big libraries (Embree, OpenCV, libgpiod).
 * Such an engine is built as a module build/lib/lensmat-NAME.so and loaded with
 * dlopen the first time a dialogue needs it, so a session that never uses it never
 * pays for its libraries.  A module exports one function that returns its table of
 * entry points (declared in the engine's own header). */
#ifndef ENGINE_H
#define ENGINE_H

/* Load module `name` (e.g. "trace") once: its handle, or NULL after printing why on
 * stderr.  Looked for, in order, in $LENSMAT_LIBDIR, EXEDIR/lib, EXEDIR/build/lib
 * (the build tree) and EXEDIR/../lib/lensmat (an installed tree: PREFIX/bin/lensmat
 * finds PREFIX/lib/lensmat), EXEDIR being the folder of the running lensmat. */
void *lm_engine_load(const char *name);
/* 1 if module `name` is there (loaded, or a readable file where lm_engine_load looks:
 * checked before a dialogue's first question without loading it, so the libraries it
 * links are paid for only at its first use), else 0 after printing why. */
int lm_engine_present(const char *name);
/* Module `name`'s symbol `sym`, or NULL after printing why on stderr. */
void *lm_engine_symbol(const char *name, const char *sym);
/* Make every later load fail as if no module were installed (fuzzers, tests). */
void lm_engine_disable(void);

#endif
