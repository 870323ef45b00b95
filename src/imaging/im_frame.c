/* im_frame.c -- frames in memory and on disk: allocation, reading a whole file safely,
 * the raw little-endian reader, the PNG structure check that runs before OpenCV sees a
 * file, the by-content reading front and the atomic writer (temporary file + rename).
 * OpenCV itself is behind im_frame_io.cpp. */
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>
#include "common/lm_out.h"
#include "im_int.h"

int im_err(char *err, size_t cap, int code, const char *fmt, ...)
{
    if (err && cap) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err, cap, fmt, ap);
        va_end(ap);
    }
    return code;
}

static im_frame *frame_alloc(int width, int height, int bits, int zero)
{
    im_frame *f;
    size_t n = (size_t)width * height;
    if (width < 1 || height < 1 || (long)width * height > IM_MAX_PIXELS) return NULL;
    if (bits != 8 && bits != 12 && bits != 16) return NULL;
    f = calloc(1, sizeof *f);
    if (!f) return NULL;
    f->px = zero ? calloc(n, sizeof *f->px) : malloc(n * sizeof *f->px);
    if (!f->px) { free(f); return NULL; }
    f->width = width;
    f->height = height;
    f->bits = bits;
    return f;
}

im_frame *im_frame_new(int width, int height, int bits)
{
    return frame_alloc(width, height, bits, 1);
}

/* For a writer of every sample (the synthesis): no zeroing of 600 kB it overwrites. */
im_frame *im_frame_new_raw(int width, int height, int bits)
{
    return frame_alloc(width, height, bits, 0);
}

void im_frame_free(im_frame *f)
{
    if (!f) return;
    free(f->px);
    free(f);
}

int im_read_file(const char *path, size_t maxlen, void **buf, size_t *len,
                 char *err, size_t cap)
{
    struct stat st;
    unsigned char *b;
    size_t n = 0;
    int fd = open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) return im_err(err, cap, IM_EIO, "%s: cannot open: %s", path, strerror(errno));
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        return im_err(err, cap, IM_EIO, "%s: not a regular file", path);
    }
    if ((unsigned long long)st.st_size > maxlen) {
        close(fd);
        return im_err(err, cap, IM_EFORMAT, "%s: %lld bytes, more than the %zu MB an "
                      "image file may have", path, (long long)st.st_size, maxlen >> 20);
    }
    b = malloc((size_t)st.st_size + 1);
    if (!b) { close(fd); return im_err(err, cap, IM_ENOMEM, "%s: out of memory", path); }
    while (n < (size_t)st.st_size) {
        ssize_t r = read(fd, b + n, (size_t)st.st_size - n);
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) {
            int e = errno;
            free(b); close(fd);
            return im_err(err, cap, IM_EIO, "%s: read error: %s", path, strerror(e));
        }
        if (r == 0) break;                 /* shrank while we read: take what is there */
        n += (size_t)r;
    }
    close(fd);
    *buf = b;
    *len = n;
    return IM_OK;
}

/* Every file the imaging engine writes (frames, pictures, videos) goes through the
 * shared writer (src/common/lm_out.h): a unique temporary renamed over a regular file,
 * a device or FIFO written in place, a link's target, "-" standard output. */
int im_write_atomic(const char *path, const void *buf, size_t len, char *err, size_t cap)
{
    if (!*path) return im_err(err, cap, IM_EINVAL, "empty output file name");
    if (lm_out_save(path, buf, len, err, cap)) return IM_EIO;
    return IM_OK;
}

