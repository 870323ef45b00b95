/* wave.c -- the --wave dialogue: a lens file (as --pupil reads it, lensrx.c), the pupil
 * grid, the Zernike ordering and terms, the MTF's frequencies, the through-focus range
 * and the pictures' name; then per field (wavecalc.c) the wavefront of rays aimed at
 * the stop (the trace module's rx_opd), its Zernike fit, PSF, Strehl ratio, energies,
 * MTF and resolving power (the wave module), polychromatic by the file's weights, and
 * the pictures (waveplot.c, the imaging module).  Texts in prompts/wave.txt. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#include "dialogues.h"
#include "engine.h"
#include "wavedlg.h"
#include "prompts_wave.h"

#define P(k) wave_prompts[WAVE_##k]

double wd_now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

/* The picture name: a base of safe characters (NAME-f1-mtf.png ... are made from it),
 * its folder writable, or "-". */
static int check_pic(void *ctx, const char *w, char *msg, size_t cap)
{
    wd *d = ctx;
    size_t n = strlen(w);
    const char *slash;
    char dir[WD_WORD];
    if (!strcmp(w, "-")) { d->pic[0] = '\0'; return 0; }
    if (n == 0 || n > 200 || strstr(w, "..")) goto bad;
    for (size_t i = 0; i < n; i++) {
        char ch = w[i];
        if (!((ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
              ch == '-' || ch == '_' || ch == '.' || ch == '/'))
            goto bad;
    }
    if (n > 4 && (!strcmp(w + n - 4, ".png") || !strcmp(w + n - 4, ".svg"))) goto bad;
    slash = strrchr(w, '/');
    if (slash) snprintf(dir, sizeof dir, "%.*s", slash == w ? 1 : (int)(slash - w), w);
    else snprintf(dir, sizeof dir, ".");
    if (access(dir, W_OK | X_OK) != 0) {
        snprintf(msg, cap, P(PICTURES_DIR), w, dir);
        return 1;
    }
    snprintf(d->pic, sizeof d->pic, "%s", w);
    return 0;
bad:
    snprintf(msg, cap, P(PICTURES_BAD), w);
    return 1;
}

static int ask_all(wd *d)
{
    static const char *const orders[] = {"fringe", "noll", "ansi", NULL};
    char q[256], buf[WD_WORD];
    int rc;
    if ((rc = lr_ask_count(&d->L, P(GRID), P(COUNT_BAD), 16, 512, &d->n))) return rc;
    if ((rc = calc_choice(&d->c, P(ORDER), P(ORDER_WHAT), orders, &d->order))) return rc;
    d->order = d->order == 0 ? WAVE_Z_FRINGE : d->order == 1 ? WAVE_Z_NOLL : WAVE_Z_ANSI;
    if ((rc = lr_ask_count(&d->L, P(NTERM), P(COUNT_BAD), 4, 37, &d->nterm))) return rc;
    if ((rc = calc_num(&d->c, P(FMAX), P(FMAX_WHAT), LM_NONNEG, &d->fmax))) return rc;
    snprintf(q, sizeof q, P(FOCUS), d->c.uname);
    if ((rc = calc_num(&d->c, q, P(FOCUS_WHAT), LM_NONNEG, &d->focus))) return rc;
    if (d->focus > 0) {
        if ((rc = lr_ask_count(&d->L, P(FOCUS_STEPS), P(COUNT_BAD), 1, 10, &d->steps)) ||
            (rc = calc_num(&d->c, P(FOCUS_FREQ), P(FOCUS_FREQ_WHAT), LM_POSITIVE, &d->ffreq)))
            return rc;
    }
    return lm_ask_word(d->io, P(PICTURES), P(PICTURES), P(PICTURES_WHAT), check_pic, d, buf,
                       sizeof buf);
}

static int refuse(wd *d, const char *why)
{
    lm_say(d->io, LM_BOTH, P(REFUSED), why);
    fprintf(stderr, "lensmat: %s: %s\n", d->io->src, why);
    return LM_FAIL;
}

static int engines(wd *d)
{
    trace_get_api_fn gt = (trace_get_api_fn)lm_engine_symbol("trace", TRACE_API_SYMBOL);
    wave_get_api_fn gw = (wave_get_api_fn)lm_engine_symbol("wave", WAVE_API_SYMBOL);
    if (gt) d->tr = gt(TRACE_ABI);
    if (gw) d->wv = gw(WAVE_ABI);
    if (!d->tr || !d->wv) {
        if (gt && gw) fprintf(stderr, "lensmat: the trace or wave module's interface does not match\n");
        return -1;
    }
    if (d->pic[0]) {
        imaging_get_api_fn gi = (imaging_get_api_fn)lm_engine_symbol("imaging", IMAGING_API_SYMBOL);
        const imaging_api *ia = gi ? gi(IMAGING_ABI) : NULL;
        if (!ia) return -1;
        d->im = ia->draw;
    }
    return 0;
}

/* The grid's cells inside the unit circle (the cells the wave module's mask keeps). */
static int make_cells(wd *d)
{
    int n = d->n, k = 0;
    d->cx = malloc(sizeof(double) * (size_t)n * n);
    d->cy = malloc(sizeof(double) * (size_t)n * n);
    d->cidx = malloc(sizeof(int) * (size_t)n * n);
    d->psf = malloc(sizeof(double) * (size_t)d->m * d->m);
    if (!d->cx || !d->cy || !d->cidx || !d->psf) return -1;
    for (int k = 0; k < d->nwl; k++) {
        wave_pupil *p = &d->wl[k].pu;
        p->n = n;
        p->w = calloc((size_t)n * n, sizeof(double));
        p->amp = calloc((size_t)n * n, sizeof(double));
        if (!p->w || !p->amp) return -1;
    }
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double x = -1 + (2.0 * j + 1) / n, y = -1 + (2.0 * i + 1) / n;
            if (x * x + y * y > 1) continue;
            d->cx[k] = x;
            d->cy[k] = y;
            d->cidx[k++] = i * n + j;
        }
    d->ncell = k;
    return 0;
}

