/* cn_export.c -- the measurement report as a file format: every number of a fit
 * (model, parameters with uncertainties, Sim K at the apex and over the 3 mm zone,
 * residuals, singular values, what is not determined, the spots left out and why) as
 * CSV rows `quantity,value,sd,unit` or as one JSON object, so two scans can be
 * compared by a script.  Both are built from one list of quantities. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "cn_int.h"

static const char *const model_names[] = {"sphere", "conic", "biconic", "asphere"};
static const char *const status_names[] = {"ok", "no_spot", "several_spots", "outlier",
                                           "missed_cornea"};
static const char *const units[CN_NPARAM] = {"mm", "1/mm", "1/mm", "", "", "mm", "mm",
                                             "mm", "rad", "rad", "mm^-3", "mm^-5"};

typedef struct qty { const char *name; double v, sd; const char *unit; } qty;

/* The clinical and fit numbers, in report order; returns how many. */
static int quantities(const cn_result *r, qty *q)
{
    const cn_clinical *k = &r->k;
    int n = 0;
#define Q(nm, val, s, u) (q[n++] = (qty){nm, val, s, u})
    Q("R", k->R, k->sd_R, "mm");
    Q("Q", k->Q, r->free[CN_QF] ? k->sd_Q : NAN, "");
    Q("R_flat", k->R_flat, k->sd_R_flat, "mm");
    Q("R_steep", k->R_steep, k->sd_R_steep, "mm");
    Q("Q_flat", k->Q_flat, r->free[CN_QF] ? k->sd_Q_flat : NAN, "");
    Q("Q_steep", k->Q_steep, r->free[CN_QF] ? k->sd_Q_steep : NAN, "");
    Q("K1", k->K1, k->sd_K1, "D");
    Q("K1_axis", k->K1_axis, k->sd_axis, "deg");
    Q("K2", k->K2, k->sd_K2, "D");
    Q("K2_axis", k->K2_axis, k->sd_axis, "deg");
    Q("Km", k->Km, k->sd_Km, "D");
    Q("cyl", k->cyl, k->sd_cyl, "D");
    Q("P", k->P, k->sd_P, "D");
    Q("zone_h", k->zone_h, NAN, "mm");
    Q("zK1", k->zK1, k->sd_zK1, "D");
    Q("zK1_axis", k->zK1_axis, k->sd_zaxis, "deg");
    Q("zK2", k->zK2, k->sd_zK2, "D");
    Q("zK2_axis", k->zK2_axis, k->sd_zaxis, "deg");
    Q("zKm", k->zKm, k->sd_zKm, "D");
    Q("zcyl", k->zcyl, k->sd_zcyl, "D");
    Q("dx", k->dx, k->sd_dx, "mm");
    Q("dy", k->dy, k->sd_dy, "mm");
    Q("dz", k->dz, k->sd_dz, "mm");
    Q("tilt_x", k->tx, k->sd_tx, "deg");
    Q("tilt_y", k->ty, k->sd_ty, "deg");
    Q("rms", r->rms * 1000, NAN, "um");
    Q("chi2_dof", r->chi2_dof, NAN, "");
    Q("chi2_z", r->chi2_z, NAN, "sd");
    Q("condition", r->cond, NAN, "");
    Q("hmax", r->hmax, NAN, "mm");
    Q("resid_corr", r->resid_corr, NAN, "");
#undef Q
    return n;
}

/* A number as text: %.10g, "inf" / "nan" in CSV, null in JSON. */
static const char *num(double v, int json, char *b)
{
    if (isfinite(v)) snprintf(b, 32, "%.10g", v);
    else strcpy(b, json ? "null" : isnan(v) ? "" : "inf");
    return b;
}

#define OUT(...) do { int w_ = snprintf(buf + (l < cap ? l : cap), l < cap ? cap - l : 0, \
                                        __VA_ARGS__); if (w_ > 0) l += (size_t)w_; } while (0)

static void counts(const cn_spot *spots, int n, int c[5])
{
    memset(c, 0, 5 * sizeof *c);
    for (int i = 0; i < n; i++)
        if (spots[i].status >= 0 && spots[i].status <= CN_S_MISS) c[spots[i].status]++;
}

