/* unit_agf.c -- the AGF glass catalogue reader and the catalogues a process finds
 * (src/paraxial/agf.c, glass_cat.c), the lens readers' glass look-up (former names,
 * several catalogues, .zmx placeholders) and the unfolded mirrors (src/lens).
 *
 * What the numbers are checked against:
 *  - tests/agf/TEST*.agf, catalogues written for this test with coefficients typed
 *    from the makers' published catalogues (each file's CC lines name its source): the
 *    formula must give the nd and Vd those catalogues print, to their printed digits;
 *  - for the AGF formulas no test catalogue uses, identities between formulas (a
 *    Sellmeier 3 with its 4th term zero is a Sellmeier 1, an Extended with c6 = c7 = 0
 *    is a Schott, ...) and values worked by hand here, so a coefficient taken from the
 *    wrong place fails;
 *  - mirrors: a concave mirror's focal length is R/2, a flat fold changes nothing. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "unit.h"
#include "paraxial/paraxial.h"
#include "lens/lens.h"

static char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    char *b;
    if (!f) return NULL;
    b = malloc(1 << 20);
    *n = b ? fread(b, 1, 1 << 20, f) : 0;
    fclose(f);
    return b;
}

/* nd computed from a record against the printed value, to half a unit of its last
 * printed digit (plus 1e-9 for the decimal rounding of the printed coefficients). */
static int printed_ok(double v, const char *printed)
{
    const char *dot = strchr(printed, '.');
    int dec = dot ? (int)strlen(dot + 1) : 0;
    return fabs(v - atof(printed)) <= 0.5 * pow(10, -dec) + 1e-9;
}

static void test_catalogues_from_files(void)   /* before the chdir to / */
{
    static const char *const files[] = {"tests/agf/TESTSCHOTT.agf", "tests/agf/TESTOHARA.agf",
                                        "tests/agf/TESTHIKARI.agf"};
    static const char *const names[] = {"TESTSCHOTT", "TESTOHARA", "TESTHIKARI"};
    for (int f = 0; f < 3; f++) {
        size_t n = 0;
        char *t = slurp(files[f], &n), err[1024];
        px_glass_cat c;
        int rc;
        CHECK(t != NULL, "%s is there", files[f]);
        if (!t) continue;
        rc = px_agf_read(t, n, names[f], files[f], &c, err, sizeof err);
        free(t);
        CHECK(rc == PX_OK, "%s reads (%s)", files[f], rc ? err : "ok");
        if (rc) continue;
        CHECK(!strcmp(c.name, names[f]), "its catalogue name is %s", c.name);
        for (int i = 0; i < c.n; i++) {
            const px_glass_rec *g = &c.rec[i];
            double nd = px_glass_formula(g, PX_LAMBDA_D), nf = px_glass_formula(g, PX_LAMBDA_F),
                   nc = px_glass_formula(g, PX_LAMBDA_C), vd = (nd - 1) / (nf - nc);
            CHECK(printed_ok(nd, g->nd), "%s %s (formula %d): nd %.7f against the printed %s",
                  names[f], g->name, g->model - PX_GLASS_AGF, nd, g->nd);
            CHECK(fabs(vd - atof(g->vd)) <= 0.5 * pow(10, -(int)strlen(strchr(g->vd, '.') + 1)) + 0.01,
                  "%s %s: Vd %.4f against the printed %s", names[f], g->name, vd, g->vd);
            CHECK(g->lmin > 0 && g->lmax > g->lmin, "%s %s: validity range %g-%g um (LD)",
                  names[f], g->name, g->lmin, g->lmax);
        }
        if (f == 0) {        /* N-BK7's IT table: the data sheet's 25 points at 25 mm */
            const px_tau_rec *tau = NULL;
            for (int i = 0; i < c.ntau; i++) if (!strcmp(c.tau[i].name, "N-BK7")) tau = &c.tau[i];
            CHECK(tau && tau->n == 25 && tau->thickness == 25 && tau->l[0] == 0.3 &&
                  tau->t[0] == 0.05 && tau->l[24] == 2.5 && tau->t[24] == 0.36,
                  "TESTSCHOTT N-BK7: 25 IT points at 25 mm, 0.300 um 0.050 to 2.500 um 0.360");
            CHECK(!strcmp(c.rec[0].status, "standard"), "status 0 is standard");
        }
        if (f == 1)
            CHECK(!strcmp(c.rec[0].status, "preferred"), "OHARA S-BAL14: status 1 is preferred");
        px_agf_free(&c);
    }
}

