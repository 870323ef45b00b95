/* t_draw.c -- the imaging engine's drawing half through its public table (imaging.h):
 * spot statistics against hand values (and far from the origin, where one-pass sums
 * cancel), plot ranges and points left off log axes, the layout's reported geometry
 * (the F2 mark exactly at x0 + scale * z_F2, coincident ticks' labels apart, every
 * mark inside the picture), bad inputs refused with messages, an unwritable path
 * leaving nothing behind, XML-escaped SVG text. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "imaging/imaging.h"
#include "unit.h"

static const im_draw_api *D;
static char dir[256], err[512];

static int exists(const char *p) { struct stat st; return stat(p, &st) == 0; }

static char *slurp(const char *p)
{
    FILE *f = fopen(p, "rb");
    static char buf[1 << 20];
    size_t n;
    if (!f) return NULL;
    n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

static void spot_stats(void)
{
    im_sd_point p[4] = {{1, 0, 0}, {-1, 0, 0}, {0, 2, 0}, {0, -2, 0}};
    im_sd_stat s;
    D->spot_stat(p, 4, -1, &s);
    CHECK(s.n == 4 && s.cx == 0 && s.cy == 0, "spot: centroid of a symmetric cross is 0");
    CHECK(fabs(s.rms - sqrt(2.5)) < 1e-15 && s.rmax == 2, "spot: RMS sqrt(2.5), max 2 (%.17g %.17g)",
          s.rms, s.rmax);
    for (int i = 0; i < 4; i++) p[i].x += 1e8;
    D->spot_stat(p, 4, -1, &s);
    CHECK(s.cx == 1e8 && fabs(s.rms - sqrt(2.5)) < 1e-8, "spot: the same 1e8 away (RMS %.17g)", s.rms);
    D->spot_stat(p, 4, 1, &s);
    CHECK(s.n == 0 && s.rms == 0, "spot: an empty group has n = 0");
}

static void spot_bad(void)
{
    im_sd_point p[2] = {{0, 0, 0}, {1, 1, 3}};
    char png[300];
    snprintf(png, sizeof png, "%s/s.png", dir);
    im_out out = {png, NULL, 0, 0, NULL, NULL};
    im_spotdiag s = {"t", "mm", 2, p, 2, NULL, 0, 0};
    im_sd_info info;
    CHECK(D->spot(&s, &out, &info, err, sizeof err) == IM_EINVAL && strstr(err, "group 3"),
          "spot: a hit in a group that is not there is refused (%s)", err);
    p[1].group = 1;
    s.airy_radius = -1;
    CHECK(D->spot(&s, &out, &info, err, sizeof err) == IM_EINVAL, "spot: a negative Airy radius is refused");
    s.airy_radius = 0.1;
    CHECK(D->spot(&s, &out, &info, err, sizeof err) == IM_OK && exists(png), "spot: drawn once it is right (%s)", err);
    CHECK(info.group[1].n == 1 && info.all.n == 2, "spot: per-group counts");
}

static void plot_ranges(void)
{
    double x[6] = {1, 10, 100, 0, -1, NAN}, y[6] = {1e-3, 1e-6, 1e-9, 1, 1, 1};
    im_series s = {"a", 6, x, y, IM_MARKERS};
    im_plot p = {"t", "x", "y", 1, 1, 0, 1, &s, NULL};
    im_plot_info info;
    char png[300], svg[300];
    snprintf(png, sizeof png, "%s/p.png", dir);
    snprintf(svg, sizeof svg, "%s/p.svg", dir);
    im_out out = {png, svg, 0, 0, NULL, NULL};
    int rc = D->plot(&p, &out, &info, err, sizeof err);
    CHECK(rc == IM_OK, "plot: log-log drawn (%s)", rc ? err : "");
    CHECK(info.skipped == 3, "plot: 0, -1 and NaN left off log axes (%d)", info.skipped);
    CHECK(info.xmin < 1 && info.xmax > 100 && info.ymin < 1e-9 && info.ymax > 1e-3,
          "plot: the axes hold the data (%g..%g, %g..%g)", info.xmin, info.xmax, info.ymin, info.ymax);
    /* the markers drawn are the three points kept, each where the log axes put it:
       x = 10 is half-way across decades 1..100, y = 1e-6 half-way up */
    int at_data = info.nmark == 3;
    for (int k = 0; k < info.nmark && k < 3; k++) {
        const im_plot_mark *m = &info.mark[k];
        double lx = (log10(x[m->point]) - log10(info.xmin)) / (log10(info.xmax) - log10(info.xmin));
        double ly = (log10(y[m->point]) - log10(info.ymin)) / (log10(info.ymax) - log10(info.ymin));
        at_data &= m->series == 0 && m->point == k &&
                   fabs(m->x - (info.box_x0 + lx * (info.box_x1 - info.box_x0))) < 1e-6 &&
                   fabs(m->y - (info.box_y1 - ly * (info.box_y1 - info.box_y0))) < 1e-6;
    }
    CHECK(at_data && info.box_x0 < info.box_x1 && info.box_y0 < info.box_y1 &&
          fabs(info.mark[1].x - 0.5 * (info.mark[0].x + info.mark[2].x)) < 1e-6 &&
          fabs(info.mark[1].y - 0.5 * (info.mark[0].y + info.mark[2].y)) < 1e-6,
          "plot: 3 markers reported where the log axes put the data (%d)", info.nmark);
    double z[2] = {0, -1};
    s.x = z; s.y = z; s.n = 2;
    CHECK(D->plot(&p, &out, &info, err, sizeof err) == IM_EINVAL && strstr(err, "positive"),
          "plot: nothing positive on log axes is refused (%s)", err);
}

