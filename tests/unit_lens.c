/* unit_lens.c -- the lens model (src/lens): thickness prescriptions and .zmx files
 * read, written and read again (every value kept), their error messages (FILE:LINE),
 * and real OpticStudio files of published designs (tests/zmx/, see SOURCE there)
 * against the first-order numbers published with them.  Run from the top of the
 * tree (tests/run.sh does). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "lens/lens.h"
#include "paraxial/paraxial.h"
#include "unit.h"

static char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    char *s;
    long n;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    rewind(f);
    s = malloc((size_t)n + 1);
    if (s && fread(s, 1, (size_t)n, f) != (size_t)n) { free(s); s = NULL; }
    fclose(f);
    if (s) { s[n] = '\0'; *len = (size_t)n; }
    return s;
}

/* Every value of two lenses equal (bit for bit, NaN-free). */
static int same_lens(const ln_lens *a, const ln_lens *b, char *why, size_t cap)
/* why: 400 bytes */
{
#define DIFF(cond, ...) do { if (cond) { snprintf(why, cap, __VA_ARGS__); return 0; } } while (0)
    DIFF(strcmp(a->title, b->title), "title '%.60s' / '%.60s'", a->title, b->title);
    DIFF(strcmp(a->unit, b->unit), "unit");
    DIFF(a->object != b->object, "object %.17g / %.17g", a->object, b->object);
    DIFF(strcmp(a->obj_glass, b->obj_glass), "object glass");
    DIFF(a->nsurf != b->nsurf, "nsurf %d / %d", a->nsurf, b->nsurf);
    DIFF(a->stop != b->stop, "stop %d / %d", a->stop, b->stop);
    DIFF(a->image_c != b->image_c || a->image_semi != b->image_semi, "image surface");
    DIFF(a->nwl != b->nwl, "nwl %d / %d", a->nwl, b->nwl);
    for (int i = 0; i < a->nwl; i++)
        DIFF(a->wl[i] != b->wl[i] || a->wl_weight[i] != b->wl_weight[i], "wavelength %d", i);
    DIFF(a->ap_kind != b->ap_kind || a->ap_value != b->ap_value, "aperture");
    DIFF(a->nfield != b->nfield || a->field_kind != b->field_kind, "fields");
    for (int i = 0; i < a->nfield; i++)
        DIFF(a->field[i].x != b->field[i].x || a->field[i].y != b->field[i].y ||
             a->field[i].weight != b->field[i].weight, "field %d", i);
    for (int i = 0; i < a->nsurf; i++) {
        const ln_surface *s = &a->surf[i], *t = &b->surf[i];
        DIFF(s->type != t->type, "surface %d type", i + 1);
        DIFF(s->c != t->c, "surface %d curvature %.17g / %.17g", i + 1, s->c, t->c);
        DIFF(s->t != t->t, "surface %d thickness %.17g / %.17g", i + 1, s->t, t->t);
        DIFF(strcmp(s->glass, t->glass), "surface %d glass %s / %s", i + 1, s->glass, t->glass);
        DIFF(s->nd != t->nd || s->vd != t->vd, "surface %d nd/vd", i + 1);
        DIFF(s->semi != t->semi, "surface %d semi", i + 1);
        DIFF(s->conic != t->conic, "surface %d conic", i + 1);
        DIFF(s->nasph != t->nasph, "surface %d nasph %d / %d", i + 1, s->nasph, t->nasph);
        for (int k = 0; k < s->nasph; k++)
            DIFF(s->asph[k] != t->asph[k], "surface %d a%d", i + 1, 2 * k + 2);
    }
    return 1;
#undef DIFF
}

static const char *TRIPLET =
    "# a thickness prescription with every key\n"
    "thickness\n"
    "title Cooke triplet # not a comment in a title\n"
    "unit mm\n"
    "wavelengths d F C\n"
    "wlweights 1 0.5 0.5\n"
    "index air\n"
    "epd 10\n"
    "field angle 0 14 0.5,20\n"
    "fieldweights 1 1 0.5\n"
    "21.48138 2 N-SK16 semi 6.5\n"
    "-124.1 5.26 air\n"
    "-19.1 1.25 F2 semi 5 stop\n"
    "22 4.69 1.6/40\n"        /* a model glass */
    "328.9 2.25 N-SK16 conic -1.5 a4 1e-5 a6 -2.5e-8\n"
    "-16.7 43 air\n"
    "image radius -500 semi 20\n"
    "object -1000\n";

