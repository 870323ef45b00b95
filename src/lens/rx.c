/* rx.c -- lensmat prescription files into the lens model and back.  A `thickness`
 * line selects the designers' tabulation (radius, thickness to the next surface,
 * glass, then optional `semi`, `conic`, `a2`..`a16`, `nd`/`vd`, `stop`, `mirror` per
 * surface; thicknesses negative after an odd number of mirrors) with `title`, `unit`,
 * `catalog` (glass catalogues, doc/glass.md), `wavelengths`, `wlweights`,
 * `epd`/`fnum`/`na`, `field`, `fieldweights` and `image` lines; without it the file
 * is the classic positions
 * format (radius, position, index), read here with the classic dialogue's reading
 * of indices (a number at one wavelength).  Format in README "Prescription files". */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "lens_text.h"
#include "paraxial/paraxial.h"

typedef struct rd {
    const char *src;
    ln_lens *l;
    ln_notes *notes;
    char *err;
    size_t cap;
    long line;
    int thick;                 /* a `thickness` line was read */
    int have_near, have_index, have_wl, have_ap, have_field, have_wlw, have_fw, have_image;
    int nwlw, nfw;             /* counts of the weights lines */
    double z0, z_last;         /* positions format: the first surface's, the last's */
    double wl;                 /* positions format: the glasses' wavelength */
    char wl_tok[LN_TOK_MAX];
} rd;

