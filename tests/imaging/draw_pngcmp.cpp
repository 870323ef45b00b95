/* draw_pngcmp.cpp -- the picture tests' eyes (tests/t_76_draw.sh), on OpenCV:
 *   draw_pngcmp cmp A.png B.png THRESH MAXCOUNT
 *       pixels whose largest channel difference exceeds THRESH; passes (exit 0) when
 *       there are at most MAXCOUNT of them and the sizes agree.  The threshold lets
 *       anti-aliasing and glyph rendering move a little; the count catches a ray or a
 *       label out of place (a misplaced ray is hundreds of pixels, a label dozens).
 *   draw_pngcmp tick FILE.png X Y R G B
 *       where the drawing shows a tick of colour (R,G,B) near pixel column X just
 *       above the axis row Y: the colour-weighted mean column of the matching pixels
 *       in rows Y-8 .. Y-3 and columns X-20 .. X+20; prints it (exit 1: none).
 *   draw_pngcmp blob FILE.png X Y R G B
 *       where the drawing shows a marker of colour (R,G,B) near pixel (X, Y): the
 *       colour-weighted mean x and y of the matching pixels within 6 pixels of it, and
 *       their weight; prints "x y weight" (exit 1: none). */
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

static cv::Mat load(const char *p)
{
    cv::Mat m = cv::imread(p, cv::IMREAD_COLOR);
    if (m.empty()) { fprintf(stderr, "%s: cannot read as an image\n", p); exit(2); }
    return m;
}

int main(int argc, char **argv)
{
    if (argc == 6 && !strcmp(argv[1], "cmp")) {
        cv::Mat a = load(argv[2]), b = load(argv[3]);
        int th = atoi(argv[4]);
        long maxc = atol(argv[5]), n = 0, worst = 0;
        if (a.size() != b.size()) {
            printf("sizes differ: %dx%d and %dx%d\n", a.cols, a.rows, b.cols, b.rows);
            return 1;
        }
        for (int y = 0; y < a.rows; y++)
            for (int x = 0; x < a.cols; x++) {
                cv::Vec3b p = a.at<cv::Vec3b>(y, x), q = b.at<cv::Vec3b>(y, x);
                int d = 0;
                for (int c = 0; c < 3; c++) d = std::max(d, std::abs(p[c] - q[c]));
                if (d > th) n++;
                worst = std::max<long>(worst, d);
            }
        printf("%ld of %ld pixels differ by more than %d (largest difference %ld)\n", n,
               (long)a.total(), th, worst);
        return n <= maxc ? 0 : 1;
    }
    if (argc == 8 && !strcmp(argv[1], "tick")) {
        cv::Mat m = load(argv[2]);
        double X = atof(argv[3]), sw = 0, sx = 0;
        int Y = (int)lround(atof(argv[4]));
        int want[3] = {atoi(argv[7]), atoi(argv[6]), atoi(argv[5])};   /* BGR */
        for (int y = Y - 8; y <= Y - 3; y++)
            for (int x = (int)X - 20; x <= (int)X + 20; x++) {
                if (y < 0 || x < 0 || y >= m.rows || x >= m.cols) continue;
                cv::Vec3b p = m.at<cv::Vec3b>(y, x);
                double d = 0;
                for (int c = 0; c < 3; c++) d = std::max(d, (double)std::abs(p[c] - want[c]));
                if (d < 60) { sw += 1 - d / 60; sx += (1 - d / 60) * x; }
            }
        if (sw <= 0) { printf("no tick of that colour there\n"); return 1; }
        printf("%.3f\n", sx / sw);
        return 0;
    }
    if (argc == 8 && !strcmp(argv[1], "blob")) {
        cv::Mat m = load(argv[2]);
        double X = atof(argv[3]), Y = atof(argv[4]), sw = 0, sx = 0, sy = 0;
        int want[3] = {atoi(argv[7]), atoi(argv[6]), atoi(argv[5])};   /* BGR */
        for (int y = (int)floor(Y) - 6; y <= (int)ceil(Y) + 6; y++)
            for (int x = (int)floor(X) - 6; x <= (int)ceil(X) + 6; x++) {
                if (y < 0 || x < 0 || y >= m.rows || x >= m.cols) continue;
                if ((x - X) * (x - X) + (y - Y) * (y - Y) > 36) continue;
                cv::Vec3b p = m.at<cv::Vec3b>(y, x);
                double d = 0;
                for (int c = 0; c < 3; c++) d = std::max(d, (double)std::abs(p[c] - want[c]));
                if (d < 60) { double w = 1 - d / 60; sw += w; sx += w * x; sy += w * y; }
            }
        if (sw <= 0) { printf("no marker of that colour there\n"); return 1; }
        printf("%.3f %.3f %.2f\n", sx / sw, sy / sw, sw);
        return 0;
    }
    fprintf(stderr, "usage: draw_pngcmp cmp A B THRESH MAXCOUNT | tick FILE X Y R G B | "
            "blob FILE X Y R G B\n");
    return 2;
}
