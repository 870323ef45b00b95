/* scene_pol.h -- polarization in a scene's run (scene_polout.c), for scene_run.c: the
 * engine told of each surface's element and coating, and the `output polar` table.
 * Internal to the scene front end. */
#ifndef SCENE_POL_H
#define SCENE_POL_H
#include <stdint.h>
#include "common/lm_out.h"
#include "scene_int.h"

typedef struct sp_out {
    lm_out o;                   /* the table's file (a .part until committed) */
    int open, bad, fmt, wl;     /* fmt: SC_OUT_TEXT (CSV) or SC_OUT_NPY */
    long header;                /* .npy: its header's bytes (rewritten at the end) */
    uint64_t rows, ray0;        /* rows written; rays of the wavelengths before */
    double nm;                  /* the run's wavelength column */
    double stokes[4];           /* the last record's S0..S3 (for the hits' columns:
                                   the engine hands it just before its hit), else NaN */
} sp_out;

/* Open the table (sc->out_polar); 0 or -1 (err).  (Without one, po is still the
 * records' sink: sp_engine hands them to it for the hits' Stokes columns.) */
int sp_open(const sc_scene *sc, sp_out *po, char *err);
/* Polarization on in ts for a run at l um (0: none named) whose rays are numbered from
 * ray0: elements, coatings, the table's rows.  0 or -1 (err: FILE:LINE). */
int sp_engine(const trace_api *tr, trace_scene *ts, const sc_scene *sc, double l,
              uint64_t ray0, sp_out *po, char *err);
/* Commit the table when ok, else keep it as .part; 0 or -1 (err). */
int sp_finish(sp_out *po, int ok, char *err);
#endif
