// im_frame_io.cpp -- the OpenCV shim for frames: decode PNG/TIFF from memory into an
// im_frame (8/16-bit grey; colour turned to grey), encode a frame as PNG or TIFF.
// Nothing C++ leaves this file: every entry point catches and returns an IM_E* code.
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <mutex>
#include <sstream>
#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include "im_int.h"

namespace {
// OpenCV's own logging (libtiff warnings go there) is silenced: the engine never
// prints; what went wrong is said in the caller's err buffer.
void quiet_opencv()
{
    static bool done = false;
    if (!done) {
        cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
        done = true;
    }
}

// imdecode reports a decoder's exception on std::cerr whatever the log level; while it
// runs, std::cerr writes into a string instead (our calls are serialised for that).
std::mutex cerr_lock;
struct quiet_cerr {
    std::ostringstream text;
    std::streambuf *old;
    std::lock_guard<std::mutex> hold{cerr_lock};
    quiet_cerr() : old(std::cerr.rdbuf(text.rdbuf())) {}
    ~quiet_cerr() { std::cerr.rdbuf(old); }
};

const char *depth_name(int depth)
{
    switch (depth) {
    case CV_8S: return "signed 8-bit";
    case CV_16S: return "signed 16-bit";
    case CV_32S: return "32-bit integer";
    case CV_32F: return "32-bit float";
    case CV_64F: return "64-bit float";
    default: return "unusual";
    }
}
}  // namespace

extern "C" int im_cv_decode(const void *buf, size_t len, const char *name, im_frame **out,
                            int *was_colour, char *err, size_t cap)
{
    *out = nullptr;
    try {
        quiet_opencv();
        if (len > (size_t)INT32_MAX)
            return im_err(err, cap, IM_EFORMAT, "%s: file too large", name);
        cv::Mat raw(1, (int)len, CV_8U, const_cast<void *>(buf));
        cv::Mat m;
        {
            quiet_cerr q;
            m = cv::imdecode(raw, cv::IMREAD_UNCHANGED | cv::IMREAD_ANYDEPTH);
        }
        if (m.empty() || m.dims != 2)
            return im_err(err, cap, IM_EFORMAT, "%s: the image data do not decode (truncated "
                          "or corrupt, or the header states more than the file holds)", name);
        if (m.rows < 1 || m.cols < 1)
            return im_err(err, cap, IM_EFORMAT, "%s: zero-size image", name);
        if (m.depth() != CV_8U && m.depth() != CV_16U)
            return im_err(err, cap, IM_EFORMAT, "%s: %s samples: a frame must be 8- or "
                          "16-bit unsigned", name, depth_name(m.depth()));
        int ch = m.channels();
        cv::Mat g;
        if (ch == 1) {
            g = m;
        } else if (ch == 2) {                      // grey + alpha: the grey
            cv::extractChannel(m, g, 0);
        } else if (ch == 3 || ch == 4) {
            cv::cvtColor(m, g, ch == 3 ? cv::COLOR_BGR2GRAY : cv::COLOR_BGRA2GRAY);
            if (was_colour) *was_colour = 1;
        } else {
            return im_err(err, cap, IM_EFORMAT, "%s: %d channels per pixel", name, ch);
        }
        if ((long)g.rows * g.cols > IM_MAX_PIXELS)
            return im_err(err, cap, IM_EFORMAT, "%s: more than %ld pixels", name,
                          (long)IM_MAX_PIXELS);
        int bits = g.depth() == CV_8U ? 8 : 16;
        im_frame *f = im_frame_new(g.cols, g.rows, bits);
        if (!f) return im_err(err, cap, IM_ENOMEM, "%s: out of memory", name);
        cv::Mat dst(g.rows, g.cols, CV_16U, f->px);
        g.convertTo(dst, CV_16U);                  // 8-bit values stay 0..255
        *out = f;
        return IM_OK;
    } catch (const cv::Exception &e) {
        return im_err(err, cap, IM_EFORMAT, "%s: cannot decode: %s", name, e.msg.c_str());
    } catch (const std::exception &e) {
        return im_err(err, cap, IM_ENOMEM, "%s: %s", name, e.what());
    } catch (...) {
        return im_err(err, cap, IM_EFORMAT, "%s: cannot decode", name);
    }
}

extern "C" int im_cv_encode(const im_frame *f, const char *ext, void **buf, size_t *len,
                            char *err, size_t cap)
{
    *buf = nullptr;
    *len = 0;
    try {
        quiet_opencv();
        cv::Mat src(f->height, f->width, CV_16U, f->px);
        cv::Mat m;
        if (f->bits == 8) src.convertTo(m, CV_8U);
        else m = src;
        std::vector<uchar> out;
        std::string e = std::string(".") + ext;
        for (auto &c : e) c = (char)std::tolower((unsigned char)c);
        if (e == ".tiff") e = ".tif";
        if (!cv::imencode(e, m, out) || out.empty())
            return im_err(err, cap, IM_EIO, "cannot encode the frame as %s", ext);
        void *b = std::malloc(out.size());
        if (!b) return im_err(err, cap, IM_ENOMEM, "out of memory");
        std::memcpy(b, out.data(), out.size());
        *buf = b;
        *len = out.size();
        return IM_OK;
    } catch (const cv::Exception &e) {
        return im_err(err, cap, IM_EIO, "cannot encode the frame: %s", e.msg.c_str());
    } catch (...) {
        return im_err(err, cap, IM_ENOMEM, "cannot encode the frame");
    }
}

extern "C" const char *im_cv_version(void) { return CV_VERSION; }