size_t cn_report_csv(const cn_result *r, const cn_spot *spots, int n, char *buf,
                     size_t cap)
{
    size_t l = 0;
    char a[32], b[32];
    qty q[48];
    int c[5], nq = quantities(r, q);
    if (cap) buf[0] = 0;
    counts(spots, n, c);
    OUT("quantity,value,sd,unit\n");
    OUT("format,lensmat-cornea-report 1,,\n");
    OUT("model,%s,,\n", model_names[r->model]);
    OUT("spots,%d,,\n", n);
    OUT("spots_fitted,%d,,\n", r->nused);
    for (int s = 1; s <= CN_S_MISS; s++) OUT("rejected_%s,%d,,\n", status_names[s], c[s]);
    OUT("iterations,%d,,\n", r->iterations);
    OUT("poor_fit,%d,,\n", r->poor);
    OUT("converged,%d,,\n", r->converged);
    OUT("model_rejected,%d,,\n", r->rejected_model);
    OUT("sd_scale,%s,,\n", num(r->inflation, 0, a));
    for (int k = 0; k < CN_NPARAM; k++)
        OUT("param_%s,%s,%s,%s\n", cn_param_name(k), num(r->par.p[k], 0, a),
            r->free[k] ? num(sqrt(r->cov[k * (CN_NPARAM + 1)]), 0, b) : "fixed", units[k]);
    for (int i = 0; i < nq; i++)
        OUT("%s,%s,%s,%s\n", q[i].name, num(q[i].v, 0, a), num(q[i].sd, 0, b), q[i].unit);
    for (int i = 0; i < r->nfree; i++) OUT("sv_%d,%s,,\n", i, num(r->sv[i], 0, a));
    for (int k = 0; k < CN_NPARAM; k++)
        if (r->undetermined & (1u << k)) OUT("undetermined,%s,,\n", cn_param_name(k));
    for (int i = 0; i < n; i++)
        if (spots[i].status != CN_S_OK)
            OUT("rejected_spot,%d,%s,%s\n", i, num(spots[i].nres, 0, a),
                status_names[spots[i].status]);
    return l;
}

static void jstr(char *buf, size_t cap, size_t *lp, const char *s)
{
    size_t l = *lp;
    OUT("\"");
    for (; *s; s++) {
        if (*s == '"' || *s == '\\') OUT("\\%c", *s);
        else if (*s == '\n') OUT("\\n");
        else if ((unsigned char)*s < 32) OUT(" ");
        else OUT("%c", *s);
    }
    OUT("\"");
    *lp = l;
}

size_t cn_report_json(const cn_result *r, const cn_spot *spots, int n, char *buf,
                      size_t cap)
{
    size_t l = 0;
    char a[32], b[32];
    qty q[48];
    int c[5], nq = quantities(r, q);
    if (cap) buf[0] = 0;
    counts(spots, n, c);
    OUT("{\"format\": \"lensmat-cornea-report 1\", \"model\": \"%s\",\n",
        model_names[r->model]);
    OUT(" \"spots\": {\"total\": %d, \"fitted\": %d", n, r->nused);
    for (int s = 1; s <= CN_S_MISS; s++) OUT(", \"%s\": %d", status_names[s], c[s]);
    OUT(",\n  \"rejected\": [");
    int first = 1;
    for (int i = 0; i < n; i++)
        if (spots[i].status != CN_S_OK) {
            OUT("%s{\"index\": %d, \"why\": \"%s\", \"nres\": %s}", first ? "" : ", ", i,
                status_names[spots[i].status], num(spots[i].nres, 1, a));
            first = 0;
        }
    OUT("]},\n \"fit\": {\"iterations\": %d, \"poor\": %d, \"converged\": %d, "
        "\"model_rejected\": %d, \"sd_scale\": %s, \"singular_values\": [",
        r->iterations, r->poor, r->converged, r->rejected_model, num(r->inflation, 1, a));
    for (int i = 0; i < r->nfree; i++) OUT("%s%s", i ? ", " : "", num(r->sv[i], 1, a));
    OUT("], \"undetermined\": [");
    first = 1;
    for (int k = 0; k < CN_NPARAM; k++)
        if (r->undetermined & (1u << k)) {
            OUT("%s\"%s\"", first ? "" : ", ", cn_param_name(k));
            first = 0;
        }
    OUT("], \"why\": ");
    jstr(buf, cap, &l, r->why);
    OUT("},\n \"parameters\": {");
    for (int k = 0; k < CN_NPARAM; k++)
        OUT("%s\n  \"%s\": {\"value\": %s, \"sd\": %s, \"unit\": \"%s\", \"free\": %s}",
            k ? "," : "", cn_param_name(k), num(r->par.p[k], 1, a),
            r->free[k] ? num(sqrt(r->cov[k * (CN_NPARAM + 1)]), 1, b) : "null", units[k],
            r->free[k] ? "true" : "false");
    OUT("},\n \"clinical\": {");
    for (int i = 0; i < nq; i++)
        OUT("%s\n  \"%s\": {\"value\": %s, \"sd\": %s, \"unit\": \"%s\"}", i ? "," : "",
            q[i].name, num(q[i].v, 1, a), num(q[i].sd, 1, b), q[i].unit);
    OUT("}}\n");
    return l;
}