/* One glass of formula f with coefficients c, read from an AGF text built here. */
static int one(int f, const double *c, int nc, px_glass_rec *out, px_glass_cat *cat)
{
    char text[2048], err[512];
    int k = snprintf(text, sizeof text, "NM G %d 0 1.5 50 0 0 0\nCD", f);
    for (int i = 0; i < nc; i++) k += snprintf(text + k, sizeof text - (size_t)k, " %.17g", c[i]);
    snprintf(text + k, sizeof text - (size_t)k, "\nLD 0.3 2.5\n");
    if (px_agf_read(text, strlen(text), "T", "t.agf", cat, err, sizeof err) != PX_OK) {
        printf("FAIL %s\n", err);
        return 1;
    }
    *out = cat->rec[0];
    return 0;
}

static double at(int f, const double *c, int nc, double l)
{
    px_glass_rec g;
    px_glass_cat cat;
    double n;
    if (one(f, c, nc, &g, &cat)) return NAN;
    n = px_glass_formula(&g, l);
    px_agf_free(&cat);
    return n;
}

static void test_formulas(void)
{
    /* N-BK7's Sellmeier as formula 2 (SCHOTT's data sheet) */
    const double s1[6] = {1.03961212, 0.00600069867, 0.231792344, 0.0200179144, 1.01046945,
                          103.560653};
    double ref[5], ls[5] = {0.4, 0.48613270, 0.58756180, 0.65627250, 1.0};
    int ok;
    for (int i = 0; i < 5; i++) ref[i] = at(2, s1, 6, ls[i]);
    CHECK(fabs(ref[2] - 1.5168) < 5e-6, "formula 2 (Sellmeier 1): N-BK7 nd %.7f (SCHOTT 1.51680)",
          ref[2]);
    {   /* Sellmeier 3 and 5: the same three terms and zeros */
        double s3[8] = {0}, s5[10] = {0};
        memcpy(s3, s1, sizeof s1);
        memcpy(s5, s1, sizeof s1);
        ok = 1;
        for (int i = 0; i < 5; i++)
            ok &= fabs(at(6, s3, 8, ls[i]) - ref[i]) < 1e-14 && fabs(at(11, s5, 10, ls[i]) - ref[i]) < 1e-14;
        CHECK(ok, "formulas 6, 11 (Sellmeier 3, 5) with the extra terms zero are formula 2");
        s3[6] = 0.1; s3[7] = 0.05;                 /* a 4th term that must count */
        CHECK(fabs(at(6, s3, 8, 0.5) - sqrt(ref[0] * 0 + 1 + 1.03961212 * 0.25 / (0.25 - 0.00600069867) +
              0.231792344 * 0.25 / (0.25 - 0.0200179144) + 1.01046945 * 0.25 / (0.25 - 103.560653) +
              0.1 * 0.25 / (0.25 - 0.05))) < 1e-14, "formula 6's 4th term counts (c6 l^2/(l^2 - c7))");
    }
    {   /* Sellmeier 2: n^2 - 1 = A + B1 l^2/(l^2 - l1^2) + B2 l^2/(l^2 - l2^2), the
         * resonances as wavelengths: N-BK7's first two terms with A = its 3rd term's
         * value... at one wavelength; here: A 0 and the two short-wave terms */
        double s2[5] = {0, s1[0], sqrt(s1[1]), s1[2], sqrt(s1[3])};
        double two[6] = {s1[0], s1[1], s1[2], s1[3], 0, 100};
        ok = 1;
        for (int i = 0; i < 5; i++) ok &= fabs(at(4, s2, 5, ls[i]) - at(2, two, 6, ls[i])) < 1e-13;
        CHECK(ok, "formula 4 (Sellmeier 2) with l_i = sqrt(C_i) is formula 2's two terms");
        s2[0] = 0.25;
        CHECK(fabs(at(4, s2, 5, 0.5) * at(4, s2, 5, 0.5) - at(2, two, 6, 0.5) * at(2, two, 6, 0.5) - 0.25) < 1e-13,
              "formula 4's A adds to n^2");
    }
    {   /* Sellmeier 4: n^2 = A + B l^2/(l^2 - C) + D l^2/(l^2 - E): A = 1 and two terms */
        double s4[5] = {1, s1[0], s1[1], s1[2], s1[3]};
        double two[6] = {s1[0], s1[1], s1[2], s1[3], 0, 100};
        ok = 1;
        for (int i = 0; i < 5; i++) ok &= fabs(at(9, s4, 5, ls[i]) - at(2, two, 6, ls[i])) < 1e-14;
        CHECK(ok, "formula 9 (Sellmeier 4) with A = 1 is formula 2's two terms");
    }
    {   /* Handbook of Optics 2: n^2 = A + B l^2/(l^2 - C) - D l^2; 1 term, D = 0 */
        double h2[4] = {1, s1[0], s1[1], 0}, one_t[6] = {s1[0], s1[1], 0, 0, 0, 1};
        CHECK(fabs(at(8, h2, 4, 0.5) - at(2, one_t, 6, 0.5)) < 1e-14,
              "formula 8 (Handbook 2) with D = 0 is a one-term Sellmeier");
        h2[3] = 0.01;
        CHECK(fabs(at(8, h2, 4, 0.5) * at(8, h2, 4, 0.5) - (1 + s1[0] * 0.25 / (0.25 - s1[1]) - 0.0025)) < 1e-14,
              "formula 8's D l^2 is subtracted");
        /* Handbook of Optics 1: n^2 = A + B/(l^2 - C) - D l^2, by hand at l = 0.5:
         * 2.2 + 0.01/(0.25 - 0.05) - 0.02 * 0.25 = 2.2 + 0.05 - 0.005 = 2.245 */
        double h1[4] = {2.2, 0.01, 0.05, 0.02};
        CHECK(fabs(at(7, h1, 4, 0.5) - sqrt(2.245)) < 1e-14, "formula 7 (Handbook 1) by hand: "
              "n^2 = 2.245 at 0.5 um");
    }
    {   /* Schott, Extended, Extended 2, Extended 3: OHARA BSM16's Schott coefficients */
        double sc[6] = {2.585926, -0.0114351, 0.01387296, 0.0005169618, -3.768293e-05, 2.058449e-06};
        double e1[8] = {0}, e2[8] = {0}, e3[9] = {0};
        memcpy(e1, sc, sizeof sc);
        memcpy(e2, sc, sizeof sc);
        e3[0] = sc[0]; e3[1] = sc[1]; e3[3] = sc[2]; e3[4] = sc[3]; e3[5] = sc[4]; e3[6] = sc[5];
        ok = 1;
        for (int i = 0; i < 5; i++) {
            double s = at(1, sc, 6, ls[i]);
            ok &= fabs(at(10, e1, 8, ls[i]) - s) < 1e-14 && fabs(at(12, e2, 8, ls[i]) - s) < 1e-14 &&
                  fabs(at(13, e3, 9, ls[i]) - s) < 1e-14;
        }
        CHECK(ok, "formulas 10, 12, 13 (Extended 1-3) with their extra terms zero are formula 1 "
              "(Extended 3's c2 l^4 shifts the negative powers to c3..)");
        CHECK(fabs(at(1, sc, 6, PX_LAMBDA_D) - 1.620410) < 5e-7, "formula 1 (Schott): OHARA BSM16 "
              "nd %.7f (OHARA 1.620410)", at(1, sc, 6, PX_LAMBDA_D));
        /* the extra terms, each by hand at l = 2 (l^2 = 4): */
        double z8[8] = {1}, z9[9] = {1};
        z8[6] = 0.01; z8[7] = 0.001;               /* Extended: c6 l^-10 + c7 l^-12 */
        CHECK(fabs(at(10, z8, 8, 2) - sqrt(1 + 0.01 / 1024 + 0.001 / 4096)) < 1e-15,
              "formula 10's c6, c7 are l^-10, l^-12");
        CHECK(fabs(at(12, z8, 8, 2) - sqrt(1 + 0.01 * 16 + 0.001 * 64)) < 1e-15,
              "formula 12's c6, c7 are l^4, l^6");
        z9[2] = 0.01; z9[7] = 0.1; z9[8] = 0.2;    /* Extended 3: c2 l^4, c7 l^-10, c8 l^-12 */
        CHECK(fabs(at(13, z9, 9, 2) - sqrt(1 + 0.16 + 0.1 / 1024 + 0.2 / 4096)) < 1e-15,
              "formula 13's c2 is l^4, c7, c8 are l^-10, l^-12");
    }
    {   /* Herzberger by hand at l = 0.5: L = 1/(0.25 - 0.028) = 1/0.222;
         * n = 1.5 + 0.01 L + 0.001 L^2 + 0.002 l^2 + 0.003 l^4 + 0.004 l^6 */
        double hz[6] = {1.5, 0.01, 0.001, 0.002, 0.003, 0.004}, L = 1 / 0.222;
        double want = 1.5 + 0.01 * L + 0.001 * L * L + 0.002 * 0.25 + 0.003 * 0.0625 + 0.004 * 0.015625;
        CHECK(fabs(at(3, hz, 6, 0.5) - want) < 1e-14, "formula 3 (Herzberger) by hand: %.12f", want);
        /* Conrady: n = n0 + A/l + B/l^3.5, at l = 0.25 (l^3.5 = 1/128) */
        double co[3] = {1.5, 0.01, 0.0001};
        CHECK(fabs(at(5, co, 3, 0.25) - (1.5 + 0.04 + 0.0128)) < 1e-14, "formula 5 (Conrady) by hand: 1.5528 at 0.25 um");
    }
}

