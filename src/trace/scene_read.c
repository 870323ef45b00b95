/* scene_read.c -- the trace front end's scene-file parser: one directive per line
 * (surfaces, sources, settings), each checked to its FILE:LINE.  Buffers in, plain
 * data out; nothing here prints, opens a file or needs Embree, so it is fuzzed alone
 * (tests/fuzz_trace_scene.c).  Its siblings: the token reader (scene_lex.c), a
 * directive's keys and values (scene_fields.c), the mesh readers (scene_mesh.c), the
 * axial-surface checks (scene_axial.c); reading a scene from disk with its meshes is
 * scene_load.c. */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include "paraxial/paraxial.h"
#include "scene_int.h"

#define PI 3.14159265358979323846

#define MAXSURF 100000
#define MAXSOURCE 10000
#define POLKEYS " polarizer retarder qwp hwp coating"   /* refracting surfaces */

/* The kind of a surface: exactly one of refract / mirror / absorb / detect (media:
 * meshes only). */
static int surface_kind(reader *r, const fields *f, const char *dname, sc_surface *s)
{
    static const char *const kinds[] = {"refract", "mirror", "absorb", "detect", "media"};
    int n = 0;
    for (int i = 0; i < 5; i++)
        if (sf_has(f, kinds[i])) { s->kind = i; n++; }
    if (n != 1)
        return sl_fail(r, "%s: give exactly one of refract N1 N2, %smirror, absorb, detect",
                    dname, s->shape == SC_MESH ? "media FILE, " : "");
    if (s->kind == SC_REFRACT) {
        int k = sf_key_index(&(tok){"refract", 7});
        s->n1 = sf_val(f, "refract")[0];
        s->n2 = sf_val(f, "refract")[1];
        memcpy(s->glass, f->glass[k], sizeof s->glass);
        if (!(s->n1 > 0) || !(s->n2 > 0))
            return sl_fail(r, "%s: refract %g %g: an index of refraction must be positive",
                        dname, s->n1, s->n2);
    }
    return 0;
}

/* A polarizing element (transmission or fast axis) or a coating's name on a
 * refracting surface (scene_polar.c, tr_polar.c). */
static int surface_polar(reader *r, const fields *f, const char *dname, sc_surface *s)
{
    static const char *const el[] = {"polarizer", "retarder", "qwp", "hwp"};
    int n = 0;
    for (int i = 0; i < 4; i++)
        if (sf_has(f, el[i])) {
            const double *v = sf_val(f, el[i]);
            double m = sqrt(dot3(v, v));
            if (n++ || m == 0)
                return sl_fail(r, "%s: %s", dname, m == 0 ? "a polarizer's or retarder's "
                               "axis must not be zero" : "give one of polarizer, retarder, "
                               "qwp, hwp");
            for (int k = 0; k < 3; k++) s->pol_axis[k] = v[k] / m;
            s->pol_el = i ? TRACE_POL_RETARDER : TRACE_POL_POLARIZER;
            s->pol_ret = (i == 1 ? v[3] : i == 2 ? 90 : 180) * 0.017453292519943295;
        }
    if (sf_has(f, "coating")) {
        const tok *w = &f->word[sf_key_index(&(tok){"coating", 7})];
        if (w->n >= SC_GLASSMAX) return sl_fail(r, "%s: coating: the name is too long", dname);
        memcpy(s->coat_name, w->s, w->n);
        n++;
    }
    if (n && s->kind != SC_REFRACT)
        return sl_fail(r, "%s: polarizer, retarder, qwp, hwp and coating go on a refracting "
                       "surface (refract N1 N2)", dname);
    return 0;
}

/* Does the axial surface exist out to its aperture?  (The conic's square root must
 * stay real, and the sag must be finite.) */
