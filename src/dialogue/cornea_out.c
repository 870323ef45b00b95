/* cornea_out.c -- the --cornea-scan dialogue's files (issue 12): the measurement
 * report as text (what the session said), CSV and JSON (the cornea engine's rows plus the dialogue's: scan
 * settings, the simulated truth, the errors) and the maps of the fit (elevation
 * against the best-fit sphere, axial and tangential curvature in diopters in 0.25-0.5
 * D steps, the residual map of the spots), drawn by the imaging engine, which is
 * loaded only when maps are asked for.  Every file goes through the shared writer
 * (src/common/lm_out.h: a unique temporary renamed over the name when complete). */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "common/lm_out.h"
#include "cornea_out.h"
#include "engine.h"
#include "../imaging/imaging.h"
#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

const char *const cs_out_suffix[] = {".txt", ".csv", ".json", "-elevation.png", "-axial.png",
                                     "-tangential.png", "-residual.png", "-axial-abs.png",
                                     NULL};

int cs_check_name(void *io, const char *word, char *msg, size_t cap)
{
    char path[1100], dir[1024];
    if (!strcmp(word, "-")) return 0;
    if (strlen(word) > 1000 || !*word) { snprintf(msg, cap, "the name is too long"); return -1; }
    for (int i = 0; cs_out_suffix[i]; i++) {
        snprintf(path, sizeof path, "%s%s", word, cs_out_suffix[i]);
        if (lm_check_output(io, path, msg, cap)) return -1;
        snprintf(path, sizeof path, "%s%s.part", word, cs_out_suffix[i]);
        if (lm_check_output(io, path, msg, cap)) return -1;
    }
    const char *slash = strrchr(word, '/');
    if (slash) snprintf(dir, sizeof dir, "%.*s", slash == word ? 1 : (int)(slash - word), word);
    else snprintf(dir, sizeof dir, ".");
    if (access(dir, W_OK | X_OK) != 0) {
        snprintf(msg, cap, "cannot write in the folder %s", dir);
        return -1;
    }
    return 0;
}

static const char *fmtnum(double v, int json, char *b)
{
    if (isfinite(v)) snprintf(b, 32, "%.10g", v);
    else strcpy(b, json ? "null" : isnan(v) ? "" : "inf");
    return b;
}

int cs_write_report(const cornea_api *cn, const char *name, const char *text, size_t len,
                    const cn_result *r, const cn_spot *sp, int n, const cs_row *rows,
                    int nrows, char *msg, size_t cap)
{
    static const char *const ext[] = {".txt", ".csv", ".json"};
    char path[3][1100], a[32], b[32];
    size_t need = cn->report_csv(r, sp, n, NULL, 0) + cn->report_json(r, sp, n, NULL, 0) +
                  (size_t)nrows * 200 + 64, lc, lj;
    char *csv = malloc(need), *json = malloc(need);
    int rc = -1;
    if (!csv || !json) { snprintf(msg, cap, "out of memory"); goto out; }
    for (int i = 0; i < 3; i++)         /* names are at most 1000 (cs_check_name) */
        snprintf(path[i], sizeof path[i], "%.1000s%s", name, ext[i]);
    lc = cn->report_csv(r, sp, n, csv, need);
    for (int i = 0; i < nrows && lc < need; i++)
        lc += snprintf(csv + lc, need - lc, "%s,%s,%s,%s\n", rows[i].name,
                       fmtnum(rows[i].v, 0, a), fmtnum(rows[i].sd, 0, b), rows[i].unit);
    if (lc >= need) { snprintf(msg, cap, "report too long"); goto out; }
    lj = cn->report_json(r, sp, n, json, need);
    while (lj > 0 && json[lj - 1] == '\n') lj--;
    if (lj > 0 && json[lj - 1] == '}') lj--;       /* reopen the top-level object */
    lj += snprintf(json + lj, need - lj, ",\n \"dialogue\": {");
    for (int i = 0; i < nrows && lj < need; i++)
        lj += snprintf(json + lj, need - lj, "%s\n  \"%s\": {\"value\": %s, \"sd\": %s, "
                       "\"unit\": \"%s\"}", i ? "," : "", rows[i].name,
                       fmtnum(rows[i].v, 1, a), fmtnum(rows[i].sd, 1, b), rows[i].unit);
    lj += snprintf(json + lj, need > lj ? need - lj : 0, "}}\n");
    if (lj >= need) { snprintf(msg, cap, "report too long"); goto out; }
    if (lm_stop_requested()) { snprintf(msg, cap, "stopped"); goto out; }
    /* each through the shared writer (src/common/lm_out.h): complete under its name or
     * not there, a device or FIFO written in place, never a temporary left behind */
    if (lm_out_save(path[0], text ? text : "", text ? len : 0, msg, cap) ||
        lm_out_save(path[1], csv, lc, msg, cap) || lm_out_save(path[2], json, lj, msg, cap))
        goto out;
    rc = 0;
out:
    free(csv);
    free(json);
    return rc;
}