static void test_bad_files(void)
{
    px_glass_cat c;
    char err[512];
    const char *t1 = "NM X 14 0 1.5 50 0 0 0\nCD 1 2 3\n";
    const char *t2 = "CC nothing\nCD 1 2 3\n";
    const char *t3 = "NM X 2 0 1.5 50 0 0 0\nCD 1 zwei 3\n";
    const char *t4 = "just some text\n";
    CHECK(px_agf_read(t1, strlen(t1), "B", "b.agf", &c, err, sizeof err) == PX_BAD &&
          strstr(err, "b.agf:1: NM X: formula 14 is not one of the AGF formulas 1-13"),
          "formula 14 refused with FILE:LINE (%s)", err);
    CHECK(px_agf_read(t2, strlen(t2), "B", "b.agf", &c, err, sizeof err) == PX_BAD &&
          strstr(err, "b.agf:2: CD before the first NM line"), "CD before NM refused (%s)", err);
    CHECK(px_agf_read(t3, strlen(t3), "B", "b.agf", &c, err, sizeof err) == PX_BAD &&
          strstr(err, "b.agf:2: X: CD coefficient 2 'zwei' is not a number"),
          "a coefficient that is not a number refused (%s)", err);
    CHECK(px_agf_read(t4, strlen(t4), "B", "b.agf", &c, err, sizeof err) == PX_BAD &&
          strstr(err, "b.agf: no NM line: not an AGF glass catalogue"),
          "a text that is not AGF refused (%s)", err);
    {   /* as redistributed files come: a text line above the catalogue, a CD line
         * wrapped onto lines of bare numbers, a name lensmat cannot hold (a liquid
         * "X-1,6") -- the file reads, each said.  W is NIKON's J-FK5 (formula 13, nd
         * 1.487490) as its CD lines wrap in nikon.agf distributed at
         * github.com/nzhagen/zemaxglass (AGF_files/, "Updated 12/2018") */
        const char *t = "Reproduced from the maker's site\nNM BAD-1,6 2 0 1.5 50 0 0 0\n"
                        "CD 1 0.01 0 0 0 1\nNM W 13 0 1.5 50 0 0 0\nCD 2.188268550E+000 "
                        "-9.190447240E-003 -1.116210710E-004 9.263728150E-003\n"
                        "7.349007330E-005 4.197242420E-006 -1.154122030E-007 0.0\n0.0\nLD 0.3 2.5\n";
        int rc = px_agf_read(t, strlen(t), "B", "b.agf", &c, err, sizeof err);
        CHECK(rc == PX_OK && c.n == 1 && !strcmp(c.rec[0].name, "W") &&
              c.rec[0].coef[4] == 7.349007330E-005 && c.rec[0].coef[6] == -1.154122030E-007 &&
              fabs(px_glass_formula(&c.rec[0], PX_LAMBDA_D) - 1.487490) < 5e-7 && c.notes &&
              strstr(c.notes, "b.agf:1: 'Reproduced...' before the first NM line is not an AGF "
                     "line: skipped") && strstr(c.notes, "b.agf:2: NM BAD-1,6: a glass name with"),
              "a header line and an unusable name are skipped and said; a wrapped CD line goes "
              "on (Nikon J-FK5's coefficients give its nd 1.487490: %.7f)",
              rc == PX_OK && c.n ? px_glass_formula(&c.rec[0], PX_LAMBDA_D) : 0.0);
        if (rc == PX_OK) px_agf_free(&c);
    }
    {   /* IT lines out of order or out of range are noted, not fatal */
        const char *t = "NM X 2 0 1.5 50 0 0 0\nCD 1 0.01 0 0 0 1\nLD 0.3 2.5\nIT 0.5 0.9 10\n"
                        "IT 0.4 0.8 10\nIT 0.6 1.5 10\nIT 0.7 0.95 5\n";
        int rc = px_agf_read(t, strlen(t), "B", "b.agf", &c, err, sizeof err);
        CHECK(rc == PX_OK && c.ntau == 1 && c.tau[0].n == 1 && c.notes &&
              strstr(c.notes, "b.agf:5: X: IT wavelengths must ascend") &&
              strstr(c.notes, "b.agf:6: X: IT 0.6 1.5 10 is outside") &&
              strstr(c.notes, "b.agf:7: X: IT at 5 mm after points at 10 mm"),
              "bad IT lines are noted with their lines and skipped");
        if (rc == PX_OK) px_agf_free(&c);
    }
}

