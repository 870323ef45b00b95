/* ds_api.c -- the design module's table (design.h): what the problem says about its
 * variables, operands and tolerances, the merit, and the optimised lens written back
 * as a prescription with the file's own design lines. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "ds_int.h"

static int nvar(const ds_problem *p) { return p->nvar; }
static int nop(const ds_problem *p) { return p->nop; }
static int ntol(const ds_problem *p) { return p->ntol; }

static void var_info(const ds_problem *p, int i, ds_var_info *out)
{
    static const char *const k[] = {"c", "t", "k", "a", "nd", "vd"};
    const ds_var *v = &p->var[i];
    memset(out, 0, sizeof *out);
    if (v->kind == DV_A) snprintf(out->name, sizeof out->name, "a%d %d", 2 * v->term + 2, v->surf + 1);
    else snprintf(out->name, sizeof out->name, "%s %d", k[v->kind], v->surf + 1);
    out->value = ds_get_var(p, i);
    out->line = v->line;
}

static void tol_info(const ds_problem *p, int i, ds_tol_info *out)
{
    static const char *const k[] = {"r", "t", "n", "k"};
    const ds_tol *t = &p->tol[i];
    memset(out, 0, sizeof *out);
    if (t->kind == DT_TILT || t->kind == DT_DEC) {
        const ds_grp *g = &p->grp[t->grp];
        char what[4] = {t->kind == DT_TILT ? 't' : 'd', t->axis ? 'y' : 'x', 0, 0};
        if (g->s0 == g->s1) snprintf(out->name, sizeof out->name, "%s %d", what, g->s0 + 1);
        else snprintf(out->name, sizeof out->name, "%s %d-%d", what, g->s0 + 1, g->s1 + 1);
        out->angle = t->kind == DT_TILT;
    } else {
        snprintf(out->name, sizeof out->name, "%s %d", k[t->kind], t->surf + 1);
    }
    out->delta = t->delta;
    out->line = t->line;
}

static int merit(ds_problem *p, double *m, char *err, size_t cap)
{
    long n = ds_nres(p);
    double *f = malloc(sizeof(double) * (size_t)(n ? n : 1));
    char why[512];
    if (!f) { snprintf(err, cap, "out of memory"); return DS_NOMEM; }
    int rc = ds_eval(p, f, why, sizeof why);
    if (rc) {
        free(f);
        snprintf(err, cap, "%s: the lens cannot be evaluated: %s", p->src, why);
        return DS_BAD;
    }
    *m = ds_merit_of(p, f);
    free(f);
    return DS_OK;
}

static void op_info(const ds_problem *p, int i, ds_op_info *out)
{
    static const char *const k[] = {"efl", "bfd", "totr", "rms", "dist", "axcl", "spha",
                                    "ct", "et", "glassmap", "coma", "asti", "fcur", "sdis",
                                    "lacl", "rmsw"};
    const ds_op *o = &p->op[i];
    double W = 0, d = o->value - o->target;
    char extra[64] = "";
    memset(out, 0, sizeof *out);
    for (int j = 0; j < p->nop; j++) W += p->op[j].weight;
    if (o->kind == DO_RMS || o->kind == DO_DIST || o->kind == DO_RMSW) {
        if (o->wave >= 0) snprintf(extra, sizeof extra, " field %d wave %d", o->field + 1, o->wave + 1);
        else snprintf(extra, sizeof extra, " field %d", o->field + 1);
    } else if (o->kind == DO_CT || o->kind == DO_ET || o->kind == DO_GMAP) {
        snprintf(extra, sizeof extra, " surface %d", o->surf + 1);
    }
    snprintf(out->name, sizeof out->name, "%s%s%s", o->bound > 0 ? "min " : o->bound < 0 ?
             "max " : "", k[o->kind], extra);
    if (o->bound > 0 && d > 0) d = 0;
    if (o->bound < 0 && d < 0) d = 0;
    out->target = o->target;
    out->weight = o->weight;
    out->value = o->value;
    out->line = o->line;
    /* share of MF^2 (sum of w d^2 over every operand) */
    double tot = 0;
    for (int j = 0; j < p->nop; j++) {
        const ds_op *q = &p->op[j];
        double e = q->value - q->target;
        if (q->bound > 0 && e > 0) e = 0;
        if (q->bound < 0 && e < 0) e = 0;
        tot += q->weight * e * e;
    }
    out->contribution = tot > 0 ? 100 * o->weight * d * d / tot : 0;
    (void)W;
}

static void describe(const ds_problem *p, char *buf, size_t cap)
{
    /* the half pupil only while the lens is symmetric in x (ds_setup's xsym): not with
     * a break that decentres in x or turns about y or z, nor tolerances that do */
    int whole = 0;
    for (int i = 0; i < p->lens.nsurf; i++) {
        const ln_surface *s = &p->lens.surf[i];
        whole |= s->coordbrk && (s->cb_dec[0] != 0 || s->cb_tilt[1] != 0 || s->cb_tilt[2] != 0);
    }
    for (int i = 0; i < p->ntol; i++)
        whole |= (p->tol[i].kind == DT_DEC && p->tol[i].axis == 0) ||
                 (p->tol[i].kind == DT_TILT && p->tol[i].axis == 1);
    snprintf(buf, cap, "Gaussian quadrature pupil: %d ring%s x %d arm%s (%d rays per field "
             "and wavelength, %s), %s, no vignetting; "
             "method %s", p->rings, p->rings == 1 ? "" : "s", p->arms,
             p->arms == 1 ? "" : "s", p->rings * p->arms,
             whole ? "the whole pupil traced: the lens or its tolerances are not symmetric in x"
                   : "the x > 0 half traced for fields in y",
             p->aim_paraxial ? "rays sent at the paraxial entrance pupil" :
                               "rays aimed at the stop",
             p->method ? "Levenberg-Marquardt with geodesic acceleration" :
                         "Levenberg-Marquardt");
}

static char *write_lens(const ds_problem *p)
{
    char *rx = ln_write_rx(&p->lens), *out;
    const char *head = "# lensmat --optimise: the design lines it read\n";
    if (!rx) return NULL;
    if (!p->merit_len) return rx;
    size_t a = strlen(rx), h = strlen(head);
    out = malloc(a + h + p->merit_len + 1);
    if (!out) { free(rx); return NULL; }
    memcpy(out, rx, a);
    memcpy(out + a, head, h);
    memcpy(out + a + h, p->merit_lines, p->merit_len);
    out[a + h + p->merit_len] = '\0';
    free(rx);
    return out;
}

static void tol_defaults(const ds_problem *p, ds_tol_opts *o) { *o = p->topt; }
static const char *unit(const ds_problem *p) { return p->lens.unit[0] ? p->lens.unit : "mm"; }

static const ds_api api = {
    DS_ABI, ds_read, ds_free, nvar, nop, ntol, var_info, tol_info, merit, op_info,
    describe, ds_optimise, write_lens, ds_tol_nominal, ds_tol_one, ds_tol_mc, tol_defaults, unit,
};

__attribute__((visibility("default"))) const ds_api *ds_get_api(int abi)
{
    return abi == DS_ABI ? &api : NULL;
}