/* A thick biconvex lens (R 20 / -20, 4 thick, n 1.5) in air; its cardinal points by
 * the thick-lens formulas. */
static void layout_geometry(void)
{
    double n = 1.5, r1 = 20, r2 = -20, t = 4;
    double P = (n - 1) * (1 / r1 - 1 / r2 + (n - 1) * t / (n * r1 * r2)), f = 1 / P;
    double h1 = -f * (n - 1) * t / (n * r2), h2 = t - f * (n - 1) * t / (n * r1);
    im_surface s[2] = {{0, r1, 0, {0}, 0, 8, n}, {t, r2, 0, {0}, 0, 8, 1}};
    double ray[6] = {-10, 3, 0, 3, 40, -2};
    im_ray r = {ray, 3, 0, 0};
    im_layout L = {"a <lens> & rays", "mm", 1, 2, s, 1, &r,
                   h1 - f, h2 + f, h1, h2, h1, h2, -60, 3, NAN, 0, 0};
    im_layout_info info;
    char png[300], svg[300];
    snprintf(png, sizeof png, "%s/l.png", dir);
    snprintf(svg, sizeof svg, "%s/l.svg", dir);
    im_out out = {png, svg, 0, 0, NULL, NULL};
    int rc = D->layout(&L, &out, &info, err, sizeof err);
    CHECK(rc == IM_OK && exists(png) && exists(svg), "layout: drawn (%s)", rc ? err : "");
    const im_mark *f2 = NULL, *h2m = NULL, *n2m = NULL;
    int inside = 1;
    for (int i = 0; i < info.nmark; i++) {
        const im_mark *m = &info.mark[i];
        if (!strcmp(m->name, "F2")) f2 = m;
        if (!strcmp(m->name, "H2")) h2m = m;
        if (!strcmp(m->name, "N2")) n2m = m;
        if (!(m->x >= 0 && m->x < 1000 && m->label_y > 0)) inside = 0;
    }
    CHECK(info.nmark == 7, "layout: six ticks and the object arrow marked (%d)", info.nmark);
    CHECK(f2 && fabs(f2->x - (info.x0 + info.px_per_unit * (h2 + f))) < 1e-9,
          "layout: F2 drawn at x0 + scale * z_F2");
    CHECK(h2m && n2m && h2m->x == n2m->x && fabs(h2m->label_y - n2m->label_y) > 8,
          "layout: coincident H2 and N2 get labels on different rows");
    CHECK(inside, "layout: every mark inside the picture");
    char *t1 = slurp(svg);
    CHECK(t1 && strstr(t1, "a &lt;lens&gt; &amp; rays") && strstr(t1, ">F2</text>"),
          "layout: SVG text escaped, labels present");
}

static int always(void *ctx) { (void)ctx; return 1; }