/* The catalogues found through $LENSMAT_GLASS_PATH (set before the first use). */
static void test_registry(void)
{
    const px_glass_rec *all[8];
    double n;
    int k;
    CHECK(px_glass_cat_count() == 3, "3 catalogues from $LENSMAT_GLASS_PATH=tests/agf (%d)",
          px_glass_cat_count());
    CHECK(px_glass_cat_find("testohara") && px_glass_cat_find("TESTOHARA")->n == 3,
          "TESTOHARA by name, any case, 3 glasses");
    CHECK(px_glass_total() == px_glass_count() + 3 + 3 + 1, "glass_count: built-in %d + 7 AGF = %d",
          px_glass_count(), px_glass_total());
    CHECK(px_glass_index("S-BAL14", PX_LAMBDA_D, &n) == PX_OK && fabs(n - 1.568832) < 5e-7,
          "an AGF-only glass by name: S-BAL14 nd %.7f", n);
    CHECK(px_glass_index("TESTHIKARI:E-BAK4", PX_LAMBDA_D, &n) == PX_OK && fabs(n - 1.568832) < 5e-7,
          "CATALOG:NAME: TESTHIKARI:E-BAK4 nd %.7f (from the UTF-16 file)", n);
    CHECK(px_glass_index("TESTOHARA:E-BAK4", PX_LAMBDA_D, &n) == PX_NO_GLASS,
          "CATALOG:NAME looks in that catalogue only");
    CHECK(px_glass_index("BSM16", 1.0, &n) == PX_GLASS_RANGE, "BSM16 beyond its LD 0.36-0.9 um refused");
    k = px_glass_find_all("N-BAK1", all, 8);
    CHECK(k == 2 && !strcmp(all[0]->catalog, "LENSMAT") && !strcmp(all[1]->catalog, "TESTSCHOTT"),
          "N-BAK1 is in 2 catalogues: LENSMAT first, then TESTSCHOTT");
    {
        double a, b;
        CHECK(px_glass_absorption("TESTSCHOTT:N-BK7", 0.4, &a) == PX_OK &&
              px_glass_absorption("N-BK7", 0.4, &b) == PX_OK && fabs(a - b) < 1e-15 &&
              fabs(a + log(0.992) / 25) < 1e-15,
              "TESTSCHOTT:N-BK7's IT table gives the built-in table's absorption at 400 nm");
    }
}