static void rx_read(void)
{
    ln_lens l, m;
    ln_notes notes = {0};
    char err[LN_ERR_MAX], why[400], *text, *again;
    int rc = ln_read_rx(TRIPLET, strlen(TRIPLET), "t.rx", &l, &notes, err, sizeof err);
    CHECK(rc == LN_OK, "the triplet reads (%s)", rc ? err : "ok");
    if (rc) return;
    CHECK(ln_is_rx_thickness(TRIPLET, strlen(TRIPLET)), "it is recognised as a thickness prescription");
    CHECK(!strcmp(l.title, "Cooke triplet # not a comment in a title"), "title: '%s'", l.title);
    CHECK(l.nsurf == 6 && l.stop == 2, "6 surfaces, stop at surface 3");
    CHECK(l.nwl == 3 && l.wl[0] == PX_LAMBDA_D && l.wl[1] == PX_LAMBDA_F && l.wl_weight[2] == 0.5,
          "wavelengths d F C, primary first, weights");
    CHECK(l.ap_kind == LN_AP_EPD && l.ap_value == 10, "epd 10");
    CHECK(l.nfield == 3 && l.field[2].x == 0.5 && l.field[2].y == 20 && l.field[2].weight == 0.5,
          "fields: 0, 14 and (0.5, 20) degrees");
    CHECK(l.surf[0].r == 21.48138 && l.surf[0].c == 1 / 21.48138 && l.surf[0].t == 2 &&
          !strcmp(l.surf[0].glass, "N-SK16") && l.surf[0].semi == 6.5, "surface 1");
    CHECK(l.surf[1].glass[0] == '\0', "air is the empty glass");
    CHECK(l.surf[4].type == LN_EVENASPH && l.surf[4].nasph == 3 && l.surf[4].asph[0] == 0 &&
          l.surf[4].asph[1] == 1e-5 && l.surf[4].asph[2] == -2.5e-8 && l.surf[4].conic == -1.5,
          "surface 5: conic and even asphere a4, a6");
    CHECK(l.image_c == 1 / -500.0 && l.image_semi == 20, "image surface");
    CHECK(l.object == 1000 && l.nplanes == 1, "object 1000 left of surface 1");
    CHECK(notes.n == 0, "no notes");
    text = ln_write_rx(&l);
    CHECK(text != NULL, "written");
    rc = ln_read_rx(text, strlen(text), "w.rx", &m, NULL, err, sizeof err);
    CHECK(rc == LN_OK, "the written file reads (%s)", rc ? err : "ok");
    if (!rc) {
        CHECK(same_lens(&l, &m, why, sizeof why), "rx round trip keeps every value (%s)",
              same_lens(&l, &m, why, sizeof why) ? "same" : why);
        again = ln_write_rx(&m);
        CHECK(again && !strcmp(again, text), "written twice: the same bytes");
        free(again);
        ln_free(&m);
    }
    /* through .zmx and back */
    free(text);
    text = ln_write_zmx(&l);
    rc = text ? ln_read_zmx(text, strlen(text), "w.zmx", &m, &notes, err, sizeof err) : LN_NOMEM;
    CHECK(rc == LN_OK, "its .zmx reads (%s)", rc ? err : "ok");
    if (!rc) {
        ln_lens z;
        char *t2 = ln_write_zmx(&m);
        CHECK(t2 && !strcmp(t2, text), ".zmx written twice: the same bytes");
        CHECK(m.nsurf == 6 && m.stop == 2 && m.surf[4].asph[2] == -2.5e-8 &&
              !strcmp(m.surf[3].glass, "1.6/40") && m.nfield == 3 && m.nwl == 3 &&
              m.object == 1000, "the .zmx keeps surfaces, stop, asphere, model glass, fields");
        CHECK(m.surf[0].c == l.surf[0].c, "the .zmx keeps the curvature exactly");
        if (t2 && ln_read_zmx(t2, strlen(t2), "w2.zmx", &z, NULL, err, sizeof err) == LN_OK) {
            CHECK(same_lens(&m, &z, why, sizeof why), "zmx round trip keeps every value (%s)",
                  same_lens(&m, &z, why, sizeof why) ? "same" : why);
            ln_free(&z);
        } else CHECK(0, "the rewritten .zmx reads: %s", err);
        free(t2);
        ln_free(&m);
    }
    free(text);
    ln_free(&l);
    ln_notes_free(&notes);
}

