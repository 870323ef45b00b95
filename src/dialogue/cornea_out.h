/* cornea_out.h -- the --cornea-scan dialogue's files: the report (the text the session
 * said, CSV and JSON), the maps (PNG, through the imaging engine) and the frames'
 * manifest, each through the shared writer (src/common/lm_out.h). */
#ifndef CORNEA_OUT_H
#define CORNEA_OUT_H
#include <stddef.h>
#include "ask.h"
#include "../rig/rig.h"
#include "../cornea/cornea.h"

/* A number the dialogue adds to the report (scan settings, the simulated truth, the
 * errors): a CSV row `name,value,sd,unit` and a member of the JSON "dialogue"
 * object.  sd NaN: none. */
typedef struct cs_row { const char *name; double v, sd; const char *unit; } cs_row;

/* The files a report NAME makes: NAME.txt NAME.csv NAME.json NAME-elevation.png
 * NAME-axial.png NAME-tangential.png NAME-residual.png NAME-axial-abs.png
 * (NULL-terminated suffixes). */
extern const char *const cs_out_suffix[];
/* lm_ask_word's check for the report's name: "-" (none), or a name none of whose
 * files (or their .part) is an input of this session, in a writable folder. */
int cs_check_name(void *io, const char *word, char *msg, size_t cap);
/* The report, the one place it is made: NAME.txt (text[len]: every line the session
 * said about the measurement), NAME.csv and NAME.json (the engine's numbers for the
 * fit r of spots sp[n], then rows[nrows]).  All three are written as .part first and
 * renamed only when all are complete and no stop was asked: a stopped session leaves
 * none of them.  0, or -1 with why in msg. */
int cs_write_report(const cornea_api *cn, const char *name, const char *text, size_t len,
                    const cn_result *r, const cn_spot *sp, int n, const cs_row *rows,
                    int nrows, char *msg, size_t cap);
/* The maps.  zf (NULL: the fitted model's surface): the surface from the data, drawn
 * only where there are data, with its indices kc on the pictures, and the axial map
 * a second time on the absolute scale.  eye: 1 OD, 2 OS (the title names it, the x
 * axis its nasal and temporal sides), 0 not named (both readings of x are said).
 * say(ctx, line) is told each map's scale and file.  0, or -1 with why in msg (a
 * stop: no file under its final name). */
int cs_write_maps(const cornea_api *cn, const rg_geometry *g, const char *name,
                  const cn_result *r, const cn_spot *sp, int n, const cn_zfit *zf,
                  const cn_kc *kc, int eye,
                  int (*stop)(void *), void (*say)(void *ctx, const char *line),
                  void *ctx, char *msg, size_t cap);
/* The manifest of one scan's frames: PATTERN with its %d made "-frames" and its
 * extension ".txt" (frames/g%04d.png: frames/g-frames.txt), in name (cap bytes). */
void cs_manifest_name(const char *pattern, char *name, size_t cap);
/* Writes it: which frames this scan wrote (seq numbers seq[0..n-1], in order) of the
 * nplanned it would write, and how the scan ended (status: "complete", "interrupted
 * during ...").  Frames of an earlier scan that the same pattern names but the list
 * does not are not this scan's.  0, or -1 with why in msg. */
int cs_write_manifest(const char *pattern, const int *seq, int n, int nplanned,
                      const char *status, char *msg, size_t cap);
#endif
