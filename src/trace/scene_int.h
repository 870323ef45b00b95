/* scene_int.h -- what the trace front end's readers share (scene_lex.c, scene_mesh.c,
 * scene_read.c, scene_axial.c): the line and token reader with its FILE:LINE errors,
 * growable arrays of doubles, and the axial-surface checks of a parsed scene.  Not part
 * of the module's face (that is scene.h). */
#ifndef SCENE_INT_H
#define SCENE_INT_H
#include <stddef.h>
#include "scene.h"

#define MAXTOK 64          /* items on one line */
#define NUMLEN 64          /* longest number token */

typedef struct tok { const char *s; size_t n; } tok;

typedef struct reader {
    const char *p, *end, *name;
    long line;
    tok t[MAXTOK];
    int nt;
    char *err;
} reader;

/* "NAME:LINE: " and the message into r->err (SC_ERRMAX); returns -1. */
int sl_fail(reader *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
void sl_reader_init(reader *r, const char *text, size_t len, const char *name, char *err);
/* Next line with at least one item (comments and blank lines skipped).  1 with the
 * items in r->t, 0 at the end, -1 on an error. */
int sl_next_line(reader *r);
int sl_tok_is(const tok *t, const char *w);
/* A finite decimal number (no hex, inf or nan), 0 or 1e-30 <= |x| <= 1e30.  0 or -1
 * (error reported). */
int sl_tok_num(reader *r, const tok *t, const char *what, double *v);
/* The whole line as exactly n numbers. */
int sl_line_nums(reader *r, int n, const char *what, double *v);

/* Growable arrays of doubles. */
typedef struct dvec { double *v; size_t n, cap; } dvec;
int sl_dvec_push(dvec *a, const double *x, size_t k);

/* Small 3-vectors. */
static inline void sub3(const double *a, const double *b, double *c)
{
    c[0] = a[0] - b[0]; c[1] = a[1] - b[1]; c[2] = a[2] - b[2];
}
static inline double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static inline void cross3(const double *a, const double *b, double *c)
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* Axial surfaces along one axis: consecutive ones whose sags cross within their
 * apertures are an error (err, FILE:LINE of both); media that disagree are counted
 * and located in sc.  0 or -1. */
int sc_axial_pairs(sc_scene *sc, char *err);

/* Polarization lines (scene_polar.c): `coating`, `polarization`, `output polar`; after
 * the file, coatings found by name and polarization switched on where needed (0 or -1
 * with FILE:LINE in err); the scene's polarization data freed. */
int sc_polar_directive(reader *r, sc_scene *sc);
int sc_polar_resolve(sc_scene *sc, char *err);
void sc_polar_free(sc_scene *sc);
/* A source's `pol` key, its n tokens from r->t[first]: `pol X Y Z` (linear), `pol
 * right|left` (circular), `pol ellipse AZ CHI` (degrees), `pol jones JX JY PX PY`
 * (amplitudes, phases in degrees), `pol stokes S1 S2 S3` (partially polarized, over
 * S0) into s (polarised, pol, jones, stokes); 0 or -1 (FILE:LINE). */
int sc_source_pol(reader *r, int first, int n, const char *dname, sc_source *s);

#endif
