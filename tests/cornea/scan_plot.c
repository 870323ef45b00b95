/* scan_plot.c -- the cornea scan's error against run time (scripts/bench_cornea_scan.sh)
 * plotted through the imaging engine's plot call: reads the bench's table (TSV: points,
 * CPU seconds, RMS radius error um, RMS mean-K error D, the fit's sd of each; '#' lines
 * skipped) and draws log-log lines with markers, radius error in um and mean-K error in
 * millidiopters against the measurement's time, with the fit's own sd as lines, as
 * PNG and SVG (NAME.svg beside it).  Prints where each marker was drawn ("PLOT marker
 * SERIES POINTS X Y").
 * Usage: scan_plot TABLE.tsv OUT.png "NOTE" */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "imaging/imaging.h"

#define MAXROW 64

int main(int argc, char **argv)
{
    if (argc < 3 || strlen(argv[2]) < 5 || strcmp(argv[2] + strlen(argv[2]) - 4, ".png")) {
        fprintf(stderr, "usage: scan_plot TABLE.tsv OUT.png [NOTE]\n");
        return 2;
    }
    FILE *f = fopen(argv[1], "r");
    if (!f) { perror(argv[1]); return 1; }
    double pts[MAXROW], t[MAXROW], r[MAXROW], k[MAXROW], rs[MAXROW], ks[MAXROW];
    int n = 0;
    char line[512];
    while (n < MAXROW && fgets(line, sizeof line, f)) {
        if (line[0] == '#' || line[0] == '\n') continue;
        if (sscanf(line, "%lf %lf %lf %lf %lf %lf", &pts[n], &t[n], &r[n], &k[n], &rs[n],
                   &ks[n]) == 6) {
            k[n] *= 1e3;
            ks[n] *= 1e3;
            n++;
        }
    }
    fclose(f);
    if (n < 2) { fprintf(stderr, "scan_plot: %s: fewer than 2 rows\n", argv[1]); return 1; }
    const imaging_api *im = imaging_get_api(IMAGING_ABI);
    if (!im || !im->draw) { fprintf(stderr, "scan_plot: no imaging engine\n"); return 1; }
    size_t len = strlen(argv[2]);
    char *svg = malloc(len + 1), err[256];
    if (!svg) return 1;
    memcpy(svg, argv[2], len - 4);
    strcpy(svg + len - 4, ".svg");
    im_series ser[4] = {
        {"RMS apex radius error (um)", n, t, r, IM_LINES | IM_MARKERS},
        {"RMS mean K error (mD)", n, t, k, IM_LINES | IM_MARKERS},
        {"the fit's own sd of R (um)", n, t, rs, IM_LINES},
        {"the fit's own sd of mean K (mD)", n, t, ks, IM_LINES},
    };
    im_plot P = {"Cornea scan: error against run time (10 to 10 000 points)",
                 "CPU time of the measurement (s): plan, trace, frames, centroids, fit, check",
                 "RMS error", 1, 1, 0, 4, ser, argc > 3 ? argv[3] : NULL};
    im_out out = {argv[2], svg, 900, 520, NULL, NULL};
    im_plot_info info;
    if (im->draw->plot(&P, &out, &info, err, sizeof err)) {
        fprintf(stderr, "scan_plot: %s\n", err);
        free(svg);
        return 1;
    }
    for (int i = 0; i < info.nmark && i < IM_MAXPLOTMARK; i++) {
        const im_plot_mark *mk = &info.mark[i];
        printf("PLOT marker %s %.0f %.1f %.1f\n", mk->series ? "power" : "radius",
               pts[mk->point], mk->x, mk->y);
    }
    printf("PLOT written %s %s (%d points left out)\n", argv[2], svg, info.skipped);
    free(svg);
    return 0;
}
