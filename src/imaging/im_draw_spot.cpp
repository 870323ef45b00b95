/* im_draw_spot.cpp -- spot diagrams: the hits in a detector or image plane, coloured
 * by group (field or wavelength), about their centroid, with the RMS and maximum
 * radius drawn and stated, and the Airy disc's radius where a wavelength is known.
 * Fields get a panel each (same scale), wavelengths share one. */
#include "im_draw.hpp"
#include <cmath>
#include <cstring>

using namespace imd;

/* Two passes: the centroid, then the radii about it (no cancellation). */
extern "C" void im_draw_spot_stat(const im_sd_point *pt, int n, int group, im_sd_stat *s)
{
    double sx = 0, sy = 0, s2 = 0, mx = 0;
    int k = 0;
    memset(s, 0, sizeof *s);
    for (int i = 0; i < n; i++)
        if ((group < 0 || pt[i].group == group) && std::isfinite(pt[i].x) && std::isfinite(pt[i].y)) {
            sx += pt[i].x; sy += pt[i].y; k++;
        }
    if (!k) return;
    s->n = k; s->cx = sx / k; s->cy = sy / k;
    for (int i = 0; i < n; i++)
        if ((group < 0 || pt[i].group == group) && std::isfinite(pt[i].x) && std::isfinite(pt[i].y)) {
            double r2 = (pt[i].x - s->cx) * (pt[i].x - s->cx) + (pt[i].y - s->cy) * (pt[i].y - s->cy);
            s2 += r2;
            mx = fmax(mx, r2);
        }
    s->rms = sqrt(s2 / k);
    /* a centroid that is zero but for rounding (symmetric bundles) is said as 0 */
    double scale = sqrt(mx) + fabs(s->cx) + fabs(s->cy);
    if (fabs(s->cx) < 1e-12 * scale) s->cx = 0;
    if (fabs(s->cy) < 1e-12 * scale) s->cy = 0;
    s->rmax = sqrt(mx);
}

