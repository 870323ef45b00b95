/* im_draw_canvas.cpp -- the pictures' canvas: each primitive drawn into an OpenCV
 * BGR image (anti-aliased lines with 8 bits of sub-pixel position) and appended to
 * an SVG document with the same coordinates; atomic writes of both files. */
#include "im_draw.hpp"
#include "common/lm_out.h"
#include <opencv2/imgproc.hpp>
#include <opencv2/imgcodecs.hpp>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace imd {

const Rgb BLACK = {0, 0, 0}, WHITE = {255, 255, 255}, GREY = {110, 110, 110},
          LIGHTGREY = {220, 220, 220}, AXIS = {90, 90, 90}, RED = {200, 30, 30},
          BLUE = {30, 70, 200}, GREEN = {20, 140, 40}, GLASS = {205, 225, 245},
          GLASS_EDGE = {40, 60, 100};

Rgb palette(int i)
{
    static const Rgb p[] = {{31, 119, 180}, {255, 127, 14}, {44, 160, 44}, {127, 127, 127},
                            {148, 103, 189}, {140, 86, 75}, {227, 119, 194}, {23, 190, 207}};
    return p[((i % 8) + 8) % 8];
}

static const int SHIFT = 8;
static const double ONE = 256.0;      /* 1 << SHIFT */
static const int FONT = cv::FONT_HERSHEY_SIMPLEX;
static const double FONT_SCALE = 0.5; /* size 1: Hershey simplex at 0.5, ~11 px caps */

static cv::Scalar bgr(Rgb c) { return cv::Scalar(c.b, c.g, c.r); }
static cv::Point fix(Pt p) { return cv::Point((int)lround(p.x * ONE), (int)lround(p.y * ONE)); }
static std::string hex(Rgb c) { return fmt("#%02x%02x%02x", c.r, c.g, c.b); }
static bool finite(Pt p) { return std::isfinite(p.x) && std::isfinite(p.y) &&
                                  fabs(p.x) < 1e6 && fabs(p.y) < 1e6; }

static std::string xml(const std::string &s)
{
    std::string o;
    for (char ch : s) {
        if (ch == '<') o += "&lt;"; else if (ch == '>') o += "&gt;";
        else if (ch == '&') o += "&amp;"; else if (ch == '"') o += "&quot;";
        else o += ch;
    }
    return o;
}

Canvas::Canvas(int w, int h) : w_(w), h_(h), img_(h, w, CV_8UC3, cv::Scalar(255, 255, 255))
{
    svg_ = fmt("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
               "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" "
               "viewBox=\"0 0 %d %d\">\n<rect width=\"%d\" height=\"%d\" fill=\"#ffffff\"/>\n"
               "<g transform=\"translate(0.5 0.5)\" stroke-linecap=\"round\" "
               "font-family=\"DejaVu Sans, Helvetica, Arial, sans-serif\">\n",
               w, h, w, h, w, h);
}

void Canvas::seg(Pt a, Pt b, Rgb c, double width)
{
    int t = width < 1.5 ? 1 : (int)lround(width);
    cv::line(img_, fix(a), fix(b), bgr(c), t, cv::LINE_AA, SHIFT);
}

/* Clip segment a-b to the rectangle (Liang-Barsky); false if nothing is left. */
static bool clip(Pt &a, Pt &b, double x0, double y0, double x1, double y1)
{
    double t0 = 0, t1 = 1, dx = b.x - a.x, dy = b.y - a.y;
    double p[4] = {-dx, dx, -dy, dy}, q[4] = {a.x - x0, x1 - a.x, a.y - y0, y1 - a.y};
    for (int i = 0; i < 4; i++) {
        if (p[i] == 0) { if (q[i] < 0) return false; continue; }
        double t = q[i] / p[i];
        if (p[i] < 0) { if (t > t1) return false; if (t > t0) t0 = t; }
        else { if (t < t0) return false; if (t < t1) t1 = t; }
    }
    Pt a2 = {a.x + t0 * dx, a.y + t0 * dy}, b2 = {a.x + t1 * dx, a.y + t1 * dy};
    a = a2; b = b2;
    return true;
}

/* A polyline reaching far outside the picture (a ray from a distant object) is cut
 * to the picture plus a margin, in runs, before it is drawn. */
void Canvas::polyline(const std::vector<Pt> &p, Rgb c, double width, double dash)
{
    const double m = 20, x0 = -m, y0 = -m, x1 = w_ + m, y1 = h_ + m;
    bool inside = true;
    for (const Pt &q : p) {
        if (!std::isfinite(q.x) || !std::isfinite(q.y)) return;
        if (q.x < x0 || q.x > x1 || q.y < y0 || q.y > y1) inside = false;
    }
    if (inside) { run(p, c, width, dash); return; }
    std::vector<Pt> cur;
    for (size_t i = 0; i + 1 < p.size(); i++) {
        Pt a = p[i], b = p[i + 1];
        if (!clip(a, b, x0, y0, x1, y1)) { run(cur, c, width, dash); cur.clear(); continue; }
        if (cur.empty() || cur.back().x != a.x || cur.back().y != a.y) {
            run(cur, c, width, dash);
            cur.clear();
            cur.push_back(a);
        }
        cur.push_back(b);
        if (b.x != p[i + 1].x || b.y != p[i + 1].y) { run(cur, c, width, dash); cur.clear(); }
    }
    run(cur, c, width, dash);
}

