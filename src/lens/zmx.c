/* zmx.c -- Zemax OpticStudio sequential .zmx files into the lens model and back.
 * The text format: one keyword a line (surface data indented under SURF n), in
 * UTF-8/Latin-1 or, as OpticStudio writes it, UTF-16 with a byte-order mark.  What
 * the model holds is read (surfaces STANDARD and EVENASPH with CURV, DISZ, GLAS
 * (MIRROR too), DIAM, CONI, PARM, STOP; GCAT; WAVL/WAVM, ENPD/FNUM/OBNA, FTYP,
 * fields); every other surface type and glass the catalogue lacks is noted with its
 * line, coordinate breaks that tilt or decentre are refused (those that do not are
 * skipped), and the other keywords (display, tolerancing, optimisation, coatings...)
 * are listed in one note. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "lens_text.h"
#include "common/lm_text.h"
#include "paraxial/paraxial.h"

/* ---- decoding: src/common/lm_text.h (UTF-16, UTF-8, Latin-1 into UTF-8) ------- */

static char *decode(const char *text, size_t len, size_t *n) { return lm_text_utf8(text, len, n); }

/* ---- reading --------------------------------------------------------------------- */

/* One SURF block as read: a surface of the model plus what only the reader needs. */
typedef struct zsurf {
    ln_surface s;
    int stop, supported;       /* supported: STANDARD or EVENASPH */
    char type[16];
    long dline;                /* the DISZ line */
    int cb;                    /* a coordinate break (TYPE COORDBRK) */
    double cbp[6];             /* its PARM 1-6: decentre x, y; tilt about x, y, z; order */
    long cb_line;              /* the first PARM line that tilts or decentres */
} zsurf;

#define NSKIP 64
typedef struct zr {
    const char *src;
    ln_lens *l;
    ln_notes *notes;
    char *err;
    size_t cap;
    long line;
    zsurf *zs;
    int nz, capz;
    int ftyp_seen, ftyp_nfield, ftyp_nwl;
    int nwavm, pwav, nwwgt;
    double wavm[LN_WL_MAX], wavm_w[LN_WL_MAX];
    int nx, ny, nfw;
    double fx[LN_FIELD_MAX], fy[LN_FIELD_MAX], fw[LN_FIELD_MAX];
    int field_type;
    int nskip;                 /* keywords not read, each once */
    char skip[NSKIP][8];
    int more_skipped;
    unsigned aliased;          /* the aliases already noted */
} zr;

