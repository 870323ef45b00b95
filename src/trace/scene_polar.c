/* scene_polar.c -- the scene file's polarization lines (the reader's part: libc and
 * libm only, fuzzed with the other readers): a source's `pol` key (linear, circular,
 * elliptical, a Jones vector), `polarization on|off [ref X Y Z]`,
 * `coating NAME layer N D [layer N D ...]` (thin films, D in nm), `output polar FILE
 * [csv|npy]`, and, once the file is read, each surface's coating found by name and
 * polarization switched on where an element, a coating or the output asks for it.
 * The surfaces' own keys (polarizer, retarder, qwp, hwp, coating) are read with the
 * other keys in scene_read.c; tracing them is tr_polar.c's, writing the table
 * scene_polout.c's. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "scene_int.h"

static int word_fits(reader *r, const tok *t, const char *what, char *out)
{
    if (t->n >= SC_GLASSMAX)
        return sl_fail(r, "%s: '%.24s...' is too long for a name", what, t->s);
    memcpy(out, t->s, t->n);
    out[t->n] = '\0';
    return 0;
}

static int read_coating(reader *r, sc_scene *sc)
{
    sc_coating c;
    memset(&c, 0, sizeof c);
    c.src = sc->name;
    c.line = r->line;
    if (r->nt < 5 || !sl_tok_is(&r->t[2], "layer"))
        return sl_fail(r, "coating: expected 'coating NAME layer N D [layer N D ...]' "
                       "(index, thickness in nm)");
    if (word_fits(r, &r->t[1], "coating", c.name)) return -1;
    for (int i = 0; i < sc->ncoating; i++)
        if (!strcmp(sc->coating[i].name, c.name))
            return sl_fail(r, "coating %s: defined twice (first at line %ld)", c.name,
                           sc->coating[i].line);
    for (int i = 2; i < r->nt; i += 3) {
        if (!sl_tok_is(&r->t[i], "layer") || i + 2 >= r->nt)
            return sl_fail(r, "coating %s: each layer is 'layer N D' (index, thickness in nm)",
                           c.name);
        if (c.nlayer == SC_MAXLAYER)
            return sl_fail(r, "coating %s: more than %d layers", c.name, SC_MAXLAYER);
        double n, d;
        if (sl_tok_num(r, &r->t[i + 1], "coating: a layer's index", &n) ||
            sl_tok_num(r, &r->t[i + 2], "coating: a layer's thickness", &d))
            return -1;
        if (!(n > 0) || !(d >= 0))
            return sl_fail(r, "coating %s: layer %d: the index must be positive and the "
                           "thickness (nm) at least 0", c.name, c.nlayer + 1);
        c.n[c.nlayer] = n;
        c.d_nm[c.nlayer++] = d;
    }
    sc_coating *g = realloc(sc->coating, (size_t)(sc->ncoating + 1) * sizeof *g);
    if (!g) return sl_fail(r, "out of memory");
    sc->coating = g;
    sc->coating[sc->ncoating++] = c;
    return 0;
}

static int read_polarization(reader *r, sc_scene *sc)
{
    int on = r->nt >= 2 && sl_tok_is(&r->t[1], "on");
    if (!(r->nt == 2 || (r->nt == 6 && sl_tok_is(&r->t[2], "ref"))) ||
        !(on || sl_tok_is(&r->t[1], "off")))
        return sl_fail(r, "polarization: expected 'polarization on|off [ref X Y Z]'");
    if (sc->polar) return sl_fail(r, "polarization given twice");
    sc->polar = on ? 1 : -1;
    if (r->nt == 6) {
        for (int i = 0; i < 3; i++)
            if (sl_tok_num(r, &r->t[3 + i], "polarization: ref", &sc->polar_ref[i])) return -1;
        if (dot3(sc->polar_ref, sc->polar_ref) == 0)
            return sl_fail(r, "polarization: the reference direction must not be zero");
    }
    return 0;
}

static int read_output(reader *r, sc_scene *sc)
{
    if (r->nt != 3 && r->nt != 4)
        return sl_fail(r, "output polar: expected 'output polar FILE [csv|npy]'");
    if (sc->out_polar) return sl_fail(r, "output polar given twice");
    size_t n = r->t[2].n;
    int npy = r->nt == 4 ? sl_tok_is(&r->t[3], "npy") : n > 4 && !memcmp(r->t[2].s + n - 4, ".npy", 4);
    if (r->nt == 4 && !npy && !sl_tok_is(&r->t[3], "csv"))
        return sl_fail(r, "output polar: '%.*s' is not a format (csv, npy)",
                       (int)(r->t[3].n < 24 ? r->t[3].n : 24), r->t[3].s);
    if (!(sc->out_polar = malloc(n + 1))) return sl_fail(r, "out of memory");
    memcpy(sc->out_polar, r->t[2].s, n);
    sc->out_polar[n] = '\0';
    sc->out_polar_format = npy ? SC_OUT_NPY : SC_OUT_TEXT;
    return 0;
}

#define DEG (3.14159265358979323846 / 180)

/* A source's polarization state.  The Jones vectors are in the Stokes frame (x', y' =
 * dir x x', x' the `polarization ref` projected perpendicular to the ray), fields
 * exp(i(kz - wt)): S3 = 2 Im(Jx* Jy) > 0 turns from x' toward y', counterclockwise
 * facing the source, left-handed in the optics naming (Hecht, Born & Wolf); `right`
 * is (1, -i)/sqrt 2, S3 = -S0 (the --polar calculator's r). */
