/* study_plot.c -- the many-eyes study's plot (scripts/cornea-study.sh): from the
 * study table (tab-separated, a header row naming err_X and sd_X columns), the
 * cumulative distribution over the eyes of |err_X| / sd_X for R, Q, Km, cyl, axis, dy and
 * tilt_x, beside
 * the half-normal distribution they follow when every reported uncertainty is honest;
 * drawn by the imaging engine (PNG written through a .part file).
 *     study_plot study.tsv plot.png */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "imaging/imaging.h"

#define MAXC 64
#define MAXE 100000

static int cmpd(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    if (argc != 3) { fprintf(stderr, "usage: study_plot study.tsv plot.png\n"); return 2; }
    FILE *f = fopen(argv[1], "r");
    if (!f) { perror(argv[1]); return 2; }
    static char line[1 << 16];
    char *name[MAXC];
    int nc = 0;
    if (!fgets(line, sizeof line, f)) { fprintf(stderr, "%s: empty\n", argv[1]); return 2; }
    for (char *t = strtok(line, "\t\n"); t && nc < MAXC; t = strtok(NULL, "\t\n"))
        name[nc++] = strdup(t);
    int err_col[MAXC], sd_col[MAXC], np = 0;
    /* seven parameters and the reference: the palette's eight colours */
    static const char *const shown[] = {"err_R", "err_Q", "err_Km", "err_cyl", "err_axis",
                                        "err_dy", "err_tilt_x", NULL};
    for (int i = 0; i < nc; i++) {
        int want = 0;
        for (int k = 0; shown[k]; k++) want |= !strcmp(name[i], shown[k]);
        if (want)
            for (int j = 0; j < nc; j++)
                if (!strncmp(name[j], "sd_", 3) && !strcmp(name[j] + 3, name[i] + 4)) {
                    err_col[np] = i;
                    sd_col[np++] = j;
                }
    }
    static double z[MAXC][MAXE], y[MAXC][MAXE];
    int nz[MAXC] = {0}, ne = 0;
    while (fgets(line, sizeof line, f) && ne < MAXE) {
        double v[MAXC];
        int k = 0;
        char *s = line, *e;
        for (; k < nc; k++) {
            v[k] = strtod(s, &e);
            if (e == s) v[k] = NAN;
            s = strchr(s, '\t');
            if (!s) { k++; break; }
            s++;
        }
        for (; k < nc; k++) v[k] = NAN;
        for (int p = 0; p < np; p++) {
            double a = fabs(v[err_col[p]]) / v[sd_col[p]];
            if (isfinite(a)) z[p][nz[p]++] = a;
        }
        ne++;
    }
    fclose(f);
    im_series ser[MAXC + 1];
    char label[MAXC][48];
    int ns = 0;
    for (int p = 0; p < np; p++) {
        if (!nz[p]) continue;
        qsort(z[p], nz[p], sizeof **z, cmpd);
        for (int i = 0; i < nz[p]; i++) y[p][i] = (i + 0.5) / nz[p];
        snprintf(label[p], sizeof label[p], "%s (%d)", name[err_col[p]] + 4, nz[p]);
        ser[ns++] = (im_series){label[p], nz[p], z[p], y[p], IM_LINES};
    }
    static double hx[200], hy[200];
    for (int i = 0; i < 200; i++) { hx[i] = 4.0 * i / 199; hy[i] = erf(hx[i] / sqrt(2)); }
    ser[ns++] = (im_series){"half-normal", 200, hx, hy, IM_LINES};
    char note[128];
    snprintf(note, sizeof note, "%d eyes; honest uncertainties follow the half-normal", ne);
    im_plot pl = {"Many-eyes study: error / reported uncertainty", "|error| / sd",
                  "fraction of eyes", 0, 0, 0, ns, ser, note};
    const imaging_api *im = imaging_get_api(IMAGING_ABI);
    char err[256];
    im_out o = {argv[2], NULL, 900, 560, NULL, NULL};
    if (!im || im->draw->plot(&pl, &o, NULL, err, sizeof err)) {
        fprintf(stderr, "study_plot: %s\n", im ? err : "no imaging engine");
        return 1;
    }
    return 0;
}
