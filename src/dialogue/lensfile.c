/* lensfile.c -- lens files of the lens model (src/lens) in the dialogues: a thickness
 * prescription or an OpticStudio .zmx turned into the classic dialogue's answers (for
 * --prescription and lens files read by --trace), saying what the classic dialogue
 * cannot take; and the converters --to-zmx and --to-thickness, which read any lens
 * file lensmat knows (those two, a positions prescription, a classic record or its
 * answers) and write it as .zmx or as a thickness prescription.  Texts in
 * prompts/lensfile.txt. */
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "ask.h"
#include "dialogues.h"
#include "../lens/lens.h"
#include "../paraxial/paraxial.h"
#include "prompts_lensfile.h"

#define LF(k) lensfile_prompts[LENSFILE_##k]
#define LENS_FILE_MAX (16L << 20)
#define FAR_OBJECT 1e10     /* the classic's stand-in for an object at infinity */

int lm_is_model_file(const char *s, size_t len)
{
    return ln_is_zmx(s, len) || ln_is_rx_thickness(s, len);
}

static int read_model(const char *src, const char *s, size_t len, ln_lens *l,
                      ln_notes *notes, char *err, size_t cap)
{
    if (ln_is_zmx(s, len)) return ln_read_zmx(s, len, src, l, notes, err, cap);
    return ln_read_rx(s, len, src, l, notes, err, cap);
}

static void print_notes(const ln_notes *n)
{
    for (const char *p = n->s; p && *p; ) {
        const char *nl = strchr(p, '\n');
        int k = nl ? (int)(nl - p) : (int)strlen(p);
        fprintf(stderr, LF(NOTE), k, p);
        p += k + (nl != NULL);
    }
}

/* The wavelength as an answer after '@': a line's letter, else um (read back exactly). */
static void wl_token(double w, char *buf, size_t cap)
{
    static const struct { const char *name; double l; } lines[] = {
        {"d", PX_LAMBDA_D}, {"F", PX_LAMBDA_F}, {"C", PX_LAMBDA_C}, {"e", PX_LAMBDA_E},
        {"g", PX_LAMBDA_G}, {"hene", PX_LAMBDA_HENE}};
    for (size_t i = 0; i < sizeof lines / sizeof *lines; i++)
        if (w == lines[i].l) { snprintf(buf, cap, "%s", lines[i].name); return; }
    ln_format(w, buf, cap);
}

/* The classic answer for the medium right of surface i (-1: the object medium): a
 * catalogue or model glass as NAME@WAVELENGTH (so the classic takes it at the
 * primary wavelength, from the catalogue), anything else as its number. */
static void index_answer(const ln_lens *l, int i, const char *wl, char *out, size_t cap)
{
    const char *g = i < 0 ? l->obj_glass : l->surf[i].glass;
    double nd = i < 0 ? l->obj_nd : l->surf[i].nd, vd = i < 0 ? l->obj_vd : l->surf[i].vd;
    double n = 1, lambda = ln_primary(l);
    char why[LN_ERR_MAX], a[40], b[40];
    int fallback;
    const px_glass_rec *rec;
    if (!g[0]) { snprintf(out, cap, "1"); return; }
    if ((rec = px_glass_find(g))) { snprintf(out, cap, "%s@%s", rec->name, wl); return; }
    if (ln_index(l, i, lambda, &n, &fallback, why, sizeof why) != LN_OK) n = 1; /* checked */
    if (fallback && vd != 0 && !isinf(vd)) {
        ln_format(nd, a, sizeof a);
        ln_format(vd, b, sizeof b);
        snprintf(out, cap, "%s/%s@%s", a, b, wl);
    } else if (!fallback && strchr(g, '/')) snprintf(out, cap, "%s@%s", g, wl);
    else ln_format(n, out, cap);
}

typedef struct abuf { char *s; size_t len, cap; int err; } abuf;
static void add(abuf *b, const char *t)
{
    size_t n = strlen(t);
    if (b->err) return;
    if (b->len + n + 2 > b->cap) {
        size_t c = (b->cap + n + 2) * 2;
        char *s = realloc(b->s, c);
        if (!s) { b->err = 1; return; }
        b->s = s;
        b->cap = c;
    }
    memcpy(b->s + b->len, t, n);
    b->len += n;
    b->s[b->len++] = '\n';
    b->s[b->len] = '\0';
}