static int read_zmx(const char *t, ln_lens *l, ln_notes *notes, char *err)
{
    return ln_read_zmx(t, strlen(t), "g.zmx", l, notes, err, LN_ERR_MAX);
}

static void test_lens_lookup(void)
{
    ln_lens l;
    ln_notes notes = {0};
    char err[LN_ERR_MAX];
    const char *base = "VERS 1\nMODE SEQ\nUNIT MM\nGCAT %s\nSURF 0\n  DISZ INFINITY\nSURF 1\n"
                       "  CURV 0.02\n  DISZ 5\n  GLAS %s\nSURF 2\n  DISZ 40\nSURF 3\n";
    char t[1024];
    snprintf(t, sizeof t, base, "TESTSCHOTT OHARA", "N-BAK1 0 0 1.5725 57.55 0 0");
    CHECK(read_zmx(t, &l, &notes, err) == LN_OK && !strcmp(l.surf[0].glass, "TESTSCHOTT:N-BAK1") &&
          notes.s && strstr(notes.s, "g.zmx:10: glass N-BAK1 is in 2 catalogues (LENSMAT, "
                            "TESTSCHOTT): TESTSCHOTT's is taken (the first selected"),
          "GCAT TESTSCHOTT: its N-BAK1 is taken, and said");
    ln_free(&l);
    ln_notes_free(&notes);
    snprintf(t, sizeof t, base, "SCHOTT", "N-BAK1 0 0 1.5725 57.55 0 0");
    CHECK(read_zmx(t, &l, &notes, err) == LN_OK && !strcmp(l.surf[0].glass, "N-BAK1") &&
          notes.s && strstr(notes.s, "LENSMAT's is taken (the built-in catalogue first"),
          "GCAT SCHOTT (not here): the built-in N-BAK1, said");
    ln_free(&l);
    ln_notes_free(&notes);
    snprintf(t, sizeof t, base, "SCHOTT", "BAK1 0 0 1.5725 57.55 0 0");
    CHECK(read_zmx(t, &l, &notes, err) == LN_OK && !strcmp(l.surf[0].glass, "N-BAK1") &&
          notes.s && strstr(notes.s, "g.zmx:10: glass BAK1 is a former name: read as N-BAK1"),
          "BAK1 is read as N-BAK1, said");
    ln_free(&l);
    ln_notes_free(&notes);
    snprintf(t, sizeof t, base, "SCHOTT", "CROWN 0 0 1.5168 64.17 0 0");
    CHECK(read_zmx(t, &l, &notes, err) == LN_OK && notes.s &&
          strstr(notes.s, "g.zmx:10: glass CROWN is not in the glass catalogues: taken as the "
                 "medium CROWN, a constant index 1.5168 at every wavelength"),
          "a medium's name is a constant index, said");
    ln_free(&l);
    ln_notes_free(&notes);
    snprintf(t, sizeof t, base, "SCHOTT", "N-BAK1 0 0 1.6 57.55 0 0");
    CHECK(read_zmx(t, &l, &notes, err) == LN_OK && notes.s &&
          strstr(notes.s, "g.zmx:10: glass N-BAK1: the file gives nd 1.6, the catalogue's "
                 "N-BAK1 has 1.572500: the catalogue's is used"),
          "a file's nd far from the catalogue's is said");
    ln_free(&l);
    ln_notes_free(&notes);
    snprintf(t, sizeof t, base, "SCHOTT", "S-BAL14 0 0 1.5 4.0E+1 0 0");
    CHECK(read_zmx(t, &l, &notes, err) == LN_OK && !strcmp(l.surf[0].glass, "TESTOHARA:S-BAL14") &&
          notes.s && strstr(notes.s, "OpticStudio's placeholder"),
          "S-BAL14 with the placeholder 1.5/40: TESTOHARA's glass, said");
    ln_free(&l);
    ln_notes_free(&notes);
}

