/* rig_watchdog.c -- stands for the external heartbeat (charge-pump) circuit in the
 * SIGKILL test: a separate process, so killing lensmat does not stop it.  It maps
 * the simulator's chip state (LOG.state, rg_sim_shared), watches the heartbeat
 * toggle counter on the real clock (the simulator runs with sim_realtime) and models
 * the pump: light = laser line active and a toggle seen within the hold time.  When
 * the simulated process is gone it waits for the pump to run down and reports:
 *     seen_light=1 line_after=1 light_after=0 off_ms=5.1
 * (off_ms: from the last toggle seen to the light going off; the hold is the one the
 * simulator wrote from the rig file, pump=0 when it has no heartbeat line: then the
 * light stays as the laser line left it and is reported at once).  Usage:
 *     rig_watchdog STATEFILE [SECONDS]          exit 0 report printed, 1 timeout */
#define _GNU_SOURCE
#include <fcntl.h>
#include <signal.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#include "rig/rig.h"

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

int main(int argc, char **argv)
{
    double limit = argc > 2 ? atof(argv[2]) * 1e3 : 20e3, t0 = now_ms(), last_edge = 0,
           off_at = -1, hold;
    rg_sim_shared *sh = NULL;
    long long edges = -1;
    int seen = 0, light = 0, gone = 0;
    if (argc < 2) { fprintf(stderr, "usage: rig_watchdog STATEFILE [SECONDS]\n"); return 2; }
    while (!sh && now_ms() - t0 < limit) {     /* lensmat creates it when the chip opens */
        int fd = open(argv[1], O_RDONLY);
        struct stat st;
        if (fd >= 0 && (fstat(fd, &st) || st.st_size < (off_t)sizeof *sh)) { close(fd); fd = -1; }
        if (fd >= 0) {
            void *p = mmap(NULL, sizeof *sh, PROT_READ, MAP_SHARED, fd, 0);
            close(fd);
            if (p != MAP_FAILED && !memcmp(((rg_sim_shared *)p)->magic, "lmrigsim", 8)) sh = p;
            else if (p != MAP_FAILED) munmap(p, sizeof *sh);
        }
        if (!sh) usleep(2000);
    }
    if (!sh) { printf("watchdog: no state file\n"); return 1; }
    while (now_ms() - t0 < limit) {
        double t = now_ms();
        hold = sh->timeout_ns / 1e6;        /* set just after the file appears */
        if (sh->heartbeat_edges != edges) { edges = sh->heartbeat_edges; last_edge = t; }
        /* no pump (no heartbeat line): nothing cuts the light but the laser line */
        light = sh->laser && (!sh->pump || t - last_edge <= hold);
        seen |= light;
        if (!gone && kill(sh->pid, 0) && errno == ESRCH) gone = 1;
        if (gone && (!light || !sh->pump)) { off_at = t; break; }
        usleep(100);
    }
    if (off_at < 0) { printf("watchdog: timed out\n"); return 1; }
    printf("seen_light=%d line_after=%d light_after=%d off_ms=%.2f hold_ms=%.2f pump=%d\n",
           seen, (int)sh->laser, light, last_edge > 0 ? off_at - last_edge : -1, hold,
           (int)sh->pump);
    return 0;
}
