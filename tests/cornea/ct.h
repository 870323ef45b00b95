/* ct.h -- shared by the cornea engine's tests and bench: the engine tables, the
 * synthetic eye of issue 12 section 3 and small checking helpers. */
#ifndef CT_H
#define CT_H
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "rig/rig.h"
#include "cornea/cornea.h"

#pragma GCC diagnostic ignored "-Wunused-function"
#define CT_PI 3.14159265358979323846
#define CT_DEG (CT_PI / 180)
#define CT_PITCH 0.005            /* detector pixel pitch (mm) */
#define CT_SIGMA (0.04 * CT_PITCH) /* centroid noise of the imaging benchmark */

static int ct_fails;
static void ct_check(int ok, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
#include <stdarg.h>
static void ct_check(int ok, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    printf(ok ? "PASS " : "FAIL ");
    vprintf(fmt, ap);
    printf("\n");
    va_end(ap);
    if (!ok) ct_fails++;
}

static const rig_api *ct_rig(void)
{
    const rig_api *a = rig_get_api(RIG_ABI);
    if (!a) { printf("FAIL no rig table\n"); exit(1); }
    return a;
}
static const cornea_api *ct_cn(void)
{
    const cornea_api *a = cornea_get_api(CORNEA_ABI);
    if (!a) { printf("FAIL no cornea table\n"); exit(1); }
    return a;
}

/* The synthetic eye: mean apex radius R (mean K 337.5/R), cylinder cyl D with the
 * steep meridian at flat_axis + 90 deg, Q on both meridians, apex moved by
 * (dx, dy, 0) and tilted by rx, ry (rad). */
static rg_cornea ct_eye(const rig_api *rg, const rg_geometry *g, double R, double Q,
                        double cyl, double flat_axis, double dx, double dy, double rx,
                        double ry)
{
    rg_cornea c = g->cornea;
    double km = 337.5 / R;
    c.model = RG_BICONIC;
    c.R = 337.5 / (km - cyl / 2);
    c.R2 = 337.5 / (km + cyl / 2);
    c.Q = c.Q2 = Q;
    c.axis = flat_axis;
    c.zone = 0;
    double at[3] = {g->cornea.trans[0] + dx, g->cornea.trans[1] + dy, g->cornea.trans[2]};
    rg->eye_pose(&c, rx, ry, 0, at);
    return c;
}
/* Issue 12 section 3: R 7.8, Q -0.26, 0.75 D with the rule, 0.2 mm, 2 deg. */
static rg_cornea ct_eye12(const rig_api *rg, const rg_geometry *g)
{
    return ct_eye(rg, g, 7.8, -0.26, 0.75, 0, 0.2 * cos(30 * CT_DEG),
                  0.2 * sin(30 * CT_DEG), 2 * CT_DEG, 0);
}
static double ct_axis_err(double a, double b) { return fabs(remainder(a - b, 180.0)); }
#endif
