/* im_draw_plot.cpp -- plots of series against linear or log10 axes (the engines'
 * error-against-run-time tables, ray fans) and the axes every chart shares. */
#include "im_draw.hpp"
#include <cmath>
#include <cstring>

namespace imd {

static double tr(double v, bool lg) { return lg ? log10(v) : v; }

Pt Frame::at(double x, double y) const
{
    double ax = tr(xmin, logx), bx = tr(xmax, logx), ay = tr(ymin, logy), by = tr(ymax, logy);
    return {x0 + (tr(x, logx) - ax) / (bx - ax) * (x1 - x0),
            y1 - (tr(y, logy) - ay) / (by - ay) * (y1 - y0)};
}

/* Tick values along one axis: nice linear steps, or decades (with 2 and 5 between
 * when there are few). */
static std::vector<double> ticks(double lo, double hi, bool lg, std::vector<double> *minor)
{
    std::vector<double> t;
    if (!lg) {
        double s = nice_step(hi - lo, 6);
        for (double v = ceil(lo / s - 1e-9) * s; v <= hi + s * 1e-9; v += s)
            t.push_back(fabs(v) < s * 1e-9 ? 0 : v);
        return t;
    }
    int a = (int)floor(log10(lo) + 1e-9), b = (int)ceil(log10(hi) - 1e-9);
    int every = b - a > 24 ? 4 : b - a > 12 ? 2 : 1;   /* labelled decades */
    for (int e = a; e <= b; e++)
        for (int k = 1; k < 10; k++) {
            double v = k * pow(10, e);
            if (v < lo * (1 - 1e-9) || v > hi * (1 + 1e-9)) continue;
            if ((k == 1 && (e % every) == 0) || (b - a <= 2 && (k == 2 || k == 5))) t.push_back(v);
            else if (minor && (k == 1 || b - a <= 6)) minor->push_back(v);
        }
    return t;
}

void axes(Canvas &c, const Frame &f, const char *xlabel, const char *ylabel)
{
    std::vector<double> mx, my;
    std::vector<double> tx = ticks(f.xmin, f.xmax, f.logx, &mx), ty = ticks(f.ymin, f.ymax, f.logy, &my);
    double th = Canvas::text_height(1);
    for (double v : mx) { Pt p = f.at(v, f.ymin); c.line({p.x, f.y0}, {p.x, f.y1}, {240, 240, 240}); }
    for (double v : my) { Pt p = f.at(f.xmin, v); c.line({f.x0, p.y}, {f.x1, p.y}, {240, 240, 240}); }
    for (double v : tx) {
        Pt p = f.at(v, f.ymin);
        c.line({p.x, f.y0}, {p.x, f.y1}, LIGHTGREY);
        c.line({p.x, f.y1}, {p.x, f.y1 + 5}, BLACK);
        c.text({p.x, f.y1 + 8 + th}, f.logx ? fmt("%g", v) : num(v), BLACK, 0.9, CENTER);
    }
    for (double v : ty) {
        Pt p = f.at(f.xmin, v);
        c.line({f.x0, p.y}, {f.x1, p.y}, LIGHTGREY);
        c.line({f.x0 - 5, p.y}, {f.x0, p.y}, BLACK);
        c.text({f.x0 - 8, p.y + th / 2}, f.logy ? fmt("%g", v) : num(v), BLACK, 0.9, RIGHT);
    }
    c.rect({f.x0, f.y0}, {f.x1, f.y1}, BLACK, 1);
    if (xlabel) c.text({(f.x0 + f.x1) / 2, f.y1 + 2 * th + 22}, xlabel, BLACK, 1, CENTER);
    if (ylabel) c.text({f.x0, f.y0 - 10}, ylabel, BLACK, 1, LEFT);
}

} /* namespace imd */

using namespace imd;

static void marker(Canvas &c, Pt p, int shape, Rgb col)
{
    const double r = 3.5;
    switch (shape % 4) {
    case 0: c.disc(p, r, col); break;
    case 1: c.fill({{p.x - r, p.y - r}, {p.x + r, p.y - r}, {p.x + r, p.y + r}, {p.x - r, p.y + r}}, col); break;
    case 2: c.fill({{p.x, p.y - r * 1.2}, {p.x + r * 1.1, p.y + r * 0.8}, {p.x - r * 1.1, p.y + r * 0.8}}, col); break;
    default: c.fill({{p.x, p.y - r * 1.3}, {p.x + r, p.y}, {p.x, p.y + r * 1.3}, {p.x - r, p.y}}, col); break;
    }
}

