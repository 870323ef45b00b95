/* spot.c -- the --spot dialogue: a detector frame read from a PNG/TIFF or raw file or
 * synthesised (issue 10's model: Gaussian spot, background, read noise, seed), and its
 * laser spots located by the imaging engine (lensmat-imaging.so, loaded here and only
 * here).  Texts in prompts/spot.txt; the record replays exactly (timings go to stdout
 * only). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <time.h>
#include "ask.h"
#include "dialogues.h"
#include "engine.h"
#include "imaging/imaging.h"
#include "prompts_spot.h"

#define P(k) spot_prompts[SPOT_##k]
#define WORD 4096

typedef struct sdlg {
    lm_io *io;
    const im_frame_api *fa;
    im_frame *f;
    int colour, width, height, bits;
} sdlg;

static int load(sdlg *d)
{
    imaging_get_api_fn get;
    const imaging_api *im;
    if (d->fa) return 0;
    get = (imaging_get_api_fn)lm_engine_symbol("imaging", IMAGING_API_SYMBOL);
    im = get ? get(IMAGING_ABI) : NULL;
    if (!im || !im->frame) {
        if (get) fprintf(stderr, "lensmat: the imaging engine has another ABI\n");
        return -1;
    }
    d->fa = im->frame;
    return 0;
}

static int check_int(void *ctx, const char *w, char *msg, size_t cap)
{
    const long *range = ctx;
    char *end;
    long v = strtol(w, &end, 10);
    if (end == w || *end || v < range[0] || v > range[1]) {
        snprintf(msg, cap, "%s is not a whole number from %ld to %ld", w, range[0], range[1]);
        return -1;
    }
    return 0;
}
static int ask_int(sdlg *d, const char *q, const char *what, long lo, long hi, long *v)
{
    long range[2] = {lo, hi};
    char w[64];
    int rc = lm_ask_word(d->io, q, q, what, check_int, range, w, sizeof w);
    if (!rc) *v = strtol(w, NULL, 10);
    return rc;
}
static int ask_num(sdlg *d, const char *q, const char *what, unsigned flags, double *v)
{
    lm_numspec spec = {what, flags, 0};
    return lm_ask_number(d->io, q, q, &spec, v);
}

static int check_read(void *ctx, const char *w, char *msg, size_t cap)
{
    sdlg *d = ctx;
    d->fa->frame_free(d->f);
    d->f = NULL;
    if (lm_check_input(d->io, w, "the frame file", msg, cap)) return -1;
    if (d->bits) return d->fa->read_raw(w, d->width, d->height, d->bits, &d->f, msg, cap) ? -1 : 0;
    return d->fa->read(w, &d->f, &d->colour, msg, cap) ? -1 : 0;
}

static int check_write(void *ctx, const char *w, char *msg, size_t cap)
{
    sdlg *d = ctx;
    if (lm_check_output(d->io, w, msg, cap)) return -1;
    return d->fa->write(d->f, w, msg, cap) ? -1 : 0;
}

static int ask_bits(sdlg *d, int *bits)
{
    static const char *const b[] = {"8", "12", "16", NULL};
    int i = 2, rc = lm_ask_choice(d->io, P(BITS), P(BITS), P(BITS_WHAT), b, &i);
    if (!rc) *bits = i == 0 ? 8 : i == 1 ? 12 : 16;
    return rc;
}

static int synthesise(sdlg *d)
{
    im_sensor s;
    im_spot_src sp;
    long w, h, seed;
    int bits, rc, save = 0;
    char err[512], name[WORD];
    memset(&s, 0, sizeof s);
    memset(&sp, 0, sizeof sp);
    if ((rc = ask_int(d, P(WIDTH), P(WIDTH_WHAT), 1, 16384, &w)) ||
        (rc = ask_int(d, P(HEIGHT), P(HEIGHT_WHAT), 1, 16384, &h)) ||
        (rc = ask_bits(d, &bits)) ||
        (rc = ask_num(d, P(SPOT_X), P(SPOT_X_WHAT), 0, &sp.x)) ||
        (rc = ask_num(d, P(SPOT_Y), P(SPOT_Y_WHAT), 0, &sp.y)) ||
        (rc = ask_num(d, P(SPOT_W), P(SPOT_W_WHAT), LM_POSITIVE, &sp.w)) ||
        (rc = ask_num(d, P(SPOT_PEAK), P(SPOT_PEAK_WHAT), LM_NONNEG, &sp.peak)) ||
        (rc = ask_num(d, P(BIAS), P(BIAS_WHAT), LM_NONNEG, &s.bias)) ||
        (rc = ask_num(d, P(NOISE), P(NOISE_WHAT), LM_NONNEG, &s.read_noise)) ||
        (rc = ask_int(d, P(SEED), P(SEED_WHAT), 0, 0x7fffffffffffffffL, &seed)))
        return rc;
    s.width = (int)w; s.height = (int)h; s.bits = bits;
    s.pitch = 1; s.exposure = 1; s.qe = 1; s.gain = 1;
    sp.kind = IM_SPOT_ANALYTIC;
    if (d->fa->synth(&s, &sp, 1, (uint64_t)seed, 1, &d->f, err, sizeof err)) {
        lm_say(d->io, LM_BOTH, P(FAILED), err);
        return LM_FAIL;
    }
    if ((rc = lm_ask_yn(d->io, P(SAVE), P(SAVE), P(SAVE_WHAT), &save))) return rc;
    if (save) {
        if ((rc = lm_ask_file(d->io, P(SAVE_FILE), P(SAVE_FILE), P(SAVE_FILE_WHAT), check_write,
                              d, name, sizeof name)))
            return rc;
        char shown[4 * sizeof name + 4];    /* the name, control bytes escaped */
        lm_escape(name, shown, sizeof shown);
        lm_say(d->io, LM_BOTH, P(SAVED), shown);
    }
    return LM_GO;
}

