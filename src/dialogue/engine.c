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

/* dir/sub/lensmat-NAME.so: its handle; NULL if it is not there (*found = 0) or does
 * not load (*found = 1, why printed). */
static void *try_open(const char *dir, const char *sub, const char *name, int *found)
{
    char path[PATH_MAX + 64];
    void *h;
    snprintf(path, sizeof path, "%s%s/lensmat-%s.so", dir, sub, name);
    if (access(path, R_OK) != 0) return NULL;
    *found = 1;
    h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!h) fprintf(stderr, "lensmat: cannot load %s: %s\n", path, dlerror());
    return h;
}

void *lm_engine_load(const char *name)
{
    static const char *const subs[] = {"/lib", "/build/lib", "/../lib/lensmat"};
    char dir[PATH_MAX];
    const char *env = getenv("LENSMAT_LIBDIR");
    void *h = NULL;
    int found = 0, have_dir;

    for (int i = 0; i < nloaded; i++)
        if (!strcmp(loaded[i].name, name)) return loaded[i].handle;
    if (!disabled) {
        if (env && *env) h = try_open(env, "", name, &found);
        have_dir = exe_dir(dir, sizeof dir) == 0;
        for (size_t i = 0; !h && !found && have_dir && i < sizeof subs / sizeof *subs; i++)
            h = try_open(dir, subs[i], name, &found);
    }
    if (!h) {
        if (!found)
            fprintf(stderr, "lensmat: the %s engine (lensmat-%s.so) is not built or not "
                    "installed: not in $LENSMAT_LIBDIR, nor beside lensmat (lib, "
                    "build/lib, ../lib/lensmat); run make, or make install\n", name, name);
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
