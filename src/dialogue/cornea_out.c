/* cornea_out.c -- the --cornea-scan dialogue's files (issue 12): the measurement
 * report as text (what the session said), CSV and JSON (the cornea engine's rows plus the dialogue's: scan
 * settings, the simulated truth, the errors) and the maps of the fit (elevation
 * against the best-fit sphere, axial and tangential curvature in diopters in 0.25-0.5
 * D steps, the residual map of the spots), drawn by the imaging engine, which is
 * loaded only when maps are asked for.  Every file is written as FILE.part and
 * renamed when complete. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
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

/* data to path.part; 0, or -1 with why (and no .part left) */
static int write_part(const char *path, const char *data, size_t len, char *msg, size_t cap)
{
    char part[1200];
    snprintf(part, sizeof part, "%s.part", path);
    FILE *f = fopen(part, "w");
    if (!f) { snprintf(msg, cap, "%s: %s", part, strerror(errno)); return -1; }
    int ok = fwrite(data, 1, len, f) == len;
    ok &= fflush(f) == 0;
    ok &= fclose(f) == 0;
    if (!ok) {
        snprintf(msg, cap, "%s: %s", part, strerror(errno));
        remove(part);
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
    char path[3][1100], part[sizeof path + 8], a[32], b[32];   /* as gcc counts path[i] */
    size_t need = cn->report_csv(r, sp, n, NULL, 0) + cn->report_json(r, sp, n, NULL, 0) +
                  (size_t)nrows * 200 + 64;
    char *buf = malloc(need);
    int done = 0, rc = -1;
    if (!buf) { snprintf(msg, cap, "out of memory"); return -1; }
    for (int i = 0; i < 3; i++)         /* names are at most 1000 (cs_check_name) */
        snprintf(path[i], sizeof path[i], "%.1000s%s", name, ext[i]);
    if (write_part(path[0], text ? text : "", text ? len : 0, msg, cap)) goto out;
    done = 1;
    size_t l = cn->report_csv(r, sp, n, buf, need);
    for (int i = 0; i < nrows && l < need; i++)
        l += snprintf(buf + l, need - l, "%s,%s,%s,%s\n", rows[i].name,
                      fmtnum(rows[i].v, 0, a), fmtnum(rows[i].sd, 0, b), rows[i].unit);
    if (l >= need) { snprintf(msg, cap, "report too long"); goto out; }
    if (write_part(path[1], buf, l, msg, cap)) goto out;
    done = 2;
    l = cn->report_json(r, sp, n, buf, need);
    while (l > 0 && buf[l - 1] == '\n') l--;
    if (l > 0 && buf[l - 1] == '}') l--;       /* reopen the top-level object */
    l += snprintf(buf + l, need - l, ",\n \"dialogue\": {");
    for (int i = 0; i < nrows && l < need; i++)
        l += snprintf(buf + l, need - l, "%s\n  \"%s\": {\"value\": %s, \"sd\": %s, "
                      "\"unit\": \"%s\"}", i ? "," : "", rows[i].name,
                      fmtnum(rows[i].v, 1, a), fmtnum(rows[i].sd, 1, b), rows[i].unit);
    l += snprintf(buf + l, need > l ? need - l : 0, "}}\n");
    if (l >= need) { snprintf(msg, cap, "report too long"); goto out; }
    if (write_part(path[2], buf, l, msg, cap)) goto out;
    done = 3;
    if (lm_stop_requested()) { snprintf(msg, cap, "stopped"); goto out; }
    for (int i = 0; i < 3; i++) {
        snprintf(part, sizeof part, "%s.part", path[i]);
        if (rename(part, path[i])) {
            snprintf(msg, cap, "%s: %s", path[i], strerror(errno));
            goto out;
        }
    }
    done = 0;
    rc = 0;
out:
    for (int i = 0; i < done; i++) {     /* the .part files not renamed */
        snprintf(part, sizeof part, "%s.part", path[i]);
        remove(part);
    }
    free(buf);
    return rc;
}

static const double dsteps[] = {0.25, 0.5, 1.0, 1.5, 2.0, 2.5, 5.0, 10.0};

int cs_write_maps(const cornea_api *cn, const rg_geometry *g, const char *name,
                  const cn_result *r, const cn_spot *sp, int n, const cn_zfit *zf,
                  const cn_kc *kc,
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
    /* the pictures' marks: the instrument's view, superior up (the eye, OD or OS, is
       not asked: both readings of x are named); Sim K and Kmax of the data */
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
        m.title = title[kind];
        if (zf) {
            m.xlabel = "x (mm), examiner's view: OD nasal to the right, OS nasal to the left";
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