/* What the classic dialogue cannot take, as one message (stderr). */
static void say_unused(const char *src, const ln_lens *l, const char *wl_um, int far_planes)
{
    char list[2048] = "", part[300], a[40];
    int nsemi = 0, nconic = 0, nasph = 0;
    for (int i = 0; i < l->nsurf; i++) {
        const ln_surface *s = &l->surf[i];
        nsemi += s->semi != 0;
        nconic += s->conic != 0;
        nasph += s->type == LN_EVENASPH && s->nasph > 1;
    }
#define PART(cond, ...) do { if (cond) { snprintf(part, sizeof part, __VA_ARGS__); \
        if (list[0]) strncat(list, LF(SEP), sizeof list - strlen(list) - 1); \
        strncat(list, part, sizeof list - strlen(list) - 1); } } while (0)
    PART(l->nwl > 1, LF(U_WAVELENGTHS), l->nwl - 1);
    PART(nsemi, LF(U_SEMI), nsemi);
    PART(nconic, LF(U_CONIC), nconic);
    PART(nasph, LF(U_ASPH), nasph);
    PART(l->stop >= 0, LF(U_STOP), l->stop + 1);
    ln_format(l->ap_value, a, sizeof a);
    PART(l->ap_kind != LN_AP_NONE, LF(U_APERTURE), l->ap_kind == LN_AP_EPD ? "epd" :
         l->ap_kind == LN_AP_FNUM ? "fnum" : "na", a);
    PART(l->nfield, LF(U_FIELDS), l->nfield);
    ln_format(l->surf[l->nsurf - 1].t, a, sizeof a);
    PART(l->surf[l->nsurf - 1].t != 0, LF(U_IMAGE), a);
    PART(l->image_c != 0 || l->image_semi != 0, "%s", LF(U_IMAGE_SURFACE));
    PART(l->title[0], "%s", LF(U_TITLE));
    PART(far_planes, "%s", LF(U_FAR_PLANES));
#undef PART
    if (list[0]) fprintf(stderr, LF(UNUSED), src, wl_um, list);
}

int lm_model_answers(const char *src, const char *s, size_t len, char **out, size_t *outlen,
                     int quiet, char *err, size_t cap)
{
    ln_lens l;
    ln_notes notes = {0};
    abuf b = {0};
    char tok[LN_ERR_MAX], wl[40], wl_um[40];
    double z = 0;
    int far = 0, nobj = 0;
    *out = NULL;
    if (read_model(src, s, len, &l, &notes, err, cap) != LN_OK) {
        ln_notes_free(&notes);
        return LM_FAIL;
    }
    if (!quiet) print_notes(&notes);
    ln_notes_free(&notes);
    if (ln_mirrors(&l)) {                /* the classic dialogue refracts only: unfolded */
        ln_lens u;
        int nm = ln_mirrors(&l);
        if (ln_unfold(&l, &u, NULL, tok, sizeof tok) != LN_OK) {
            snprintf(err, cap, "%s: %s", src, tok);
            ln_free(&l);
            return LM_FAIL;
        }
        ln_free(&l);
        l = u;
        if (!quiet) fprintf(stderr, LF(UNFOLDED), src, nm);
    }
    wl_token(ln_primary(&l), wl, sizeof wl);
    ln_format(ln_primary(&l), wl_um, sizeof wl_um);
    ln_format(l.nearpoint, tok, sizeof tok);
    add(&b, tok);
    index_answer(&l, -1, wl, tok, sizeof tok);
    add(&b, tok);
    for (int i = 0; i < l.nsurf; i++) {
        ln_surface p = l.surf[i];
        if (i) { add(&b, "y"); z += l.surf[i - 1].t; }
        if (p.type == LN_EVENASPH && p.nasph > 0 && p.asph[0] != 0)
            ln_set_curvature(&p, ln_paraxial_curvature(&l.surf[i]));
        ln_format_radius(&p, tok, sizeof tok);
        add(&b, tok);
        ln_format(z, tok, sizeof tok);
        add(&b, tok);
        index_answer(&l, i, wl, tok, sizeof tok);
        add(&b, tok);
    }
    for (int i = 0; i < l.nplanes; i++) {
        if (isinf(l.planes[i])) { far = 1; continue; }
        add(&b, nobj++ ? "y" : "n");
        ln_format(l.planes[i], tok, sizeof tok);
        add(&b, tok);
    }
    if (!nobj) {
        char d[40];
        double at = isinf(l.object) ? -FAR_OBJECT : -l.object;
        if (isinf(l.object) && !quiet) {
            ln_format(FAR_OBJECT, d, sizeof d);
            snprintf(tok, sizeof tok, LF(AT_INFINITY), src, d);
            fprintf(stderr, LF(ERROR), tok);
        }
        add(&b, "n");
        ln_format(at, tok, sizeof tok);
        add(&b, tok);
        far = 0;
    }
    add(&b, "n");
    if (!quiet) say_unused(src, &l, wl_um, far);
    ln_free(&l);
    if (b.err) {
        free(b.s);
        snprintf(err, cap, LF(NO_MEMORY), src);
        return LM_FAIL;
    }
    *out = b.s;
    *outlen = b.len;
    return LM_GO;
}

/* ---- --to-zmx, --to-thickness ------------------------------------------------- */

