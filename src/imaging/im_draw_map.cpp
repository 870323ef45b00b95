/* im_draw_map.cpp -- maps of a scalar over a disc (cornea maps: elevation against the
 * best-fit sphere, axial and tangential curvature, residuals): the grid painted in
 * colour bands of a fixed step (topographers' 0.25-0.5 D), a colour bar with the band
 * edges, the disc's outline, mm axes, and optional scattered points (the spots of a
 * residual map) painted on the same scale.  PNG only (the raster has no SVG form). */
#include "im_draw.hpp"
#include <cmath>
#include <cstring>

namespace imd {

/* The colour of t in [0, 1]: dark blue (flat, low) through green and yellow to dark
 * red (steep, high), as clinical topography maps. */
static Rgb band_colour(double t)
{
    static const Rgb k[] = {{0, 0, 130}, {0, 60, 220}, {0, 160, 255}, {0, 200, 160},
                            {60, 190, 60}, {200, 220, 0}, {255, 180, 0}, {255, 90, 0},
                            {210, 0, 0}, {120, 0, 0}};
    const int n = (int)(sizeof k / sizeof k[0]) - 1;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    int i = (int)(t * n);
    if (i >= n) i = n - 1;
    double f = t * n - i;
    return {(unsigned char)lround(k[i].r + f * (k[i + 1].r - k[i].r)),
            (unsigned char)lround(k[i].g + f * (k[i + 1].g - k[i].g)),
            (unsigned char)lround(k[i].b + f * (k[i + 1].b - k[i].b))};
}

static int draw_map(const im_map *m, const im_out *out, im_map_info *info, char *err,
                    size_t cap)
{
    im_map_info dummy;
    if (!info) info = &dummy;
    memset(info, 0, sizeof *info);
    if (!m || !out || !out->png || m->nx < 2 || m->ny < 2 || !m->v ||
        !(m->xmax > m->xmin) || !(m->ymax > m->ymin) || (m->npts > 0 && (!m->px || !m->py || !m->pv))) {
        set_err(err, cap, "map: bad description (grid at least 2 x 2, a png name)");
        return IM_EINVAL;
    }
    if (out->svg) { set_err(err, cap, "map: PNG only (no SVG form of a raster)"); return IM_EINVAL; }
    /* the data's range: grid and points */
    double vmin = INFINITY, vmax = -INFINITY;
    for (long k = 0; k < (long)m->nx * m->ny; k++)
        if (std::isfinite(m->v[k])) { vmin = fmin(vmin, m->v[k]); vmax = fmax(vmax, m->v[k]); }
        else info->skipped++;
    for (int k = 0; k < m->npts; k++)
        if (std::isfinite(m->pv[k])) { vmin = fmin(vmin, m->pv[k]); vmax = fmax(vmax, m->pv[k]); }
    if (!(vmin <= vmax)) { set_err(err, cap, "map: no finite value to draw"); return IM_EINVAL; }
    double lo = vmin, hi = vmax;
    if (m->lo < m->hi) { lo = m->lo; hi = m->hi; }
    if (m->symmetric) { double a = fmax(fabs(lo), fabs(hi)); lo = -a; hi = a; }
    int maxb = m->max_bands > 0 ? m->max_bands : 24;
    double step = m->step;
    if (!(step > 0)) {
        step = 0;
        for (int i = 0; i < m->nsteps && m->steps; i++) {    /* the smallest that fits */
            double s = m->steps[i];
            if (s > 0 && ceil(hi / s - 1e-9) - floor(lo / s + 1e-9) <= maxb) { step = s; break; }
        }
        if (!(step > 0)) step = nice_step(fmax(hi - lo, 1e-12), maxb / 2);
    }
    if (m->symmetric) {          /* bands centred on 0: 0 in the middle of one */
        lo = (floor(lo / step + 0.5) - 0.5) * step;
        hi = (ceil(hi / step - 0.5) + 0.5) * step;
        if (hi - lo < step * 1.5) { lo = -1.5 * step; hi = 1.5 * step; }
    } else {
        lo = floor(lo / step + 1e-9) * step;
        hi = ceil(hi / step - 1e-9) * step;
        if (!(hi > lo)) hi = lo + step;
    }
    int nb = (int)lround((hi - lo) / step);
    if (nb > 400) { set_err(err, cap, "map: %d bands of %g (too many)", nb, step); return IM_EINVAL; }
    info->lo = lo; info->hi = hi; info->step = step; info->nbands = nb;
    info->vmin = vmin; info->vmax = vmax;
    auto colour = [&](double v) {
        int b = (int)floor((v - lo) / step);
        b = b < 0 ? 0 : b >= nb ? nb - 1 : b;
        return band_colour(nb > 1 ? (b + 0.5) / nb : 0.5);
    };

    const int W = out->width > 0 ? out->width : 760, H = out->height > 0 ? out->height : 660;
    double side = fmin(W - 230.0, H - 150.0);
    if (side < 100) { set_err(err, cap, "map: picture %d x %d too small", W, H); return IM_EINVAL; }
    double sx = side, sy = side * (m->ymax - m->ymin) / (m->xmax - m->xmin);
    if (sy > side) { sx = side * side / sy; sy = side; }
    Frame f = {80, 70, 80 + sx, 70 + sy, m->xmin, m->xmax, m->ymin, m->ymax, false, false};
    info->box_x0 = f.x0; info->box_y0 = f.y0; info->box_x1 = f.x1; info->box_y1 = f.y1;
    Canvas c(W, H);
    cv::Mat &img = c.pixels();
    for (int py = (int)ceil(f.y0); py <= (int)floor(f.y1); py++)
        for (int px = (int)ceil(f.x0); px <= (int)floor(f.x1); px++) {
            int i = (int)((px - f.x0) / (f.x1 - f.x0) * m->nx);
            int j = (int)((py - f.y0) / (f.y1 - f.y0) * m->ny);
            if (i < 0 || j < 0 || i >= m->nx || j >= m->ny) continue;
            double v = m->v[(long)j * m->nx + i];
            if (!std::isfinite(v)) continue;
            Rgb col = colour(v);
            img.at<cv::Vec3b>(py, px) = cv::Vec3b(col.b, col.g, col.r);
        }
    axes(c, f, m->xlabel ? m->xlabel : "x (mm)", m->ylabel ? m->ylabel : "y (mm)");
    if (m->disc > 0) {
        Pt o = f.at(0, 0), e = f.at(m->disc, 0);
        c.circle(o, e.x - o.x, BLACK, 1);
    }
    for (int k = 0; k < m->npts; k++) {
        if (!std::isfinite(m->px[k]) || !std::isfinite(m->py[k]) || !std::isfinite(m->pv[k])) continue;
        Pt q = f.at(m->px[k], m->py[k]);
        if (q.x < f.x0 || q.x > f.x1 || q.y < f.y0 || q.y > f.y1) continue;
        double r = m->point_r > 0 ? m->point_r : 3;
        c.disc(q, r, colour(m->pv[k]));
        if (m->mark && m->mark[k]) c.circle(q, r + 2, BLACK, 1.2);
    }
    /* colour bar: one box per band, labelled at its edges (every k-th) */
    double bx = f.x1 + 40, bw = 26, bh = (f.y1 - f.y0) / nb;
    int every = 1;
    while (nb / every > 24) every++;
    double th = Canvas::text_height(0.85);
    for (int b = 0; b < nb; b++) {
        double y1 = f.y1 - b * bh, y0 = y1 - bh;
        Rgb col = band_colour(nb > 1 ? (b + 0.5) / nb : 0.5);
        c.fill({{bx, y0}, {bx + bw, y0}, {bx + bw, y1}, {bx, y1}}, col);
        if (b % every == 0) c.text({bx + bw + 6, y1 + th / 2}, num(lo + b * step), BLACK, 0.85);
    }
    c.text({bx + bw + 6, f.y0 + th / 2}, num(hi), BLACK, 0.85);
    c.rect({bx, f.y0}, {bx + bw, f.y1}, BLACK, 1);
    c.text({bx, f.y0 - 12}, fmt("%s, %s steps", m->unit ? m->unit : "", num(step).c_str()), BLACK, 0.85);
    if (m->title) c.text({f.x0, 28}, m->title, BLACK, 1.2);
    if (m->note) c.text({f.x0, (double)H - 12}, m->note, GREY, 0.9);
    return c.write(out, err, cap);
}

} /* namespace imd */

extern "C" int im_draw_map(const im_map *m, const im_out *out, im_map_info *info, char *err,
                           size_t cap)
{
    try {
        return imd::draw_map(m, out, info, err, cap);
    } catch (const std::bad_alloc &) {
        imd::set_err(err, cap, "out of memory drawing the map");
        return IM_ENOMEM;
    } catch (const std::exception &e) {
        imd::set_err(err, cap, "map: %s", e.what());
        return IM_EIO;
    }
}
