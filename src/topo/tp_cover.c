/* tp_cover.c -- how much of each clinical zone a measurement covers (issue 19 item 4):
 * the zones of 0-3, 3-6, 6-9 and 9-10 mm diameter about the surface-from-the-data's
 * axis (the reference fit's eye frame), a point of a zone counted as covered where the
 * maps show data (cornea_api.zcovered: a spot within the map's gap, 2.5 spot
 * spacings), and the zone diameter covered: the largest whose every ring, in steps of
 * 0.1 mm diameter, lies >= 95 % within the data (a ring that is not is where the zone
 * ends, a hole inside it included). */
#include <math.h>
#include <string.h>
#include "tp_int.h"

#define PI 3.14159265358979323846

const double tp_zone_edges[TP_NZONE + 1] = {0, 3, 6, 9, 10};

void tp_cover_zones(const tp_run *r, tp_cover *c)
{
    const cn_zfit *z = r->zf;
    const cornea_api *cn = r->cn;
    memset(c, 0, sizeof *c);
    if (!r->have_z || !z) return;
    /* area: a 0.05 mm grid over each annulus */
    const double step = 0.05;
    int in[TP_NZONE] = {0}, all[TP_NZONE] = {0};
    const int half = (int)ceil(0.5 * tp_zone_edges[TP_NZONE] / step);
    for (int i = -half; i <= half; i++)
        for (int j = -half; j <= half; j++) {
            double x = (i + 0.5) * step, y = (j + 0.5) * step, d = 2 * hypot(x, y);
            for (int k = 0; k < TP_NZONE; k++)
                if (d >= tp_zone_edges[k] && d < tp_zone_edges[k + 1]) {
                    all[k]++;
                    in[k] += cn->zcovered(z, x, y);
                }
        }
    for (int k = 0; k < TP_NZONE; k++) c->frac[k] = all[k] ? (double)in[k] / all[k] : 0;
    for (int i = 0; i < z->npts; i++) {
        double d = 2 * hypot(z->xy[2 * i], z->xy[2 * i + 1]);
        for (int k = 0; k < TP_NZONE; k++)
            if (d >= tp_zone_edges[k] && d < tp_zone_edges[k + 1]) c->nspots[k]++;
    }
    /* the zone diameter: rings of 0.1 mm diameter steps, 720 points each */
    c->zone_mm = 0;
    for (int ring = 1; ring <= 120; ring++) {
        double rr = 0.05 * ring;
        int hit = 0;
        for (int a = 0; a < 720; a++)
            hit += cn->zcovered(z, rr * cos(2 * PI * a / 720), rr * sin(2 * PI * a / 720));
        if (hit < 0.95 * 720) break;
        c->zone_mm = 2 * rr;
    }
    c->valid = 1;
}
