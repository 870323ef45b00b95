/* vm_sim.h -- shared by the gpio-vm tests (vm_rig.c, vm_safety.c): the clock, and the
 * gpio-sim chip's sysfs lines under sim_dir ($GPIO_SIM/sim_gpioN/value: what the
 * program drives; pull: drives an input). */
#ifndef VM_SIM_H
#define VM_SIM_H
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <time.h>
#include <unistd.h>

#pragma GCC diagnostic ignored "-Wunused-function"

static const char *sim_dir;

static int64_t now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)t.tv_sec * 1000 + t.tv_nsec / 1000000;
}

static void msleep(int ms) { usleep((useconds_t)ms * 1000); }

/* The level the program drives on `line`: 1, 0, or -1 (unreadable). */
static int sysval(int line)
{
    char p[300], b[8] = "";
    int fd;
    snprintf(p, sizeof p, "%s/sim_gpio%d/value", sim_dir, line);
    fd = open(p, O_RDONLY);
    if (fd < 0) return -1;
    if (read(fd, b, sizeof b - 1) < 1) b[0] = '?';
    close(fd);
    return b[0] == '1' ? 1 : b[0] == '0' ? 0 : -1;
}

/* Drive input `line` high (up) or low, as a switch would. */
static void pull(int line, int up)
{
    char p[300];
    FILE *f;
    snprintf(p, sizeof p, "%s/sim_gpio%d/pull", sim_dir, line);
    if ((f = fopen(p, "w"))) { fputs(up ? "pull-up" : "pull-down", f); fclose(f); }
}
#endif