static void test_mirrors(void)
{
    ln_lens l;
    ln_notes notes = {0};
    char err[LN_ERR_MAX];
    px_system s;
    px_first f;
    const char *cm = "VERS 1\nMODE SEQ\nUNIT MM\nSURF 0\n  DISZ INFINITY\nSURF 1\n  CURV -0.005\n"
                     "  DISZ -100\n  GLAS MIRROR\nSURF 2\n";
    /* Cassegrain (closed form): primary R1 = -400 (f1 200), secondary R2 = -200 (convex
     * toward the returning light, f2 -100 as a reflector), d = 150 apart: the system
     * focal length f1 f2 / (f1 + f2 - d) = 200 (-100) / (200 - 100 - 150) = 400 */
    const char *cass = "VERS 1\nMODE SEQ\nUNIT MM\nSURF 0\n  DISZ INFINITY\nSURF 1\n  CURV -0.0025\n"
                       "  DISZ -150\n  GLAS MIRROR\nSURF 2\n  CURV -0.005\n  DISZ 250\n  GLAS MIRROR\nSURF 3\n";
    int rc = read_zmx(cm, &l, &notes, err);
    CHECK(rc == LN_OK && l.surf[0].mirror && l.surf[0].t == -100, "a concave mirror reads (%s)",
          rc ? err : "ok");
    if (rc == LN_OK) {
        rc = ln_paraxial(&l, PX_LAMBDA_D, &s, err, sizeof err);
        CHECK(rc == LN_OK && px_first_order(&s, &f) == PX_OK && fabs(f.efl.v - 100) < 1e-12 &&
              fabs(f.bfd.v - 100) < 1e-12, "R -200: efl %.15g, bfd %.15g (R/2 = 100)", f.efl.v, f.bfd.v);
        if (rc == LN_OK) px_system_free(&s);
        char *z = ln_write_zmx(&l), *x = ln_write_rx(&l);
        CHECK(z && strstr(z, "  GLAS MIRROR") && strstr(z, "  DISZ -100"), "written back: GLAS MIRROR, DISZ -100");
        CHECK(x && strstr(x, "-100") && strstr(x, " mirror\n"), "a prescription: the mirror key");
        ln_lens b;
        ln_notes nb = {0};
        CHECK(x && ln_read_rx(x, strlen(x), "m.rx", &b, &nb, err, sizeof err) == LN_OK &&
              b.surf[0].mirror && b.surf[0].t == -100 && b.surf[0].c == -0.005,
              "the prescription reads back");
        ln_free(&b);
        ln_notes_free(&nb);
        free(z);
        free(x);
        ln_free(&l);
    }
    ln_notes_free(&notes);
    rc = read_zmx(cass, &l, &notes, err);
    CHECK(rc == LN_OK, "a Cassegrain reads (%s)", rc ? err : "ok");
    if (rc == LN_OK) {
        rc = ln_paraxial(&l, PX_LAMBDA_D, &s, err, sizeof err);
        /* back focal distance from the secondary: f (f1 - d)/f1 = 400 * 50/200 = 100 */
        CHECK(rc == LN_OK && px_first_order(&s, &f) == PX_OK && fabs(f.efl.v - 400) < 1e-9 &&
              fabs(f.bfd.v - 100) < 1e-9, "Cassegrain efl %.12g (400), bfd %.12g (100)",
              f.efl.v, f.bfd.v);
        if (rc == LN_OK) px_system_free(&s);
        ln_free(&l);
    }
    ln_notes_free(&notes);
    {   /* thickness signs: positive after one mirror is refused */
        const char *bad = "VERS 1\nMODE SEQ\nUNIT MM\nSURF 0\n  DISZ INFINITY\nSURF 1\n  CURV -0.005\n"
                          "  DISZ 100\n  GLAS MIRROR\nSURF 2\n";
        rc = read_zmx(bad, &l, &notes, err);
        CHECK(rc == LN_BAD && strstr(err, "g.zmx:8: DISZ 100: a positive thickness where the "
                                     "light travels toward -z"), "DISZ 100 after a mirror refused (%s)", err);
        ln_notes_free(&notes);
    }
}

int main(void)
{
    /* only this test's catalogues: $LENSMAT_GLASS_PATH by its full path, and the
     * working directory moved to / so that no data/agf or ../shared/glass is seen */
    char cwd[4096], path[4200];
    if (!getcwd(cwd, sizeof cwd)) return 1;
    snprintf(path, sizeof path, "%s/tests/agf", cwd);
    setenv("LENSMAT_GLASS_PATH", path, 1);
    if (chdir(cwd) != 0) return 1;
    test_catalogues_from_files();
    if (chdir("/") != 0) return 1;
    test_formulas();
    test_bad_files();
    test_registry();
    test_lens_lookup();
    test_mirrors();
    return unit_failed();
}
