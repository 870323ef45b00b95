/* engine.c -- dlopen-based loading of engine modules; see engine.h. */
#include <dlfcn.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "engine.h"

#define MAX_MODULES 8
static struct { const char *name; void *handle; } loaded[MAX_MODULES];
static int nloaded, disabled;

void lm_engine_disable(void) { disabled = 1; }

static void not_found(const char *name)
{
    fprintf(stderr, "lensmat: the %s engine (lensmat-%s.so) is not built or not installed: "
            "not in $LENSMAT_LIBDIR, nor beside lensmat (lib, build/lib, ../lib/lensmat); "
            "run make, or make install\n", name, name);
}

static int exe_dir(char *dir, size_t cap)
{
    ssize_t n = readlink("/proc/self/exe", dir, cap - 1);
    char *slash;
    if (n <= 0) return -1;
    dir[n] = '\0';
    slash = strrchr(dir, '/');
    if (!slash) return -1;
    *slash = '\0';
    return 0;
}

/* Where module `name` is: the first of the folders of engine.h that holds a readable
 * lensmat-NAME.so.  0 and its path, or -1. */
static int find_module(const char *name, char *path, size_t cap)
{
    static const char *const subs[] = {"/lib", "/build/lib", "/../lib/lensmat"};
    char dir[PATH_MAX];
    const char *env = getenv("LENSMAT_LIBDIR");
    if (disabled) return -1;
    if (env && *env) {
        snprintf(path, cap, "%s/lensmat-%s.so", env, name);
        if (access(path, R_OK) == 0) return 0;
    }
    if (exe_dir(dir, sizeof dir) != 0) return -1;
    for (size_t i = 0; i < sizeof subs / sizeof *subs; i++) {
        snprintf(path, cap, "%s%s/lensmat-%s.so", dir, subs[i], name);
        if (access(path, R_OK) == 0) return 0;
    }
    return -1;
}

int lm_engine_present(const char *name)
{
    char path[PATH_MAX + 64];
    for (int i = 0; i < nloaded; i++)
        if (!strcmp(loaded[i].name, name)) return 1;
    if (find_module(name, path, sizeof path) == 0) return 1;
    not_found(name);
    return 0;
}

void *lm_engine_load(const char *name)
{
    char path[PATH_MAX + 64];
    void *h;

    for (int i = 0; i < nloaded; i++)
        if (!strcmp(loaded[i].name, name)) return loaded[i].handle;
    if (find_module(name, path, sizeof path) != 0) { not_found(name); return NULL; }
    h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        fprintf(stderr, "lensmat: cannot load %s: %s\n", path, dlerror());
        return NULL;
    }
    if (nloaded < MAX_MODULES) {
        loaded[nloaded].name = name;
        loaded[nloaded].handle = h;
        nloaded++;
    }
    return h;
}

void *lm_engine_symbol(const char *name, const char *sym)
{
    void *h = lm_engine_load(name), *p;
    if (!h) return NULL;
    p = dlsym(h, sym);
    if (!p) fprintf(stderr, "lensmat: lensmat-%s.so lacks %s\n", name, sym);
    return p;
}