int im_decode_raw(const void *buf, size_t len, const char *name, int width, int height,
                  int bits, im_frame **out, char *err, size_t cap)
{
    const unsigned char *b = buf;
    size_t need, i, n;
    unsigned max;
    im_frame *f;
    *out = NULL;
    if (width < 1 || height < 1)
        return im_err(err, cap, IM_EINVAL, "%s: zero-size raw frame (%dx%d)", name,
                      width, height);
    if ((long)width * height > IM_MAX_PIXELS)
        return im_err(err, cap, IM_EINVAL, "%s: %dx%d is more than %ld pixels", name,
                      width, height, (long)IM_MAX_PIXELS);
    if (bits != 8 && bits != 12 && bits != 16)
        return im_err(err, cap, IM_EINVAL, "%s: %d-bit raw samples: 8, 12 or 16 only",
                      name, bits);
    n = (size_t)width * height;
    need = n * 2;
    if (len != need)
        return im_err(err, cap, IM_EFORMAT, "%s: a raw %dx%d 16-bit frame is %zu bytes, "
                      "the file has %zu (%s)", name, width, height, need, len,
                      len < need ? "truncated, or a smaller frame" : "a larger frame?");
    f = im_frame_new(width, height, bits);
    if (!f) return im_err(err, cap, IM_ENOMEM, "%s: out of memory", name);
    max = (1u << bits) - 1;
    for (i = 0; i < n; i++) {
        unsigned v = b[2 * i] | (unsigned)b[2 * i + 1] << 8;
        if (v > max) {
            im_frame_free(f);
            return im_err(err, cap, IM_EFORMAT, "%s: sample %u at pixel (%zu, %zu) is "
                          "beyond %d bits: wrong bit depth or byte order", name, v,
                          i % (size_t)width, i / (size_t)width, bits);
        }
        f->px[i] = (uint16_t)v;
    }
    *out = f;
    return IM_OK;
}

/* ---- PNG structure ---------------------------------------------------------------- */
static uint32_t crc_table[256];
static void crc_init(void)
{
    for (uint32_t n = 0; n < 256; n++) {
        uint32_t c = n;
        for (int k = 0; k < 8; k++) c = c & 1 ? 0xedb88320u ^ (c >> 1) : c >> 1;
        crc_table[n] = c;
    }
}
__attribute__((unused)) static uint32_t crc32_of(const unsigned char *p, size_t n)
{
    uint32_t c = 0xffffffffu;
    if (!crc_table[1]) crc_init();
    while (n--) c = crc_table[(c ^ *p++) & 0xff] ^ (c >> 8);
    return c ^ 0xffffffffu;
}
static uint32_t be32(const unsigned char *p)
{
    return (uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3];
}

/* The image data must inflate to exactly what the header states (every row with its
 * filter byte, filters 0..4), so a file whose header lies never reaches libpng (which
 * would print its complaint on stderr). */
typedef struct png_hdr { uint32_t w, h; int depth, ctype, interlace; } png_hdr;

static unsigned long long png_expected(const png_hdr *p, size_t *rowbytes)
{
    static const int ch[7] = {1, 0, 3, 1, 2, 0, 4};
    static const int xs[7] = {0, 4, 0, 2, 0, 1, 0}, ys[7] = {0, 0, 4, 0, 2, 0, 1};
    static const int dx[7] = {8, 8, 4, 4, 2, 2, 1}, dy[7] = {8, 8, 8, 4, 4, 2, 2};
    unsigned long long bpp = (unsigned long long)ch[p->ctype] * p->depth, total = 0;
    *rowbytes = (size_t)((p->w * bpp + 7) / 8);
    if (!p->interlace) return (unsigned long long)p->h * (1 + *rowbytes);
    for (int k = 0; k < 7; k++) {
        unsigned long long pw = p->w > (uint32_t)xs[k] ? (p->w - xs[k] + dx[k] - 1) / dx[k] : 0;
        unsigned long long ph = p->h > (uint32_t)ys[k] ? (p->h - ys[k] + dy[k] - 1) / dy[k] : 0;
        if (pw && ph) total += ph * (1 + (pw * bpp + 7) / 8);
    }
    return total;
}