static double now_us(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e6 + t.tv_nsec * 1e-3;
}

/* A result as text: fmt for a finite number, else a word (a noiseless frame has an
 * unbounded SNR; a failed fit, undetermined uncertainties) -- never nan or inf. */
typedef struct numtxt { char s[40]; } numtxt;
static numtxt txt(const char *fmt, double v)
{
    numtxt t;
    if (isnan(v)) snprintf(t.s, sizeof t.s, "undetermined");
    else if (isinf(v)) snprintf(t.s, sizeof t.s, "unbounded");
    else snprintf(t.s, sizeof t.s, fmt, v);
    return t;
}

static int locate(sdlg *d)
{
    enum { CAP = 16 };
    im_spot s[CAP];
    im_centroid_result r;
    im_centroid_opt o;
    char err[256];
    int rc;
    memset(&o, 0, sizeof o);
    if ((rc = ask_num(d, P(THRESHOLD), P(THRESHOLD_WHAT), LM_POSITIVE, &o.threshold))) return rc;
    lm_say(d->io, LM_BOTH, P(FRAME), d->f->width, d->f->height, d->f->bits,
           d->colour ? P(COLOUR) : "");
    double t0 = now_us();
    rc = d->fa->centroid(NULL, d->f, &o, s, CAP, &r, err, sizeof err);
    double t1 = now_us();
    if (rc) {
        lm_say(d->io, LM_BOTH, P(FAILED), err);
        return LM_FAIL;
    }
    lm_say(d->io, LM_BOTH, P(BG), txt("%.2f", r.background).s, txt("%.2f", r.noise).s);
    if (r.outcome == IM_FOUND_NONE) {
        lm_say(d->io, LM_BOTH, P(NONE), o.threshold, txt("%.0f", r.best_x).s,
               txt("%.0f", r.best_y).s, txt("%.2f", r.best_snr).s);
    } else if (r.outcome == IM_FOUND_ONE) {
        lm_say(d->io, LM_BOTH, "%s", P(ONE));
    } else {
        char more[96] = "";
        if (r.ndetected > r.nspots) snprintf(more, sizeof more, P(NOT_ALL), r.ndetected, r.nspots);
        lm_say(d->io, LM_BOTH, P(SEVERAL), r.ndetected, more);
    }
    for (int i = 0; i < r.nspots; i++) {
        lm_say(d->io, LM_BOTH, P(SPOT), i + 1, txt("%.4f", s[i].x).s, txt("%.4f", s[i].sx).s,
               txt("%.4f", s[i].y).s, txt("%.4f", s[i].sy).s, txt("%.3f", s[i].w).s,
               txt("%.1f", s[i].amp).s, txt("%.6g", s[i].power).s, txt("%.1f", s[i].snr).s);
        if (s[i].flags & IM_SF_SATURATED) lm_say(d->io, LM_BOTH, P(FLAG_SAT), s[i].nsat);
        if (s[i].flags & IM_SF_EDGE) lm_say(d->io, LM_BOTH, "%s", P(FLAG_EDGE));
        if (s[i].flags & IM_SF_FIT_FAILED) lm_say(d->io, LM_BOTH, "%s", P(FLAG_FIT));
    }
    lm_say(d->io, LM_OUT, P(TIME_OUT), t1 - t0);
    return LM_GO;
}