/* All of `in` (NUL bytes kept: a UTF-16 .zmx holds them); NULL with err set. */
static char *slurp_all(FILE *in, const char *src, size_t *len, char *err, size_t cap)
{
    size_t room = 65536, n;
    char *s = malloc(room + 1), *t;
    *len = 0;
    if (!s) { snprintf(err, cap, LF(NO_MEMORY), src); return NULL; }
    while ((n = fread(s + *len, 1, room - *len, in)) > 0) {
        *len += n;
        if (*len == room) {
            if (room > (size_t)LENS_FILE_MAX) {
                snprintf(err, cap, LF(TOO_BIG), src, LENS_FILE_MAX >> 20);
                free(s);
                return NULL;
            }
            if (!(t = realloc(s, 2 * room + 1))) {
                snprintf(err, cap, LF(NO_MEMORY), src);
                free(s);
                return NULL;
            }
            s = t;
            room *= 2;
        }
    }
    if (ferror(in)) {
        snprintf(err, cap, LF(CANNOT_READ), src, strerror(errno));
        free(s);
        return NULL;
    }
    s[*len] = '\0';
    return s;
}

/* Digits after the point of v's shortest decimal (the answer as it was typed);
 * -1 when it has an exponent or is not finite. */
static int decimals(double v)
{
    char b[40];
    const char *dot;
    ln_format(v, b, sizeof b);
    if (!isfinite(v) || strpbrk(b, "eE")) return -1;
    dot = strchr(b, '.');
    return dot ? (int)strlen(dot + 1) : 0;
}

/* b - a as the decimal the typed a and b make (positions 9.2666 and 10.26623 are
 * 0.99963 apart, not 0.9996299999999998): the difference rounded to the longer of
 * their decimals, which is exact for decimal answers. */
static double decimal_diff(double a, double b)
{
    int da = decimals(a), db = decimals(b), d = da > db ? da : db;
    char t[64];
    if (da < 0 || db < 0 || d > 17) return b - a;
    snprintf(t, sizeof t, "%.*f", d, b - a);
    return strtod(t, NULL);
}

/* The medium of a classic answer in the model: the glass it named (kept, so a
 * converted lens keeps its dispersion), else its number ("" for 1: air). */
static void classic_glass(double n, const char *glass, char *out, size_t cap)
{
    if (glass[0]) snprintf(out, cap, "%s", glass);
    else if (n != 1) ln_format(n, out, cap);
    else out[0] = '\0';
}

/* A lens of the classic kind (radii, positions, indices) as a model. */
static int model_of_classic(const lm_lens_file *lf, ln_lens *l)
{
    double z0 = lf->nsurf ? lf->surf[0].z : 0;
    ln_init(l);
    l->nearpoint = lf->nearpoint;
    classic_glass(lf->n_object, lf->obj_glass, l->obj_glass, sizeof l->obj_glass);
    for (int i = 0; i < lf->nsurf; i++) {
        ln_surface *s = ln_add_surface(l);
        if (!s) return LM_FAIL;
        ln_set_radius(s, lf->surf[i].radius);
        classic_glass(lf->surf[i].n_right, lf->surf[i].glass, s->glass, sizeof s->glass);
        s->t = i + 1 < lf->nsurf ? decimal_diff(lf->surf[i].z, lf->surf[i + 1].z) : 0;
    }
    for (int i = 0; i < lf->nobj; i++)
        if (ln_add_plane(l, decimal_diff(z0, lf->obj[i]))) return LM_FAIL;
    l->object = lf->nobj ? decimal_diff(lf->obj[0], z0) : INFINITY;
    return LM_GO;
}

static int convert(lm_io *io, int zmx)
{
    char err[1400], *s, *text;
    size_t len;
    ln_lens l;
    ln_notes notes = {0};
    int rc = LM_GO;
    if (!(s = slurp_all(io->in, io->src, &len, err, sizeof err))) {
        fprintf(stderr, LF(ERROR), err);
        return LM_FAIL;
    }
    if (lm_is_model_file(s, len)) {
        if (read_model(io->src, s, len, &l, &notes, err, sizeof err) != LN_OK) rc = LM_FAIL;
        print_notes(&notes);
        ln_notes_free(&notes);
    } else {
        lm_lens_file lf;
        if (lm_lens_of_text(io->src, s, len, &lf, err, sizeof err)) rc = LM_FAIL;
        else {
            if (model_of_classic(&lf, &l)) {
                snprintf(err, sizeof err, LF(NO_MEMORY), io->src);
                ln_free(&l);
                rc = LM_FAIL;
            }
            lm_lens_file_free(&lf);
        }
    }
    free(s);
    if (rc) { fprintf(stderr, LF(ERROR), err); return rc; }
    text = zmx ? ln_write_zmx(&l) : ln_write_rx(&l);
    ln_free(&l);
    if (!text) {
        snprintf(err, sizeof err, LF(NO_MEMORY), io->src);
        fprintf(stderr, LF(ERROR), err);
        return LM_FAIL;
    }
    lm_say(io, LM_REC, "%s", text);
    free(text);
    return LM_GO;
}

int lm_to_zmx(lm_io *io) { return convert(io, 1); }
int lm_to_thickness(lm_io *io) { return convert(io, 0); }
const char *lm_to_zmx_example(void) { return LF(TO_ZMX_EXAMPLE); }
const char *lm_to_thickness_example(void) { return LF(TO_THICKNESS_EXAMPLE); }