static int png_inflate_check(const unsigned char *b, size_t n, const png_hdr *hd,
                             const char *name, char *err, size_t cap)
{
    size_t rowbytes, at = 8;
    unsigned long long want = png_expected(hd, &rowbytes), got = 0;
    unsigned char out[16384];
    z_stream z;
    int zr = Z_OK, rc = IM_OK;
    memset(&z, 0, sizeof z);
    if (inflateInit(&z) != Z_OK) return im_err(err, cap, IM_ENOMEM, "%s: out of memory", name);
    while (at + 12 <= n && zr != Z_STREAM_END) {
        uint32_t clen = be32(b + at);
        if (!memcmp(b + at + 4, "IDAT", 4)) {
            z.next_in = (unsigned char *)b + at + 8;
            z.avail_in = clen;
            while (z.avail_in > 0 && zr != Z_STREAM_END) {
                z.next_out = out;
                z.avail_out = sizeof out;
                zr = inflate(&z, Z_NO_FLUSH);
                if (zr != Z_OK && zr != Z_STREAM_END) {
                    rc = im_err(err, cap, IM_EFORMAT, "%s: corrupt PNG image data (%s)", name,
                                z.msg ? z.msg : "inflate failed");
                    goto done;
                }
                size_t k = sizeof out - z.avail_out;
                if (!hd->interlace)
                    for (size_t i = 0; i < k; i++)
                        if ((got + i) % (rowbytes + 1) == 0 && out[i] > 4) {
                            rc = im_err(err, cap, IM_EFORMAT, "%s: corrupt PNG image data "
                                        "(row %llu has filter %d)", name,
                                        (got + i) / (rowbytes + 1), out[i]);
                            goto done;
                        }
                got += k;
                if (got > want) break;
            }
            if (got > want) break;
        }
        if (!memcmp(b + at + 4, "IEND", 4)) break;
        at += 12 + (size_t)clen;
    }
    if (got != want)
        rc = im_err(err, cap, IM_EFORMAT, "%s: the PNG header states %lux%lu (%llu bytes of "
                    "image data), the file holds %llu%s", name, (unsigned long)hd->w,
                    (unsigned long)hd->h, want, got, got < want ? " (truncated or lying)" : "");
done:
    inflateEnd(&z);
    return rc;
}

int im_png_check(const unsigned char *b, size_t n, const char *name, char *err, size_t cap)
{
    png_hdr hd = {0, 0, 0, 0, 0};
    static const unsigned char sig[8] = {137, 'P', 'N', 'G', 13, 10, 26, 10};
    size_t at = 8;
    int seen_ihdr = 0, seen_idat = 0, seen_plte = 0;
    if (n < 8 || memcmp(b, sig, 8) != 0)
        return im_err(err, cap, IM_EFORMAT, "%s: not a PNG file", name);
    for (;;) {
        uint32_t clen;
        char type[5];
        if (n - at < 12)
            return im_err(err, cap, IM_EFORMAT, "%s: truncated PNG (%zu bytes, no IEND "
                          "chunk)", name, n);
        clen = be32(b + at);
        memcpy(type, b + at + 4, 4);
        type[4] = '\0';
        for (int k = 0; k < 4; k++)
            if (!((type[k] >= 'a' && type[k] <= 'z') || (type[k] >= 'A' && type[k] <= 'Z')))
                return im_err(err, cap, IM_EFORMAT, "%s: corrupt PNG (bad chunk type at "
                              "byte %zu)", name, at + 4);
        if (clen > 0x7fffffffu || clen > n - at - 12)
            return im_err(err, cap, IM_EFORMAT, "%s: truncated PNG (chunk %s at byte %zu "
                          "needs %lu bytes, %zu left)", name, type, at, (unsigned long)clen,
                          n - at - 12);
#ifndef FUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION   /* the fuzzer could never guess one */
        if (crc32_of(b + at + 4, clen + 4) != be32(b + at + 8 + clen))
            return im_err(err, cap, IM_EFORMAT, "%s: corrupt PNG (CRC of chunk %s at byte "
                          "%zu)", name, type, at);
#endif
        if (!seen_ihdr) {
            const unsigned char *h = b + at + 8;
            uint32_t w, ht;
            int depth, ctype;
            if (strcmp(type, "IHDR") != 0 || clen != 13)
                return im_err(err, cap, IM_EFORMAT, "%s: corrupt PNG (no IHDR first)", name);
            w = be32(h);
            ht = be32(h + 4);
            depth = h[8];
            ctype = h[9];
            if (w == 0 || ht == 0)
                return im_err(err, cap, IM_EFORMAT, "%s: zero-size image (%lux%lu)", name,
                              (unsigned long)w, (unsigned long)ht);
            if (w > 0x7fffffffu || ht > 0x7fffffffu ||
                (unsigned long long)w * ht > (unsigned long long)IM_MAX_PIXELS)
                return im_err(err, cap, IM_EFORMAT, "%s: %lux%lu is more than %ld pixels",
                              name, (unsigned long)w, (unsigned long)ht, (long)IM_MAX_PIXELS);
            if (!(depth == 1 || depth == 2 || depth == 4 || depth == 8 || depth == 16) ||
                !(ctype == 0 || ctype == 2 || ctype == 3 || ctype == 4 || ctype == 6) ||
                (ctype == 3 && depth == 16) || (ctype != 0 && ctype != 3 && depth < 8))
                return im_err(err, cap, IM_EFORMAT, "%s: PNG with bit depth %d and colour "
                              "type %d: not a valid combination", name, depth, ctype);
            if (h[12] > 1)
                return im_err(err, cap, IM_EFORMAT, "%s: corrupt PNG (interlace %d)", name,
                              h[12]);
            hd.w = w; hd.h = ht; hd.depth = depth; hd.ctype = ctype; hd.interlace = h[12];
            seen_ihdr = 1;
        } else if (!strcmp(type, "IDAT")) {
            if (seen_idat == 2)
                return im_err(err, cap, IM_EFORMAT, "%s: corrupt PNG (image data chunks "
                              "not together)", name);
            if (hd.ctype == 3 && !seen_plte)
                return im_err(err, cap, IM_EFORMAT, "%s: corrupt PNG (palette image "
                              "without a palette)", name);
            seen_idat = 1;
        } else if (!strcmp(type, "IHDR")) {
            return im_err(err, cap, IM_EFORMAT, "%s: corrupt PNG (a second IHDR)", name);
        } else if (!strcmp(type, "PLTE")) {
            if (seen_idat || seen_plte || clen % 3 || clen == 0 || clen > 768 ||
                hd.ctype == 0 || hd.ctype == 4)
                return im_err(err, cap, IM_EFORMAT, "%s: corrupt PNG (palette chunk out of "
                              "place or of a bad size)", name);
            seen_plte = 1;
        } else if (type[0] >= 'A' && type[0] <= 'Z' && strcmp(type, "IEND")) {
            return im_err(err, cap, IM_EFORMAT, "%s: PNG with an unknown critical chunk %s",
                          name, type);
        } else if (!strcmp(type, "IEND")) {
            if (!seen_idat)
                return im_err(err, cap, IM_EFORMAT, "%s: PNG without image data", name);
            return png_inflate_check(b, n, &hd, name, err, cap);
        }
        if (seen_idat == 1 && strcmp(type, "IDAT")) seen_idat = 2;
        at += 12 + (size_t)clen;
    }
}