int sc_source_pol(reader *r, int first, int n, const char *dname, sc_source *s)
{
    const tok *t = &r->t[first];
    char what[64];
    double v[4];
    snprintf(what, sizeof what, "%s: 'pol'", dname);
    if (n == 3 && !sl_tok_is(t, "ellipse") && !sl_tok_is(t, "stokes")) {   /* linear */
        for (int i = 0; i < 3; i++)
            if (sl_tok_num(r, &t[i], what, &s->pol[i])) return -1;
        double m = sqrt(dot3(s->pol, s->pol));
        if (!(m > 0) || !isfinite(m))
            return sl_fail(r, "%s: 'pol' %g %g %g is a zero-length direction", dname,
                           s->pol[0], s->pol[1], s->pol[2]);
        for (int i = 0; i < 3; i++) s->pol[i] /= m;
        s->polarised = 1;
        return 0;
    }
    if (n == 1 && (sl_tok_is(t, "right") || sl_tok_is(t, "left"))) {
        double h = sqrt(0.5);
        memset(s->jones, 0, sizeof s->jones);
        s->jones[0][0] = h;
        s->jones[1][1] = sl_tok_is(t, "right") ? -h : h;
        s->polarised = 2;
        return 0;
    }
    int ell = 0, jon = 0, sto = 0;
    if (n >= 1) {
        ell = sl_tok_is(t, "ellipse");
        jon = sl_tok_is(t, "jones");
        sto = sl_tok_is(t, "stokes");
    }
    if (!(ell && n == 3) && !(jon && n == 5) && !(sto && n == 4))
        return sl_fail(r, "%s: 'pol' expects X Y Z (linear), right or left (circular, "
                       "optics convention: right turns clockwise facing the source), "
                       "ellipse AZ CHI (azimuth, ellipticity angle in degrees), jones "
                       "JX JY PX PY (amplitudes, phases in degrees) or stokes S1 S2 S3 "
                       "(partially polarized: over S0, at most 1 in length)", dname);
    for (int i = 0; i < n - 1; i++)
        if (sl_tok_num(r, &t[1 + i], what, &v[i])) return -1;
    if (sto) {
        double q = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        if (!(q <= 1 + 1e-12))
            return sl_fail(r, "%s: 'pol stokes' %g %g %g: the degree of polarization "
                           "sqrt(S1^2 + S2^2 + S3^2) = %.6g is more than 1 (give S1 S2 S3 "
                           "over S0)", dname, v[0], v[1], v[2], sqrt(q));
        memcpy(s->stokes, v, sizeof s->stokes);
        s->polarised = 3;
        return 0;
    }
    if (ell) {
        if (!(fabs(v[1]) <= 45))
            return sl_fail(r, "%s: 'pol ellipse': the ellipticity angle %g must lie in "
                           "[-45, 45] degrees (tan CHI = minor / major axis; > 0: "
                           "left-handed)", dname, v[1]);
        double ps = v[0] * DEG, ch = v[1] * DEG;   /* R(psi) (cos chi, i sin chi) */
        s->jones[0][0] = cos(ps) * cos(ch);
        s->jones[0][1] = -sin(ps) * sin(ch);
        s->jones[1][0] = sin(ps) * cos(ch);
        s->jones[1][1] = cos(ps) * sin(ch);
    } else {
        if (!(v[0] >= 0 && v[1] >= 0) || !(v[0] > 0 || v[1] > 0))
            return sl_fail(r, "%s: 'pol jones': the amplitudes %g %g must be at least 0 and "
                           "not both 0", dname, v[0], v[1]);
        double m = hypot(v[0], v[1]);
        if (!isfinite(m) || !isfinite(v[0] / m * cos(v[2] * DEG)))
            return sl_fail(r, "%s: 'pol jones': the amplitudes are too large", dname);
        for (int i = 0; i < 2; i++) {
            s->jones[i][0] = v[i] / m * cos(v[2 + i] * DEG);
            s->jones[i][1] = v[i] / m * sin(v[2 + i] * DEG);
        }
    }
    s->polarised = 2;
    return 0;
}

int sc_polar_directive(reader *r, sc_scene *sc)
{
    if (sl_tok_is(&r->t[0], "coating")) return read_coating(r, sc);
    if (sl_tok_is(&r->t[0], "polarization")) return read_polarization(r, sc);
    return read_output(r, sc);
}

int sc_polar_resolve(sc_scene *sc, char *err)
{
    int any = sc->out_polar != NULL;
    for (int i = 0; i < sc->nsurf; i++) {
        sc_surface *s = &sc->surf[i];
        if (s->pol_el) any = 1;
        if (!s->coat_name[0]) continue;
        any = 1;
        for (int k = 0; k < sc->ncoating && !s->coat; k++)
            if (!strcmp(sc->coating[k].name, s->coat_name)) s->coat = k + 1;
        if (!s->coat)
            return snprintf(err, SC_ERRMAX, "%s:%ld: coating %s: no such coating (define "
                            "it with a line 'coating %s layer N D ...')", s->src, s->line,
                            s->coat_name, s->coat_name), -1;
    }
    if (any && sc->polar < 0)
        return snprintf(err, SC_ERRMAX, "%s: `polarization off`, but the scene has a "
                        "polarizer, retarder, coating or polar output", sc->name), -1;
    sc->polar = sc->polar > 0 || any;
    return 0;
}

void sc_polar_free(sc_scene *sc)
{
    free(sc->coating);
    free(sc->out_polar);
    sc->coating = NULL;
    sc->out_polar = NULL;
}
