/* im_draw.hpp -- internal to the pictures half of the imaging engine (C++): a canvas
 * that draws every primitive twice, into an OpenCV image (anti-aliased, sub-pixel)
 * and as SVG text, so the PNG and the SVG are one drawing; atomic file writes; and
 * the small helpers the pictures share (nice tick steps, number labels, palette).
 * Coordinates are PNG pixels, (0, 0) the centre of the top-left pixel. */
#ifndef IM_DRAW_HPP
#define IM_DRAW_HPP
#include <opencv2/core.hpp>
#include <string>
#include <vector>
extern "C" {
#include "imaging.h"
}

namespace imd {

struct Rgb { unsigned char r, g, b; };
struct Pt { double x, y; };

enum Anchor { LEFT, CENTER, RIGHT };

extern const Rgb BLACK, WHITE, GREY, LIGHTGREY, AXIS, RED, BLUE, GREEN, GLASS, GLASS_EDGE;
Rgb palette(int i);              /* colours of groups 0, 1, ... */

class Canvas {
public:
    Canvas(int w, int h);
    int width() const { return w_; }
    int height() const { return h_; }
    void line(Pt a, Pt b, Rgb c, double width = 1, double dash = 0);
    void polyline(const std::vector<Pt> &p, Rgb c, double width = 1, double dash = 0);
    void fill(const std::vector<Pt> &p, Rgb c);       /* closed polygon */
    void circle(Pt c, double r, Rgb col, double width = 1, double dash = 0);
    void disc(Pt c, double r, Rgb col);
    void rect(Pt a, Pt b, Rgb col, double width = 1);
    void arrow(Pt from, Pt to, Rgb c, double width = 1, double dash = 0);
    /* Text of `size` (cap height about 16 size px) with its baseline at y; returns
     * its width in pixels. */
    double text(Pt at, const std::string &s, Rgb c, double size = 1, Anchor a = LEFT);
    static double text_width(const std::string &s, double size = 1);
    static double text_height(double size = 1);
    /* Encode and write atomically.  IM_OK or an error with err set. */
    int write(const im_out *out, char *err, size_t cap) const;
    const cv::Mat &image() const { return img_; }
    cv::Mat &pixels() { return img_; }   /* rasters (maps): PNG only, not in the SVG */
private:
    void seg(Pt a, Pt b, Rgb c, double width);
    void run(const std::vector<Pt> &p, Rgb c, double width, double dash);
    int w_, h_;
    cv::Mat img_;
    std::string svg_;
};

/* A plot frame: the box (pixels), the data ranges, linear or log10 axes. */
struct Frame {
    double x0, y0, x1, y1;          /* box: left, top, right, bottom */
    double xmin, xmax, ymin, ymax;  /* data range (log axes: the values, not logs) */
    bool logx, logy;
    Pt at(double x, double y) const;
};
/* Draw the box, the grid, ticks with labels and the axis labels. */
void axes(Canvas &c, const Frame &f, const char *xlabel, const char *ylabel);

/* Write len bytes to path through a temporary file beside it and rename. */
int write_atomic(const char *path, const void *data, size_t len, char *err, size_t cap);
/* A step of 1, 2 or 5 times a power of ten near span / target. */
double nice_step(double span, int target);
/* A short label for v (tick labels: %g with at most 4 significant digits). */
std::string num(double v);
std::string fmt(const char *f, ...);
void set_err(char *err, size_t cap, const char *f, ...);

} /* namespace imd */

extern "C" const im_draw_api *im_draw_table(void);
#endif
