/* unit_out.c -- the shared output writer (src/common/lm_out.c) on its own: modes of a
 * new file (0666 less the umask) and of a replaced one (kept), a replacement is a new
 * inode (renamed over, never rewritten), a given-up write leaves the old bytes and no
 * temporary, or its part as NAME.part; the temporary sits beside a link's target;
 * chains and loops of links, a folder, /dev/full, names at NAME_MAX.  Run by
 * tests/t_52_outputs.sh, optimised and under ASan/UBSan. */
#include <errno.h>
#include <dirent.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include "unit.h"
#include "common/lm_out.h"

static char dir[256];

static const char *at(const char *name)
{
    static char p[4][1024];
    static int k;
    k = (k + 1) % 4;
    snprintf(p[k], sizeof p[k], "%s/%s", dir, name);
    return p[k];
}

static char *slurp(const char *path)
{
    static char buf[4096];
    FILE *f = fopen(path, "r");
    size_t n = f ? fread(buf, 1, sizeof buf - 1, f) : 0;
    if (f) fclose(f);
    buf[n] = '\0';
    return f ? buf : NULL;
}

/* entries of a folder whose names hold "part" */
static int parts_in(const char *d)
{
    DIR *dd = opendir(d);
    struct dirent *e;
    int n = 0;
    while (dd && (e = readdir(dd)))
        if (strstr(e->d_name, "part")) n++;
    if (dd) closedir(dd);
    return n;
}

int main(void)
{
    char err[1200];
    struct stat st, st2;
    lm_out o;
    snprintf(dir, sizeof dir, "/tmp/unit_out.XXXXXX");
    if (!mkdtemp(dir)) { printf("FAIL mkdtemp\n"); return 1; }

    /* a new file: a plain create's modes */
    mode_t old = umask(027);
    CHECK(lm_out_save(at("new"), "abc\n", 4, err, sizeof err) == 0, "a new file: %s", err);
    CHECK(stat(at("new"), &st) == 0 && (st.st_mode & 0777) == 0640,
          "its modes are 0666 less the umask 027: %o", (unsigned)(st.st_mode & 0777));
    umask(old);

    /* replacing: the old file's modes, a new inode, the new bytes */
    chmod(at("new"), 0604);
    stat(at("new"), &st);
    CHECK(lm_out_save(at("new"), "defg\n", 5, err, sizeof err) == 0, "replace: %s", err);
    CHECK(stat(at("new"), &st2) == 0 && (st2.st_mode & 0777) == 0604, "modes kept: %o",
          (unsigned)(st2.st_mode & 0777));
    CHECK(st2.st_ino != st.st_ino, "a new inode: renamed over, never rewritten in place");
    CHECK(!strcmp(slurp(at("new")), "defg\n"), "the new bytes");

    /* giving up: the old bytes, no temporary; or its part kept as NAME.part */
    CHECK(lm_out_open(&o, at("new"), 0, err, sizeof err) == 0, "open: %s", err);
    CHECK(o.how == LM_OUT_TEMP && !strncmp(o.tmp, at("new.part."), strlen(at("new.part."))),
          "a unique temporary beside it: %s", o.tmp);
    fputs("half", o.f);
    lm_out_abort(&o, 0);
    CHECK(!strcmp(slurp(at("new")), "defg\n") && parts_in(dir) == 0,
          "abort: the old bytes, nothing left");
    CHECK(lm_out_open(&o, at("new"), 0, err, sizeof err) == 0, "open again: %s", err);
    fputs("half", o.f);
    lm_out_abort(&o, 1);
    CHECK(!strcmp(slurp(at("new")), "defg\n") && slurp(at("new.part")) &&
          !strcmp(slurp(at("new.part")), "half"), "abort keeping the part: NEW.part holds it");
    unlink(at("new.part"));

    /* two open at once: two temporaries, the last commit wins whole */
    lm_out a, b;
    CHECK(lm_out_open(&a, at("two"), 0, err, sizeof err) == 0 &&
          lm_out_open(&b, at("two"), 0, err, sizeof err) == 0 && strcmp(a.tmp, b.tmp),
          "two writers, two temporaries");
    fputs("from a\n", a.f);
    fputs("from b\n", b.f);
    CHECK(lm_out_commit(&b, err, sizeof err) == 0 && lm_out_commit(&a, err, sizeof err) == 0,
          "both commit");
    CHECK(!strcmp(slurp(at("two")), "from a\n") && parts_in(dir) == 0, "one whole output");

    /* links: a chain to a name not there; the temporary beside the target */
    mkdir(at("sub"), 0755);
    symlink("sub/c", at("b"));
    symlink("b", at("a"));
    CHECK(lm_out_open(&o, at("a"), 0, err, sizeof err) == 0, "through a chain: %s", err);
    CHECK(!strncmp(o.tmp, at("sub/c.part."), strlen(at("sub/c.part."))),
          "the temporary is in the target's folder: %s", o.tmp);
    fputs("chain\n", o.f);
    CHECK(lm_out_commit(&o, err, sizeof err) == 0, "commit: %s", err);
    CHECK(lstat(at("a"), &st) == 0 && S_ISLNK(st.st_mode) && lstat(at("b"), &st) == 0 &&
          S_ISLNK(st.st_mode) && !strcmp(slurp(at("sub/c")), "chain\n"),
          "the links stay, the target holds it");
    char *t = lm_out_target(at("a"));
    CHECK(t && !strcmp(t, at("sub/c")), "lm_out_target: %s", t ? t : "(null)");
    free(t);
    symlink("loop2", at("loop1"));
    symlink("loop1", at("loop2"));
    CHECK(lm_out_open(&o, at("loop1"), 0, err, sizeof err) < 0 && strstr(err, "symbolic links"),
          "a loop of links: %s", err);
    CHECK(lm_out_open(&o, at("sub"), 0, err, sizeof err) < 0 && strstr(err, "folder"),
          "a folder: %s", err);

    /* devices */
    CHECK(lm_out_save("/dev/full", "x\n", 2, err, sizeof err) < 0 && strstr(err, "No space"),
          "/dev/full: %s", err);
    CHECK(lm_out_save("/dev/null", "x\n", 2, err, sizeof err) == 0 && stat("/dev/null", &st) == 0 &&
          S_ISCHR(st.st_mode), "/dev/null written in place, still a device");
    CHECK(lm_out_open(&o, "/dev/null", LM_OUT_REGULAR, err, sizeof err) < 0 &&
          strstr(err, "regular"), "a mapped output refuses a device: %s", err);
    CHECK(lm_out_open(&o, "-", LM_OUT_REGULAR, err, sizeof err) < 0, "and standard output");
    CHECK(lm_out_open(&o, "", 0, err, sizeof err) < 0, "an empty name: %s", err);

    /* a name at NAME_MAX: NAME.part.XXXXXX would be too long, the folder's
     * .lensmat.XXXXXX is used */
    char longname[300];
    memset(longname, 'n', 255);
    longname[255] = '\0';
    CHECK(lm_out_save(at(longname), "long\n", 5, err, sizeof err) == 0 &&
          !strcmp(slurp(at(longname)), "long\n"), "a 255-byte name: %s", err);
    CHECK(parts_in(dir) == 0, "no temporary left");

    /* the whole folder cleaned */
    char cmd[400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) printf("FAIL cleaning %s\n", dir);
    return unit_failed();
}