static int axial_check(reader *r, const char *dname, const sc_surface *s)
{
    double c = s->radius != 0 ? 1 / s->radius : 0, a = s->aperture;
    double q = 1 - (1 + s->conic) * c * c * a * a;
    if (q < 0) {
        if (s->shape == SC_CAP)
            return sl_fail(r, "%s: aperture %g exceeds the radius %g: no real surface there",
                        dname, a, fabs(s->radius));
        return sl_fail(r, "%s: radius %g, conic %g: no real surface at the aperture %g "
                    "(1 - (1+k) s^2/R^2 = %g < 0; the surface ends at s = %g)", dname,
                    s->radius, s->conic, a, q, sqrt(1 / ((1 + s->conic) * c * c)));
    }
    return 0;
}

static int read_surface(reader *r, sc_scene *sc, const char *dname, int shape)
{
    static const char *const allowed[] = {
        [SC_PLANE] = "refract mirror absorb detect at normal disc hole rect up tessellate "
                     "refine" POLKEYS,
        [SC_SPHERE] = "refract mirror absorb detect center radius tessellate refine" POLKEYS,
        [SC_CAP] = "refract mirror absorb detect vertex axis radius aperture tessellate refine"
                   POLKEYS,
        [SC_CONIC] = "refract mirror absorb detect vertex axis radius conic aperture "
                     "tessellate refine" POLKEYS,
        [SC_ASPHERE] = "refract mirror absorb detect vertex axis radius conic coef aperture "
                       "tessellate refine" POLKEYS,
        [SC_MESH] = "refract mirror absorb detect media file sphere" POLKEYS,
    };
    static const char *const required[] = {
        [SC_PLANE] = "at normal", [SC_SPHERE] = "center radius",
        [SC_CAP] = "vertex radius aperture", [SC_CONIC] = "vertex radius conic aperture",
        [SC_ASPHERE] = "vertex radius coef aperture", [SC_MESH] = "file",
    };
    fields f;
    sc_surface s;
    sc_surface *grown;

    memset(&s, 0, sizeof s);
    s.shape = shape;
    s.src = sc->name;
    s.line = r->line;
    s.axis[2] = 1;
    if (sf_parse_fields(r, 1, dname, allowed[shape], &f) || sf_need(r, &f, dname, required[shape])
        || surface_kind(r, &f, dname, &s) || surface_polar(r, &f, dname, &s))
        return -1;
    if (sf_has(&f, "tessellate")) {
        long t;
        if (sf_int_val(r, &f, dname, "tessellate", 1, 1000, &t)) return -1;
        s.tessellate = (int)t;
    }
    s.refine = sf_has(&f, "refine");
    if (s.refine && !s.tessellate)
        return sl_fail(r, "%s: 'refine' applies to a tessellated surface (tessellate N)", dname);
    switch (shape) {
    case SC_PLANE:
        memcpy(s.at, sf_val(&f, "at"), sizeof s.at);
        if (sf_unit_vec(r, &f, dname, "normal", s.axis)) return -1;
        if (sf_has(&f, "disc") == sf_has(&f, "rect"))
            return sl_fail(r, "plane: give its bounds, either disc R or rect W H");
        if (sf_has(&f, "disc")) {
            s.aperture = sf_val(&f, "disc")[0];
            if (sf_positive(r, dname, "the disc radius", s.aperture)) return -1;
            if (sf_has(&f, "hole")) {
                s.hole = sf_val(&f, "hole")[0];
                if (!(s.hole > 0 && s.hole < s.aperture))
                    return sl_fail(r, "plane: hole %g must lie between 0 and the disc radius %g",
                                s.hole, s.aperture);
                if (s.tessellate) return sl_fail(r, "plane: a disc with a hole cannot be tessellated");
            }
        } else {
            if (sf_has(&f, "hole")) return sl_fail(r, "plane: 'hole' goes with 'disc'");
            s.rect[0] = sf_val(&f, "rect")[0];
            s.rect[1] = sf_val(&f, "rect")[1];
            if (sf_positive(r, dname, "the width", s.rect[0]) ||
                sf_positive(r, dname, "the height", s.rect[1]))
                return -1;
        }
        if (sf_up_vector(r, &f, dname, s.axis, s.up)) return -1;
        break;
    case SC_SPHERE:
        memcpy(s.at, sf_val(&f, "center"), sizeof s.at);
        s.radius = sf_val(&f, "radius")[0];
        if (sf_positive(r, dname, "the radius", s.radius)) return -1;
        break;
    case SC_MESH:
        s.mesh_file = sf_tok_dup(&f.word[sf_key_index(&(tok){"file", 4})]);
        if (sf_has(&f, "media"))
            s.media_file = sf_tok_dup(&f.word[sf_key_index(&(tok){"media", 5})]);
        if (!s.mesh_file || (sf_has(&f, "media") && !s.media_file)) {
            free(s.mesh_file);
            free(s.media_file);
            return sl_fail(r, "out of memory");
        }
        if (sf_has(&f, "sphere")) {
            memcpy(s.sphere, sf_val(&f, "sphere"), sizeof s.sphere);
            if (sf_positive(r, dname, "the sphere's radius", s.sphere[3])) goto mesh_bad;
        }
        break;
    default:   /* cap, conic, asphere */
        memcpy(s.at, sf_val(&f, "vertex"), sizeof s.at);
        if (sf_has(&f, "axis") && sf_unit_vec(r, &f, dname, "axis", s.axis)) return -1;
        s.radius = sf_val(&f, "radius")[0];
        s.aperture = sf_val(&f, "aperture")[0];
        if (sf_positive(r, dname, "the aperture (semi-diameter)", s.aperture)) return -1;
        if (sf_has(&f, "conic")) s.conic = sf_val(&f, "conic")[0];
        if (sf_has(&f, "coef")) {
            s.ncoef = f.count[sf_key_index(&(tok){"coef", 4})];
            memcpy(s.coef, sf_val(&f, "coef"), (size_t)s.ncoef * sizeof *s.coef);
        }
        if (axial_check(r, dname, &s)) return -1;
    }
    if (sc->nsurf == MAXSURF) {
        sl_fail(r, "more than %d surfaces", MAXSURF);
        goto mesh_bad;
    }
    grown = realloc(sc->surf, (size_t)(sc->nsurf + 1) * sizeof *grown);
    if (!grown) { sl_fail(r, "out of memory"); goto mesh_bad; }
    sc->surf = grown;
    sc->surf[sc->nsurf++] = s;
    return 0;
mesh_bad:
    free(s.mesh_file);
    free(s.media_file);
    return -1;
}

