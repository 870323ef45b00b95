/* bench_centroid.c -- issue 10's centroid and synthesis figures: 1000 synthetic 640x480
 * 16-bit frames (B = 100, sigma = 50, A = 1000, w = 3 px, uniform sub-pixel positions)
 * located by each method; RMS error per coordinate against the Cramer-Rao bound, median
 * time per frame (one thread), the same-run baseline of reading the frame once, and the
 * synthesis time.  Arguments: [N frames] [TSV file for the method table] [PNG file]:
 * with a PNG name (ending .png), the table is also plotted through the engine's plot
 * call, error against time per frame on log-log axes, one marker per method, as PNG
 * and SVG (NAME.svg beside it), and the placed markers are printed ("PLOT ..." lines,
 * for tests/t_77_centroid_plot.sh). */
#include "it.h"

enum { NMETH = 4 };
static const char *meth_name[NMETH] = {"gauss_fit", "moments", "moments_bg", "gauss_fit_plane"};
static const int meth_id[NMETH] = {IM_CM_GAUSS, IM_CM_MOMENTS, IM_CM_MOMENTS_BG, IM_CM_GAUSS};

static const char *meth_label[NMETH] = {"Gaussian fit", "moments (raw counts)",
                                        "moments above background",
                                        "Gaussian fit, tilted background"};

static volatile uint64_t sink;

/* The method table as a plot: one series (one marker) per method, the Cramer-Rao bound
 * as a line across them.  Prints the plot box and where each marker was placed. */
static int plot_methods(const char *png, int n, const double *rms, const double *us,
                        double crb)
{
    const imaging_api *im = imaging_get_api(IMAGING_ABI);
    size_t len = strlen(png);          /* ends in .png: main checked before measuring */
    char *svg = malloc(len + 1), err[256], cpu[128] = "", note[256], crbname[64];
    if (!im || !im->draw || !svg) return 1;
    memcpy(svg, png, len - 4);
    strcpy(svg + len - 4, ".svg");
    FILE *ci = fopen("/proc/cpuinfo", "r");
    if (ci) {
        char line[256];
        while (fgets(line, sizeof line, ci))
            if (!strncmp(line, "model name", 10) && strchr(line, ':')) {
                snprintf(cpu, sizeof cpu, "%s", strchr(line, ':') + 2);
                cpu[strcspn(cpu, "\n")] = 0;
                break;
            }
        fclose(ci);
    }
    /* series 0: the bound, a line under the markers; 1..NMETH: the methods in
       meth_name order */
    im_series ser[1 + NMETH];
    double bx[2], by[2] = {crb, crb};
    bx[0] = bx[1] = us[0];
    for (int m = 0; m < NMETH; m++) {
        if (us[m] < bx[0]) bx[0] = us[m];
        if (us[m] > bx[1]) bx[1] = us[m];
    }
    bx[0] /= 1.25; bx[1] *= 1.25;     /* the bound reaches past the markers */
    snprintf(crbname, sizeof crbname, "Cramer-Rao bound %.4f px", crb);
    ser[0] = (im_series){crbname, 2, bx, by, IM_LINES};
    for (int m = 0; m < NMETH; m++)
        ser[1 + m] = (im_series){meth_label[m], 1, &us[m], &rms[m], IM_MARKERS};
    snprintf(note, sizeof note, "%d frames 640x480 16-bit, B=100 sigma=50 A=1000 w=3 px; "
             "one thread%s%s", n, cpu[0] ? ", " : "", cpu);
    im_plot P = {"Centroid methods: RMS error against time per frame",
                 "median time per frame (us)", "RMS error per coordinate (px)",
                 1, 1, 0, 1 + NMETH, ser, note};
    im_out out = {png, svg, 900, 520, NULL, NULL};
    im_plot_info info;
    if (im->draw->plot(&P, &out, &info, err, sizeof err)) {
        fprintf(stderr, "bench_centroid: %s\n", err);
        free(svg);
        return 1;
    }
    printf("PLOT box %.3f %.3f %.3f %.3f range %.6g %.6g %.6g %.6g\n", info.box_x0,
           info.box_y0, info.box_x1, info.box_y1, info.xmin, info.xmax, info.ymin, info.ymax);
    for (int k = 0; k < info.nmark && k < IM_MAXPLOTMARK; k++) {
        const im_plot_mark *mk = &info.mark[k];
        if (mk->series >= 1)
            printf("PLOT marker %s %.3f %.3f\n", meth_name[mk->series - 1], mk->x, mk->y);
    }
    printf("PLOT written %s %s (%d points left out)\n", png, svg, info.skipped);
    free(svg);
    return 0;
}

/* The baseline: every sample read once and summed, vectorised like the engine's pass. */
__attribute__((target_clones("arch=skylake-avx512", "avx2", "default"), optimize("O3")))
static uint64_t sum_frame(const uint16_t *restrict p, size_t n)
{
    uint64_t total = 0;
    for (size_t i = 0; i < n; i += 4096) {
        uint32_t s = 0;
        size_t e = i + 4096 < n ? i + 4096 : n;
        for (size_t k = i; k < e; k++) s += p[k];
        total += s;
    }
    return total;
}