static int draw_plot(const im_plot *p, const im_out *out, im_plot_info *info, char *err, size_t cap)
{
    im_plot_info dummy;
    if (!info) info = &dummy;
    memset(info, 0, sizeof *info);
    if (!out || !out->png) { set_err(err, cap, "no picture file named"); return IM_EINVAL; }
    if (p->nseries < 1 || !p->series) { set_err(err, cap, "a plot needs at least one series"); return IM_EINVAL; }
    int W = out->width > 0 ? out->width : 800, H = out->height > 0 ? out->height : 500;
    if (W < 300 || H < 200 || W > 20000 || H > 20000) {
        set_err(err, cap, "%dx%d: a plot is 300x200 to 20000x20000 pixels", W, H);
        return IM_EINVAL;
    }
    auto ok = [&](double x, double y) {
        return std::isfinite(x) && std::isfinite(y) && (!p->logx || x > 0) && (!p->logy || y > 0);
    };
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (int i = 0; i < p->nseries; i++) {
        const im_series *s = &p->series[i];
        if (s->n < 0 || (s->n > 0 && (!s->x || !s->y))) {
            set_err(err, cap, "series %d has no points", i + 1);
            return IM_EINVAL;
        }
        for (int k = 0; k < s->n; k++) {
            if (!ok(s->x[k], s->y[k])) { info->skipped++; continue; }
            xmin = fmin(xmin, s->x[k]); xmax = fmax(xmax, s->x[k]);
            ymin = fmin(ymin, s->y[k]); ymax = fmax(ymax, s->y[k]);
        }
    }
    if (!(xmin <= xmax)) { set_err(err, cap, "nothing to plot: no point is finite%s",
                                   p->logx || p->logy ? " and positive" : ""); return IM_EINVAL; }
    if (p->zero_line && !p->logy) { ymin = fmin(ymin, 0); ymax = fmax(ymax, 0); }
    /* pad the ranges: a decade-fraction on log axes, 6 % on linear ones */
    auto pad = [](double &lo, double &hi, bool lg) {
        if (lg) {
            double a = log10(lo), b = log10(hi), d = fmax(b - a, 0.5) * 0.08;
            if (b - a < 0.5) { a -= 0.25; b += 0.25; }
            lo = pow(10, a - d); hi = pow(10, b + d);
        } else {
            double d = hi - lo;
            if (!(d > 0)) d = fabs(hi) > 0 ? fabs(hi) * 0.2 : 1;
            lo -= 0.06 * d; hi += 0.06 * d;
        }
    };
    pad(xmin, xmax, p->logx);
    pad(ymin, ymax, p->logy);
    if (p->zero_line && !p->logy) {   /* a symmetric fan: 0 in the middle */
        double a = fmax(fabs(ymin), fabs(ymax));
        ymin = -a; ymax = a;
    }
    info->xmin = xmin; info->xmax = xmax; info->ymin = ymin; info->ymax = ymax;

    bool legend = false;
    double lw = 0;
    for (int i = 0; i < p->nseries; i++)
        if (p->series[i].name) { legend = true; lw = fmax(lw, Canvas::text_width(p->series[i].name)); }
    Frame f = {90, 50, W - (legend ? lw + 70 : 30), (double)H - 70, xmin, xmax, ymin, ymax,
               p->logx != 0, p->logy != 0};
    if (f.x1 - f.x0 < 120) f.x1 = f.x0 + 120;
    info->box_x0 = f.x0; info->box_y0 = f.y0; info->box_x1 = f.x1; info->box_y1 = f.y1;
    Canvas c(W, H);
    axes(c, f, p->xlabel, p->ylabel);
    if (p->zero_line && !p->logy) c.line(f.at(xmin, 0), f.at(xmax, 0), GREY, 1);
    for (int i = 0; i < p->nseries; i++) {
        const im_series *s = &p->series[i];
        std::vector<Pt> pts;
        for (int k = 0; k < s->n; k++)
            if (ok(s->x[k], s->y[k])) pts.push_back(f.at(s->x[k], s->y[k]));
        int style = s->style ? s->style : IM_LINES | IM_MARKERS;
        if (style & IM_LINES) c.polyline(pts, palette(i), 1.6);
        if (style & IM_MARKERS)
            for (int k = 0, j = 0; k < s->n; k++) {
                if (!ok(s->x[k], s->y[k])) continue;
                Pt q = pts[j++];
                marker(c, q, i, palette(i));
                if (info->nmark < IM_MAXPLOTMARK)
                    info->mark[info->nmark] = {i, k, q.x, q.y};
                info->nmark++;
            }
    }
    double th = Canvas::text_height(1), ly = f.y0 + th;
    for (int i = 0; i < p->nseries; i++) {
        if (!p->series[i].name) continue;
        int style = p->series[i].style ? p->series[i].style : IM_LINES | IM_MARKERS;
        Pt a = {f.x1 + 14, ly - th / 2}, b = {f.x1 + 38, ly - th / 2};
        if (style & IM_LINES) c.line(a, b, palette(i), 1.6);
        if (style & IM_MARKERS) marker(c, {(a.x + b.x) / 2, a.y}, i, palette(i));
        c.text({f.x1 + 46, ly}, p->series[i].name, BLACK);
        ly += th + 10;
    }
    if (p->note) c.text({f.x0, (double)H - 12}, p->note, GREY, 0.9);
    if (p->title) c.text({f.x0, 24}, p->title, BLACK, 1.2);
    return c.write(out, err, cap);
}

extern "C" int im_draw_plot(const im_plot *p, const im_out *out, im_plot_info *info,
                            char *err, size_t cap)
{
    try {
        return draw_plot(p, out, info, err, cap);
    } catch (const std::bad_alloc &) {
        set_err(err, cap, "out of memory drawing the plot");
        return IM_ENOMEM;
    } catch (const std::exception &e) {
        set_err(err, cap, "plot: %s", e.what());
        return IM_EIO;
    }
}
