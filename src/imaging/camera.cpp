// camera.cpp -- lensmat-camera.so: live cameras and video files through OpenCV videoio.
// A separate module because videoio maps FFmpeg, GStreamer and V4L2 libraries that a
// session reading PNG frames never needs.  Exports camera_get_api (im_camera.h).
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>
#include <sys/stat.h>
#include <unistd.h>
#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include "common/lm_out.h"
#include "imaging/im_camera.h"

namespace {
struct cam {
    cv::VideoCapture cap;
    std::string name;
    int kind = 0;
    long n = 0;
};

int say(char *err, size_t cap, int code, const char *fmt, const char *a, const char *b = "")
{
    if (err && cap) snprintf(err, cap, fmt, a, b);
    return code;
}

void *cam_open(const char *spec, int kind, int index, int timeout_ms, char *err, size_t cap)
{
    try {
        cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
        struct stat st;
        char dev[64];
        const char *path = spec;
        if (kind == 1 && index >= 0) {
            snprintf(dev, sizeof dev, "/dev/video%d", index);
            path = dev;
        }
        if (stat(path, &st) != 0) {
            say(err, cap, -3, kind ? "%s: no such camera (%s is not there)"
                                   : "%s: cannot open: no such file%s", spec,
                kind ? path : "");
            return nullptr;
        }
        if (kind == 0 && !S_ISREG(st.st_mode)) {
            say(err, cap, -3, "%s: not a regular file%s", spec);
            return nullptr;
        }
        if (kind == 1 && !S_ISCHR(st.st_mode)) {
            say(err, cap, -3, "%s: %s is not a camera device", spec, path);
            return nullptr;
        }
        cam *c = new cam;
        c->name = spec;
        c->kind = kind;
        std::vector<int> params;
        if (timeout_ms > 0) params = {cv::CAP_PROP_OPEN_TIMEOUT_MSEC, timeout_ms,
                                      cv::CAP_PROP_READ_TIMEOUT_MSEC, timeout_ms};
        int api = kind == 1 ? cv::CAP_V4L2 : cv::CAP_ANY;
        bool ok = c->cap.open(path, api, params);
        // A backend that does not take the timeouts refuses the open: try without
        // (V4L2 then waits for a frame up to its own select timeout, 10 s).
        if (!ok && !params.empty()) ok = c->cap.open(path, api);
        if (!ok || !c->cap.isOpened()) {
            delete c;
            say(err, cap, -3, kind ? "%s: the camera does not open (busy, or not a "
                                     "video capture device)%s"
                                   : "%s: cannot open as a video (unknown or corrupt "
                                     "format)%s", spec);
            return nullptr;
        }
        return c;
    } catch (...) {
        say(err, cap, -3, "%s: cannot open%s", spec);
        return nullptr;
    }
}

int cam_next(void *h, uint16_t **px, int *width, int *height, int *bits, double *t,
             char *err, size_t cap)
{
    cam *c = static_cast<cam *>(h);
    *px = nullptr;
    try {
        cv::Mat m;
        if (!c->cap.read(m) || m.empty()) {
            if (c->kind == 0) {
                if (c->n == 0)
                    return say(err, cap, -5, "%s: a video without a single frame%s",
                               c->name.c_str());
                return 0;
            }
            return say(err, cap, -3, "%s: the camera stopped delivering frames%s",
                       c->name.c_str());
        }
        cv::Mat g;
        if (m.channels() == 3) cv::cvtColor(m, g, cv::COLOR_BGR2GRAY);
        else if (m.channels() == 4) cv::cvtColor(m, g, cv::COLOR_BGRA2GRAY);
        else if (m.channels() == 1) g = m;
        else return say(err, cap, -5, "%s: frames with an unusual channel count%s",
                        c->name.c_str());
        if (g.depth() != CV_8U && g.depth() != CV_16U)
            return say(err, cap, -5, "%s: frames are not 8- or 16-bit%s", c->name.c_str());
        size_t n = (size_t)g.rows * g.cols;
        uint16_t *b = static_cast<uint16_t *>(std::malloc(n * sizeof *b));
        if (!b) return say(err, cap, -2, "%s: out of memory%s", c->name.c_str());
        cv::Mat dst(g.rows, g.cols, CV_16U, b);
        g.convertTo(dst, CV_16U);
        *px = b;
        *width = g.cols;
        *height = g.rows;
        *bits = g.depth() == CV_8U ? 8 : 16;
        double ms = c->cap.get(cv::CAP_PROP_POS_MSEC);
        *t = ms > 0 ? ms / 1000 : (double)c->n;
        c->n++;
        return 1;
    } catch (const cv::Exception &e) {
        return say(err, cap, -3, "%s: %s", c->name.c_str(), e.msg.c_str());
    } catch (...) {
        return say(err, cap, -3, "%s: read error%s", c->name.c_str());
    }
}

void cam_close(void *h)
{
    try { delete static_cast<cam *>(h); } catch (...) {}
}

int cam_write_video(const char *path, const uint16_t *const *frames, int n, int width,
                    int height, int bits, double fps, char *err, size_t cap)
{
    try {
        cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
        cv::VideoWriter w;
        // The encoder wants a file named .avi: a unique one beside the output (so two
        // writers never share it), then its bytes go through the shared writer
        // (src/common/lm_out.h: a device or FIFO in place, a link's target, "-").
        std::string tmpl = std::string(path) + ".part.XXXXXX.avi";
        std::vector<char> tv(tmpl.begin(), tmpl.end());
        tv.push_back('\0');
        int tfd = mkstemps(tv.data(), 4);
        if (tfd < 0) return say(err, cap, -3, "%s: cannot write a video%s", path);
        close(tfd);
        std::string tmp(tv.data());
        struct unlink_tmp { std::string p; ~unlink_tmp() { unlink(p.c_str()); } } guard{tmp};
        // FFmpeg's MJPEG encoder; OpenCV's own one (no FFmpeg) asserts on smooth frames.
        bool ok = w.open(tmp, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'),
                         fps > 0 ? fps : 10, cv::Size(width, height), true);
        if (!ok) ok = w.open(tmp, cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'),
                             fps > 0 ? fps : 10, cv::Size(width, height), true);
        if (!ok) return say(err, cap, -3, "%s: cannot write a video%s", path);
        double scale = bits > 8 ? 255.0 / ((1 << bits) - 1) : 1;
        for (int k = 0; k < n; k++) {
            cv::Mat src(height, width, CV_16U, const_cast<uint16_t *>(frames[k])), g, c;
            src.convertTo(g, CV_8U, scale);
            cv::cvtColor(g, c, cv::COLOR_GRAY2BGR);
            w.write(c);
        }
        w.release();
        std::FILE *f = std::fopen(tmp.c_str(), "rb");
        if (!f) return say(err, cap, -3, "%s: cannot write a video%s", path);
        std::vector<char> bytes;
        char chunk[65536];
        size_t got;
        while ((got = std::fread(chunk, 1, sizeof chunk, f)) > 0)
            bytes.insert(bytes.end(), chunk, chunk + got);
        bool bad = std::ferror(f);
        std::fclose(f);
        if (bad) return say(err, cap, -3, "%s: cannot write a video%s", path);
        char why[512];
        if (lm_out_save(path, bytes.data(), bytes.size(), why, sizeof why))
            return say(err, cap, -3, "%s%s", why);
        return 0;
    } catch (const cv::Exception &e) {
        return say(err, cap, -3, "%s: cannot write a video: %s", path, e.msg.c_str());
    } catch (...) {
        return say(err, cap, -3, "%s: cannot write a video%s", path);
    }
}

const im_cam_api table = {IM_CAMERA_ABI, cam_open, cam_next, cam_close, cam_write_video};
}  // namespace

extern "C" __attribute__((visibility("default"))) const im_cam_api *camera_get_api(int abi)
{
    return abi == IM_CAMERA_ABI ? &table : nullptr;
}