/* A bad line gives FILE:LINE and the reason. */
static void rx_bad(const char *text, const char *want)
{
    ln_lens l;
    char err[LN_ERR_MAX];
    int rc = ln_read_rx(text, strlen(text), "bad.rx", &l, NULL, err, sizeof err);
    CHECK(rc == LN_BAD && strstr(err, want), "refused with '%s': %s", want, rc ? err : "(read)");
    if (!rc) ln_free(&l);
}

static void rx_errors(void)
{
    rx_bad("thickness\n10 2 N-BK7 semi\n", "bad.rx:2: 'semi' needs a value");
    rx_bad("thickness\n10 -2 N-BK7\n", "bad.rx:2: the thickness -2 is negative");
    rx_bad("thickness\n10 2 N-BK7@C\n", "bad.rx:2: 'N-BK7@C'");
    rx_bad("thickness\n10 2 NO-SUCH-GLASS\n-10 5 air\n", "bad.rx:2: surface 1: glass NO-SUCH-GLASS");
    rx_bad("thickness\n10 2 N-BK7 stop\n-10 5 air stop\n", "bad.rx:3: a second stop");
    rx_bad("thickness\nwavelengths d x\n", "bad.rx:2: 'x' is not a wavelength");
    rx_bad("thickness\n10 2 N-BK7 a3 1\n", "bad.rx:2: 'a3' is not a surface key");
    rx_bad("thickness\n10 2 N-BK7\nepd 4\n", "bad.rx:3: epd comes before the surfaces");
    rx_bad("thickness\nwavelengths 3000\n10 2 N-BK7\n", "N-BK7's formula holds");
    rx_bad("thickness\n", "bad.rx: no surface");
    rx_bad("thickness\nepd 4\nfnum 2\n", "bad.rx:3: one aperture only");
    rx_bad("epd 4\n", "bad.rx:1: 'epd' is a keyword of thickness prescriptions");
    rx_bad("thickness\n10 0x10 N-BK7\n", "bad.rx:2: the thickness: '0x10' is not a number");
}

/* A positions prescription read into the model: thicknesses from positions, an
 * index by name as the classic dialogue takes it (a number). */
static void rx_positions(void)
{
    const char *t = "nearpoint 30\nindex 1\n3 5 N-BK7@C\n-3 6.5 1\nobject 1\nobject -4\n";
    ln_lens l;
    char err[LN_ERR_MAX];
    double n;
    int rc = ln_read_rx(t, strlen(t), "p.rx", &l, NULL, err, sizeof err);
    CHECK(rc == LN_OK, "a positions prescription reads (%s)", rc ? err : "ok");
    if (rc) return;
    px_glass_index("N-BK7", PX_LAMBDA_C, &n);
    CHECK(l.nsurf == 2 && l.surf[0].t == 1.5 && l.nearpoint == 30, "positions -> thickness 1.5");
    CHECK(strtod(l.surf[0].glass, NULL) == n, "N-BK7@C -> its index %s", l.surf[0].glass);
    CHECK(l.nplanes == 2 && l.planes[0] == -4 && l.planes[1] == -9 && l.object == 4,
          "object planes relative to the first surface");
    ln_free(&l);
}