static int read_source(reader *r, sc_scene *sc)
{
    static const struct { const char *name, *allowed, *required; } types[] = {
        [SC_RAY] = {"ray", "from dir power medium pol lambda", "from dir"},
        [SC_FAN] = {"fan", "from dir angle up to rays power medium pol lambda", "from rays"},
        [SC_POINT] = {"point", "from toward radius rings power medium pol lambda",
                      "from toward radius rings"},
        [SC_CONE] = {"cone", "from dir angle rings power medium pol lambda",
                     "from dir angle rings"},
        [SC_COLLIMATED] = {"collimated", "from dir radius grid power medium pol lambda",
                           "from dir radius grid"},
        [SC_GAUSSIAN] = {"gaussian", "from dir waist wavelength rings trunc power medium pol lambda",
                         "from dir waist wavelength rings"},
    };
    sc_source s;
    fields f;
    char dname[32];
    long v;
    int t = -1;
    sc_source *grown;

    if (r->nt < 2)
        return sl_fail(r, "source: which kind? (ray, fan, point, cone, collimated, gaussian)");
    for (int i = 0; i < 6; i++)
        if (sl_tok_is(&r->t[1], types[i].name)) t = i;
    if (t < 0)
        return sl_fail(r, "source: unknown kind '%.*s' (ray, fan, point, cone, collimated, "
                    "gaussian)", (int)(r->t[1].n < 24 ? r->t[1].n : 24), r->t[1].s);
    snprintf(dname, sizeof dname, "source %s", types[t].name);
    if (sf_parse_fields(r, 2, dname, types[t].allowed, &f) || sf_need(r, &f, dname, types[t].required))
        return -1;
    memset(&s, 0, sizeof s);
    s.type = t;
    s.src = sc->name;
    s.line = r->line;
    s.power = 1;
    s.medium = 1;
    memcpy(s.from, sf_val(&f, "from"), sizeof s.from);
    if (sf_has(&f, "dir") && sf_unit_vec(r, &f, dname, "dir", s.dir)) return -1;
    if (sf_has(&f, "power")) {
        s.power = sf_val(&f, "power")[0];
        if (sf_positive(r, dname, "power", s.power)) return -1;
    }
    if (sf_has(&f, "lambda")) {
        int k = sf_key_index(&(tok){"lambda", 6});
        s.nlambda = f.count[k];
        memcpy(s.lambda, f.num[k], (size_t)s.nlambda * sizeof *s.lambda);
    }
    if (sf_has(&f, "medium")) {
        memcpy(s.glass, f.glass[sf_key_index(&(tok){"medium", 6})][0], sizeof s.glass);
        s.medium = sf_val(&f, "medium")[0];
        if (!(s.medium > 0))
            return sl_fail(r, "%s: medium %g: an index of refraction must be positive", dname,
                        s.medium);
    }
    int kp = sf_key_index(&(tok){"pol", 3});
    if (f.has[kp] && sc_source_pol(r, f.at[kp], f.count[kp], dname, &s)) return -1;
    if (sf_has(&f, "angle")) {
        s.angle = sf_val(&f, "angle")[0];
        if (s.angle < 0 || s.angle >= (t == SC_FAN ? 180 : 90))
            return sl_fail(r, "%s: half angle %g must lie in [0, %d) degrees", dname, s.angle,
                        t == SC_FAN ? 180 : 90);
    }
    if (sf_has(&f, "radius")) {
        s.radius = sf_val(&f, "radius")[0];
        if (sf_positive(r, dname, "the radius", s.radius)) return -1;
    }
    if (sf_has(&f, "rays")) {
        if (sf_int_val(r, &f, dname, "rays", 1, 100000000L, &v)) return -1;
        s.count = v;
    }
    if (sf_has(&f, "grid")) {
        if (sf_int_val(r, &f, dname, "grid", 1, 10000, &v)) return -1;
        s.count = v;
    }
    if (sf_has(&f, "rings")) {
        if (sf_int_val(r, &f, dname, "rings", 0, t == SC_POINT ? 500 : 5000, &v)) return -1;
        s.rings = (int)v;
    }
    switch (t) {
    case SC_FAN:
        if (sf_has(&f, "to") == sf_has(&f, "dir"))
            return sl_fail(r, "%s: give either dir D angle A [up U], or to P1 P2 (rays toward "
                        "points on the segment P1-P2, as opticrt)", dname);
        if (sf_has(&f, "to")) {
            double a[3], b[3], c[3];
            if (sf_has(&f, "angle") || sf_has(&f, "up"))
                return sl_fail(r, "%s: 'angle' and 'up' go with 'dir', not with 'to'", dname);
            s.has_to = 1;
            memcpy(s.to, sf_val(&f, "to"), sizeof s.to);
            sub3(s.to[0], s.from, a);
            sub3(s.to[1], s.from, b);
            if (dot3(a, a) == 0 || (s.count > 1 && dot3(b, b) == 0))
                return sl_fail(r, "%s: a 'to' point is the source point: a zero-direction ray",
                            dname);
            cross3(a, b, c);
            if (s.count > 1 && dot3(c, c) == 0 && dot3(a, b) < 0)
                return sl_fail(r, "%s: the segment P1-P2 passes through the source point "
                            "(a zero-direction ray)", dname);
        } else {
            if (!sf_has(&f, "angle")) return sl_fail(r, "%s: 'angle' is missing", dname);
            if (sf_up_vector(r, &f, dname, s.dir, s.up)) return -1;
        }
        break;
    case SC_POINT: {
        double d[3];
        memcpy(s.toward, sf_val(&f, "toward"), sizeof s.toward);
        sub3(s.toward, s.from, d);
        if (dot3(d, d) == 0)
            return sl_fail(r, "%s: 'toward' is the source point: a zero-direction ray", dname);
        break;
    }
    case SC_GAUSSIAN:
        s.waist = sf_val(&f, "waist")[0];
        s.wavelength = sf_val(&f, "wavelength")[0];
        if (sf_positive(r, dname, "the waist", s.waist) ||
            sf_positive(r, dname, "the wavelength", s.wavelength))
            return -1;
        if (sf_has(&f, "trunc")) {
            s.trunc = sf_val(&f, "trunc")[0];
            if (sf_positive(r, dname, "trunc", s.trunc)) return -1;
        }
        if (s.wavelength / (PI * s.waist) > 0.5)
            return sl_fail(r, "%s: wavelength %g against waist %g: divergence %g rad is beyond "
                        "the paraxial Gaussian beam", dname, s.wavelength, s.waist,
                        s.wavelength / (PI * s.waist));
        break;
    default:
        break;
    }
    if (sc->nsource == MAXSOURCE) return sl_fail(r, "more than %d sources", MAXSOURCE);
    grown = realloc(sc->source, (size_t)(sc->nsource + 1) * sizeof *grown);
    if (!grown) return sl_fail(r, "out of memory");
    sc->source = grown;
    sc->source[sc->nsource++] = s;
    return 0;
}

