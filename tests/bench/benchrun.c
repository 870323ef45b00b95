/* benchrun.c -- time a command: run it N times with stdin from a file and stdout
 * to /dev/null, print the median wall time in milliseconds.  Used by the bench
 * scripts so that every figure is measured the same way, baseline included. */
#define _GNU_SOURCE
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: benchrun N INFILE CMD [ARGS...]\n");
        return 2;
    }
    int n = atoi(argv[1]);
    double *t = calloc(n > 0 ? n : 1, sizeof *t);
    for (int i = 0; i < n; i++) {
        double t0 = now_ms();
        pid_t pid = fork();
        if (pid == 0) {
            int in = open(argv[2], O_RDONLY), out = open("/dev/null", O_WRONLY);
            if (in < 0 || out < 0) _exit(127);
            dup2(in, 0);
            dup2(out, 1);
            execv(argv[3], argv + 3);
            _exit(127);
        }
        int st;
        waitpid(pid, &st, 0);
        t[i] = now_ms() - t0;
        if (!WIFEXITED(st) || WEXITSTATUS(st) != 0) {
            fprintf(stderr, "benchrun: %s failed\n", argv[3]);
            return 1;
        }
    }
    qsort(t, n, sizeof *t, cmp);
    printf("%.3f\n", t[n / 2]);
    free(t);
    return 0;
}