/* Dashes are cut here for the PNG (OpenCV has none) and given to SVG as a dasharray,
 * starting at the same phase. */
void Canvas::run(const std::vector<Pt> &p, Rgb c, double width, double dash)
{
    std::string d;
    if (p.size() < 2) return;
    for (const Pt &q : p) if (!finite(q)) return;
    double phase = 0;
    if (dash <= 0) {   /* one path: joints are not painted twice (no beads on curves) */
        /* points in line with their neighbours dropped: OpenCV paints each joint
         * of a thick anti-aliased line twice (beads along a flat surface) */
        std::vector<cv::Point> q;
        size_t kept = 0;   /* the last point kept: the chord is measured from it */
        for (size_t i = 0; i < p.size(); i++) {
            if (i > 0 && i + 1 < p.size()) {   /* every point since `kept` near the chord? */
                const Pt &a = p[kept], &e = p[i + 1];
                double len = hypot(e.x - a.x, e.y - a.y);
                bool near = len > 0;
                for (size_t j = kept + 1; j <= i && near; j++) {
                    const Pt &b = p[j];
                    double cross = (b.x - a.x) * (e.y - a.y) - (b.y - a.y) * (e.x - a.x);
                    near = fabs(cross) / len < 0.02;
                }
                if (near) continue;
            }
            kept = i;
            q.push_back(fix(p[i]));
        }
        int t = width < 1.5 ? 1 : (int)lround(width);
        cv::polylines(img_, q, false, bgr(c), t, cv::LINE_AA, SHIFT);
    }
    for (size_t i = 0; i + 1 < p.size() && dash > 0; i++) {
        Pt a = p[i], b = p[i + 1];
        double len = hypot(b.x - a.x, b.y - a.y), s = 0;
        while (s < len) {
            double per = fmod(phase, 2 * dash), run = per < dash ? dash - per : 2 * dash - per;
            double e = fmin(len, s + run);
            if (per < dash) {
                Pt u = {a.x + (b.x - a.x) * s / len, a.y + (b.y - a.y) * s / len};
                Pt v = {a.x + (b.x - a.x) * e / len, a.y + (b.y - a.y) * e / len};
                seg(u, v, c, width);
            }
            phase += e - s;
            s = e;
        }
    }
    for (size_t i = 0; i < p.size(); i++)
        d += fmt("%s%.2f,%.2f", i ? " " : "", p[i].x, p[i].y);
    svg_ += fmt("<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"%.2g\"%s points=\"%s\"/>\n",
                hex(c).c_str(), width,
                dash > 0 ? fmt(" stroke-dasharray=\"%.3g\"", dash).c_str() : "", d.c_str());
}

void Canvas::line(Pt a, Pt b, Rgb c, double width, double dash)
{
    polyline({a, b}, c, width, dash);
}

void Canvas::fill(const std::vector<Pt> &p, Rgb c)
{
    std::vector<cv::Point> q;
    std::string d;
    if (p.size() < 3) return;
    for (const Pt &r : p) { if (!finite(r)) return; q.push_back(fix(r)); }
    const cv::Point *pts = q.data();
    int n = (int)q.size();
    cv::fillPoly(img_, &pts, &n, 1, bgr(c), cv::LINE_AA, SHIFT);
    for (size_t i = 0; i < p.size(); i++) d += fmt("%s%.2f,%.2f", i ? " " : "", p[i].x, p[i].y);
    svg_ += fmt("<polygon fill=\"%s\" stroke=\"none\" points=\"%s\"/>\n", hex(c).c_str(), d.c_str());
}

void Canvas::circle(Pt c, double r, Rgb col, double width, double dash)
{
    if (!finite(c) || !(r > 0) || r > 1e5) return;
    if (dash > 0) {   /* the PNG's dashes along a polygon of small steps */
        std::vector<Pt> p;
        int n = (int)fmax(24, fmin(2000, r * 2));
        for (int i = 0; i <= n; i++)
            p.push_back({c.x + r * cos(2 * M_PI * i / n), c.y + r * sin(2 * M_PI * i / n)});
        std::string keep = svg_;
        polyline(p, col, width, dash);
        svg_ = keep;
    } else {
        int t = width < 1.5 ? 1 : (int)lround(width);
        cv::circle(img_, fix(c), (int)lround(r * ONE), bgr(col), t, cv::LINE_AA, SHIFT);
    }
    svg_ += fmt("<circle cx=\"%.2f\" cy=\"%.2f\" r=\"%.2f\" fill=\"none\" stroke=\"%s\" "
                "stroke-width=\"%.2g\"%s/>\n", c.x, c.y, r, hex(col).c_str(), width,
                dash > 0 ? fmt(" stroke-dasharray=\"%.3g\"", dash).c_str() : "");
}