/* ---- formats ---------------------------------------------------------------------- */

static int ends_with(const char *s, const char *tail)
{
    size_t n = strlen(s), m = strlen(tail);
    if (n < m) return 0;
    for (size_t i = 0; i < m; i++) {
        char c = s[n - m + i];
        if (c >= 'A' && c <= 'Z') c = (char)(c - 'A' + 'a');
        if (c != tail[i]) return 0;
    }
    return 1;
}

static sc_out_format out_format_of(const char *name, sc_out_format keyword)
{
    if (keyword != SC_OUT_AUTO) return keyword;
    if (ends_with(name, ".npy")) return SC_OUT_NPY;
    if (ends_with(name, ".h5") || ends_with(name, ".hdf5")) return SC_OUT_H5;
    return SC_OUT_TEXT;
}

/* The keyword s[0..n) (csv, text, csv17, npy, h5, hdf5) into f: 0, or -1. */
static int out_format_keyword(const char *s, size_t n, sc_out_format *f)
{
    static const struct { const char *k; sc_out_format f; } kw[] = {
        {"csv", SC_OUT_TEXT}, {"text", SC_OUT_TEXT}, {"csv17", SC_OUT_CSV17}, {"npy", SC_OUT_NPY},
        {"h5", SC_OUT_H5}, {"hdf5", SC_OUT_H5}};
    for (size_t i = 0; i < sizeof kw / sizeof kw[0]; i++)
        if (strlen(kw[i].k) == n && memcmp(kw[i].k, s, n) == 0) return *f = kw[i].f, 0;
    return -1;
}

