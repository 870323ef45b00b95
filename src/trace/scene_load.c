/* scene_load.c -- a scene from disk: read the scene file (16 MB at most, regular
 * files only), parse it (scene_read.c), load the mesh and media files its surfaces
 * name, relative to the scene file (a mesh that cannot fit in the memory available
 * is refused before it is read), and refuse an output that would overwrite an
 * input (the scene, a mesh or media file, another output).  Nothing here prints. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/resource.h>
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
    struct stat st;   /* a regular file: its size, so the buffer is not grown past it */
    if (fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0 &&
        (unsigned long long)st.st_size < ((size_t)1 << 32)) {
        cap = (size_t)st.st_size + 1;
        if (!(buf = malloc(cap))) cap = 0;
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

/* ---- memory, before a mesh is read ------------------------------------------------
 * A mesh costs its file's text while it is parsed, then about SC_MESH_BYTES_PER_TRI a
 * triangle and SC_MESH_RES_PER_VTX a vertex while it is traced: the scene's vertices and indices, the engine's double
 * vertices and indices, their welding and adjacency, Embree's grown float triangles
 * and its BVH (the peak measured by scripts/bench_trace_mesh.sh on a 1e6-triangle
 * OBJ: trace_mesh_bytes_per_tri).  The file is counted first (read in 1 MiB pieces,
 * nothing kept) and refused if that need exceeds what the system has: MemAvailable
 * (/proc/meminfo), and the address-space limit (RLIMIT_AS) less what the process
 * already maps (VmSize, /proc/self/status) against the address space it needs. */
/* resident: a triangle Embree's grown float triangles and BVH build (146 measured on
 * bare Embree) and its indices (12); a vertex its doubles (24) and welding (4), each
 * with some room: 186 a triangle on the 998 000-triangle sphere (174 measured), 266 on
 * the same as a triangle soup (3 vertices a triangle; 242 without the text) */
#define SC_MESH_BYTES_PER_TRI 170.0
/* a mesh of more than SC_MESH_CHUNK triangles (the engine's TR_CHUNK_TRI) goes to
 * Embree in chunks, each one's grown triangles and build temporaries gone before the
 * next (tr_meshbvh.c): 62 bytes a triangle less (112 measured on the sphere, estimated
 * 124) */
#define SC_MESH_CHUNK 131072
#define SC_MESH_CHUNKED_PER_TRI 108.0
#define SC_MESH_RES_PER_VTX 32.0
#define SC_MESH_BYTES_PER_VTX 48.0     /* while parsing (with the array's growth) */
#define SC_MESH_VBYTES_PER_TRI 320.0   /* address space */
#define SC_MESH_VBASE (192.0 * 1048576)

/* Vertices and triangles in an OBJ (v lines; f lines of k vertices: k - 2 triangles)
 * or a triangle file (three number lines a triangle).  0, or -1 if it cannot be read. */
static int count_mesh(const char *path, int obj, double *nv, double *nt)
{
    FILE *f = fopen(path, "rb");
    static char buf[1 << 20];
    size_t got;
    /* per line: its first word (1 "v", 2 "f", 3 other), the words so far, in a word */
    int first = 0, words = 0, inword = 0, len = 0;
    double lines = 0;
    *nv = *nt = 0;
    if (!f) return -1;
    for (;;) {
        got = fread(buf, 1, sizeof buf, f);
        for (size_t i = 0; i <= got; i++) {
            char c = i < got ? buf[i] : '\n';   /* the end of a piece is not a line's */
            if (i == got && got == sizeof buf) break;
            if (c == '\n') {
                if (first == 2 && words > 3) *nt += words - 3;
                if (first == 1) (*nv)++;
                if (words && first != 4) lines++;
                first = words = inword = len = 0;
                continue;
            }
            int blank = c == ' ' || c == '\t' || c == '\r';
            if (!blank && !inword) {
                words++;
                len = 0;
                if (words == 1) first = c == '#' ? 4 : c == 'v' ? 1 : c == 'f' ? 2 : 3;
            }
            if (!blank && words == 1 && ++len > 1 && first != 4) first = 3;   /* vt, vn */
            inword = !blank;
        }
        if (got < sizeof buf) break;
    }
    if (!obj) { *nt = lines / 3; *nv = 0; }
    fclose(f);
    return 0;
}

/* MemAvailable (/proc/meminfo) and the room under RLIMIT_AS (the limit less VmSize,
 * /proc/self/status), in bytes; -1 where unknown or unlimited. */
static void memory_left(double *avail, double *room)
{
    double kb;
    char line[256];
    FILE *f = fopen("/proc/meminfo", "r");
    *avail = *room = -1;
    while (f && fgets(line, sizeof line, f))
        if (sscanf(line, "MemAvailable: %lf kB", &kb) == 1) *avail = kb * 1024;
    if (f) fclose(f);
    /* LENSMAT_MEMAVAILABLE_KB: MemAvailable as given -- to check the refusal
     * (tests/t_64_mesh.sh) on a machine with more */
    const char *e = getenv("LENSMAT_MEMAVAILABLE_KB");
    if (e && sscanf(e, "%lf", &kb) == 1 && kb >= 0) *avail = kb * 1024;
    struct rlimit rl;
    if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) {
        double used = 0;
        if ((f = fopen("/proc/self/status", "r"))) {
            while (fgets(line, sizeof line, f))
                if (sscanf(line, "VmSize: %lf kB", &kb) == 1) used = kb * 1024;
            fclose(f);
        }
        *room = fmax(0, (double)rl.rlim_cur - used);
    }
}

