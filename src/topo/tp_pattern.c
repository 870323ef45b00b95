/* tp_pattern.c -- the scan patterns of a topography measurement: a sunflower
 * (Vogel) spiral, concentric rings, a square grid, as rig targets (theta, phi) about
 * the nominal cornea's centre of curvature. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "tp_int.h"

#define PI 3.14159265358979323846
#define GOLDEN 2.399963229728653        /* the golden angle, rad */

static int by_radius(const void *a, const void *b)
{
    const rg_target *x = a, *y = b;
    if (x->a != y->a) return x->a < y->a ? -1 : 1;
    return x->b < y->b ? -1 : x->b > y->b;
}

int tp_pattern(int pattern, int n, double zone, rg_target *t)
{
    if (n <= 0 || !(zone > 0)) return 0;
    if (pattern == TP_RINGS) {
        /* concentric rings, points per ring growing with the ring's radius (ring i of
           nr gets a share i / (1 + 2 + ... + nr)), each ring started half a step
           further round than the last */
        int nr = (int)floor(sqrt(n / PI) + 0.5), k = 0;
        if (nr < 1) nr = 1;
        double total = nr * (nr + 1) / 2.0;
        for (int i = 1; i <= nr; i++) {
            int m = (int)floor(n * (i * (i + 1) / 2.0) / total + 0.5) -
                    (int)floor(n * ((i - 1) * i / 2.0) / total + 0.5);
            for (int j = 0; j < m && k < n; j++, k++) {
                t[k].kind = RG_T_ANGLES;
                t[k].a = zone * i / nr;
                t[k].b = fmod(2 * PI * (j + 0.5 * (i & 1)) / m, 2 * PI);
            }
        }
        return k;
    }
    if (pattern == TP_GRID) {
        /* a square grid in (theta cos phi, theta sin phi), spacing shrunk until the
           disc holds n points; the n nearest the centre, centre first */
        double d = zone * sqrt(PI / n) * 1.05;
        for (int tries = 0; tries < 200; tries++, d *= 0.99) {
            int half = (int)ceil(zone / d), k = 0;
            for (int i = -half; i <= half; i++)
                for (int j = -half; j <= half; j++) {
                    double x = i * d, y = j * d, r = hypot(x, y);
                    if (r > zone * (1 + 1e-12)) continue;
                    if (k < n) {
                        t[k].kind = RG_T_ANGLES;
                        t[k].a = r;
                        t[k].b = r > 0 ? fmod(atan2(y, x) + 2 * PI, 2 * PI) : 0;
                    }
                    k++;
                }
            if (k >= n) {
                /* more than n: keep the n nearest (recount in order, sorted) */
                rg_target *all = malloc(sizeof *all * (size_t)k);
                if (!all) return 0;
                int q = 0;
                for (int i = -half; i <= half; i++)
                    for (int j = -half; j <= half; j++) {
                        double x = i * d, y = j * d, r = hypot(x, y);
                        if (r > zone * (1 + 1e-12)) continue;
                        all[q].kind = RG_T_ANGLES;
                        all[q].a = r;
                        all[q].b = r > 0 ? fmod(atan2(y, x) + 2 * PI, 2 * PI) : 0;
                        q++;
                    }
                qsort(all, (size_t)q, sizeof *all, by_radius);
                memcpy(t, all, sizeof *t * (size_t)n);
                free(all);
                return n;
            }
        }
        return 0;
    }
    for (int k = 0; k < n; k++) {      /* sunflower (Vogel) spiral */
        t[k].kind = RG_T_ANGLES;
        t[k].a = zone * sqrt((k + 0.5) / n);
        t[k].b = fmod(k * GOLDEN, 2 * PI);
    }
    return n;
}