/* depth N / cutoff X / threads N / escape L / fresnel on|off / reflections on|off /
 * output segments|hits|summary|all FILE [csv|csv17|npy|h5] */
static int read_setting(reader *r, sc_scene *sc)
{
    double v;
    char w[32];
    const tok *d = &r->t[0];
    if (sl_tok_is(d, "output")) {
        static const char *const what[] = {"segments", "hits", "summary"};
        char **slot[] = {&sc->out_segments, &sc->out_hits, &sc->out_summary};
        sc_out_format f = SC_OUT_AUTO;
        int all = r->nt >= 2 && sl_tok_is(&r->t[1], "all");
        if (r->nt != 3 && r->nt != 4)
            return sl_fail(r, "output: expected 'output segments|hits|summary|all FILE "
                           "[csv|csv17|npy|h5]'");
        if (r->nt == 4 && out_format_keyword(r->t[3].s, r->t[3].n, &f))
            return sl_fail(r, "output: '%.*s' is not a format (csv, csv17, npy, h5)",
                           (int)(r->t[3].n < 24 ? r->t[3].n : 24), r->t[3].s);
        if (all) {   /* one HDF5 file with every table */
            for (int i = 0; i < 3; i++) {
                if (*slot[i]) return sl_fail(r, "output %s given twice", what[i]);
                if (!(*slot[i] = sf_tok_dup(&r->t[2]))) return sl_fail(r, "out of memory");
                sc->out_format[i] = SC_OUT_H5;
            }
            if (out_format_of(sc->out_summary, f) != SC_OUT_H5)
                return sl_fail(r, "output all: the tables go together in one HDF5 file "
                               "(FILE.h5 or FILE.hdf5, or the keyword h5)");
            return 0;
        }
        for (int i = 0; i < 3; i++)
            if (sl_tok_is(&r->t[1], what[i])) {
                if (*slot[i]) return sl_fail(r, "output %s given twice", what[i]);
                if (!(*slot[i] = sf_tok_dup(&r->t[2]))) return sl_fail(r, "out of memory");
                sc->out_format[i] = (int)out_format_of(*slot[i], f);
                if (i == 2 && sc->out_format[i] != SC_OUT_TEXT && sc->out_format[i] != SC_OUT_H5)
                    return sl_fail(r, "output summary: text or h5");
                if (i == 0 && sc->out_format[i] == SC_OUT_CSV17)
                    return sl_fail(r, "output segments: csv17 is a hits format");
                return 0;
            }
        return sl_fail(r, "output: '%.*s' is not segments, hits or summary (or all)",
                    (int)(r->t[1].n < 24 ? r->t[1].n : 24), r->t[1].s);
    }
    if (sl_tok_is(d, "mismatch")) {
        if (r->nt != 2 || !(sl_tok_is(&r->t[1], "warn") || sl_tok_is(&r->t[1], "error")))
            return sl_fail(r, "mismatch: expected warn or error");
        sc->mismatch_error = sl_tok_is(&r->t[1], "error");
        return 0;
    }
    if (sl_tok_is(d, "fresnel") || sl_tok_is(d, "reflections")) {
        int *flag = sl_tok_is(d, "fresnel") ? &sc->fresnel : &sc->reflections;
        if (r->nt != 2 || !(sl_tok_is(&r->t[1], "on") || sl_tok_is(&r->t[1], "off")))
            return sl_fail(r, "%.*s: expected on or off", (int)d->n, d->s);
        *flag = sl_tok_is(&r->t[1], "on");
        return 0;
    }
    if (r->nt != 2) return sl_fail(r, "%.*s: expected one number", (int)d->n, d->s);
    snprintf(w, sizeof w, "%.*s", (int)(d->n < 24 ? d->n : 24), d->s);
    if (sl_tok_num(r, &r->t[1], w, &v)) return -1;
    if (sl_tok_is(d, "depth")) {
        if (v != floor(v) || v < 1 || v > 1000)
            return sl_fail(r, "depth %g: must be an integer from 1 to 1000", v);
        sc->depth = (int)v;
    } else if (sl_tok_is(d, "cutoff")) {
        if (!(v >= 0 && v < 1)) return sl_fail(r, "cutoff %g: must lie in [0, 1)", v);
        sc->cutoff = v;
    } else if (sl_tok_is(d, "escape")) {
        if (!(v > 0)) return sl_fail(r, "escape %g: the length must be positive", v);
        sc->escape = v;
    } else {
        if (v != floor(v) || v < 0 || v > 1024)
            return sl_fail(r, "threads %g: must be an integer from 0 (all cores) to 1024", v);
        sc->threads = (int)v;
    }
    return 0;
}