static int zbad(zr *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int zbad(zr *r, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int rc = ln_vfail(r->err, r->cap, r->src, r->line, fmt, ap);
    va_end(ap);
    return rc;
}

static int znum(zr *r, const char *key, const char *tok, double *v)
{
    if (!tok) return zbad(r, "%s: a number is missing", key);
    if (ln_parse_number(tok, 1, v) && !isnan(*v)) return LN_OK;
    return zbad(r, "%s: '%s' is not a number", key, tok);
}

static void skipped(zr *r, const char *key)
{
    for (int i = 0; i < r->nskip; i++) if (!strcmp(r->skip[i], key)) return;
    if (r->nskip == NSKIP) { r->more_skipped = 1; return; }
    snprintf(r->skip[r->nskip], sizeof r->skip[0], "%s", key);
    r->nskip++;
}

static zsurf *cur(zr *r) { return r->nz ? &r->zs[r->nz - 1] : NULL; }

static int new_surface(zr *r, const char *tok)
{
    double v;
    zsurf *z;
    if (!tok || !ln_parse_number(tok, 0, &v) || v != r->nz)
        return zbad(r, "SURF %s: surfaces must be numbered 0, 1, 2... in order (this "
                    "is SURF %d)", tok ? tok : "", r->nz);
    if (r->nz == r->capz) {
        int c = r->capz ? 2 * r->capz : 16;
        if (r->capz > (1 << 16)) return zbad(r, "more than %d surfaces", 1 << 16);
        if (!(z = realloc(r->zs, (size_t)c * sizeof *z))) return zbad(r, "out of memory");
        r->zs = z;
        r->capz = c;
    }
    z = &r->zs[r->nz++];
    memset(z, 0, sizeof *z);
    z->s.type = LN_STANDARD;
    z->s.r = INFINITY;
    z->s.line = r->line;
    z->supported = 1;
    strcpy(z->type, "STANDARD");
    return LN_OK;
}

/* OpticStudio's names for glasses lensmat's catalogue holds under another name:
 * {OpticStudio, lensmat, where OpticStudio has it}. */
static const char *const aliases[][3] = {
    {"SILICA", "F_SILICA", "MISC catalogue's fused silica, Malitson 1965"},
};

/* GLAS NAME FIX? ? ND VD ...: the catalogue's glass, a model glass (___BLANK), a
 * 6-digit glass code, or a name with the file's nd/Vd as its fallback (noted). */
static int glass(zr *r, zsurf *z, char **tok, int n)
{
    double nd = 0, vd = 0, idx;
    int placeholder;
    const char *name = tok[1];
    if (n < 2) return zbad(r, "GLAS: a glass name is missing");
    z->s.nd = z->s.vd = 0;                  /* a second GLAS line replaces the first */
    if (n >= 6 && (!ln_parse_number(tok[4], 0, &nd) || !ln_parse_number(tok[5], 0, &vd)))
        nd = vd = 0;
    if (!strcasecmp(name, "MIRROR")) {      /* back into the medium it came from (air) */
        z->s.mirror = 1;
        z->s.glass[0] = '\0';
        return LN_OK;
    }
    z->s.mirror = 0;
    if (strlen(name) >= LN_NAME_MAX) return zbad(r, "GLAS: name too long");
    for (const char *p = name; *p; p++)      /* what a prescription's column can hold */
        if (*p <= ' ' || *p > '~' || *p == '@' || *p == '#' || *p == ',')
            return zbad(r, "GLAS: '%s' is not a glass name lensmat takes (printable "
                        "ASCII without @ # ,)", name);
    if (!strcasecmp(name, "AIR")) { z->s.glass[0] = '\0'; return LN_OK; }
    if (!strcmp(name, "___BLANK")) {                        /* a model glass */
        if (!(nd > 0)) return zbad(r, "GLAS ___BLANK: a model glass needs nd (> 0)");
        if (vd == 0) ln_format(nd, z->s.glass, LN_NAME_MAX);
        else {
            char a[32], b[32];
            ln_format(nd, a, sizeof a);
            ln_format(vd, b, sizeof b);
            snprintf(z->s.glass, LN_NAME_MAX, "%s/%s", a, b);
            if (px_glass_index(z->s.glass, PX_LAMBDA_D, &idx) != PX_OK)
                return zbad(r, "GLAS ___BLANK: nd %s, Vd %s is not a model glass lensmat "
                            "takes (1 < nd < 3, 5 <= Vd <= 150)", a, b);
        }
        return LN_OK;
    }
    for (size_t i = 0; i < sizeof aliases / sizeof *aliases; i++)
        if (!strcasecmp(name, aliases[i][0])) {
            if (!(r->aliased & (1u << i)))
                ln_note(r->notes, r->src, r->line, "glass %s (OpticStudio's %s) is read as "
                        "lensmat's %s, the same formula", name, aliases[i][2], aliases[i][1]);
            r->aliased |= 1u << i;
            name = aliases[i][1];
        }
    /* OpticStudio writes nd 1.5, Vd 40 -- its model-glass defaults -- for a glass the
     * exporting machine's catalogues lacked: not the glass's data */
    placeholder = n >= 6 && nd == 1.5 && vd == 40;
    if (ln_glass_lookup(r->l, name, z->s.glass, r->notes, r->src, r->line)) {
        double nc;
        if (placeholder)
            ln_note(r->notes, r->src, r->line, "glass %s: the file's nd 1.5, Vd 40 are "
                    "OpticStudio's placeholder (the exporting machine lacked the glass): "
                    "the catalogue's %s is used", tok[1], z->s.glass);
        else if (nd > 1 && px_glass_index(z->s.glass, PX_LAMBDA_D, &nc) == PX_OK &&
                 fabs(nc - nd) > 5e-4)  /* another maker's glass of that name, a typo */
            ln_note(r->notes, r->src, r->line, "glass %s: the file gives nd %.6g, the "
                    "catalogue's %s has %.6f: the catalogue's is used", tok[1], nd,
                    z->s.glass, nc);
        return LN_OK;
    }
    if (ln_parse_number(name, 0, &idx)) {   /* an index as a name: its shortest spelling */
        if (px_glass_index(name, PX_LAMBDA_D, &idx) == PX_OK) {
            ln_format(idx, z->s.glass, LN_NAME_MAX);
            ln_note(r->notes, r->src, r->line, "glass %s: a constant index %s at every "
                    "wavelength (no dispersion)", name, z->s.glass);
            return LN_OK;
        }
    } else if (px_glass_index(name, PX_LAMBDA_D, &idx) == PX_OK) {
        snprintf(z->s.glass, LN_NAME_MAX, "%s", name);   /* a medium, a model ND/VD */
        ln_glass_spelling(z->s.glass);
        if (!strchr(name, '/'))
            ln_note(r->notes, r->src, r->line, "glass %s is not in the glass catalogues: "
                    "taken as the medium %s, a constant index %.6g at every wavelength "
                    "(no dispersion)", name, name, idx);
        return LN_OK;
    }
    snprintf(z->s.glass, LN_NAME_MAX, "%s", name);
    if (strlen(name) == 6 && strspn(name, "0123456789") == 6 && !(nd >= 1)) {
        nd = 1 + atoi(name) / 1000 / 1000.0;               /* 517642: nd 1.517, Vd 64.2 */
        vd = (atoi(name) % 1000) / 10.0;
    }
    if (placeholder)
        return zbad(r, "glass %s is not in lensmat's glass catalogues, and the file's nd "
                    "1.5, Vd 40 are OpticStudio's placeholder for a glass the exporting "
                    "machine lacked, not %s's data: add the glass's catalogue (its maker's "
                    "AGF file in data/agf/, ../shared/glass/ or $LENSMAT_GLASS_PATH) or "
                    "its formula to data/glass.txt", name, name);
    if (!(nd > 1)) return zbad(r, "glass %s is not in lensmat's glass catalogues "
                               "(data/glass.txt, AGF files) and the file gives no nd for "
                               "it (add the glass's catalogue or formula, or nd and Vd to "
                               "this GLAS line)", name);
    z->s.nd = nd;
    z->s.vd = vd;
    ln_note(r->notes, r->src, r->line, "glass %s is not in lensmat's catalogue: taken as "
            "the model glass nd %.6g, Vd %.4g the file gives (n = A + B/l^2; the real "
            "glass's dispersion differs slightly)", name, nd, vd);
    return LN_OK;
}

/* XFLN/YFLN/FWGN (and XFLD/YFLD/FWGT): the values of up to LN_FIELD_MAX fields. */
static int field_row(zr *r, const char *key, char **tok, int n, double *dst, int *count)
{
    if (n - 1 > LN_FIELD_MAX) n = LN_FIELD_MAX + 1;
    for (int i = 1; i < n; i++) if (znum(r, key, tok[i], &dst[i - 1])) return LN_BAD;
    *count = n - 1;
    return LN_OK;
}

static int surface_line(zr *r, zsurf *z, const char *k, char **tok, int n)
{
    double v;
    if (!strcmp(k, "TYPE")) {
        if (n < 2) return zbad(r, "TYPE: a surface type is missing");
        snprintf(z->type, sizeof z->type, "%s", tok[1]);
        if (!strcmp(tok[1], "STANDARD")) z->s.type = LN_STANDARD;
        else if (!strcmp(tok[1], "EVENASPH")) z->s.type = LN_EVENASPH;
        else if (!strcmp(tok[1], "COORDBRK")) { z->supported = 0; z->cb = 1; }
        else {
            z->supported = 0;
            ln_note(r->notes, r->src, r->line, "surface %d: type %s is not supported: read "
                    "as a standard surface with its CURV, CONI and DISZ (its other "
                    "parameters are skipped)", r->nz - 1, z->type);
        }
        return LN_OK;
    }
    if (!strcmp(k, "CURV")) {
        if (znum(r, k, n > 1 ? tok[1] : NULL, &v)) return LN_BAD;
        if (isinf(v)) return zbad(r, "CURV: the curvature must be finite");
        ln_set_curvature(&z->s, v);
        return LN_OK;
    }
    if (!strcmp(k, "DISZ")) {
        if (znum(r, k, n > 1 ? tok[1] : NULL, &v)) return LN_BAD;
        if (r->nz == 1) {            /* the object's distance (< 0: a virtual object) */
            if (v == -INFINITY) return zbad(r, "DISZ -INFINITY: the object at infinity is "
                                            "DISZ INFINITY");
            r->l->object = v;
            return LN_OK;
        }
        if (isinf(v)) return zbad(r, "DISZ INFINITY: only the object may lie at infinity");
        z->s.t = v;          /* < 0 after a mirror: checked in assemble */
        z->dline = r->line;
        return LN_OK;
    }
    if (!strcmp(k, "GLAS")) return glass(r, z, tok, n);
    if (!strcmp(k, "DIAM")) {
        if (znum(r, k, n > 1 ? tok[1] : NULL, &v)) return LN_BAD;
        if (!(v >= 0) || isinf(v)) return zbad(r, "DIAM %s: a semi-diameter is a positive number", tok[1]);
        z->s.semi = v;
        return LN_OK;
    }
    if (!strcmp(k, "CONI")) {
        if (znum(r, k, n > 1 ? tok[1] : NULL, &v)) return LN_BAD;
        if (isinf(v)) return zbad(r, "CONI: the conic must be finite");
        z->s.conic = v;
        return LN_OK;
    }
    if (!strcmp(k, "PARM")) {
        double i;
        if (n < 3 || !ln_parse_number(tok[1], 0, &i) || i != floor(i) || i < 0)
            return zbad(r, "PARM N VALUE: a parameter number and a value are needed");
        if (znum(r, k, tok[2], &v)) return LN_BAD;
        if (isinf(v)) return zbad(r, "PARM: the value must be finite");
        if (z->cb) {                          /* decentre x, y, tilt x, y, z, order */
            if (i >= 1 && i <= 6) z->cbp[(int)i - 1] = v;
            if (i >= 1 && i <= 5 && v != 0 && !z->cb_line) z->cb_line = r->line;
            return LN_OK;
        }
        if (z->s.type == LN_EVENASPH && i >= 1 && i <= LN_ASPH_MAX) {
            z->s.asph[(int)i - 1] = v;
            if (v != 0 && (int)i > z->s.nasph) z->s.nasph = (int)i;
        } else if (v != 0 && z->supported)
            ln_note(r->notes, r->src, r->line, "surface %d: PARM %g = %s is skipped (%s "
                    "surfaces have %s)", r->nz - 1, i, tok[2], z->type,
                    z->s.type == LN_EVENASPH ? "8 parameters, r^2 to r^16" : "none");
        return LN_OK;
    }
    if (!strcmp(k, "STOP")) { z->stop = 1; return LN_OK; }
    if (!strcmp(k, "XDAT") && z->supported) {
        ln_note(r->notes, r->src, r->line, "surface %d: extra data (XDAT) is skipped",
                r->nz - 1);
        return LN_OK;
    }
    return 1;                                                 /* not a surface keyword */
}

static int system_line(zr *r, const char *k, char **tok, int n, const char *rest)
{
    ln_lens *l = r->l;
    double v;
    if (!strcmp(k, "NAME")) {
        size_t len;
        rest += strspn(rest, " \t");
        len = strlen(rest);
        while (len && strchr(" \t\r", rest[len - 1])) len--;
        if (len >= 2 && rest[0] == '"' && rest[len - 1] == '"') { rest++; len -= 2; }
        ln_title(l->title, rest, len);
        return LN_OK;
    }
    if (!strcmp(k, "GCAT")) {                  /* the glass catalogues, in order */
        l->ncat = 0;
        for (int i = 1; i < n && l->ncat < LN_CAT_MAX; i++)
            if (strlen(tok[i]) < LN_NAME_MAX) snprintf(l->catalogs[l->ncat++], LN_NAME_MAX,
                                                       "%s", tok[i]);
        return LN_OK;
    }
    if (!strcmp(k, "MODE")) {
        if (n > 1 && strcmp(tok[1], "SEQ"))
            return zbad(r, "MODE %s: only sequential files (MODE SEQ) are read", tok[1]);
        return LN_OK;
    }
    if (!strcmp(k, "UNIT")) {
        static const char *const z[] = {"MM", "CM", "METER", "IN", "INCH"};
        static const char *const u[] = {"mm", "cm", "m", "in", "in"};
        if (n < 2) return zbad(r, "UNIT: a unit is missing");
        for (size_t i = 0; i < sizeof z / sizeof *z; i++)
            if (!strcasecmp(tok[1], z[i])) { strcpy(l->unit, u[i]); return LN_OK; }
        return zbad(r, "UNIT %s: mm, cm, m or inches", tok[1]);
    }
    if (!strcmp(k, "ENPD") || !strcmp(k, "FNUM") || !strcmp(k, "OBNA")) {
        if (znum(r, k, n > 1 ? tok[1] : NULL, &v)) return LN_BAD;
        if (!(v > 0) || isinf(v)) return zbad(r, "%s %s: the aperture must be a positive "
                                              "number", k, tok[1]);
        l->ap_kind = k[0] == 'E' ? LN_AP_EPD : k[0] == 'F' ? LN_AP_FNUM : LN_AP_NA;
        l->ap_value = v;
        if (k[0] == 'F' && n > 2 && strcmp(tok[2], "0"))
            ln_note(r->notes, r->src, r->line, "FNUM %s %s: the paraxial working F/# is "
                    "taken as the image-space F/#", tok[1], tok[2]);
        return LN_OK;
    }
    if (!strcmp(k, "FLOA")) {
        l->ap_kind = LN_AP_NONE;
        l->ap_value = 0;
        ln_note(r->notes, r->src, r->line, "FLOA: the aperture floats by the stop's size "
                "(no EPD, F/# or NA is set: the stop's semi-diameter gives it)");
        return LN_OK;
    }
    if (!strcmp(k, "FTYP")) {
        double t, nf = 0, nw = 0;
        if (n < 2 || !ln_parse_number(tok[1], 0, &t)) return zbad(r, "FTYP: a field type is missing");
        r->ftyp_seen = 1;
        r->field_type = (int)t;
        if (n >= 5 && ln_parse_number(tok[3], 0, &nf) && ln_parse_number(tok[4], 0, &nw)) {
            r->ftyp_nfield = nf >= 0 && nf <= LN_FIELD_MAX ? (int)nf : -1;
            r->ftyp_nwl = nw >= 0 && nw <= LN_WL_MAX ? (int)nw : -1;
        } else r->ftyp_nfield = r->ftyp_nwl = -1;
        if (t != 0 && t != 1)
            ln_note(r->notes, r->src, r->line, "FTYP %s: fields given as %s are not "
                    "supported (object angles or heights are): the fields are skipped",
                    tok[1], t == 2 ? "paraxial image heights" : t == 3 ?
                    "real image heights" : "this type");
        return LN_OK;
    }
    if (!strcmp(k, "XFLN") || !strcmp(k, "XFLD")) return field_row(r, k, tok, n, r->fx, &r->nx);
    if (!strcmp(k, "YFLN") || !strcmp(k, "YFLD")) return field_row(r, k, tok, n, r->fy, &r->ny);
    if (!strcmp(k, "FWGN") || !strcmp(k, "FWGT")) return field_row(r, k, tok, n, r->fw, &r->nfw);
    if (!strcmp(k, "WAVL")) {                  /* old files: WAVL w1 w2 ... (um) */
        r->nwavm = 0;
        for (int i = 1; i < n && r->nwavm < LN_WL_MAX; i++) {
            if (znum(r, k, tok[i], &r->wavm[r->nwavm])) return LN_BAD;
            r->wavm_w[r->nwavm++] = 1;
        }
        return LN_OK;
    }
    if (!strcmp(k, "WWGT")) {
        for (int i = 1; i < n && i <= LN_WL_MAX; i++)
            if (znum(r, k, tok[i], &r->wavm_w[i - 1])) return LN_BAD;
        r->nwwgt = n - 1;
        return LN_OK;
    }
    if (!strcmp(k, "WAVM")) {                  /* WAVM i wavelength weight */
        double i, w = 1;
        if (n < 3 || !ln_parse_number(tok[1], 0, &i) || i != floor(i) || i < 1)
            return zbad(r, "WAVM N WAVELENGTH [WEIGHT]");
        if (znum(r, k, tok[2], &v) || (n > 3 && znum(r, k, tok[3], &w))) return LN_BAD;
        if (i > LN_WL_MAX) return LN_OK;
        r->wavm[(int)i - 1] = v;
        r->wavm_w[(int)i - 1] = w;
        if ((int)i > r->nwavm) r->nwavm = (int)i;
        return LN_OK;
    }
    if (!strcmp(k, "PWAV")) {
        if (znum(r, k, n > 1 ? tok[1] : NULL, &v)) return LN_BAD;
        r->pwav = v >= 1 && v <= LN_WL_MAX ? (int)v : 0;
        return LN_OK;
    }
    return 1;
}

static int zline(zr *r, char *s)
{
    char *tok[LN_TOKS], *rest, key[8];
    int n, rc;
    size_t w = strspn(s, " \t");
    size_t kl = strcspn(s + w, " \t\r");
    if (kl == 0) return LN_OK;
    if (kl < sizeof key) { memcpy(key, s + w, kl); key[kl] = '\0'; }
    else snprintf(key, sizeof key, "%.7s", s + w);
    rest = s + w + kl;
    if (!strcmp(key, "NAME") || !strcmp(key, "NOTE") || !strcmp(key, "COMM")) {
        if (!strcmp(key, "NAME")) return system_line(r, key, NULL, 0, rest);
        skipped(r, key);
        return LN_OK;
    }
    if ((n = ln_split(s, 0, tok, LN_TOKS)) < 0) {
        skipped(r, key);                       /* a long line of data we do not read */
        return LN_OK;
    }
    if (!strcmp(key, "SURF")) return new_surface(r, n > 1 ? tok[1] : NULL);
    if (cur(r) && (rc = surface_line(r, cur(r), key, tok, n)) != 1) return rc;
    if ((rc = system_line(r, key, tok, n, rest)) != 1) return rc;
    skipped(r, key);
    return LN_OK;
}

/* The SURF blocks into the lens: 0 the object, the last the image plane. */
static int assemble(zr *r)
{
    ln_lens *l = r->l;
    if (r->nz < 3) {
        snprintf(r->err, r->cap, "%s: %d surfaces: a lens file needs the object, at least "
                 "one surface and the image (SURF 0, 1, 2)", r->src, r->nz);
        return LN_BAD;
    }
    if (r->zs[0].s.glass[0] || r->zs[0].s.nd) {
        strcpy(l->obj_glass, r->zs[0].s.glass);
        l->obj_nd = r->zs[0].s.nd;
        l->obj_vd = r->zs[0].s.vd;
    }
    for (int i = 1, sigma = 1; i < r->nz - 1; i++) {    /* thickness signs: by DISZ line */
        double t = r->zs[i].s.t;
        if (r->zs[i].s.mirror) sigma = -sigma;
        if (sigma > 0 ? t < 0 : t > 0) {
            char a[32];
            r->line = r->zs[i].dline;
            ln_format(t, a, sizeof a);
            return zbad(r, sigma > 0 ? "DISZ %s: a negative thickness where the light travels "
                        "toward +z (thicknesses are negative only after an odd number of "
                        "mirrors)" : "DISZ %s: a positive thickness where the light travels "
                        "toward -z (after an odd number of mirrors thicknesses are negative)", a);
        }
    }
    for (int i = 1; i < r->nz - 1; i++) {
        ln_surface *s;
        if (r->zs[i].cb) {
            zsurf *z = &r->zs[i];
            if (z->cb_line) {            /* a frame for the surfaces after it */
                if (!(s = ln_add_surface(l))) {
                    snprintf(r->err, r->cap, "%s: out of memory", r->src);
                    return LN_NOMEM;
                }
                memset(s, 0, sizeof *s);
                s->type = LN_STANDARD;
                ln_set_curvature(s, 0);
                s->line = z->s.line;
                s->t = z->s.t;
                s->coordbrk = 1;
                s->cb_dec[0] = z->cbp[0];
                s->cb_dec[1] = z->cbp[1];
                for (int j = 0; j < 3; j++) s->cb_tilt[j] = z->cbp[2 + j];
                s->cb_order = z->cbp[5] != 0;   /* OpticStudio: any non-zero order flag */
                if (l->nsurf > 1) {             /* it stands in the medium before it */
                    strcpy(s->glass, l->surf[l->nsurf - 2].glass);
                    s->nd = l->surf[l->nsurf - 2].nd;
                    s->vd = l->surf[l->nsurf - 2].vd;
                } else {
                    strcpy(s->glass, l->obj_glass);
                    s->nd = l->obj_nd;
                    s->vd = l->obj_vd;
                }
                if (z->stop) ln_note(r->notes, r->src, z->s.line, "surface %d: the stop on "
                                     "a coordinate break is skipped", i);
                continue;
            }
            /* a break that moves nothing (files keep them as placeholders): its
             * thickness joins the gap before it */
            if (l->nsurf) l->surf[l->nsurf - 1].t += z->s.t;
            else l->object += z->s.t;
            ln_note(r->notes, r->src, z->s.line, "surface %d: a coordinate break with no "
                    "decentre or tilt is skipped (its thickness %g joins the gap before it)",
                    i, z->s.t);
            if (z->stop) ln_note(r->notes, r->src, z->s.line, "surface %d: the stop on a "
                                 "coordinate break is skipped", i);
            continue;
        }
        if (!(s = ln_add_surface(l))) { snprintf(r->err, r->cap, "%s: out of memory", r->src); return LN_NOMEM; }
        *s = r->zs[i].s;
        if (r->zs[i].stop) {
            if (l->stop >= 0)
                ln_note(r->notes, r->src, r->zs[i].s.line, "surface %d: a second STOP "
                        "(surface %d is the stop)", i, l->stop + 1);
            else l->stop = l->nsurf - 1;
        }
    }
    if (r->zs[0].stop || r->zs[r->nz - 1].stop)
        ln_note(r->notes, r->src, r->zs[r->zs[0].stop ? 0 : r->nz - 1].s.line,
                "the stop on the object or image surface is skipped");
    l->image_c = r->zs[r->nz - 1].s.c;
    l->image_semi = r->zs[r->nz - 1].s.semi;
    if (r->zs[r->nz - 1].s.glass[0])
        ln_note(r->notes, r->src, r->zs[r->nz - 1].s.line, "the image surface's glass is "
                "skipped");
    /* wavelengths: FTYP's count when there is one (OpticStudio pads WAVM to 24) */
    {
        int nw = r->nwavm, p;
        if (r->ftyp_seen && r->ftyp_nwl > 0 && r->ftyp_nwl < nw) nw = r->ftyp_nwl;
        p = r->pwav >= 1 && r->pwav <= nw ? r->pwav - 1 : 0;
        for (int i = 0, k = 0; i < nw; i++) {
            int j = i == 0 ? p : (i <= p ? i - 1 : i);    /* primary first */
            double w = r->wavm[j];
            if (!(w >= 0.1 && w <= 100)) {
                snprintf(r->err, r->cap, "%s: wavelength %d: %g um is not a wavelength "
                         "(0.1 to 100 um)", r->src, j + 1, w);
                return LN_BAD;
            }
            l->wl[k] = w;
            l->wl_weight[k++] = r->wavm_w[j];
            l->nwl = k;
        }
    }
    /* fields */
    if (r->field_type == 0 || r->field_type == 1) {
        int nf = r->nx > r->ny ? r->nx : r->ny;
        if (r->ftyp_seen && r->ftyp_nfield >= 0 && r->ftyp_nfield < nf) nf = r->ftyp_nfield;
        l->field_kind = r->field_type == 0 ? LN_FIELD_ANGLE : LN_FIELD_HEIGHT;
        for (int i = 0; i < nf; i++) {
            l->field[i].x = i < r->nx ? r->fx[i] : 0;
            l->field[i].y = i < r->ny ? r->fy[i] : 0;
            l->field[i].weight = i < r->nfw ? r->fw[i] : 1;
        }
        l->nfield = nf;
    }
    if (r->nskip) {
        ln_buf b = {0};
        for (int i = 0; i < r->nskip; i++)
            ln_buf_printf(&b, "%s%s", i ? " " : "", r->skip[i]);
        if (ln_buf_done(&b))
            ln_note(r->notes, r->src, 0, "not read (display, tolerancing, optimisation, "
                    "coating and other data the lens model does not hold): %s%s", b.s,
                    r->more_skipped ? ", and more" : "");
        free(b.s);
    }
    return ln_check(l, r->src, r->err, r->cap);
}

int ln_read_zmx(const char *text, size_t len, const char *src, ln_lens *l,
                ln_notes *notes, char *err, size_t cap)
{
    zr r;
    size_t n;
    char *s = decode(text, len, &n), *p;
    int rc = LN_OK;
    ln_init(l);
    if (!s) { snprintf(err, cap, "%s: out of memory", src); return LN_NOMEM; }
    memset(&r, 0, sizeof r);
    r.src = src; r.l = l; r.notes = notes; r.err = err; r.cap = cap;
    for (p = s; rc == LN_OK && *p; ) {
        char *nl = strchr(p, '\n');
        if (nl) *nl = '\0';
        r.line++;
        rc = zline(&r, p);
        p = nl ? nl + 1 : p + strlen(p);
    }
    free(s);
    if (rc == LN_OK) rc = assemble(&r);
    free(r.zs);
    if (rc != LN_OK) ln_free(l);
    return rc;
}

int ln_is_zmx(const char *text, size_t len)
{
    size_t n;
    char *s = decode(text, len < 65536 ? len : 65536, &n), *p;
    int surf = 0, head = 0;
    if (!s) return 0;
    for (p = s; *p; ) {
        char *nl = strchr(p, '\n');
        p += strspn(p, " \t");
        if (!strncmp(p, "SURF ", 5)) surf = 1;
        if (!strncmp(p, "VERS ", 5) || !strncmp(p, "MODE ", 5) || !strncmp(p, "UNIT ", 5))
            head = 1;
        p = nl ? nl + 1 : p + strlen(p);
    }
    free(s);
    return surf && head;
}

/* ---- writing ---------------------------------------------------------------------- */

static void zfmt(double v, char *buf, size_t cap)
{
    if (isinf(v)) snprintf(buf, cap, "INFINITY");
    else ln_format(v, buf, cap);
}

static void write_glass(ln_buf *b, const char *g, double nd, double vd, int mirror)
{
    double n, v = 0;
    char a[40], c[40];
    if (mirror) { ln_buf_printf(b, "  GLAS MIRROR 0 0 0 0 0 0 0 0 0 0\r\n"); return; }
    if (!g[0]) return;
    if (nd > 1 && px_glass_index(g, PX_LAMBDA_D, &n) == PX_NO_GLASS) {
        ln_format(nd, a, sizeof a);
        ln_format(vd, c, sizeof c);
        ln_buf_printf(b, "  GLAS %s 0 0 %s %s 0 0 0 0 0 0\r\n", g, a, c);
        return;
    }
    if (px_glass_find(g)) {                 /* nd, Vd as OpticStudio lists them */
        if (px_glass_index(g, PX_LAMBDA_D, &n) != PX_OK) n = 0;
        if (px_glass_abbe(g, &v) != PX_OK) v = 0;
        ln_format(n, a, sizeof a);
        ln_format(v, c, sizeof c);
        ln_buf_printf(b, "  GLAS %s 0 0 %s %s 0 0 0 0 0 0\r\n", px_glass_find(g)->name, a, c);
        return;
    }
    if (px_glass_index(g, PX_LAMBDA_D, &n) != PX_OK) n = 1;
    if (!strchr(g, '/') && !ln_parse_number(g, 0, &v)) {  /* a medium lensmat names */
        ln_format(n, a, sizeof a);
        ln_buf_printf(b, "  GLAS %s 0 0 %s 0 0 0 0 0 0 0\r\n", g, a);
        return;
    }
    /* a model glass ND/VD or a number: OpticStudio's model glass */
    v = 0;
    if (strchr(g, '/')) v = strtod(strchr(g, '/') + 1, NULL);
    if (strchr(g, '/')) n = strtod(g, NULL);               /* its own nd, exactly */
    ln_format(n, a, sizeof a);
    ln_format(v, c, sizeof c);
    ln_buf_printf(b, "  GLAS ___BLANK 1 0 %s %s 0 0 0 0 0 0\r\n", a, c);
}

static void write_surface(ln_buf *b, int k, const ln_surface *s, int stop, double disz,
                          const char *glass, double nd, double vd)
{
    char a[40];
    ln_buf_printf(b, "SURF %d\r\n", k);
    if (s->coordbrk) {                  /* PARM 1-6: decentre x, y, tilt x, y, z, order */
        double p[6] = {s->cb_dec[0], s->cb_dec[1], s->cb_tilt[0], s->cb_tilt[1],
                       s->cb_tilt[2], s->cb_order};
        ln_buf_printf(b, "  TYPE COORDBRK\r\n  CURV 0 0 0 0 0 \"\"\r\n");
        for (int i = 0; i < 6; i++) {
            ln_format(p[i], a, sizeof a);
            ln_buf_printf(b, "  PARM %d %s\r\n", i + 1, a);
        }
        zfmt(disz, a, sizeof a);
        ln_buf_printf(b, "  DISZ %s\r\n", a);
        return;
    }
    if (stop) ln_buf_printf(b, "  STOP\r\n");
    ln_buf_printf(b, "  TYPE %s\r\n", s->type == LN_EVENASPH ? "EVENASPH" : "STANDARD");
    ln_format(s->c, a, sizeof a);
    ln_buf_printf(b, "  CURV %s 0 0 0 0 \"\"\r\n", a);
    if (s->type == LN_EVENASPH)
        for (int i = 0; i < LN_ASPH_MAX; i++) {
            ln_format(i < s->nasph ? s->asph[i] : 0, a, sizeof a);
            ln_buf_printf(b, "  PARM %d %s\r\n", i + 1, a);
        }
    zfmt(disz, a, sizeof a);
    ln_buf_printf(b, "  DISZ %s\r\n", a);
    write_glass(b, glass, nd, vd, s->mirror);
    if (s->conic != 0) { ln_format(s->conic, a, sizeof a); ln_buf_printf(b, "  CONI %s\r\n", a); }
    if (s->semi != 0) {
        ln_format(s->semi, a, sizeof a);
        ln_buf_printf(b, "  DIAM %s 1 0 0 1 \"\"\r\n", a);      /* 1: a fixed semi-diameter */
    }
}

char *ln_write_zmx(const ln_lens *lens)
{
    ln_buf b = {0};
    ln_surface s0, img;
    char a[40];
    /* OpticStudio wants a field and a wavelength: a lens without them is on axis at
     * the d line, which is what the model means by none (ln_primary) */
    ln_lens lv = *lens;
    const ln_lens *l = &lv;
    if (lv.nwl == 0) { lv.nwl = 1; lv.wl[0] = PX_LAMBDA_D; lv.wl_weight[0] = 1; }
    if (lv.nfield == 0) { lv.nfield = 1; lv.field[0].x = lv.field[0].y = 0; lv.field[0].weight = 1; }
    int nrow = l->nfield > 12 ? l->nfield : 12;
    static const char *const zu[] = {"mm", "MM", "cm", "CM", "m", "METER", "in", "IN"};
    const char *unit = "MM";
    for (size_t i = 0; i < sizeof zu / sizeof *zu; i += 2)
        if (!strcmp(l->unit, zu[i])) unit = zu[i + 1];
    {   /* the reader takes one pair of quotes off a title: a quoted title keeps its own;
         * a title read as Latin-1 bytes (a thickness prescription) is written in UTF-8 */
        size_t n = strlen(l->title), m;
        int q = n >= 2 && l->title[0] == '"' && l->title[n - 1] == '"';
        char *t = lm_utf8_fix(l->title, n, &m);
        ln_buf_printf(&b, "MODE SEQ\r\nNAME %s%s%s\r\nUNIT %s X W X CM MR CPMM\r\n",
                      q ? "\"" : "", t ? t : "", q ? "\"" : "", unit);
        free(t);
    }
    if (l->ncat) {
        ln_buf_printf(&b, "GCAT");
        for (int i = 0; i < l->ncat; i++) ln_buf_printf(&b, " %s", l->catalogs[i]);
        ln_buf_printf(&b, "\r\n");
    }
    if (l->ap_kind != LN_AP_NONE) {
        ln_format(l->ap_value, a, sizeof a);
        if (l->ap_kind == LN_AP_EPD) ln_buf_printf(&b, "ENPD %s\r\n", a);
        else ln_buf_printf(&b, "%s %s 0\r\n", l->ap_kind == LN_AP_FNUM ? "FNUM" : "OBNA", a);
    }
    ln_buf_printf(&b, "FTYP %d 0 %d %d 0 0 0\r\n", l->field_kind == LN_FIELD_HEIGHT,
                  l->nfield, l->nwl);
    for (int row = 0; row < 3; row++) {
        ln_buf_printf(&b, "%s", row == 0 ? "XFLN" : row == 1 ? "YFLN" : "FWGN");
        for (int i = 0; i < nrow; i++) {
            double v = i >= l->nfield ? (row == 2) : row == 0 ? l->field[i].x :
                       row == 1 ? l->field[i].y : l->field[i].weight;
            ln_format(v, a, sizeof a);
            ln_buf_printf(&b, " %s", a);
        }
        ln_buf_printf(&b, "\r\n");
    }
    for (int i = 0; i < l->nwl; i++) {
        char w[40];
        ln_format(l->wl[i], a, sizeof a);
        ln_format(l->wl_weight[i], w, sizeof w);
        ln_buf_printf(&b, "WAVM %d %s %s\r\n", i + 1, a, w);
    }
    ln_buf_printf(&b, "PWAV 1\r\n");
    memset(&s0, 0, sizeof s0);
    write_surface(&b, 0, &s0, 0, l->object, l->obj_glass, l->obj_nd, l->obj_vd);
    for (int i = 0; i < l->nsurf; i++) {
        const ln_surface *s = &l->surf[i];
        write_surface(&b, i + 1, s, l->stop == i, s->t, s->glass, s->nd, s->vd);
    }
    memset(&img, 0, sizeof img);
    img.c = l->image_c;
    img.semi = l->image_semi;
    write_surface(&b, l->nsurf + 1, &img, 0, 0, "", 0, 0);
    return ln_buf_done(&b);
}