/* Thorlabs' .zmx files (tests/zmx/SOURCE) against Thorlabs' published focal lengths. */
static void thorlabs(const char *path, int utf16, double efl_pub, double bfl_pub,
                     const char *glass2)
{
    size_t len, n16;
    char *s = slurp(path, &len), *use = s, err[LN_ERR_MAX];
    ln_lens l;
    ln_notes notes = {0};
    px_system sys;
    px_first f;
    int rc;
    CHECK(s != NULL, "%s reads from disk", path);
    if (!s) return;
    if (utf16) {                       /* as OpticStudio writes: UTF-16LE with a mark */
        use = malloc(2 * len + 2);
        use[0] = (char)0xff; use[1] = (char)0xfe;
        for (size_t i = 0; i < len; i++) { use[2 + 2 * i] = s[i]; use[3 + 2 * i] = 0; }
        n16 = 2 * len + 2;
    } else n16 = len;
    CHECK(ln_is_zmx(use, n16), "%s%s is recognised as .zmx", path, utf16 ? " (UTF-16LE)" : "");
    rc = ln_read_zmx(use, n16, path, &l, &notes, err, sizeof err);
    CHECK(rc == LN_OK, "%s%s reads (%s)", path, utf16 ? " (UTF-16LE)" : "", rc ? err : "ok");
    if (!rc) {
        CHECK(l.nsurf == 3 && l.stop == 0 && !strcmp(l.surf[0].glass, "N-BK7") &&
              !strcmp(l.surf[1].glass, glass2) && l.surf[0].semi == 12.7 &&
              isinf(l.object), "3 surfaces, stop on the first, N-BK7 and %s, semi 12.7", glass2);
        CHECK(l.nwl == 3 && l.wl[0] == 0.5876 && l.wl[1] == 0.4861 && l.wl[2] == 0.6563,
              "wavelengths: the primary (PWAV 2) first, FTYP's 3 of the 24 WAVM lines");
        CHECK(l.ap_kind == LN_AP_EPD && l.ap_value == 22.86, "ENPD 22.86");
        CHECK(l.nfield == 1 && l.field[0].y == 0, "one field, on axis (FTYP's count)");
        CHECK(notes.n == 1 && strstr(notes.s, "not read") && strstr(notes.s, "COAT") &&
              strstr(notes.s, ": VERS NOTE PFIL"), "one note lists the keywords not read");
        rc = ln_paraxial(&l, l.wl[0], &sys, err, sizeof err);
        CHECK(rc == LN_OK && px_first_order(&sys, &f) == PX_OK, "first order at 587.6 nm");
        if (rc == LN_OK) {
            CHECK(fabs(f.efl.v - efl_pub) <= 0.05 + 1e-9, "EFL %.4f mm against Thorlabs' %.1f",
                  f.efl.v, efl_pub);
            /* BFL within one unit of the published digit: AC254-100-A's paraxial
             * 97.164 lies 0.064 from Thorlabs' 97.1 (nearer the file's own image
             * distance 97.068, a best focus); README "Prescription files" says so */
            CHECK(fabs(f.bfd.v - bfl_pub) <= 0.1 + 1e-9, "BFL %.4f mm against Thorlabs' %.1f "
                  "(difference %.3f)", f.bfd.v, bfl_pub, f.bfd.v - bfl_pub);
            CHECK(fabs(f.bfd.v - l.surf[2].t) < 0.2, "the file's image distance %.4f lies "
                  "near the paraxial focus %.4f", l.surf[2].t, f.bfd.v);
            px_system_free(&sys);
        }
        ln_free(&l);
    }
    ln_notes_free(&notes);
    if (use != s) free(use);
    free(s);
}

static void zmx_bad(const char *text, const char *want)
{
    ln_lens l;
    ln_notes notes = {0};
    char err[LN_ERR_MAX];
    int rc = ln_read_zmx(text, strlen(text), "bad.zmx", &l, &notes, err, sizeof err);
    CHECK(rc == LN_BAD && strstr(err, want), "refused with '%s': %s", want, rc ? err : "(read)");
    if (!rc) ln_free(&l);
    ln_notes_free(&notes);
}