static int read_directive(reader *r, sc_scene *sc)
{
    static const char *const shapes[] = {[SC_PLANE] = "plane", [SC_SPHERE] = "sphere",
                                         [SC_CAP] = "cap", [SC_CONIC] = "conic",
                                         [SC_ASPHERE] = "asphere", [SC_MESH] = "mesh"};
    static const char *const settings[] = {"depth", "cutoff", "threads", "escape", "fresnel",
                                           "reflections", "output", "mismatch", NULL};
    const tok *d = &r->t[0];
    for (int i = 0; i < 6; i++)
        if (sl_tok_is(d, shapes[i])) return read_surface(r, sc, shapes[i], i);
    if (sl_tok_is(d, "coating") || sl_tok_is(d, "polarization") ||
        (sl_tok_is(d, "output") && r->nt >= 2 && sl_tok_is(&r->t[1], "polar")))
        return sc_polar_directive(r, sc);   /* scene_polar.c */
    if (sl_tok_is(d, "source")) return read_source(r, sc);
    for (int i = 0; settings[i]; i++)
        if (sl_tok_is(d, settings[i])) return read_setting(r, sc);
    return sl_fail(r, "unknown directive '%.*s' (plane, sphere, cap, conic, asphere, mesh, "
                "source, depth, cutoff, threads, escape, fresnel, reflections, output, mismatch, "
                "polarization, coating)",
                (int)(d->n < 24 ? d->n : 24), d->s);
}

