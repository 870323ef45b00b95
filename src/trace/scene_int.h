/* scene_int.h -- what the trace front end's readers share (scene_lex.c, scene_mesh.c,
 * scene_read.c, scene_fields.c, scene_axial.c): the line and token reader with its
 * FILE:LINE errors, a directive's fields, growable arrays of doubles, and the
 * axial-surface checks of a parsed scene.  Not part
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

/* The fields of one directive line (scene_fields.c): per key of the scene files'
 * table, whether the line gave it, its numbers (count of them), its word (a file or a
 * coating name), for a key read by its own reader the first token, and for an index
 * key the glass named ("": a number). */
#define SC_NKEYS 42
typedef struct fields {
    int has[SC_NKEYS];
    double num[SC_NKEYS][SC_MAXCOEF];
    int count[SC_NKEYS];
    tok word[SC_NKEYS];
    int at[SC_NKEYS];
    char glass[SC_NKEYS][2][SC_GLASSMAX];
} fields;
/* Key k's index in the table, or -1. */
int sf_key_index(const tok *t);
/* Read t[first..] as key/value groups allowed by `allowed` (space-separated key names)
 * into f; 0 or -1 (FILE:LINE in r->err, dname naming the directive). */
int sf_parse_fields(reader *r, int first, const char *dname, const char *allowed, fields *f);
int sf_has(const fields *f, const char *k);
const double *sf_val(const fields *f, const char *k);
char *sf_tok_dup(const tok *t);
/* Key k as a unit vector (a zero one refused). */
int sf_unit_vec(reader *r, const fields *f, const char *dname, const char *k, double *u);
/* Every key of the space-separated list given, else "'KEY' is missing". */
int sf_need(reader *r, const fields *f, const char *dname, const char *list);
int sf_positive(reader *r, const char *dname, const char *what, double v);
/* Key k's value as an integer in [lo, hi]. */
int sf_int_val(reader *r, const fields *f, const char *dname, const char *k, long lo,
               long hi, long *out);
/* `up` projected perpendicular to the unit direction d (none: some perpendicular). */
int sf_up_vector(reader *r, const fields *f, const char *dname, const double *d, double *u);

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