static int check_source(void *ctx, const char *w, char *msg, size_t cap)
{
    sdlg *d = ctx;
    im_source *s;
    int rc;
    if (!strchr(w, '%') && lm_check_input(d->io, w, "the frame file", msg, cap)) return -1;
    rc = d->fa->source_open(w, d->width, 0, &s, msg, cap);
    if (rc == IM_OK) { d->fa->source_close(s); return 0; }
    /* A sequence's pattern is checked here; its first number comes next. */
    return rc == IM_EIO && strchr(w, '%') && !d->width ? 0 : -1;
}

/* The first number of a sequence: a whole number whose frame is there. */
struct firstctx { sdlg *d; const char *pattern; };
static int check_first(void *ctx, const char *w, char *msg, size_t cap)
{
    struct firstctx *fc = ctx;
    long range[2] = {0, 1000000000L};
    im_source *s;
    if (check_int(range, w, msg, cap)) return -1;
    if (fc->d->fa->source_open(fc->pattern, (int)strtol(w, NULL, 10), 0, &s, msg, cap)) return -1;
    fc->d->fa->source_close(s);
    return 0;
}

/* A sequence, a video or a camera: one line per frame. */
static int stream(sdlg *d)
{
    char name[WORD], err[512];
    long first = 0, count;
    double thr;
    im_source *src;
    im_centroider *c;
    int rc, n = 0, more = 0;
    d->width = 0;
    if ((rc = lm_ask_file(d->io, P(STREAM), P(STREAM), P(STREAM_WHAT), check_source, d,
                          name, sizeof name)))
        return rc;
    if (strchr(name, '%')) {
        struct firstctx fc = {d, name};
        char w[64];
        if ((rc = lm_ask_word(d->io, P(FIRST), P(FIRST), P(FIRST_WHAT), check_first, &fc, w,
                              sizeof w)))
            return rc;
        first = strtol(w, NULL, 10);
    }
    if ((rc = ask_int(d, P(COUNT), P(COUNT_WHAT), 1, 1000000, &count)) ||
        (rc = ask_num(d, P(THRESHOLD), P(THRESHOLD_WHAT), LM_POSITIVE, &thr)))
        return rc;
    if (d->fa->source_open(name, (int)first, 0, &src, err, sizeof err)) {
        lm_say(d->io, LM_BOTH, P(STREAM_FAILED), err);
        return LM_FAIL;
    }
    c = d->fa->centroider_new();
    im_centroid_opt o;
    memset(&o, 0, sizeof o);
    o.threshold = thr;
    rc = LM_GO;
    while (n < count) {
        im_frame *f;
        im_spot s[4];
        im_centroid_result r;
        int got = d->fa->source_next(src, &f, err, sizeof err);
        if (got == 0) break;
        if (got < 0 || d->fa->centroid(c, f, &o, s, 4, &r, err, sizeof err)) {
            if (got == 1) d->fa->frame_free(f);
            lm_say(d->io, LM_BOTH, P(STREAM_FAILED), err);
            rc = LM_FAIL;
            break;
        }
        char fl[64] = "";
        if (r.nspots > 0 && (s[0].flags & (IM_SF_SATURATED | IM_SF_EDGE | IM_SF_FIT_FAILED)))
            snprintf(fl, sizeof fl, P(SFLAGS), s[0].flags & IM_SF_SATURATED ? "saturated " : "",
                     s[0].flags & IM_SF_EDGE ? "edge " : "",
                     s[0].flags & IM_SF_FIT_FAILED ? "moments" : "");
        lm_say(d->io, LM_BOTH, P(SFRAME), n + 1, f->width, f->height, f->t);
        if (r.outcome == IM_FOUND_NONE)
            lm_say(d->io, LM_BOTH, P(SNONE), r.best_snr);
        else if (r.outcome == IM_FOUND_ONE)
            lm_say(d->io, LM_BOTH, P(SONE), s[0].x, s[0].sx, s[0].y, s[0].sy, s[0].snr, fl);
        else
            lm_say(d->io, LM_BOTH, P(SSEVERAL), r.ndetected, s[0].x, s[0].sx, s[0].y, s[0].sy,
                   s[0].snr, fl);
        d->fa->frame_free(f);
        n++;
        fflush(stdout);                 /* each frame's line as it is computed */
        if (lm_stop_requested()) {      /* say where, on stderr and in the record */
            lm_say(d->io, LM_BOTH, P(SINTERRUPTED), n, count, lm_stop_requested());
            fprintf(stderr, "lensmat: ");
            fprintf(stderr, P(SINTERRUPTED), n, count, lm_stop_requested());
            rc = LM_FAIL;
            break;
        }
    }
    if (rc == LM_GO && n == count) {
        im_frame *f;
        if (d->fa->source_next(src, &f, err, sizeof err) == 1) { more = 1; d->fa->frame_free(f); }
    }
    if (rc == LM_GO) lm_say(d->io, LM_BOTH, P(SEND), n, more ? P(SEND_MORE) : "");
    d->fa->centroider_free(c);
    d->fa->source_close(src);
    return rc;
}

