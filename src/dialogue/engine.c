/* engine.c -- dlopen-based loading of engine modules; see engine.h. */
#include <dlfcn.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "engine.h"

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

static void *try_open(const char *dir, const char *sub, const char *name)
{
    char path[PATH_MAX + 64];
    snprintf(path, sizeof path, "%s%s/lensmat-%s.so", dir, sub, name);
    if (access(path, R_OK) != 0) return NULL;
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!h) fprintf(stderr, "lensmat: cannot load %s: %s\n", path, dlerror());
    return h;
}

void *lm_engine_symbol(const char *name, const char *sym)
{
    char dir[PATH_MAX];
    const char *env = getenv("LENSMAT_LIBDIR");
    void *h = NULL, *p;

    if (env && *env) h = try_open(env, "", name);
    if (!h && exe_dir(dir, sizeof dir) == 0) {
        h = try_open(dir, "/lib", name);
        if (!h) h = try_open(dir, "/build/lib", name);
    }
    if (!h) {
        fprintf(stderr, "lensmat: the %s engine (lensmat-%s.so) is not built or not "
                "found; run make\n", name, name);
        return NULL;
    }
    p = dlsym(h, sym);
    if (!p) fprintf(stderr, "lensmat: lensmat-%s.so lacks %s\n", name, sym);
    return p;
}