static void zmx_notes(void)
{
    const char *t = "VERS 1\nMODE SEQ\nUNIT MM\nFTYP 2 0 1 1 0 0 0\nWAVL 0.55\n"
                    "SURF 0\n  DISZ 100\nSURF 1\n  TYPE TOROIDAL\n  CURV 0.02\n  DISZ 5\n"
                    "  GLAS LM-NOGLASS1 0 0 1.78472 25.68 0 0\nSURF 2\n  TYPE EVENASPH\n  CURV -0.01\n"
                    "  PARM 2 1e-6\n  PARM 9 1\n  DISZ 40\nSURF 3\n";
    ln_lens l;
    ln_notes notes = {0};
    char err[LN_ERR_MAX];
    int rc = ln_read_zmx(t, strlen(t), "n.zmx", &l, &notes, err, sizeof err);
    CHECK(rc == LN_OK, "a file with unsupported parts reads (%s)", rc ? err : "ok");
    if (!rc) {
        CHECK(notes.s && strstr(notes.s, "n.zmx:9: surface 1: type TOROIDAL is not supported"),
              "the toroid is noted with its line");
        CHECK(notes.s && strstr(notes.s, "n.zmx:12: glass LM-NOGLASS1 is not in lensmat's catalogue"),
              "the unknown glass is noted with its line");
        CHECK(notes.s && strstr(notes.s, "n.zmx:4: FTYP 2"), "image-height fields are noted");
        CHECK(notes.s && strstr(notes.s, "n.zmx:17: surface 2: PARM 9"), "PARM 9 is noted");
        CHECK(l.surf[0].nd == 1.78472 && l.surf[1].asph[1] == 1e-6 && l.surf[1].nasph == 2 &&
              l.object == 100 && l.nwl == 1 && l.wl[0] == 0.55, "values read around them");
        ln_free(&l);
    }
    ln_notes_free(&notes);
    zmx_bad("MODE SEQ\nSURF 0\nSURF 1\n  GLAS N-BK7\nSURF 2\n  GLAS MIRROR 0 0\nSURF 3\n",
            "bad.zmx:5: a mirror in N-BK7 (a Mangin mirror) is not supported");
    zmx_bad("MODE SEQ\nSURF 0\nSURF 1\n  DISZ -3\nSURF 2\n", "bad.zmx:4: DISZ -3");
    zmx_bad("MODE NSC\n", "bad.zmx:1: MODE NSC");
    zmx_bad("MODE SEQ\nSURF 0\nSURF 2\n", "bad.zmx:3: SURF 2");
    zmx_bad("MODE SEQ\nSURF 0\nSURF 1\n  CURV x\nSURF 2\n", "bad.zmx:4: CURV: 'x'");
    zmx_bad("MODE SEQ\nSURF 0\nSURF 1\n  GLAS NOPE 0 0 0 0\nSURF 2\n", "bad.zmx:4: glass NOPE");
    zmx_bad("MODE SEQ\nSURF 0\nSURF 1\n", "bad.zmx: 2 surfaces");
}

/* Reiley's OpticStudio file of US patent 5,831,776 example 1 (MIT licence, tests/zmx/
 * SOURCE): a 248 nm lithography lens, 42 fused-silica and air surfaces, finite object,
 * CRLF lines.  The file's own numbers: object field semi-height 47.99 (DIAM of the
 * object surface) imaged to 12.01 (the image surface's), a 4x reduction; the
 * designer's image distance 13.0765 (last DISZ), at NA 0.15 on the object side. */
static void lithography(void)
{
    size_t len;
    char *s = slurp("tests/zmx/US05831776-1.zmx", &len), err[LN_ERR_MAX];
    ln_lens l;
    ln_notes notes = {0};
    px_system sys;
    px_conj cj;
    int rc;
    CHECK(s != NULL, "US05831776-1.zmx reads from disk");
    if (!s) return;
    rc = ln_read_zmx(s, len, "US05831776-1.zmx", &l, &notes, err, sizeof err);
    CHECK(rc == LN_OK, "US05831776-1.zmx reads (%s)", rc ? err : "ok");
    if (!rc) {
        CHECK(l.nsurf == 42 && l.stop == 19 && l.nwl == 1 && l.wl[0] == 0.248 &&
              l.ap_kind == LN_AP_NA && l.ap_value == 0.15 && l.object == 110.8588354359,
              "42 surfaces, stop on surface 20, 248 nm, NA 0.15, object 110.86 left");
        CHECK(!strcmp(l.surf[0].glass, "F_SILICA") && notes.s &&
              strstr(notes.s, "US05831776-1.zmx:97: glass SILICA (OpticStudio's MISC"),
              "OpticStudio's SILICA is read as F_SILICA, noted once with its line");
        CHECK(notes.s && strstr(notes.s, "US05831776-1.zmx:38: FTYP 3"),
              "its real-image-height fields are noted as skipped");
        CHECK(l.nfield == 0, "so it has no field");
        rc = ln_paraxial(&l, l.wl[0], &sys, err, sizeof err);
        CHECK(rc == LN_OK, "paraxial system at 248 nm (%s)", rc ? err : "ok");
        if (!rc) {
            double m_file = -1.201117255762e1 / 4.799458807792e1;
            rc = px_conjugate(&sys, -l.object, &cj);
            CHECK(rc == PX_OK, "the object plane has an image");
            CHECK(fabs(cj.lateral.v - m_file) < 2e-3, "paraxial magnification %.5f against "
                  "the file's field heights 12.011/47.995 = %.5f", cj.lateral.v, m_file);
            CHECK(fabs(cj.d2.v - l.surf[41].t) < 0.05, "paraxial image %.4f past the last "
                  "surface against the designer's 13.0765", cj.d2.v);
            px_system_free(&sys);
        }
        ln_free(&l);
    }
    ln_notes_free(&notes);
    free(s);
}