static void layout_bad(void)
{
    im_surface s[1] = {{0, 10, 0, {0}, 0, NAN, 1.5}};
    im_layout L = {NULL, NULL, 1, 1, s, 0, NULL, NAN, NAN, NAN, NAN, NAN, NAN, NAN, 0, NAN, 0, 0};
    char png[300];
    snprintf(png, sizeof png, "%s/bad.png", dir);
    im_out out = {png, NULL, 0, 0, NULL, NULL};
    CHECK(D->layout(&L, &out, NULL, err, sizeof err) == IM_EINVAL && strstr(err, "surface 1"),
          "layout: a NaN semi-diameter is refused (%s)", err);
    L.nsurf = 0;
    CHECK(D->layout(&L, &out, NULL, err, sizeof err) == IM_EINVAL, "layout: no surface is refused");
    s[0].semi = 5;
    L.nsurf = 1;
    double far[4] = {-1e300, 1e300, 1e300, -1e300};
    im_ray r = {far, 2, 0, 1};
    L.nray = 1; L.ray = &r;
    CHECK(D->layout(&L, &out, NULL, err, sizeof err) == IM_OK && exists(png),
          "layout: a ray out at 1e300 is left out, not a crash");
    out.png = "/proc/nothere/x.png";
    CHECK(D->layout(&L, &out, NULL, err, sizeof err) == IM_EIO && strstr(err, "/proc/nothere/x.png"),
          "layout: an unwritable picture is an error naming it (%s)", err);
    char stopped[300];
    snprintf(stopped, sizeof stopped, "%s/stopped.png", dir);
    out.png = stopped;
    out.stop = always;
    CHECK(D->layout(&L, &out, NULL, err, sizeof err) == IM_ESTOP && !exists(stopped),
          "layout: a stop asked before writing writes nothing");
    out.stop = NULL;
    out.png = png;
    out.width = 50;
    CHECK(D->layout(&L, &out, NULL, err, sizeof err) == IM_EINVAL, "layout: a 50-pixel picture is refused");
}

/* The profile of an asphere (paraboloid R 10, k = -1, plus A4 s^4) drawn where its
 * sag puts it: the first point of its outline in the SVG is the edge at y = -semi,
 * z = s^2/20 + A4 s^4. */
static void asphere_profile(void)
{
    const double semi = 6, a4 = 1e-3;
    im_surface s[1] = {{0, 10, -1, {0, a4}, 2, semi, 1.5}};
    im_layout L = {NULL, "mm", 1, 1, s, 0, NULL, NAN, NAN, NAN, NAN, NAN, NAN, NAN, 0, NAN, 0, 0};
    im_layout_info info;
    char png[300], svg[300];
    snprintf(png, sizeof png, "%s/a.png", dir);
    snprintf(svg, sizeof svg, "%s/a.svg", dir);
    im_out out = {png, svg, 0, 0, NULL, NULL};
    int rc = D->layout(&L, &out, &info, err, sizeof err);
    char *t = rc == IM_OK ? slurp(svg) : NULL;
    const char *key = "stroke=\"#283c64\" stroke-width=\"1.5\" points=\"";
    char *p = t ? strstr(t, key) : NULL;
    double x = NAN, y = NAN;
    if (p) sscanf(p + strlen(key), "%lf,%lf", &x, &y);
    double sag = semi * semi / 20 + a4 * pow(semi, 4);
    double ex = info.x0 + info.px_per_unit * sag, ey = info.y0 + info.px_per_unit * semi;
    CHECK(p && fabs(x - ex) < 0.01 && fabs(y - ey) < 0.01,
          "layout: the asphere's edge at its sag (%.2f, %.2f), want (%.2f, %.2f)", x, y, ex, ey);
}

int main(void)
{
    const imaging_api *im = imaging_get_api(IMAGING_ABI);
    if (!im || !im->draw) { printf("FAIL no drawing table\n"); return 1; }
    D = im->draw;
    snprintf(dir, sizeof dir, "/tmp/t_draw.XXXXXX");
    if (!mkdtemp(dir)) { printf("FAIL mkdtemp\n"); return 1; }
    spot_stats();
    spot_bad();
    plot_ranges();
    layout_geometry();
    layout_bad();
    asphere_profile();
    /* nothing but the pictures: no temporary file left */
    char cmd[400];
    snprintf(cmd, sizeof cmd, "ls %s | grep -q part", dir);
    CHECK(system(cmd) != 0, "no temporary file left behind");
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd)) return 1;
    return unit_failed();
}