static int is_tiff(const unsigned char *b, size_t n)
{
    return n >= 8 && ((b[0] == 'I' && b[1] == 'I' && b[2] == 42 && b[3] == 0) ||
                      (b[0] == 'M' && b[1] == 'M' && b[2] == 0 && b[3] == 42));
}

/* A TIFF's first image: its stated width and height (tags 256, 257 of the first IFD)
 * checked before the decoder allocates for them: at most IM_MAX_PIXELS, and at most
 * TIFF_MAX_RATIO pixels a byte of the file (no TIFF compression packs more: LZW,
 * the densest, about 1300:1), so that a few hundred bytes cannot state a frame the
 * decoder then spends seconds filling (the fuzzer found one: 58892 x 9993 in 270
 * bytes, 6 s in libtiff). */
#define TIFF_MAX_RATIO 4096
static int im_tiff_check(const unsigned char *b, size_t n, const char *name, char *err,
                         size_t cap)
{
    int le = b[0] == 'I';
#define T16(p) (le ? (uint32_t)(p)[0] | (uint32_t)(p)[1] << 8 : (uint32_t)(p)[0] << 8 | (p)[1])
#define T32(p) (le ? T16(p) | T16((p) + 2) << 16 : T16(p) << 16 | T16((p) + 2))
    uint32_t ifd = T32(b + 4), w = 0, h = 0;
    if (ifd < 8 || ifd > n - 2)
        return im_err(err, cap, IM_EFORMAT, "%s: corrupt TIFF (its first directory at "
                      "byte %lu lies outside the file)", name, (unsigned long)ifd);
    uint32_t ne = T16(b + ifd);
    if ((size_t)ne * 12 > n - ifd - 2)
        return im_err(err, cap, IM_EFORMAT, "%s: corrupt TIFF (a directory of %lu entries "
                      "at byte %lu runs past the end)", name, (unsigned long)ne,
                      (unsigned long)ifd);
    for (uint32_t i = 0; i < ne; i++) {
        const unsigned char *e = b + ifd + 2 + 12 * i;
        uint32_t tag = T16(e), type = T16(e + 2), v = type == 3 ? T16(e + 8) : T32(e + 8);
        if (type != 3 && type != 4) continue;
        if (tag == 256) w = v;
        if (tag == 257) h = v;
    }
#undef T16
#undef T32
    if (w == 0 || h == 0)
        return im_err(err, cap, IM_EFORMAT, "%s: TIFF without a width and height", name);
    unsigned long long px = (unsigned long long)w * h;
    if (px > (unsigned long long)IM_MAX_PIXELS)
        return im_err(err, cap, IM_EFORMAT, "%s: %lux%lu is more than %ld pixels", name,
                      (unsigned long)w, (unsigned long)h, (long)IM_MAX_PIXELS);
    if (px > (unsigned long long)TIFF_MAX_RATIO * n)
        return im_err(err, cap, IM_EFORMAT, "%s: a %lux%lu TIFF cannot be held in %zu bytes "
                      "(truncated or corrupt)", name, (unsigned long)w, (unsigned long)h, n);
    return IM_OK;
}