/* 0, or -1 with err: the mesh at path would not fit. */
static int mesh_fits(const char *path, int obj, char *err)
{
    struct stat st;
    double nv, nt, avail, room;
    if (stat(path, &st) || !S_ISREG(st.st_mode) || count_mesh(path, obj, &nv, &nt))
        return 0;   /* the reader says what is wrong with it */
    double text = (double)st.st_size, mb = 1048576;
    double nvk = obj ? nv : 3 * nt;      /* a triangle file: three vertices each */
    double per = nt > SC_MESH_CHUNK ? SC_MESH_CHUNKED_PER_TRI : SC_MESH_BYTES_PER_TRI;
    double need = fmax(text + nv * SC_MESH_BYTES_PER_VTX + nt * 24,
                       nt * per + nvk * SC_MESH_RES_PER_VTX);
    /* address space: Embree's allocator and each thread's malloc arena reserve more
     * than they touch (measured: a limit of 475 MB lets a 1e6-triangle OBJ trace on
     * one thread, 325 MB 5e5, 300 MB 1.8e5, with 70 MB mapped before): 320 bytes a
     * triangle and 192 MB, an estimate that errs on the side of refusing */
    double vneed = fmax(text + nv * SC_MESH_BYTES_PER_VTX + nt * 24,
                        nt * SC_MESH_VBYTES_PER_TRI) + SC_MESH_VBASE;
    memory_left(&avail, &room);
    if (avail >= 0 && need > avail)
        return snprintf(err, SC_ERRMAX, "%s: %.0f triangles need about %.0f MB to trace "
                        "(%.0f bytes a triangle and %.0f a vertex, the file's %.0f MB while "
                        "it is read), more than the %.0f MB of memory available "
                        "(MemAvailable): not read", path, nt, need / mb, per,
                        SC_MESH_RES_PER_VTX, text / mb, avail / mb), -1;
    if (room >= 0 && vneed > room)
        return snprintf(err, SC_ERRMAX, "%s: %.0f triangles need about %.0f MB of address "
                        "space to trace (%.0f bytes a triangle and %.0f MB for Embree), more "
                        "than the %.0f MB left under the limit (ulimit -v): not read", path,
                        nt, vneed / mb, SC_MESH_VBYTES_PER_TRI, SC_MESH_VBASE / mb, room / mb), -1;
    return 0;
}

static int load_mesh(const sc_scene *sc, sc_surface *s, char *err)
{
    char *path = join(sc->dir, s->mesh_file), *text;
    size_t len;
    int rc;
    if (!path) return snprintf(err, SC_ERRMAX, "out of memory"), -1;
    if (mesh_fits(path, ends_with(path, ".obj"), err)) { free(path); return from_scene(s, err); }
    if (!(text = slurp(path, &len, err))) { free(path); return from_scene(s, err); }
    rc = ends_with(path, ".obj") ?
         sc_parse_obj_ix(text, len, path, &s->vtx, &s->nvtx, &s->idx, &s->ntri, err) :
         sc_parse_triangles(text, len, path, &s->tri, &s->ntri, err);
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
    const char *what[4] = {"segments", "hits", "summary", "polar"};
    const char *out[4] = {sc->out_segments, sc->out_hits, sc->out_summary, sc->out_polar};
    for (int i = 0; i < 4; i++) {
        if (!out[i]) continue;
        if (clash(sc, what[i], out[i], path, "the scene file", err)) return -1;
        for (int j = 0; j < i; j++)
            if (out[j] && (i == 3 || !h5_shared(sc, i, j)) && (clash(sc, what[i], out[i], out[j], "output", err) ||
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