static int bad(rd *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int bad(rd *r, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int rc = ln_vfail(r->err, r->cap, r->src, r->line, fmt, ap);
    va_end(ap);
    return rc;
}

static int number(rd *r, const char *what, const char *tok, int allow_inf, double *v)
{
    if (ln_parse_number(tok, allow_inf, v)) return LN_OK;
    return bad(r, "%s: '%s' is not a number", what, tok);
}

static int radius(rd *r, const char *tok, double *v)
{
    if (!strcasecmp(tok, "plane")) { *v = INFINITY; return LN_OK; }
    if (ln_parse_number(tok, 1, v)) return LN_OK;
    return bad(r, "'%s' is not a radius (a number, or plane/inf/0 for a plane)", tok);
}

/* Positions format: an index token as the classic dialogue reads it (a number; a
 * bare medium name: the seed's constant; a glass, or NAME@WAVELENGTH, at the
 * file's wavelength or d), as a number: these files are at one wavelength. */
static int classic_index(rd *r, const char *tok, char *out)
{
    char name[LN_TOK_MAX];
    const char *at = strchr(tok, '@');
    double n, l = r->wl;
    size_t len = at ? (size_t)(at - tok) : strlen(tok);
    if (ln_parse_number(tok, 0, &n)) {
        if (!(n > 0)) return bad(r, "the index must be greater than 0");
        ln_format(n, out, LN_NAME_MAX);
        return LN_OK;
    }
    memcpy(name, tok, len);
    name[len] = '\0';
    if (at && px_wavelength(at + 1, &l) != PX_OK)
        return bad(r, "'%s' is not a wavelength (F, d, C, e, g, hene, or a number: nm "
                   "above 100, else um)", at + 1);
    if (!at && (n = px_medium_index(name)) > 0) ;
    else if (px_glass_index(name, l, &n) != PX_OK)
        return bad(r, "'%s' is not an index (a number, a medium, a glass such as N-BK7 "
                   "or N-BK7@C, or nd/Vd) at %g um", tok, l);
    ln_format(n, out, LN_NAME_MAX);
    return LN_OK;
}

static int set_glass(rd *r, const char *tok, char *out)
{
    if (!strcasecmp(tok, "air")) { out[0] = '\0'; return LN_OK; }
    if (strchr(tok, '@'))
        return bad(r, "'%s': a thickness prescription names glasses without '@' (its "
                   "wavelengths line says where they are taken)", tok);
    if (strlen(tok) >= LN_NAME_MAX) return bad(r, "glass name '%.40s...' too long", tok);
    strcpy(out, tok);
    ln_glass_spelling(out);
    if (ln_parse_number(out, 0, &(double){0}) || strchr(out, '/')) return LN_OK;
    if (ln_glass_lookup(r->l, tok, out, r->notes, r->src, r->line)) return LN_OK;
    if (px_medium_index(tok) > 0)             /* crown, flint, water...: the seed's media */
        ln_note(r->notes, r->src, r->line, "%s is not in the glass catalogues: taken as "
                "the medium's constant index %.6g at every wavelength (no dispersion)",
                tok, px_medium_index(tok));
    return LN_OK;
}

static int wavelengths(rd *r, char **tok, int n)
{
    ln_lens *l = r->l;
    if (r->have_wl) return bad(r, "wavelengths given twice");
    if (n < 1) return bad(r, "wavelengths: at least one (primary first)");
    if (n > LN_WL_MAX) return bad(r, "wavelengths: at most %d", LN_WL_MAX);
    for (int i = 0; i < n; i++) {
        if (px_wavelength(tok[i], &l->wl[i]) != PX_OK)
            return bad(r, "'%s' is not a wavelength (F, d, C, e, g, hene, or a number: nm "
                       "above 100, else um)", tok[i]);
        l->wl_weight[i] = 1;
    }
    l->nwl = n;
    r->have_wl = 1;
    return LN_OK;
}

static int weights(rd *r, const char *what, char **tok, int n, int *have, int *count,
                   double *w, size_t stride)
{
    if (*have) return bad(r, "%s given twice", what);
    if (n > LN_FIELD_MAX) return bad(r, "%s: too many", what);
    for (int i = 0; i < n; i++) {
        double v;
        if (number(r, what, tok[i], 0, &v)) return LN_BAD;
        if (!(v >= 0)) return bad(r, "%s: '%s' must not be negative", what, tok[i]);
        *(double *)((char *)w + stride * (size_t)i) = v;
    }
    *have = 1;
    *count = n;
    return LN_OK;
}

static int fields(rd *r, char **tok, int n)
{
    ln_lens *l = r->l;
    if (r->have_field) return bad(r, "field given twice");
    if (n < 2 || (strcmp(tok[0], "angle") && strcmp(tok[0], "height")))
        return bad(r, "field angle|height V... (V: y, or x,y)");
    if (n - 1 > LN_FIELD_MAX) return bad(r, "field: at most %d", LN_FIELD_MAX);
    l->field_kind = !strcmp(tok[0], "angle") ? LN_FIELD_ANGLE : LN_FIELD_HEIGHT;
    for (int i = 1; i < n; i++) {
        ln_field *f = &l->field[i - 1];
        char *comma = strchr(tok[i], ',');
        f->x = 0;
        f->weight = 1;
        if (comma) {
            *comma = '\0';
            if (number(r, "field x", tok[i], 0, &f->x)) return LN_BAD;
            if (number(r, "field y", comma + 1, 0, &f->y)) return LN_BAD;
        } else if (number(r, "field", tok[i], 0, &f->y)) return LN_BAD;
        if (l->field_kind == LN_FIELD_ANGLE && (fabs(f->x) >= 90 || fabs(f->y) >= 90))
            return bad(r, "field angle %s: under 90 degrees", tok[i]);
    }
    l->nfield = n - 1;
    r->have_field = 1;
    return LN_OK;
}

static int aperture(rd *r, int kind, const char *tok)
{
    double v;
    if (r->have_ap) return bad(r, "one aperture only (epd, fnum or na)");
    if (number(r, "the aperture", tok, 0, &v)) return LN_BAD;
    if (!(v > 0)) return bad(r, "the aperture must be greater than 0");
    r->l->ap_kind = kind;
    r->l->ap_value = v;
    r->have_ap = 1;
    return LN_OK;
}

/* The keys after a thickness surface's three columns. */
static int surface_keys(rd *r, ln_surface *s, char **tok, int n)
{
    for (int i = 0; i < n; i++) {
        const char *k = tok[i];
        double v;
        int a;
        if (!strcmp(k, "stop")) {
            if (r->l->stop >= 0) return bad(r, "a second stop (the first is surface %d)",
                                            r->l->stop + 1);
            r->l->stop = r->l->nsurf - 1;
            continue;
        }
        if (!strcmp(k, "mirror")) {              /* reflects: back into the same medium */
            s->mirror = 1;
            continue;
        }
        if (i + 1 == n) return bad(r, "'%s' needs a value (keys: semi, conic, a2..a16, "
                                   "nd, vd, stop, mirror)", k);
        if (number(r, k, tok[++i], 0, &v)) return LN_BAD;
        if (!strcmp(k, "semi")) {
            if (!(v >= 0)) return bad(r, "semi: the semi-diameter must not be negative");
            s->semi = v;
        } else if (!strcmp(k, "conic") || !strcmp(k, "k")) s->conic = v;
        else if (!strcmp(k, "nd")) {
            if (!(v >= 1)) return bad(r, "nd must be at least 1");
            s->nd = v;
        } else if (!strcmp(k, "vd")) {
            if (!(v >= 0)) return bad(r, "vd must not be negative");
            s->vd = v;
        } else if (k[0] == 'a' && (a = atoi(k + 1)) >= 2 && a <= 2 * LN_ASPH_MAX && !(a & 1) &&
                   strspn(k + 1, "0123456789") == strlen(k + 1) && k[1] != '0') {
            int j = a / 2 - 1;
            s->type = LN_EVENASPH;
            s->asph[j] = v;
            if (j + 1 > s->nasph) s->nasph = j + 1;
        } else return bad(r, "'%s' is not a surface key (semi, conic, a2..a16, nd, vd, "
                          "stop, mirror)", k);
    }
    return LN_OK;
}

/* coordbrk THICKNESS [decenter X Y] [tilt A B C] [order 0|1]: a coordinate break in
 * the medium before it (lens.h's ln_surface). */
static int coordbrk(rd *r, char **tok, int n)
{
    ln_lens *l = r->l;
    ln_surface *s;
    double t;
    if (n < 2) return bad(r, "coordbrk THICKNESS [decenter X Y] [tilt A B C] [order 0|1]");
    if (number(r, "the thickness", tok[1], 0, &t)) return LN_BAD;
    if (!(s = ln_add_surface(l))) return bad(r, "out of memory");
    s->line = r->line;
    s->t = t;
    s->coordbrk = 1;
    if (l->nsurf > 1) {
        strcpy(s->glass, l->surf[l->nsurf - 2].glass);
        s->nd = l->surf[l->nsurf - 2].nd;
        s->vd = l->surf[l->nsurf - 2].vd;
    } else strcpy(s->glass, l->obj_glass);
    for (int i = 2; i < n; i++) {
        const char *k = tok[i];
        int m = !strcmp(k, "decenter") ? 2 : !strcmp(k, "tilt") ? 3 : !strcmp(k, "order") ? 1 : 0;
        double v[3];
        if (!m) return bad(r, "'%s' is not a coordinate-break key (decenter X Y, tilt A B C, "
                           "order 0|1)", k);
        if (i + m >= n) return bad(r, "'%s' needs %d value%s", k, m, m > 1 ? "s" : "");
        for (int j = 0; j < m; j++)
            if (number(r, k, tok[i + 1 + j], 0, &v[j])) return LN_BAD;
        if (m == 2) { s->cb_dec[0] = v[0]; s->cb_dec[1] = v[1]; }
        else if (m == 3) memcpy(s->cb_tilt, v, sizeof s->cb_tilt);
        else if (v[0] != 0 && v[0] != 1) return bad(r, "order: 0 (decentre, then tilt) or 1 "
                                                    "(tilt, then decentre)");
        else s->cb_order = (int)v[0];
        i += m;
    }
    return LN_OK;
}

static int surface(rd *r, char **tok, int n)
{
    ln_lens *l = r->l;
    ln_surface *s;
    double rad, t;
    if (r->have_image) return bad(r, "surfaces must come before the image line");
    if (!r->thick && l->nplanes) return bad(r, "surfaces must come before the object lines");
    if (r->thick && !strcmp(tok[0], "coordbrk")) return coordbrk(r, tok, n);
    if (n < 3 || (!r->thick && n != 3))
        return bad(r, r->thick ? "a surface line needs radius, thickness, glass (then "
                   "optional keys)" : "a surface line needs three numbers: radius, "
                   "position, index");
    if (radius(r, tok[0], &rad) ||
        number(r, r->thick ? "the thickness" : "the position", tok[1], 0, &t))
        return LN_BAD;
    if (!(s = ln_add_surface(l))) return bad(r, "out of memory");
    s->line = r->line;
    ln_set_radius(s, rad);
    if (r->thick) {
        s->t = t;            /* < 0 after a mirror; ln_check checks the signs */
        if (set_glass(r, tok[2], s->glass)) return LN_BAD;
        return surface_keys(r, s, tok + 3, n - 3);
    }
    if (l->nsurf > 1) {
        if (t < r->z_last) return bad(r, "the position lies left of the previous surface "
                                      "(positions must not decrease)");
        l->surf[l->nsurf - 2].t = t - r->z_last;
    } else r->z0 = t;
    r->z_last = t;
    return classic_index(r, tok[2], s->glass);
}

static int keyword(rd *r, char **tok, int n)
{
    ln_lens *l = r->l;
    const char *k = tok[0];
    double v;
    if (!strcmp(k, "object")) {
        if (n != 2) return bad(r, "object POSITION (one number)");
        if (!l->nsurf && !r->thick) return bad(r, "a surface line needs three numbers: "
                                               "radius, position, index");
        if (number(r, "the object plane", tok[1], r->thick, &v)) return LN_BAD;
        if (v == INFINITY) return bad(r, "object -inf: an object at infinity lies left");
        if (ln_add_plane(l, r->thick ? v : v - r->z0)) return bad(r, "out of memory");
        return LN_OK;
    }
    if (l->nsurf && strcmp(k, "image"))
        return bad(r, "%s comes before the surfaces", k);
    if (!strcmp(k, "thickness")) {
        if (n != 1) return bad(r, "thickness takes no value");
        if (r->thick) return bad(r, "thickness given twice");
        if (r->have_near || r->have_index || r->have_wl)
            return bad(r, "thickness is the first line (it says how to read the rest)");
        r->thick = 1;
        return LN_OK;
    }
    if (!strcmp(k, "nearpoint")) {
        if (n != 2) return bad(r, "nearpoint V");
        if (r->have_near) return bad(r, "nearpoint given twice");
        if (number(r, "the nearpoint", tok[1], 0, &v)) return LN_BAD;
        if (v < 0) return bad(r, "the nearpoint must not be negative");
        l->nearpoint = v;
        r->have_near = 1;
        return LN_OK;
    }
    if (!strcmp(k, "index")) {
        if (n != 2 && !(r->thick && n > 2)) return bad(r, "index GLASS");
        if (r->have_index) return bad(r, "index given twice");
        r->have_index = 1;
        if (!r->thick) return classic_index(r, tok[1], l->obj_glass);
        for (int i = 2; i < n; i += 2) {       /* index NAME nd V vd V: a file's nd, Vd */
            double *dst = !strcmp(tok[i], "nd") ? &l->obj_nd : !strcmp(tok[i], "vd") ?
                          &l->obj_vd : NULL;
            if (!dst || i + 1 == n) return bad(r, "index GLASS [nd V] [vd V]");
            if (number(r, tok[i], tok[i + 1], 0, dst)) return LN_BAD;
            if (dst == &l->obj_nd ? !(v = *dst, v >= 1) : !(*dst >= 0))
                return bad(r, "%s: nd must be at least 1, vd not negative", tok[i]);
        }
        return set_glass(r, tok[1], l->obj_glass);
    }
    if (!strcmp(k, "wavelength") || !strcmp(k, "wavelengths")) {
        if (!r->thick) {
            if (n != 2 || strcmp(k, "wavelength")) return bad(r, "wavelength W");
            if (r->have_index) return bad(r, "wavelength comes before index (it applies "
                                          "to the index's glass too)");
        }
        if (wavelengths(r, tok + 1, n - 1)) return LN_BAD;
        r->wl = l->wl[0];
        return LN_OK;
    }
    if (!r->thick) return bad(r, "'%s' is a keyword of thickness prescriptions (begin the "
                              "file with a line: thickness)", k);
    if (!strcmp(k, "unit")) {
        static const char *const units[] = {"mm", "cm", "m", "in"};
        if (n != 2) return bad(r, "unit mm|cm|m|in");
        for (size_t i = 0; i < sizeof units / sizeof *units; i++)
            if (!strcmp(tok[1], units[i])) { strcpy(l->unit, units[i]); return LN_OK; }
        return bad(r, "unit '%s': mm, cm, m or in", tok[1]);
    }
    if (!strcmp(k, "catalog")) {              /* catalog SCHOTT OHARA ...: lookup order */
        if (n < 2) return bad(r, "catalog NAME...: the glass catalogues to look glasses up "
                              "in, in order (LENSMAT: the built-in one)");
        if (l->ncat) return bad(r, "catalog given twice");
        if (n - 1 > LN_CAT_MAX) return bad(r, "catalog: at most %d catalogues", LN_CAT_MAX);
        for (int i = 1; i < n; i++) {
            if (strcasecmp(tok[i], "LENSMAT") && !px_glass_cat_find(tok[i]))
                return bad(r, "catalog %s: no such glass catalogue (no %s.agf in "
                           "$LENSMAT_GLASS_PATH, data/agf/ or ../shared/glass/; LENSMAT is "
                           "the built-in one)", tok[i], tok[i]);
            snprintf(l->catalogs[l->ncat++], LN_NAME_MAX, "%s", tok[i]);
        }
        return LN_OK;
    }
    if (!strcmp(k, "wlweights"))
        return weights(r, "wlweights", tok + 1, n - 1, &r->have_wlw, &r->nwlw,
                       l->wl_weight, sizeof l->wl_weight[0]);
    if (!strcmp(k, "fieldweights"))
        return weights(r, "fieldweights", tok + 1, n - 1, &r->have_fw, &r->nfw,
                       &l->field[0].weight, sizeof l->field[0]);
    if (!strcmp(k, "epd") || !strcmp(k, "fnum") || !strcmp(k, "na")) {
        if (n != 2) return bad(r, "%s V", k);
        return aperture(r, k[0] == 'e' ? LN_AP_EPD : k[0] == 'f' ? LN_AP_FNUM : LN_AP_NA, tok[1]);
    }
    if (!strcmp(k, "field")) return fields(r, tok + 1, n - 1);
    if (!strcmp(k, "image")) {
        if (!l->nsurf) return bad(r, "the image line comes after the surfaces");
        if (r->have_image) return bad(r, "image given twice");
        r->have_image = 1;
        for (int i = 1; i < n; i++) {
            if (i + 1 == n) return bad(r, "image [radius R | curvature C] [semi V]");
            if (!strcmp(tok[i], "radius")) {
                ln_surface tmp;
                if (radius(r, tok[++i], &v)) return LN_BAD;
                ln_set_radius(&tmp, v);
                l->image_c = tmp.c;
            } else if (!strcmp(tok[i], "curvature")) {
                if (number(r, "curvature", tok[++i], 0, &l->image_c)) return LN_BAD;
            } else if (!strcmp(tok[i], "semi")) {
                if (number(r, "semi", tok[++i], 0, &v)) return LN_BAD;
                if (!(v >= 0)) return bad(r, "semi: must not be negative");
                l->image_semi = v;
            } else return bad(r, "image [radius R | curvature C] [semi V]");
        }
        return LN_OK;
    }
    return bad(r, "'%s' is not a keyword here", k);
}

static int is_keyword(const char *k)
{
    static const char *const keys[] = {"object", "thickness", "nearpoint", "index",
        "wavelength", "wavelengths", "unit", "wlweights", "fieldweights", "epd", "fnum",
        "na", "field", "image", "title", "catalog"};
    for (size_t i = 0; i < sizeof keys / sizeof *keys; i++)
        if (!strcmp(k, keys[i])) return 1;
    return 0;
}

/* The title: the rest of the line after the word, blanks trimmed ('#' kept). */
static int title(rd *r, char *rest)
{
    size_t n;
    if (r->l->nsurf) return bad(r, "title comes before the surfaces");
    if (!r->thick) return bad(r, "'title' is a keyword of thickness prescriptions");
    if (r->l->title[0]) return bad(r, "title given twice");
    n = strlen(rest);
    if (n >= LN_TITLE_MAX + 8) return bad(r, "title longer than %d bytes", LN_TITLE_MAX - 1);
    ln_title(r->l->title, rest, n);
    return LN_OK;
}

static int one_line(rd *r, char *s)
{
    char *tok[LN_TOKS];
    int n;
    size_t w = strspn(s, " \t");
    if (!strncmp(s + w, "title", 5) && (s[w + 5] == ' ' || s[w + 5] == '\t' || !s[w + 5] ||
                                        s[w + 5] == '\r'))
        return title(r, s + w + 5);
    if ((n = ln_split(s, 1, tok, LN_TOKS)) < 0)
        return bad(r, "line too long (at most %d words of %d bytes)", LN_TOKS, LN_TOK_MAX - 1);
    if (n == 0) return LN_OK;
    if (is_keyword(tok[0])) return keyword(r, tok, n);
    return surface(r, tok, n);
}

static int finish(rd *r)
{
    ln_lens *l = r->l;
    if (!l->nsurf) {
        snprintf(r->err, r->cap, "%s: no surface (lines: radius %s)", r->src,
                 r->thick ? "thickness glass" : "position index");
        return LN_BAD;
    }
    if (!r->thick && !l->nplanes) {
        snprintf(r->err, r->cap, "%s: no object plane (add a line: object POSITION)", r->src);
        return LN_BAD;
    }
    if (r->have_wlw && r->nwlw != l->nwl) {
        snprintf(r->err, r->cap, "%s: %d wavelength weights for %d wavelengths", r->src,
                 r->nwlw, l->nwl);
        return LN_BAD;
    }
    if (r->have_fw && r->nfw != l->nfield) {
        snprintf(r->err, r->cap, "%s: %d field weights for %d fields", r->src, r->nfw,
                 l->nfield);
        return LN_BAD;
    }
    if (!r->thick) l->surf[l->nsurf - 1].t = 0;
    l->object = l->nplanes ? -l->planes[0] : INFINITY;
    return ln_check(l, r->src, r->err, r->cap);
}

int ln_read_rx(const char *text, size_t len, const char *src, ln_lens *l,
               ln_notes *notes, char *err, size_t cap)
{
    rd r;
    char *s, *p;
    int rc = LN_OK;
    ln_init(l);
    if (memchr(text, '\0', len)) {
        long line = 1;
        for (const char *q = text; *q; q++) line += *q == '\n';
        snprintf(err, cap, "%s:%ld: this line holds a NUL byte (a text file is needed)", src, line);
        return LN_BAD;
    }
    if (!(s = malloc(len + 1))) { snprintf(err, cap, "%s: out of memory", src); return LN_NOMEM; }
    memcpy(s, text, len);
    s[len] = '\0';
    memset(&r, 0, sizeof r);
    r.src = src; r.l = l; r.notes = notes; r.err = err; r.cap = cap;
    r.wl = PX_LAMBDA_D;
    p = s;
    if (!strncmp(p, "\xef\xbb\xbf", 3)) p += 3;
    while (rc == LN_OK && *p) {
        char *nl = strchr(p, '\n');
        if (nl) *nl = '\0';
        r.line++;
        rc = one_line(&r, p);
        p = nl ? nl + 1 : p + strlen(p);
    }
    free(s);
    if (rc == LN_OK) rc = finish(&r);
    if (rc != LN_OK) ln_free(l);
    return rc;
}

int ln_is_rx_thickness(const char *text, size_t len)
{
    const char *p = text, *end = text + len;
    if (len >= 3 && !memcmp(p, "\xef\xbb\xbf", 3)) p += 3;
    while (p < end) {
        const char *nl = memchr(p, '\n', (size_t)(end - p)), *e = nl ? nl : end;
        while (p < e && (*p == ' ' || *p == '\t')) p++;
        if (e - p >= 9 && !memcmp(p, "thickness", 9) &&
            (e - p == 9 || strchr(" \t\r#", p[9]))) return 1;
        if (p < e && *p != '#' && *p != '\r') {
            /* a keyword line may come first; a surface line ends the search */
            size_t n = 0;
            while (p + n < e && !strchr(" \t\r#", p[n])) n++;
            char word[16];
            if (n >= sizeof word) return 0;
            memcpy(word, p, n);
            word[n] = '\0';
            if (strcmp(word, "title") && !is_keyword(word)) return 0;
        }
        p = nl ? nl + 1 : end;
    }
    return 0;
}

/* ---- writing ---------------------------------------------------------------- */

static void wl_text(double w, char *buf, size_t cap)
{
    if (w == PX_LAMBDA_F) snprintf(buf, cap, "F");
    else if (w == PX_LAMBDA_D) snprintf(buf, cap, "d");
    else if (w == PX_LAMBDA_C) snprintf(buf, cap, "C");
    else if (w == PX_LAMBDA_E) snprintf(buf, cap, "e");
    else if (w == PX_LAMBDA_G) snprintf(buf, cap, "g");
    else ln_format(w, buf, cap);
}

char *ln_write_rx(const ln_lens *l)
{
    ln_buf b = {0};
    char a[40], c[40];
    int weights = 0;
    ln_buf_printf(&b, "# lensmat prescription by thickness (lensmat --prescription -i FILE "
                  "OUTFILE runs it)\n# radius (plane: plane, inf or 0)  thickness to the "
                  "next surface  glass to its right\n# then optional keys: semi V, conic "
                  "V, a2..a16 V (even asphere), nd V vd V, stop\nthickness\n");
    if (l->title[0]) ln_buf_printf(&b, "title %s\n", l->title);
    if (strcmp(l->unit, "mm") && l->unit[0]) ln_buf_printf(&b, "unit %s\n", l->unit);
    {   /* the selected catalogues this machine has (a .zmx's GCAT may name others:
         * its glasses are stored by name, CATALOG:NAME when an AGF file gave them) */
        int k = 0;
        for (int i = 0; i < l->ncat; i++)
            if (!strcasecmp(l->catalogs[i], "LENSMAT") || px_glass_cat_find(l->catalogs[i]))
                ln_buf_printf(&b, "%s %s", k++ ? "" : "catalog", l->catalogs[i]);
        if (k) ln_buf_printf(&b, "\n");
    }
    if (l->nearpoint != 25) { ln_format(l->nearpoint, a, sizeof a); ln_buf_printf(&b, "nearpoint %s\n", a); }
    if (l->nwl) {
        ln_buf_printf(&b, "wavelengths");
        for (int i = 0; i < l->nwl; i++) {
            wl_text(l->wl[i], a, sizeof a);
            ln_buf_printf(&b, " %s", a);
            weights |= l->wl_weight[i] != 1;
        }
        ln_buf_printf(&b, "\n");
        if (weights) {
            ln_buf_printf(&b, "wlweights");
            for (int i = 0; i < l->nwl; i++) {
                ln_format(l->wl_weight[i], a, sizeof a);
                ln_buf_printf(&b, " %s", a);
            }
            ln_buf_printf(&b, "\n");
        }
    }
    if (l->obj_glass[0]) {
        ln_buf_printf(&b, "index %s", l->obj_glass);
        if (l->obj_nd != 0) { ln_format(l->obj_nd, a, sizeof a); ln_buf_printf(&b, " nd %s", a); }
        if (l->obj_vd != 0) { ln_format(l->obj_vd, a, sizeof a); ln_buf_printf(&b, " vd %s", a); }
        ln_buf_printf(&b, "\n");
    }
    if (l->ap_kind != LN_AP_NONE) {
        ln_format(l->ap_value, a, sizeof a);
        ln_buf_printf(&b, "%s %s\n", l->ap_kind == LN_AP_EPD ? "epd" :
                      l->ap_kind == LN_AP_FNUM ? "fnum" : "na", a);
    }
    if (l->nfield) {
        weights = 0;
        ln_buf_printf(&b, "field %s", l->field_kind == LN_FIELD_ANGLE ? "angle" : "height");
        for (int i = 0; i < l->nfield; i++) {
            ln_format(l->field[i].y, a, sizeof a);
            if (l->field[i].x != 0) {
                ln_format(l->field[i].x, c, sizeof c);
                ln_buf_printf(&b, " %s,%s", c, a);
            } else ln_buf_printf(&b, " %s", a);
            weights |= l->field[i].weight != 1;
        }
        ln_buf_printf(&b, "\n");
        if (weights) {
            ln_buf_printf(&b, "fieldweights");
            for (int i = 0; i < l->nfield; i++) {
                ln_format(l->field[i].weight, a, sizeof a);
                ln_buf_printf(&b, " %s", a);
            }
            ln_buf_printf(&b, "\n");
        }
    }
    for (int i = 0; i < l->nsurf; i++) {
        const ln_surface *s = &l->surf[i];
        if (s->coordbrk) {
            char e[32], f[32];
            ln_format(s->t, c, sizeof c);
            ln_format(s->cb_dec[0], a, sizeof a);
            ln_format(s->cb_dec[1], e, sizeof e);
            ln_buf_printf(&b, "%-24s %-24s decenter %s %s", "coordbrk", c, a, e);
            ln_format(s->cb_tilt[0], a, sizeof a);
            ln_format(s->cb_tilt[1], e, sizeof e);
            ln_format(s->cb_tilt[2], f, sizeof f);
            ln_buf_printf(&b, " tilt %s %s %s order %d\n", a, e, f, s->cb_order);
            continue;
        }
        ln_format_radius(s, a, sizeof a);
        ln_format(s->t, c, sizeof c);
        ln_buf_printf(&b, "%-24s %-24s %s", a, c, s->glass[0] ? s->glass : "air");
        if (s->nd != 0) { ln_format(s->nd, a, sizeof a); ln_buf_printf(&b, " nd %s", a); }
        if (s->vd != 0) { ln_format(s->vd, a, sizeof a); ln_buf_printf(&b, " vd %s", a); }
        if (s->semi != 0) { ln_format(s->semi, a, sizeof a); ln_buf_printf(&b, " semi %s", a); }
        if (s->conic != 0) { ln_format(s->conic, a, sizeof a); ln_buf_printf(&b, " conic %s", a); }
        if (s->type == LN_EVENASPH)
            for (int k = 0; k < s->nasph; k++) {
                ln_format(s->asph[k], a, sizeof a);
                ln_buf_printf(&b, " a%d %s", 2 * k + 2, a);
            }
        if (l->stop == i) ln_buf_printf(&b, " stop");
        if (s->mirror) ln_buf_printf(&b, " mirror");
        ln_buf_printf(&b, "\n");
    }
    if (l->image_c != 0 || l->image_semi != 0) {
        ln_buf_printf(&b, "image");
        if (l->image_c != 0 && 1 / (1 / l->image_c) == l->image_c) {
            ln_format(1 / l->image_c, a, sizeof a);
            ln_buf_printf(&b, " radius %s", a);
        } else if (l->image_c != 0) {                    /* 1/c does not read back as c */
            ln_format(l->image_c, a, sizeof a);
            ln_buf_printf(&b, " curvature %s", a);
        }
        if (l->image_semi != 0) { ln_format(l->image_semi, a, sizeof a); ln_buf_printf(&b, " semi %s", a); }
        ln_buf_printf(&b, "\n");
    }
    if (l->nplanes)
        for (int i = 0; i < l->nplanes; i++) {
            ln_format(l->planes[i], a, sizeof a);
            ln_buf_printf(&b, "object %s\n", isinf(l->planes[i]) ? "-infinity" : a);
        }
    else if (!isinf(l->object)) {
        ln_format(-l->object, a, sizeof a);
        ln_buf_printf(&b, "object %s\n", a);
    }
    return ln_buf_done(&b);
}
