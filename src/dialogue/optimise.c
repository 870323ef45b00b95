/* optimise.c -- the --optimise dialogue: a lens file and its merit (the design lines
 * of doc/design.md, in the lens file or a merit file of their own), damped least
 * squares by the design module (loaded on first use, with the trace module it
 * traces through), the merit against iteration, and the optimised prescription
 * written through a temporary name.  Seconds go to the terminal only, so that the
 * record replays exactly.  Texts in prompts/optimise.txt. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "calcio.h"
#include "designio.h"
#include "dialogues.h"
#include "prompts_optimise.h"

#define P(k) optimise_prompts[OPTIMISE_##k]

typedef struct odlg {
    lm_io *io;
    calc c;
    dz_files f;
    const ds_api *ds;
    int iters;
    char out[4096];
} odlg;


static int check_out(void *ctx, const char *w, char *msg, size_t cap)
{
    odlg *d = ctx;
    return dz_check_out(d->io, &d->f, w, msg, cap) ? 1 : 0;
}

static void ops(odlg *d)
{
    for (int i = 0; i < d->ds->nop(d->f.p); i++) {
        ds_op_info o;
        d->ds->op_info(d->f.p, i, &o);
        calc_say(&d->c, P(OP_ROW), o.name, o.target, o.weight, lm_clean(d->io, o.value),
                 o.contribution, o.line);
    }
}

static void vars(odlg *d)
{
    for (int i = 0; i < d->ds->nvar(d->f.p); i++) {
        ds_var_info v;
        d->ds->var_info(d->f.p, i, &v);
        calc_say(&d->c, P(VAR_ROW), v.name, lm_clean(d->io, v.value), v.line);
    }
}

static int progress(void *ctx, const ds_step *s)
{
    odlg *d = ctx;
    lm_say(d->io, LM_OUT, P(ITER_TIME), s->iter, s->merit, s->evaluations, s->seconds);
    lm_say(d->io, LM_REC, P(ITER_ROW), s->iter, s->merit, s->evaluations);
    return lm_stop_requested() != 0;
}

static int stop(void *ctx) { (void)ctx; return lm_stop_requested() != 0; }

static int run(odlg *d)
{
    const ds_api *ds = d->ds;
    ds_problem *p = d->f.p;
    ds_opt_result r;
    char err[DS_ERR_MAX], desc[512];
    double m;
    int nv = ds->nvar(p), no = ds->nop(p);
    calc_say(&d->c, P(HEAD), d->f.lens, nv, nv == 1 ? "" : "s", no, no == 1 ? "" : "s");
    ds->describe(p, desc, sizeof desc);
    calc_say(&d->c, P(SAMPLING), desc);
    if (ds->merit(p, &m, err, sizeof err) != DS_OK) {
        calc_say(&d->c, P(REFUSED), err);
        fprintf(stderr, P(ERR), err);
        return LM_FAIL;
    }
    calc_say(&d->c, "%s", P(VAR_HEAD));
    vars(d);
    calc_say(&d->c, "%s", P(OP_HEAD));
    ops(d);
    int rc = ds->optimise(p, d->iters, progress, stop, d, &r, err, sizeof err);
    if (rc == DS_STOPPED || lm_stop_requested()) {
        calc_say(&d->c, "%s", P(STOPPED));
        fprintf(stderr, "%s", P(STOPPED_ERR));
        return LM_FAIL;
    }
    if (rc != DS_OK) {
        calc_say(&d->c, P(REFUSED), err);
        fprintf(stderr, P(ERR), err);
        return LM_FAIL;
    }
    calc_say(&d->c, P(METHOD), r.method);
    calc_say(&d->c, P(DONE), r.merit0, r.merit, r.iterations,
             r.reason == 1 ? P(REASON_STEP) : r.reason == 2 ? P(REASON_GRAD) :
             r.reason == 3 ? P(REASON_ITER) : P(REASON_FLAT));
    lm_say(d->io, LM_OUT, P(TIME), r.seconds, r.evaluations);
    calc_say(&d->c, "%s", P(VAR_END));
    vars(d);
    calc_say(&d->c, "%s", P(OP_END));
    ops(d);
    char *text = ds->write(p);
    if (!text) return LM_FAIL;
    if (dz_write(d->out, text, strlen(text), err, sizeof err)) {
        free(text);
        calc_say(&d->c, P(REFUSED), err);
        fprintf(stderr, P(ERR), err);
        return LM_FAIL;
    }
    free(text);
    calc_say(&d->c, P(WROTE), d->out);
    return LM_GO;
}

int lm_optimise(lm_io *io)
{
    odlg dd, *d = &dd;
    int rc;
    memset(d, 0, sizeof *d);
    d->io = io;
    d->c.io = io;
    d->c.unit = PX_MM;
    d->c.uname = "mm";
    if (!(d->ds = dz_api())) return LM_FAIL;
    rc = dz_ask_files(io, P(FILE), P(FILE_WHAT), P(MERIT), P(MERIT_WHAT), &d->f);
    if (rc == LM_GO)
        rc = lm_ask_count(io, P(ITER), P(ITER), P(ITER_WHAT), P(ITER_BAD), 1, 10000, &d->iters);
    if (rc == LM_GO)
        rc = lm_ask_word(io, P(OUT), P(OUT), P(OUT_WHAT), check_out, d, d->out, sizeof d->out);
    if (rc == LM_GO) rc = lm_stop_requested() ? LM_FAIL : run(d);
    if (rc == LM_GO) rc = calc_done(&d->c);
    if (d->f.p) d->ds->free(d->f.p);
    return rc;
}
const char *lm_optimise_example(void) { return P(EXAMPLE); }