void Canvas::disc(Pt c, double r, Rgb col)
{
    if (!finite(c) || !(r > 0)) return;
    cv::circle(img_, fix(c), (int)lround(r * ONE), bgr(col), cv::FILLED, cv::LINE_AA, SHIFT);
    svg_ += fmt("<circle cx=\"%.2f\" cy=\"%.2f\" r=\"%.2f\" fill=\"%s\"/>\n", c.x, c.y, r,
                hex(col).c_str());
}

void Canvas::rect(Pt a, Pt b, Rgb col, double width)
{
    polyline({a, {b.x, a.y}, b, {a.x, b.y}, a}, col, width);
}

void Canvas::arrow(Pt from, Pt to, Rgb c, double width, double dash)
{
    double dx = to.x - from.x, dy = to.y - from.y, len = hypot(dx, dy);
    line(from, to, c, width, dash);
    if (!(len > 0)) return;
    double hl = fmin(10, len * 0.4), ux = dx / len, uy = dy / len;
    Pt l = {to.x - hl * ux + 0.45 * hl * uy, to.y - hl * uy - 0.45 * hl * ux};
    Pt r = {to.x - hl * ux - 0.45 * hl * uy, to.y - hl * uy + 0.45 * hl * ux};
    fill({to, l, r}, c);
}

double Canvas::text_width(const std::string &s, double size)
{
    int base = 0;
    cv::Size z = cv::getTextSize(s, FONT, FONT_SCALE * size, 1, &base);
    return z.width;
}

double Canvas::text_height(double size)
{
    int base = 0;
    return cv::getTextSize("H", FONT, FONT_SCALE * size, 1, &base).height;
}

double Canvas::text(Pt at, const std::string &s, Rgb c, double size, Anchor a)
{
    double w = text_width(s, size), x = at.x;
    if (a == CENTER) x -= w / 2;
    else if (a == RIGHT) x -= w;
    if (!finite(at)) return w;
    cv::putText(img_, s, cv::Point((int)lround(x), (int)lround(at.y)), FONT, FONT_SCALE * size,
                bgr(c), size > 1.3 ? 2 : 1, cv::LINE_AA);
    /* Hershey simplex at scale 0.5 is ~11 px caps and ~9.5 px per character: a
     * 15 px sans-serif font matches it, textLength pins the width. */
    svg_ += fmt("<text x=\"%.1f\" y=\"%.1f\" font-size=\"%.1f\" fill=\"%s\" "
                "textLength=\"%.1f\" lengthAdjust=\"spacingAndGlyphs\">%s</text>\n",
                x, at.y, 15.5 * size, hex(c).c_str(), w, xml(s).c_str());
    return w;
}

int Canvas::write(const im_out *out, char *err, size_t cap) const
{
    std::vector<unsigned char> png;
    if (out->stop && out->stop(out->stop_ctx)) {
        set_err(err, cap, "%s: stopped before it was written", out->png);
        return IM_ESTOP;
    }
    try {
        if (!cv::imencode(".png", img_, png)) {
            set_err(err, cap, "%s: the PNG encoder failed", out->png);
            return IM_EIO;
        }
    } catch (const cv::Exception &e) {
        set_err(err, cap, "%s: %s", out->png, e.what());
        return IM_EIO;
    }
    int rc = write_atomic(out->png, png.data(), png.size(), err, cap);
    if (rc == IM_OK && out->svg) {
        std::string s = svg_ + "</g>\n</svg>\n";
        rc = write_atomic(out->svg, s.data(), s.size(), err, cap);
    }
    return rc;
}

/* pictures go through the shared writer (src/common/lm_out.h), like frames: a unique
 * temporary renamed over a regular file, a device or FIFO in place, a link's target */
int write_atomic(const char *path, const void *data, size_t len, char *err, size_t cap)
{
    return lm_out_save(path, data, len, err, cap) ? IM_EIO : IM_OK;
}

double nice_step(double span, int target)
{
    if (!(span > 0) || !std::isfinite(span)) return 1;
    double raw = span / (target > 0 ? target : 1), p = pow(10, floor(log10(raw))), m = raw / p;
    return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}

std::string num(double v)
{
    if (fabs(v) < 1e-12) v = 0;
    return fmt("%.4g", v);
}

std::string fmt(const char *f, ...)
{
    char buf[1024];
    va_list ap;
    va_start(ap, f);
    int n = vsnprintf(buf, sizeof buf, f, ap);
    va_end(ap);
    if (n < (int)sizeof buf) return std::string(buf, n > 0 ? (size_t)n : 0);
    std::string s((size_t)n + 1, '\0');
    va_start(ap, f);
    vsnprintf(&s[0], s.size(), f, ap);
    va_end(ap);
    s.resize((size_t)n);
    return s;
}

void set_err(char *err, size_t cap, const char *f, ...)
{
    va_list ap;
    if (!err || !cap) return;
    va_start(ap, f);
    vsnprintf(err, cap, f, ap);
    va_end(ap);
}

} /* namespace imd */