static const double dsteps[] = {0.25, 0.5, 1.0, 1.5, 2.0, 2.5, 5.0, 10.0};

int cs_write_maps(const cornea_api *cn, const rg_geometry *g, const char *name,
                  const cn_result *r, const cn_spot *sp, int n, const cn_zfit *zf,
                  const cn_kc *kc, int eye,
                  int (*stop)(void *), void (*say)(void *ctx, const char *line),
                  void *ctx, char *msg, size_t cap)
{
    imaging_get_api_fn get;
    *(void **)&get = lm_engine_symbol("imaging", IMAGING_API_SYMBOL);
    const imaging_api *im = get ? get(IMAGING_ABI) : NULL;
    if (!im || !im->draw || !im->draw->map) {
        snprintf(msg, cap, "the imaging engine module cannot be loaded");
        return -1;
    }
    enum { N = 201 };
    double hmax = zf ? zf->rho : r->hmax > 0 ? r->hmax : 1.5;
    double *grid = malloc(sizeof *grid * N * N);
    double *xy = malloc(sizeof *xy * 2 * (size_t)(n > 0 ? n : 1));
    double *pv = malloc(sizeof *pv * (size_t)(n > 0 ? n : 1));
    double *px = malloc(sizeof *px * (size_t)(n > 0 ? n : 1));
    double *py = malloc(sizeof *py * (size_t)(n > 0 ? n : 1));
    unsigned char *mk = malloc((size_t)(n > 0 ? n : 1));
    int rc = 0;
    if (!grid || !xy || !pv || !px || !py || !mk) { snprintf(msg, cap, "out of memory"); rc = -1; goto out; }
    static const char *const title[] = {"Elevation against the best-fit sphere",
                                        "Axial curvature", "Tangential curvature",
                                        "Residuals of the fit (|r| / sigma)",
                                        "Axial curvature, absolute scale"};
    static const char *const file[] = {"-elevation.png", "-axial.png", "-tangential.png",
                                       "-residual.png", "-axial-abs.png"};
    /* the pictures' marks: the examiner's view, superior up; the eye named (OD: nasal
       to the right, OS: to the left) or, when not, both readings of x; Sim K and
       Kmax of the data */
    char marks[200] = "";
    if (zf && kc)
        snprintf(marks, sizeof marks, "; Sim K %.2f / %.2f D @ %.0f, Kmax %.2f D at "
                 "(%.2f, %.2f) mm", kc->simk1, kc->simk2, kc->simk_axis, kc->kmax,
                 kc->kmax_x, kc->kmax_y);
    for (int kind = 0; kind < (zf ? 5 : 4) && !rc; kind++) {
        char path[1100], note[480], line[1400];
        double aux = NAN;
        im_map m = {0};
        m.nx = m.ny = N;
        m.v = grid;
        m.xmin = m.ymin = -hmax;
        m.xmax = m.ymax = hmax;
        m.disc = hmax;
        char ttl[120];
        snprintf(ttl, sizeof ttl, "%s%s", title[kind], eye == 1 ? ", OD" : eye == 2 ? ", OS" : "");
        m.title = ttl;
        if (zf || eye) {
            m.xlabel = eye == 1 ? "x (mm), examiner's view: T (temporal) left, N (nasal) right"
                       : eye == 2 ? "x (mm), examiner's view: N (nasal) left, T (temporal) right"
                       : "x (mm), examiner's view: OD nasal to the right, OS nasal to the left";
            m.ylabel = "y (mm), superior up";
        }
        if (zf && kind != 3) {
            int zk = kind == 4 ? CN_ZMAP_AXIAL : kind;
            if (cn->zmap(zk, zf, hmax, N, grid, &aux)) {
                snprintf(msg, cap, "%.200s: the surface has no value there", title[kind]);
                rc = -1;
                break;
            }
        } else if (kind < 3) {
            if (cn->map(kind, r->model, &r->par, NULL, hmax, N, grid, &aux)) {
                snprintf(msg, cap, "%.200s: the surface has no value there", title[kind]);
                rc = -1;
                break;
            }
        } else
            for (int k = 0; k < N * N; k++) grid[k] = NAN;
        if (zf && kind == CN_MAP_ELEVATION) {
            m.unit = "um";
            m.symmetric = 1;
            snprintf(note, sizeof note, "from the slopes (Zernike order %d); best-fit sphere "
                     "R %.4f mm; + toward the observer%s", zf->order, aux, marks);
        } else if (zf && (kind == 1 || kind == 2)) {
            m.unit = "D";
            m.steps = dsteps;
            m.nsteps = (int)(sizeof dsteps / sizeof *dsteps);
            snprintf(note, sizeof note, "n 1.3375; from the slopes, where there are data "
                     "(to %.2f mm), normalised scale%s", hmax, marks);
        } else if (kind == 4) {
            /* the absolute scale: 28 to 65.5 D in 1.5 D steps (Smolek, Klyce and
               Hovis's universal standard scale; doc/topography.md), the same colours
               for every eye */
            m.unit = "D";
            m.step = 1.5;
            m.lo = 28;
            m.hi = 65.5;
            snprintf(note, sizeof note, "n 1.3375; absolute scale 28-65.5 D in 1.5 D steps%s",
                     marks);
        } else if (kind == CN_MAP_ELEVATION) {
            m.unit = "um";
            m.symmetric = 1;
            snprintf(note, sizeof note, "best-fit sphere R %.4f mm; + toward the observer; "
                     "fitted surface's eye frame", aux);
        } else if (kind < 3) {
            m.unit = "D";
            m.steps = dsteps;
            m.nsteps = (int)(sizeof dsteps / sizeof *dsteps);
            snprintf(note, sizeof note, "n 1.3375; fitted %s surface over the data's zone "
                     "(%.2f mm)", kind == CN_MAP_AXIAL ? "axial" : "tangential", hmax);
        } else {
            int np = 0;
            cn->spot_xy(g, r, sp, n, xy);
            for (int i = 0; i < n; i++) {
                if (isnan(xy[2 * i])) continue;
                px[np] = xy[2 * i];
                py[np] = xy[2 * i + 1];
                pv[np] = sp[i].nres;
                mk[np] = sp[i].status == CN_S_OUTLIER;
                np++;
            }
            m.npts = np;
            m.px = px; m.py = py; m.pv = pv; m.mark = mk;
            m.unit = "sigma";
            /* discs about half the spots' spacing across the ~520 px map */
            m.point_r = fmax(1.5, fmin(8, 0.45 * 520 * sqrt(M_PI / (np > 0 ? np : 1)) / 2));
            snprintf(note, sizeof note, "ringed: rejected as outliers; neighbour "
                     "correlation %.2f (noise ~0, a missing shape ~1)", r->resid_corr);
        }
        m.note = note;
        snprintf(path, sizeof path, "%s%s", name, file[kind]);
        im_out o = {path, NULL, 0, 0, stop, NULL};
        im_map_info info;
        char err[256];
        if (im->draw->map(&m, &o, &info, err, sizeof err)) {
            snprintf(msg, cap, "%s", err);
            rc = -1;
            break;
        }
        snprintf(line, sizeof line, "%s: %.4g to %.4g %s in %.4g %s steps: %s", title[kind],
                 info.vmin, info.vmax, m.unit, info.step, m.unit, path);
        say(ctx, line);
    }
out:
    free(grid); free(xy); free(pv); free(px); free(py); free(mk);
    return rc;
}