void sc_scene_defaults(sc_scene *sc)
{
    memset(sc, 0, sizeof *sc);
    sc->depth = 16;
    sc->cutoff = 1e-6;
    sc->fresnel = sc->reflections = 1;
    sc->escape = 1;
}

int sc_parse_scene(const char *text, size_t len, const char *name, sc_scene *sc,
                   char *err)
{
    reader r;
    int st;

    sc_scene_defaults(sc);
    sl_reader_init(&r, text, len, name, err);
    if (!(sc->name = malloc(strlen(name) + 1))) return -1;
    strcpy(sc->name, name);
    r.name = sc->name;
    while ((st = sl_next_line(&r)) > 0)
        if (read_directive(&r, sc)) goto bad;
    if (st < 0) goto bad;
    if (!sc->nsurf) { sl_fail(&r, "the scene has no surface"); goto bad; }
    if (!sc->nsource) { sl_fail(&r, "the scene has no source of rays"); goto bad; }
    {   /* wavelengths: named by some source?  (at most SC_MAXWLS distinct ones) */
        double seen[SC_MAXWLS];
        int nseen = 0;
        for (int i = 0; i < sc->nsource; i++)
            for (int j = 0; j < sc->source[i].nlambda; j++) {
                int k = 0;
                sc->named_wl = 1;
                while (k < nseen && seen[k] != sc->source[i].lambda[j]) k++;
                if (k < nseen) continue;
                if (nseen == SC_MAXWLS) {
                    snprintf(err, SC_ERRMAX, "%s:%ld: more than %d different wavelengths "
                             "in one scene", sc->name, sc->source[i].line, SC_MAXWLS);
                    goto bad;
                }
                seen[nseen++] = sc->source[i].lambda[j];
            }
    }
    if (sc_axial_pairs(sc, err)) goto bad;
    if (sc_check_coincident(sc, err)) goto bad;     /* with both lines */
    if (sc_polar_resolve(sc, err)) goto bad;
    return 0;
bad:
    sc_free(sc);
    return -1;
}

void sc_free(sc_scene *sc)
{
    for (int i = 0; i < sc->nsurf; i++) {
        free(sc->surf[i].tri);
        free(sc->surf[i].vtx);
        free(sc->surf[i].idx);
        free(sc->surf[i].media);
        free(sc->surf[i].mesh_file);
        free(sc->surf[i].media_file);
    }
    free(sc->surf);
    free(sc->source);
    free(sc->out_segments);
    free(sc->out_hits);
    free(sc->out_summary);
    free(sc->name);
    free(sc->dir);
    sc_polar_free(sc);
    memset(sc, 0, sizeof *sc);
}
