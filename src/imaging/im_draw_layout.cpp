/* im_draw_layout.cpp -- the lens layout in the style of the document's Figures 4-8:
 * the meridional section of a sequential lens (surface profiles from radius, conic
 * and aspheric sag up to each semi-diameter, glass bodies shaded with their edges
 * joined), the optic axis, traced rays, the cardinal points F1 F2 H1 H2 N1 N2 as
 * labelled ticks, object and image arrows, a scale bar with the unit.  The scale is
 * the same along both axes and chosen so that the lens, the object, the image and
 * the cardinal points near the lens fit; points far away are left out and counted. */
#include "im_draw.hpp"
#include <algorithm>
#include <cmath>
#include <cstring>

using namespace imd;

static const int DEF_W = 1000, DEF_H = 520;
static const double FAR = 6;   /* keep points within FAR lens sizes of the lens */

/* Sag at height s (NaN beyond the conic's own limit). */
static double sag(const im_surface *f, double s)
{
    double z = 0, s2 = s * s, p = s2;
    if (std::isfinite(f->radius) && f->radius != 0) {
        double c = 1 / f->radius, q = 1 - (1 + f->conic) * c * c * s2;
        if (q < 0) return NAN;
        z = c * s2 / (1 + sqrt(q));
    }
    for (int i = 0; i < f->nasph && i < IM_MAXASPH; i++, p *= s2) z += f->asph[i] * p;
    return z;
}

/* The surface's height limit: its semi-diameter, or where the conic ends. */
static double reach(const im_surface *f)
{
    double h = f->semi > 0 ? f->semi : 0;
    if (std::isfinite(f->radius) && f->radius != 0 && 1 + f->conic > 0) {
        double lim = fabs(f->radius) / sqrt(1 + f->conic);
        if (h > lim) h = lim * (1 - 1e-9);
    }
    return h;
}

struct Map {
    double s, x0, y0;
    Pt operator()(double z, double y) const { return {x0 + s * z, y0 - s * y}; }
};

/* Profile of surface f from height a to b (flat beyond its reach), n points. */
static void profile(const im_surface *f, double a, double b, int n, const Map &m,
                    std::vector<Pt> &out)
{
    double r = reach(f);
    for (int i = 0; i <= n; i++) {
        double y = a + (b - a) * i / n, s = fmax(-r, fmin(r, y)), z = sag(f, s);
        if (!std::isfinite(z)) continue;
        out.push_back(m(f->z + z, y));
    }
}

static bool glass(double n) { return fabs(n - 1) > 1e-6; }

struct Tick { const char *name; double z; Rgb col; };

static int check(const im_layout *l, char *err, size_t cap)
{
    if (l->nsurf < 1 || !l->surf) { set_err(err, cap, "a layout needs at least one surface"); return IM_EINVAL; }
    for (int i = 0; i < l->nsurf; i++) {
        const im_surface *f = &l->surf[i];
        if (!std::isfinite(f->z) || !(f->semi > 0) || !std::isfinite(f->semi) ||
            std::isnan(f->radius) || !std::isfinite(f->conic) || f->nasph < 0 ||
            f->nasph > IM_MAXASPH) {
            set_err(err, cap, "surface %d: location, semi-diameter, radius or conic out of range", i + 1);
            return IM_EINVAL;
        }
    }
    for (int i = 0; i < l->nray; i++)
        if (l->ray[i].n < 0 || (l->ray[i].n > 0 && !l->ray[i].zy)) {
            set_err(err, cap, "ray %d has no points", i + 1);
            return IM_EINVAL;
        }
    return IM_OK;
}