void cs_manifest_name(const char *pattern, char *name, size_t cap)
{
    const char *dot = strrchr(pattern, '.');
    size_t o = 0;
    if (!cap) return;
    for (const char *p = pattern; *p && p != dot && o + 1 < cap; p++) {
        if (*p == '%' && p[1] == '%') { name[o++] = '%'; p++; continue; }
        if (*p == '%') {                /* %d, %04d: the frame number */
            while (*p && *p != 'd') p++;
            if (!*p) break;
            o += (size_t)snprintf(name + o, cap - o, "-frames");
            if (o >= cap) { o = cap - 1; break; }
            continue;
        }
        name[o++] = *p;
    }
    name[o] = '\0';
    snprintf(name + o, cap - o, ".txt");
}

int cs_write_manifest(const char *pattern, const int *seq, int n, int nplanned,
                      const char *status, char *msg, size_t cap)
{
    char path[1100], one[1100];
    size_t need = 512 + strlen(pattern) + strlen(status) + (size_t)n * (sizeof one), len;
    char *buf = malloc(need);
    int rc;
    if (!buf) { snprintf(msg, cap, "out of memory"); return -1; }
    cs_manifest_name(pattern, path, sizeof path);
    len = (size_t)snprintf(buf, need, "# lensmat --cornea-scan: the frames of one scan, "
                           "saved as %s.\n# A frame that pattern names but this list does "
                           "not is not this scan's.\nscan %s\nframes %d of %d\n",
                           pattern, status, n, nplanned);
    for (int i = 0; i < n && len < need; i++) {
        snprintf(one, sizeof one, pattern, seq[i]);
        len += (size_t)snprintf(buf + len, need - len, "%s\n", one);
    }
    rc = len < need ? lm_out_save(path, buf, len, msg, cap) : -1;
    if (len >= need) snprintf(msg, cap, "manifest too long");
    free(buf);
    return rc;
}