int im_decode(const void *buf, size_t len, const char *name, im_frame **out,
              int *was_colour, char *err, size_t cap)
{
    const unsigned char *b = buf;
    int rc;
    *out = NULL;
    if (was_colour) *was_colour = 0;
    if (len == 0) return im_err(err, cap, IM_EFORMAT, "%s: empty file", name);
    if (len >= 8 && b[0] == 137 && b[1] == 'P' && b[2] == 'N' && b[3] == 'G') {
        if ((rc = im_png_check(b, len, name, err, cap)) != IM_OK) return rc;
    } else if (!is_tiff(b, len)) {
        return im_err(err, cap, IM_EFORMAT, "%s: not a PNG or TIFF image (a raw frame "
                      "needs its width and height stated)", name);
    } else if ((rc = im_tiff_check(b, len, name, err, cap)) != IM_OK) {
        return rc;
    }
    return im_cv_decode(buf, len, name, out, was_colour, err, cap);
}

int im_read(const char *path, im_frame **out, int *was_colour, char *err, size_t cap)
{
    void *buf = NULL;
    size_t len = 0;
    int rc;
    *out = NULL;
    if ((rc = im_read_file(path, IM_MAX_FILE, &buf, &len, err, cap)) != IM_OK) return rc;
    rc = im_decode(buf, len, path, out, was_colour, err, cap);
    free(buf);
    return rc;
}

int im_read_raw(const char *path, int width, int height, int bits, im_frame **out,
                char *err, size_t cap)
{
    void *buf;
    size_t len;
    int rc;
    *out = NULL;
    if ((rc = im_read_file(path, IM_MAX_FILE, &buf, &len, err, cap)) != IM_OK) return rc;
    rc = im_decode_raw(buf, len, path, width, height, bits, out, err, cap);
    free(buf);
    return rc;
}

static const char *ext_of(const char *path)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    return dot && (!slash || dot > slash) ? dot + 1 : "";
}

int im_write(const im_frame *f, const char *path, char *err, size_t cap)
{
    const char *ext = ext_of(path);
    void *buf = NULL;
    size_t len = 0;
    int rc;
    if (!f || !f->px || f->width < 1 || f->height < 1)
        return im_err(err, cap, IM_EINVAL, "%s: no frame to write", path);
    if (!strcasecmp(ext, "raw")) {
        size_t n = (size_t)f->width * f->height;
        unsigned char *b = malloc(2 * n);
        if (!b) return im_err(err, cap, IM_ENOMEM, "%s: out of memory", path);
        for (size_t i = 0; i < n; i++) {
            b[2 * i] = (unsigned char)(f->px[i] & 0xff);
            b[2 * i + 1] = (unsigned char)(f->px[i] >> 8);
        }
        rc = im_write_atomic(path, b, 2 * n, err, cap);
        free(b);
        return rc;
    }
    if (strcasecmp(ext, "png") && strcasecmp(ext, "tif") && strcasecmp(ext, "tiff"))
        return im_err(err, cap, IM_EINVAL, "%s: frames are written as .png, .tif or .raw",
                      path);
    if ((rc = im_cv_encode(f, ext, &buf, &len, err, cap)) != IM_OK) return rc;
    rc = im_write_atomic(path, buf, len, err, cap);
    free(buf);
    return rc;
}