static int draw_spot(const im_spotdiag *sp, const im_out *out, im_sd_info *info, char *err, size_t cap)
{
    im_sd_info dummy;
    if (!info) info = &dummy;
    memset(info, 0, sizeof *info);
    if (!out || !out->png) { set_err(err, cap, "no picture file named"); return IM_EINVAL; }
    if (sp->n < 1 || !sp->pt) { set_err(err, cap, "a spot diagram needs at least one hit"); return IM_EINVAL; }
    if (sp->ngroup < 1 || sp->ngroup > IM_MAXGROUP) {
        set_err(err, cap, "%d groups: a spot diagram has 1 to %d", sp->ngroup, IM_MAXGROUP);
        return IM_EINVAL;
    }
    if (!(sp->airy_radius >= 0) || !std::isfinite(sp->airy_radius)) {
        set_err(err, cap, "the Airy radius must be a finite number >= 0");
        return IM_EINVAL;
    }
    for (int i = 0; i < sp->n; i++)
        if (sp->pt[i].group < 0 || sp->pt[i].group >= sp->ngroup) {
            set_err(err, cap, "hit %d is in group %d (of %d)", i + 1, sp->pt[i].group, sp->ngroup);
            return IM_EINVAL;
        }
    im_draw_spot_stat(sp->pt, sp->n, -1, &info->all);
    if (!info->all.n) { set_err(err, cap, "no hit has finite coordinates"); return IM_EINVAL; }
    for (int g = 0; g < sp->ngroup; g++) im_draw_spot_stat(sp->pt, sp->n, g, &info->group[g]);

    int npanel = sp->panels && sp->ngroup > 1 ? sp->ngroup : 1;
    int P = out->width > 0 ? out->width / npanel : 520;
    if (P < 240 || P > 8000) { set_err(err, cap, "spot diagram panels are 240 to 8000 pixels wide"); return IM_EINVAL; }
    const char *unit = sp->unit && *sp->unit ? sp->unit : "units";
    double th = Canvas::text_height(1);
    int lines = 4;   /* text lines under a panel: name, centroid, RMS/max, Airy */
    int W = P * npanel, H = out->height > 0 ? out->height : P + 40 + (int)(lines * (th + 8)) + 40;

    /* the half-width shown: the largest spot or Airy disc, with a margin */
    double R = 0;
    for (int k = 0; k < npanel; k++) {
        const im_sd_stat &s = npanel > 1 ? info->group[k] : info->all;
        R = fmax(R, s.rmax);
    }
    R = fmax(R, sp->airy_radius);
    if (!(R > 0)) R = fmax(1e-9, 1e-6 * fmax(fabs(info->all.cx), fabs(info->all.cy)));
    R *= 1.15;

    Canvas c(W, H);
    for (int k = 0; k < npanel; k++) {
        const im_sd_stat &s = npanel > 1 ? info->group[k] : info->all;
        double ox = k * P;
        Frame f = {ox + 70, 60, ox + P - 20, 60 + (P - 90.0), -R, R, -R, R, false, false};
        info->px_per_unit = (f.x1 - f.x0) / (2 * R);
        axes(c, f, fmt("x - centroid (%s)", unit).c_str(), k == 0 ? fmt("y - centroid (%s)", unit).c_str() : NULL);
        Pt o = f.at(0, 0);
        for (int i = 0; i < sp->n; i++) {
            const im_sd_point &q = sp->pt[i];
            if (npanel > 1 && q.group != k) continue;
            c.disc(f.at(q.x - s.cx, q.y - s.cy), 1.5, palette(q.group));
        }
        double px = info->px_per_unit;
        c.circle(o, s.rms * px, BLACK, 1, 4);
        c.circle(o, s.rmax * px, GREY, 1, 2);
        if (sp->airy_radius > 0) c.circle(o, sp->airy_radius * px, GREEN, 1.6);
        c.line({o.x - 7, o.y}, {o.x + 7, o.y}, BLACK, 1.5);
        c.line({o.x, o.y - 7}, {o.x, o.y + 7}, BLACK, 1.5);
        /* the figures under the panel */
        double y = f.y1 + 2 * th + 50;
        std::string name = npanel > 1 || sp->ngroup == 1
            ? (sp->group_name ? sp->group_name[npanel > 1 ? k : 0] : fmt("%d", k + 1))
            : std::string("");
        if (npanel == 1 && sp->ngroup > 1) {   /* a legend of the groups */
            double x = f.x0;
            for (int g = 0; g < sp->ngroup; g++) {
                std::string n = sp->group_name ? sp->group_name[g] : fmt("%d", g + 1);
                c.disc({x + 4, y - th / 2}, 4, palette(g));
                x += 14 + c.text({x + 12, y}, n, BLACK) + 14;
            }
        } else {
            c.disc({f.x0 + 4, y - th / 2}, 4, palette(npanel > 1 ? k : 0));
            c.text({f.x0 + 14, y}, fmt("%s: %d hits", name.c_str(), s.n), BLACK);
        }
        y += th + 8;
        c.text({f.x0, y}, fmt("centroid (%.6g, %.6g) %s", s.cx, s.cy, unit), BLACK);
        y += th + 8;
        c.text({f.x0, y}, fmt("RMS radius %.4g, max %.4g %s", s.rms, s.rmax, unit), BLACK);
        y += th + 8;
        if (sp->airy_radius > 0)
            c.text({f.x0, y}, fmt("Airy radius %.4g %s", sp->airy_radius, unit), GREEN);
        else
            c.text({f.x0, y}, "Airy radius: no wavelength given", GREY);
    }
    if (sp->title) c.text({20, 24}, sp->title, BLACK, 1.2);
    /* the key of the circles, top right */
    double kx = W - 20 - 3 * 90;
    const char *kname[3] = {"RMS", "max", "Airy"};
    Rgb kcol[3] = {BLACK, GREY, GREEN};
    double kdash[3] = {4, 2, 0};
    for (int i = 0; i < 3; i++) {
        if (i == 2 && !(sp->airy_radius > 0)) break;
        c.line({kx + 90 * i, 20}, {kx + 90 * i + 28, 20}, kcol[i], i == 2 ? 1.6 : 1, kdash[i]);
        c.text({kx + 90 * i + 34, 20 + th / 2}, kname[i], kcol[i], 0.9);
    }
    return c.write(out, err, cap);
}

extern "C" int im_draw_spot(const im_spotdiag *s, const im_out *out, im_sd_info *info,
                            char *err, size_t cap)
{
    try {
        return draw_spot(s, out, info, err, cap);
    } catch (const std::bad_alloc &) {
        set_err(err, cap, "out of memory drawing the spot diagram");
        return IM_ENOMEM;
    } catch (const std::exception &e) {
        set_err(err, cap, "spot diagram: %s", e.what());
        return IM_EIO;
    }
}