static int compute(wd *d)
{
    const ln_lens *l = &d->L.lens;
    char why[LN_ERR_MAX], ob[64], ws[512];
    int rc = LM_GO, nwl = l->nwl ? l->nwl : 1;
    double lp = ln_primary(l);
    if (lr_prepare(&d->L, why, sizeof why)) return refuse(d, why);
    if (isinf(l->object)) snprintf(ob, sizeof ob, "%s", P(OBJ_INF));
    else snprintf(ob, sizeof ob, P(OBJ_AT), l->object, d->c.uname);
    calc_say(&d->c, P(HEAD), l->title[0] ? l->title : "(untitled)", l->nsurf, l->stop + 1,
             l->ap_kind == LN_AP_FNUM ? "f-number" : l->ap_kind == LN_AP_NA ? "NA" : "EPD",
             l->ap_value, ob, l->nfield, l->nfield == 1 ? "" : "s", nwl, nwl == 1 ? "" : "s");
    if (d->L.image_from_file) calc_say(&d->c, P(IMAGE_FILE), d->L.z_image, d->c.uname);
    else if (!isfinite(d->L.z_image)) return refuse(d, P(NO_IMAGE));
    else calc_say(&d->c, P(IMAGE_PARAXIAL), lm_clean(d->io, d->L.z_image), d->c.uname, lp * 1000);
    /* Q 4 up to a 256-cell grid (m = 4n <= 1024), Q 2 above: m >= 2n keeps the MTF
     * unaliased; the field is n lambda F whatever Q */
    d->Q = d->n <= 256 ? 4 : 2;
    d->m = d->Q * d->n;
    d->nwl = nwl;
    if (engines(d)) return LM_FAIL;
    if (make_cells(d) || !(d->ctx = d->wv->ctx_new())) return refuse(d, "out of memory");
    calc_say(&d->c, P(SAMPLING), d->n, d->n, d->ncell, d->m, d->m, d->Q, d->Q, d->n);
    calc_say(&d->c, "%s", P(CONVENTIONS));
    calc_say(&d->c, P(ZORDER), d->order == WAVE_Z_FRINGE ? "Fringe" : d->order == WAVE_Z_NOLL
             ? "Noll" : "ANSI", d->nterm, d->order == WAVE_Z_FRINGE ? P(FRINGE_NOTE) :
             d->order == WAVE_Z_NOLL ? P(NOLL_NOTE) : P(ANSI_NOTE));
    ws[0] = '\0';
    for (int k = 0; k < nwl; k++) {
        size_t u = strlen(ws);
        d->wl[k].lambda = l->nwl ? l->wl[k] : lp;
        d->wl[k].weight = l->nwl ? l->wl_weight[k] : 1;
        snprintf(ws + u, sizeof ws - u, "%s%g nm (%g)", k ? ", " : "", d->wl[k].lambda * 1000,
                 d->wl[k].weight);
    }
    calc_say(&d->c, P(WEIGHTS), ws);
    for (int f = 0; f < l->nfield && rc == LM_GO; f++) rc = wd_field(d, f);
    if (rc == LM_GO) lm_say(d->io, LM_OUT, P(TIMES), d->trace_ms, d->wave_ms);
    return rc;
}

int lm_wave(lm_io *io)
{
    wd *d = calloc(1, sizeof *d);
    int rc;
    if (!d) return LM_FAIL;
    d->io = io;
    d->c.io = io;
    d->c.unit = PX_MM;
    d->c.uname = "mm";
    d->t = (lr_texts){P(FILE), P(FILE_WHAT), P(NOTE), P(STOP), P(STOP_WHAT), P(STOP_BAD),
                      P(AP_KIND), P(AP_KIND_WHAT), P(AP_VALUE), P(AP_VALUE_WHAT), P(NFIELD),
                      P(NFIELD_WHAT), P(NFIELD_BAD), P(FIELD_ANGLE), P(FIELD_HEIGHT),
                      P(FIELD_WHAT), P(FIELD_BAD), P(AGAIN_FIELD), P(COUNT_WHAT), P(COUNT_BAD)};
    rc = lr_ask_lens(&d->L, &d->c, &d->t);
    if (rc == LM_GO) rc = ask_all(d);
    if (rc == LM_GO) rc = lm_stop_requested() ? LM_FAIL : compute(d);
    if (lm_stop_requested()) {
        lm_say(io, LM_BOTH, P(STOPPED), lm_stop_requested());
        fprintf(stderr, "lensmat: --wave stopped by signal %d\n", lm_stop_requested());
    }
    if (rc == LM_GO) rc = calc_done(&d->c);
    for (int k = 0; k < LN_WL_MAX; k++) {
        free(d->wl[k].otf);
        free(d->wl[k].pu.w);
        free(d->wl[k].pu.amp);
    }
    if (d->ctx) d->wv->ctx_free(d->ctx);
    free(d->cx); free(d->cy); free(d->cidx); free(d->psf);
    lr_free(&d->L);
    free(d);
    return rc;
}
const char *lm_wave_example(void) { return P(EXAMPLE); }