static int draw_layout(const im_layout *l, const im_out *out, im_layout_info *info,
                       char *err, size_t cap)
{
    im_layout_info dummy;
    if (!info) info = &dummy;
    memset(info, 0, sizeof *info);
    if (!out || !out->png) { set_err(err, cap, "no picture file named"); return IM_EINVAL; }
    int rc = check(l, err, cap);
    if (rc) return rc;
    int W = out->width > 0 ? out->width : DEF_W, H = out->height > 0 ? out->height : DEF_H;
    if (W < 200 || H < 150 || W > 20000 || H > 20000) {
        set_err(err, cap, "%dx%d: a layout is 200x150 to 20000x20000 pixels", W, H);
        return IM_EINVAL;
    }

    /* the lens's extent */
    double zlo = INFINITY, zhi = -INFINITY, ymax = 0;
    for (int i = 0; i < l->nsurf; i++) {
        const im_surface *f = &l->surf[i];
        double r = reach(f);
        for (int k = 0; k <= 16; k++) {
            double z = f->z + sag(f, r * k / 16);
            if (std::isfinite(z)) { zlo = fmin(zlo, z); zhi = fmax(zhi, z); }
        }
        ymax = fmax(ymax, f->semi);
    }
    double size = fmax(zhi - zlo, 2 * ymax), mid = (zlo + zhi) / 2;
    auto near = [&](double z) { return std::isfinite(z) && fabs(z - mid) <= FAR * size; };
    Tick ticks[] = {{"F1", l->z_f1, RED}, {"F2", l->z_f2, RED}, {"H1", l->z_h1, BLUE},
                    {"H2", l->z_h2, BLUE}, {"N1", l->z_n1, GREEN}, {"N2", l->z_n2, GREEN}};
    for (const Tick &t : ticks) {
        if (std::isnan(t.z)) continue;
        if (near(t.z)) { zlo = fmin(zlo, t.z); zhi = fmax(zhi, t.z); }
        else info->offpicture++;
    }
    bool obj = near(l->z_obj) && std::isfinite(l->y_obj);
    bool img = near(l->z_img) && std::isfinite(l->y_img);
    if (std::isfinite(l->z_obj) && !obj) info->offpicture++;
    if (std::isfinite(l->z_img) && !img) info->offpicture++;
    if (obj) { zlo = fmin(zlo, l->z_obj); zhi = fmax(zhi, l->z_obj); ymax = fmax(ymax, fabs(l->y_obj)); }
    if (img) { zlo = fmin(zlo, l->z_img); zhi = fmax(zhi, l->z_img); ymax = fmax(ymax, fabs(l->y_img)); }
    if (!std::isfinite(l->z_obj) && l->nray > 0) zlo -= 0.25 * size;   /* incoming beam */
    double span = fmax(zhi - zlo, 1e-9 * fmax(1, fabs(zhi)));
    zlo -= 0.05 * span; zhi += 0.05 * span;
    ymax *= 1.12;

    /* the scale: the same along z and y */
    const double left = 20, right = 20, top = 38, bottom = 78;
    Map m;
    m.s = fmin((W - left - right) / (zhi - zlo), (H - top - bottom) / (2 * ymax));
    if (out->height <= 0) {   /* no height asked: as tall as the lens needs at this scale */
        H = (int)fmax(260, fmin(H, ceil(top + bottom + 2 * ymax * m.s + 40)));
        m.s = fmin(m.s, (H - top - bottom) / (2 * ymax));
    }
    m.x0 = left + ((W - left - right) - m.s * (zhi - zlo)) / 2 - m.s * zlo;
    m.y0 = top + (H - top - bottom) / 2;
    info->px_per_unit = m.s;
    info->x0 = m.x0;
    info->y0 = m.y0;

    Canvas cv(W, H);
    /* glass bodies: between surface i and i+1 where the medium is not air */
    for (int i = 0; i + 1 < l->nsurf; i++) {
        if (!glass(l->surf[i].n_right)) continue;
        const im_surface *a = &l->surf[i], *b = &l->surf[i + 1];
        double d = fmax(a->semi, b->semi);
        std::vector<Pt> poly, back;
        profile(a, -d, d, 96, m, poly);
        profile(b, d, -d, 96, m, back);
        poly.insert(poly.end(), back.begin(), back.end());
        cv.fill(poly, GLASS);
        if (!poly.empty()) poly.push_back(poly.front());
        cv.polyline(poly, GLASS_EDGE, 1.2);
    }
    /* a medium that is not air before the first or after the last surface (a single
     * refracting surface, an eye, water): shaded out to the picture's edge */
    auto medium = [&](const im_surface *f, double zedge) {
        std::vector<Pt> poly;
        profile(f, -f->semi, f->semi, 96, m, poly);
        poly.push_back(m(zedge, f->semi));
        poly.push_back(m(zedge, -f->semi));
        cv.fill(poly, GLASS);
    };
    if (glass(l->n_object)) medium(&l->surf[0], zlo);
    if (glass(l->surf[l->nsurf - 1].n_right)) medium(&l->surf[l->nsurf - 1], zhi);
    /* the optic axis */
    cv.line({left, m.y0}, {W - right, m.y0}, AXIS, 1, 0);   /* across the picture */
    /* rays */
    for (int i = 0; i < l->nray; i++) {
        std::vector<Pt> p;
        for (int k = 0; k < l->ray[i].n; k++)
            p.push_back(m(l->ray[i].zy[2 * k], l->ray[i].zy[2 * k + 1]));
        cv.polyline(p, palette(l->ray[i].group), 1, l->ray[i].dashed ? 3 : 0);
    }
    /* every surface's profile (also those that bound no body) */
    for (int i = 0; i < l->nsurf; i++) {
        std::vector<Pt> p;
        profile(&l->surf[i], -l->surf[i].semi, l->surf[i].semi, 96, m, p);
        cv.polyline(p, GLASS_EDGE, 1.5);
    }

    auto add_mark = [&](const char *name, Pt foot, Pt label) {
        if (info->nmark >= IM_MAXMARK) return;
        im_mark *k = &info->mark[info->nmark++];
        snprintf(k->name, sizeof k->name, "%s", name);
        k->x = foot.x; k->y = foot.y; k->label_x = label.x; k->label_y = label.y;
    };
    /* Labels never overlap: each is put at its wanted place or moved away from the
     * axis a row at a time until it clears every label placed before it. */
    double th = Canvas::text_height(1);
    struct Box { double x0, y0, x1, y1; };
    std::vector<Box> placed;
    auto place = [&](double x, double base, double w, int dir) {
        for (int row = 0; row < 8; row++, base += dir * (th + 6)) {
            Box b = {x - 2, base - th - 3, x + w + 2, base + 3};
            bool clash = false;
            for (const Box &o : placed)
                if (b.x0 < o.x1 && b.x1 > o.x0 && b.y0 < o.y1 && b.y1 > o.y0) clash = true;
            if (!clash || row == 7) { placed.push_back(b); return base; }
        }
        return base;
    };
    auto label = [&](Pt at, const char *s, Rgb col) {
        double w = Canvas::text_width(s);
        cv.fill({{at.x - 2, at.y + 3}, {at.x + w + 2, at.y + 3}, {at.x + w + 2, at.y - th - 3},
                 {at.x - 2, at.y - th - 3}}, WHITE);
        cv.text(at, s, col);
    };

    /* cardinal ticks across the axis, labels below it */
    std::vector<int> order;
    for (int i = 0; i < 6; i++) if (!std::isnan(ticks[i].z) && near(ticks[i].z)) order.push_back(i);
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return ticks[a].z < ticks[b].z; });
    struct Lab { Pt at; const char *s; Rgb col; };
    std::vector<Lab> labels;
    for (int i : order) {
        Pt foot = m(ticks[i].z, 0);
        cv.line({foot.x, foot.y - 9}, {foot.x, foot.y + 9}, ticks[i].col, 2);
        double w = Canvas::text_width(ticks[i].name), x = foot.x - w / 2;
        double want = foot.y + 12 + th, y = place(x, want, w, +1);
        if (y > want) cv.line({foot.x, foot.y + 9}, {foot.x, y - th - 2}, ticks[i].col, 1, 2);
        labels.push_back({{x, y}, ticks[i].name, ticks[i].col});
        add_mark(ticks[i].name, foot, {x, y});
    }
    /* object and image arrows, labelled beyond their tips */
    auto arrow = [&](const char *name, double z, double y, bool dashed) {
        Pt foot = m(z, 0), tip = m(z, y);
        cv.arrow(foot, tip, BLACK, 2, dashed ? 4 : 0);
        double w = Canvas::text_width(name), x = tip.x - w / 2;
        double base = place(x, y >= 0 ? tip.y - 6 : tip.y + 6 + th, w, y >= 0 ? -1 : +1);
        labels.push_back({{x, base}, name, BLACK});
        add_mark(name, foot, {x, base});
    };
    if (obj) arrow("object", l->z_obj, l->y_obj, false);
    if (img) arrow(l->image_virtual ? "image (virtual)" : "image", l->z_img, l->y_img,
                   l->image_virtual != 0);
    for (const Lab &k : labels) label(k.at, k.s, k.col);

    /* scale bar, bottom left, and the title */
    const char *unit = l->unit && *l->unit ? l->unit : "units";
    double step = nice_step((W - left - right) / m.s, 6), bar = step * m.s;
    Pt b0 = {left + 10, (double)H - 26}, b1 = {b0.x + bar, b0.y};
    cv.line(b0, b1, BLACK, 2);
    cv.line({b0.x, b0.y - 5}, {b0.x, b0.y + 5}, BLACK, 1.5);
    cv.line({b1.x, b1.y - 5}, {b1.x, b1.y + 5}, BLACK, 1.5);
    cv.text({b1.x + 8, b0.y + th / 2}, num(step) + " " + unit, BLACK);
    if (info->offpicture)
        cv.text({(double)W - right, (double)H - 26 + th / 2},
                fmt("%d point%s too far from the lens to show", info->offpicture,
                    info->offpicture > 1 ? "s" : ""), GREY, 1, RIGHT);
    if (l->title) cv.text({left, 24}, l->title, BLACK, 1.2);
    return cv.write(out, err, cap);
}

extern "C" int im_draw_layout(const im_layout *l, const im_out *out, im_layout_info *info,
                              char *err, size_t cap)
{
    try {
        return draw_layout(l, out, info, err, cap);
    } catch (const std::bad_alloc &) {
        set_err(err, cap, "out of memory drawing the layout");
        return IM_ENOMEM;
    } catch (const std::exception &e) {
        set_err(err, cap, "layout: %s", e.what());
        return IM_EIO;
    }
}
