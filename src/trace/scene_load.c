/* scene_load.c -- a scene from disk: read the scene file (16 MB at most, regular
 * files only), parse it (scene_read.c), load the mesh and media files its surfaces
 * name, relative to the scene file, and refuse an output that would overwrite an
 * input (the scene, a mesh or media file, another output).  Nothing here prints. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include "scene.h"

/* ---- files -------------------------------------------------------------------- */

/* Read a whole file into a malloc'd buffer. */
static char *slurp(const char *path, size_t *len, char *err)
{
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    size_t cap = 0, n = 0;
    if (!f) {
        snprintf(err, SC_ERRMAX, "%s: cannot open: %s", path, strerror(errno));
        return NULL;
    }
    for (;;) {
        size_t got;
        if (n == cap) {
            char *b;
            cap = cap ? cap * 2 : 65536;
            if (cap > ((size_t)1 << 32) || !(b = realloc(buf, cap))) {
                snprintf(err, SC_ERRMAX, "%s: too large or out of memory", path);
                free(buf);
                fclose(f);
                return NULL;
            }
            buf = b;
        }
        got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (got == 0) break;
    }
    if (ferror(f)) {
        snprintf(err, SC_ERRMAX, "%s: read error", path);
        free(buf);
        fclose(f);
        return NULL;
    }
    fclose(f);
    *len = n;
    return buf;
}

/* dir/name unless name is absolute. */
static char *join(const char *dir, const char *name)
{
    size_t a = strlen(dir), b = strlen(name);
    char *p = malloc(a + b + 2);
    if (!p) return NULL;
    if (name[0] == '/' || !a) memcpy(p, name, b + 1);
    else {
        memcpy(p, dir, a);
        p[a] = '/';
        memcpy(p + a + 1, name, b + 1);
    }
    return p;
}

static int ends_with(const char *s, const char *suf)
{
    size_t a = strlen(s), b = strlen(suf);
    return a >= b && !strcasecmp(s + a - b, suf);
}

/* Prefix err (a file's own message) with the scene line that named the file. */
static int from_scene(const sc_surface *s, char *err)
{
    char tmp[SC_ERRMAX];
    snprintf(tmp, sizeof tmp, "%s:%ld: %s", s->src, s->line, err);
    memcpy(err, tmp, SC_ERRMAX);
    return -1;
}

static int load_mesh(const sc_scene *sc, sc_surface *s, char *err)
{
    char *path = join(sc->dir, s->mesh_file), *text;
    size_t len;
    int rc;
    if (!path) return snprintf(err, SC_ERRMAX, "out of memory"), -1;
    if (!(text = slurp(path, &len, err))) { free(path); return from_scene(s, err); }
    rc = ends_with(path, ".obj") ? sc_parse_obj(text, len, path, &s->tri, &s->ntri, err)
                                 : sc_parse_triangles(text, len, path, &s->tri, &s->ntri, err);
    free(text);
    free(path);
    if (rc) return from_scene(s, err);
    if (!s->media_file) return 0;
    if (!(path = join(sc->dir, s->media_file)))
        return snprintf(err, SC_ERRMAX, "out of memory"), -1;
    if (!(text = slurp(path, &len, err))) { free(path); return from_scene(s, err); }
    rc = sc_parse_media(text, len, path, s->ntri, &s->media, err);
    free(text);
    free(path);
    return rc ? from_scene(s, err) : 0;
}

/* ---- no output over an input ---------------------------------------------------- */

/* The same existing file (device and inode: links and other spellings count)? */
static int same_file(const char *a, const char *b)
{
    struct stat x, y;
    return a && b && stat(a, &x) == 0 && stat(b, &y) == 0 && x.st_dev == y.st_dev &&
           x.st_ino == y.st_ino;
}

/* out (or out.part, which the trace writes first) is input?  0, or -1 with err. */
static int clash(const sc_scene *sc, const char *what, const char *out, const char *in,
                 const char *in_what, char *err)
{
    char *part = malloc(strlen(out) + 6);
    int bad;
    if (!part) return snprintf(err, SC_ERRMAX, "out of memory"), -1;
    sprintf(part, "%s.part", out);
    bad = strcmp(out, in) == 0 || strcmp(part, in) == 0 || same_file(out, in) ||
          same_file(part, in);
    free(part);
    if (bad)
        snprintf(err, SC_ERRMAX, "%s: output %s %s would overwrite %s %s: an output is "
                 "never written over an input", sc->name, what, out, in_what, in);
    return bad ? -1 : 0;
}

/* Outputs i and j are tables of one HDF5 file (the same name, both HDF5): allowed. */
static int h5_shared(const sc_scene *sc, int i, int j)
{
    const char *out[3] = {sc->out_segments, sc->out_hits, sc->out_summary};
    return sc->out_format[i] == SC_OUT_H5 && sc->out_format[j] == SC_OUT_H5 &&
           strcmp(out[i], out[j]) == 0;
}

/* Every output (and its .part) against the scene file, its mesh and media files and
 * the other outputs, before anything is opened for writing. */
static int outputs_over_inputs(const sc_scene *sc, const char *path, char *err)
{
    const char *what[3] = {"segments", "hits", "summary"};
    const char *out[3] = {sc->out_segments, sc->out_hits, sc->out_summary};
    for (int i = 0; i < 3; i++) {
        if (!out[i]) continue;
        if (clash(sc, what[i], out[i], path, "the scene file", err)) return -1;
        for (int j = 0; j < i; j++)
            if (out[j] && !h5_shared(sc, i, j) && (clash(sc, what[i], out[i], out[j], "output", err) ||
                           clash(sc, what[j], out[j], out[i], "output", err)))
                return -1;
        for (int k = 0; k < sc->nsurf; k++) {
            const char *f[2] = {sc->surf[k].mesh_file, sc->surf[k].media_file};
            for (int m = 0; m < 2; m++) {
                if (!f[m]) continue;
                char *in = join(sc->dir, f[m]);
                if (!in) return snprintf(err, SC_ERRMAX, "out of memory"), -1;
                int rc = clash(sc, what[i], out[i], in, m ? "the media file" :
                               "the mesh file", err);
                free(in);
                if (rc) return -1;
            }
        }
    }
    return 0;
}

int sc_load(const char *path, sc_scene *sc, char *err)
{
    size_t len;
    char *text = slurp(path, &len, err), *slash;
    if (!text) { sc_scene_defaults(sc); return -1; }
    if (sc_parse_scene(text, len, path, sc, err)) { free(text); return -1; }
    free(text);
    if (!(sc->dir = malloc(strlen(path) + 1))) goto oom;
    strcpy(sc->dir, path);
    slash = strrchr(sc->dir, '/');
    if (slash) *slash = '\0';
    else sc->dir[0] = '\0';
    for (int i = 0; i < sc->nsurf; i++) {
        sc_surface *s = &sc->surf[i];
        if (s->shape == SC_MESH && load_mesh(sc, s, err)) goto bad;
        if (s->shape != SC_MESH && s->tessellate &&
            sc_tessellate(s, s->tessellate, &s->tri, &s->ntri, err)) {
            from_scene(s, err);
            goto bad;
        }
    }
    if (outputs_over_inputs(sc, path, err)) goto bad;
    return 0;
oom:
    snprintf(err, SC_ERRMAX, "%s: out of memory", path);
bad:
    sc_free(sc);
    return -1;
}