int lm_spot(lm_io *io)
{
    static const char *const src[] = {"file", "raw", "synth", "stream", NULL};
    sdlg d = {io, NULL, NULL, 0, 0, 0, 0};
    char name[WORD];
    int rc = LM_GO, k, again = 1;
    lm_say(io, LM_BOTH, "%s", P(INTRO));
    if (load(&d)) return LM_FAIL;
    while (again && rc == LM_GO) {
        d.bits = 0;
        if ((rc = lm_ask_choice(io, P(SOURCE), P(SOURCE), P(SOURCE_WHAT), src, &k))) break;
        if (k == 0) {
            rc = lm_ask_file(io, P(FILE), P(FILE), P(FILE_WHAT), check_read, &d, name, sizeof name);
        } else if (k == 1) {
            long w, h;
            int bits;
            if (!(rc = ask_int(&d, P(WIDTH), P(WIDTH_WHAT), 1, 16384, &w)) &&
                !(rc = ask_int(&d, P(HEIGHT), P(HEIGHT_WHAT), 1, 16384, &h)) &&
                !(rc = ask_bits(&d, &bits))) {
                d.width = (int)w; d.height = (int)h; d.bits = bits;
                rc = lm_ask_file(io, P(RAW_FILE), P(RAW_FILE), P(FILE_WHAT), check_read, &d,
                                 name, sizeof name);
            }
        } else if (k == 2) {
            rc = synthesise(&d);
        }
        if (k == 3) rc = stream(&d);
        else if (rc == LM_GO) rc = locate(&d);
        d.fa->frame_free(d.f);
        d.f = NULL;
        if (rc == LM_GO) rc = lm_ask_yn(io, P(AGAIN), P(AGAIN), P(AGAIN_WHAT), &again);
    }
    if (rc == LM_GO) lm_check_leftover(io);
    return rc;
}
const char *lm_spot_example(void) { return P(EXAMPLE); }