/* The bridge to the paraxial engine and the sag: px_csurf surfaces give the same
 * first order as ln_paraxial; an asphere's r^2 term is part of the paraxial power;
 * sags of a sphere, a paraboloid and an even asphere against their formulas. */
static void bridge(void)
{
    const char *t = "thickness\nwavelengths d F C\n50 5 N-BK7 stop\n-50 40 1.6/40 a2 0.001\n"
                    "plane 1 air\n";
    ln_lens l;
    char err[LN_ERR_MAX], names[8][LN_NAME_MAX];
    px_csurf cs[8];
    const char *obj;
    px_colour col;
    px_system sys;
    px_first f;
    ln_surface s;
    int rc = ln_read_rx(t, strlen(t), "b.rx", &l, NULL, err, sizeof err);
    CHECK(rc == LN_OK, "the bridge lens reads (%s)", rc ? err : "ok");
    if (rc) return;
    CHECK(ln_paraxial_curvature(&l.surf[1]) == -0.02 + 0.002, "a2 adds 2 a2 to the curvature");
    CHECK(ln_to_csurf(&l, cs, names, &obj, err, sizeof err) == LN_OK && !strcmp(obj, "AIR") &&
          cs[1].r == 1 / (-0.02 + 0.002) && !strcmp(cs[1].glass, "1.6/40") && cs[0].t == 5,
          "px_csurf: paraxial radius, thickness, glass names, AIR for air");
    CHECK(px_colour_fdc(cs, l.nsurf, obj, &col) == PX_OK, "px_colour_fdc runs on them");
    rc = ln_paraxial(&l, PX_LAMBDA_F, &sys, err, sizeof err);
    CHECK(rc == LN_OK && px_first_order(&sys, &f) == PX_OK &&
          fabs(f.efl.v - col.first[0].efl.v) <= 1e-12 * fabs(f.efl.v),
          "ln_paraxial at F gives px_colour's efl at F (%.12g)", f.efl.v);
    if (rc == LN_OK) px_system_free(&sys);
    ln_free(&l);
    memset(&s, 0, sizeof s);
    ln_set_radius(&s, 50);
    CHECK(fabs(ln_sag(&s, 10) - (50 - sqrt(2400.0))) < 1e-12, "sphere sag R - sqrt(R^2 - h^2)");
    s.conic = -1;
    CHECK(fabs(ln_sag(&s, 10) - 1.0) < 1e-12, "paraboloid sag c h^2 / 2");
    s.type = LN_EVENASPH;
    s.nasph = 2;
    s.asph[1] = 1e-5;
    CHECK(fabs(ln_sag(&s, 10) - 1.1) < 1e-12, "even asphere: + a4 h^4");
    s.type = LN_STANDARD;
    s.conic = 5;
    CHECK(isnan(ln_sag(&s, 21)) && !isnan(ln_sag(&s, 20)), "no real point past an oblate conic's edge: NaN");
}

int main(void)
{
    rx_read();
    rx_errors();
    rx_positions();
    /* Thorlabs' published values (product page, as tabulated in DCC-Lab/RayTracing's
     * raytracing/thorlabs.py): AC254-100-A f 100.1, BFL 97.1; AC254-125-A 125.0, 122.0 */
    thorlabs("tests/zmx/AC254-100-A.zmx", 0, 100.1, 97.1, "SF5");
    thorlabs("tests/zmx/AC254-100-A.zmx", 1, 100.1, 97.1, "SF5");
    thorlabs("tests/zmx/AC254-125-A.zmx", 0, 125.0, 122.0, "N-SF5");
    zmx_notes();
    lithography();
    bridge();
    return unit_failed();
}