int main(int argc, char **argv)
{
    const im_frame_api *fa = it_api();
    int n = argc > 1 ? atoi(argv[1]) : 1000;
    const char *tsv = argc > 2 ? argv[2] : NULL, *png = argc > 3 ? argv[3] : NULL;
    im_sensor s = it_sensor();
    im_centroider *c = fa->centroider_new();
    double *tsyn = malloc(sizeof(double) * n), *tread = malloc(sizeof(double) * n);
    double *tm[NMETH], se[NMETH] = {0}, sig2 = 0;
    int found[NMETH] = {0}, nsig = 0;
    long iters = 0;
    uint64_t z = 12345;
    char err[256];
    if (png && (strlen(png) < 5 || strcmp(png + strlen(png) - 4, ".png"))) {
        fprintf(stderr, "bench_centroid: %s: the plot's name must end in .png\n", png);
        return 1;
    }
    for (int m = 0; m < NMETH; m++) tm[m] = malloc(sizeof(double) * n);
    if (n < 1 || !c || !tsyn || !tread) return 1;
    for (int k = 0; k < n; k++) {
        double x = 20 + 600 * it_uniform(&z), y = 20 + 440 * it_uniform(&z), t0;
        im_spot_src sp = it_spot(x, y);
        im_frame *f;
        t0 = it_now();
        if (fa->synth(&s, &sp, 1, 1000 + (uint64_t)k, 1, &f, err, sizeof err)) {
            fprintf(stderr, "bench_centroid: %s\n", err);
            return 1;
        }
        tsyn[k] = it_now() - t0;
        /* Baseline: read every sample of the frame once. */
        sink += sum_frame(f->px, (size_t)f->width * f->height);
        t0 = it_now();
        sink += sum_frame(f->px, (size_t)f->width * f->height);
        tread[k] = it_now() - t0;
        for (int m = 0; m < NMETH; m++) {
            im_centroid_opt o;
            im_spot spot[4];
            im_centroid_result r;
            memset(&o, 0, sizeof o);
            o.method = meth_id[m];
            o.plane = m == 3;
            t0 = it_now();
            int rc = fa->centroid(c, f, &o, spot, 4, &r, err, sizeof err);
            tm[m][k] = it_now() - t0;
            if (rc || r.outcome != IM_FOUND_ONE) continue;
            found[m]++;
            se[m] += (spot[0].x - x) * (spot[0].x - x) + (spot[0].y - y) * (spot[0].y - y);
            if (m == 0) iters += spot[0].iter;
            if (m == 0) { sig2 += 0.5 * (spot[0].sx * spot[0].sx + spot[0].sy * spot[0].sy); nsig++; }
        }
        fa->frame_free(f);
    }
    /* Shot noise on (a camera at gain 1 e/count), the other synthesis path. */
    im_sensor s2 = s;
    s2.shot_noise = 1; s2.background = 1e5; s2.read_noise = 10;
    double tshot[21];
    for (int k = 0; k < 21; k++) {
        im_spot_src sp = it_spot(320.3, 240.7);
        im_frame *f;
        double t0 = it_now();
        fa->synth(&s2, &sp, 1, (uint64_t)k, 1, &f, err, sizeof err);
        tshot[k] = it_now() - t0;
        fa->frame_free(f);
    }
    double crb = it_crb();
    double rms[NMETH], med[NMETH];
    for (int m = 0; m < NMETH; m++) {
        rms[m] = found[m] ? sqrt(se[m] / (2.0 * found[m])) : INFINITY;
        med[m] = it_median(tm[m], n) * 1e6;
    }
    double read_us = it_median(tread, n) * 1e6;
    printf("# %d frames 640x480 16-bit, B=100 sigma=50 A=1000 w=3 px; CRB %.4f px; "
           "found %d/%d/%d/%d of %d; %.1f fit iterations\n", n, crb, found[0], found[1],
           found[2], found[3], n, (double)iters / n);
    printf("BENCH centroid_rms_px %.4f px\n", rms[0]);
    printf("BENCH centroid_vs_crb %.3f ratio\n", rms[0] / crb);
    printf("BENCH centroid_sigma_vs_rms %.3f ratio\n", sqrt(sig2 / (nsig ? nsig : 1)) / rms[0]);
    printf("BENCH centroid_moments_rms_px %.4f px\n", rms[1]);
    printf("BENCH centroid_moments_bg_rms_px %.4f px\n", rms[2]);
    printf("BENCH centroid_plane_rms_px %.4f px\n", rms[3]);
    printf("BENCH centroid_us %.1f us\n", med[0]);
    printf("BENCH centroid_plane_us %.1f us\n", med[3]);
    printf("BENCH centroid_moments_us %.1f us\n", med[1]);
    printf("BENCH centroid_moments_bg_us %.1f us\n", med[2]);
    printf("BENCH frame_read_once_us %.1f us\n", read_us);
    printf("BENCH centroid_vs_read %.2f ratio\n", med[0] / read_us);
    printf("BENCH frame_synth_ms %.3f ms\n", it_median(tsyn, n) * 1e3);
    printf("BENCH frame_synth_shot_ms %.3f ms\n", it_median(tshot, 21) * 1e3);
    if (tsv) {   /* written beside its name and renamed: never a half table */
        char part[4096];
        snprintf(part, sizeof part, "%s.part", tsv);
        FILE *o = fopen(part, "w");
        int bad = !o;
        if (o) {
            fprintf(o, "method\trms_px\tus_per_frame\n");
            for (int m = 0; m < NMETH; m++)
                fprintf(o, "%s\t%.5f\t%.2f\n", meth_name[m], rms[m], med[m]);
            bad = ferror(o) | fclose(o);
            if (bad || rename(part, tsv)) { bad = 1; remove(part); }
        }
        if (bad) { fprintf(stderr, "bench_centroid: cannot write %s\n", tsv); return 1; }
    }
    fa->centroider_free(c);
    return png ? plot_methods(png, n, rms, med, crb) : 0;
}
