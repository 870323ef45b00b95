/* fuzz_rig_geom.c -- libFuzzer target for the rig geometry: the input is rig-file
 * geometry lines (key and words) applied to the example geometry, then, if the
 * geometry passes its check, targets taken from the input's last bytes solved,
 * quantised, differentiated and traced forward.  Any crash, sanitizer report or hang
 * (the solver's loops are all bounded) is a bug. */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "rig/rig.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const rig_api *rg = rig_get_api(RIG_ABI);
    if (!rg || size > 4096) return 0;
    rg_geometry g;
    rg->geometry_default(&g);
    char buf[4097], err[512];
    memcpy(buf, data, size);
    buf[size] = 0;
    char *save = NULL;
    for (char *line = strtok_r(buf, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
        char *w[16], *s2 = NULL;
        int n = 0;
        for (char *t = strtok_r(line, " \t", &s2); t && n < 16; t = strtok_r(NULL, " \t", &s2))
            w[n++] = t;
        if (n) rg->geometry_key(&g, n, (const char *const *)w, err, sizeof err);
    }
    if (rg->geometry_check(&g, err, sizeof err)) return 0;
    for (int k = 0; k < 4; k++) {
        uint8_t a = size > (size_t)k * 2 ? data[size - 1 - k * 2] : 0;
        uint8_t b = size > (size_t)k * 2 + 1 ? data[size - 2 - k * 2] : 0;
        rg_target t = {k & 1, (k & 1) ? a / 25.0 : a * (1.6 / 255), b * (6.3 / 255)};
        rg_solution s;
        rg_quantised q;
        rg_beam bm;
        double J[4 * RG_NJOINTS], cond;
        int rc = rg->solve(&g, &t, NULL, &s, err, sizeof err);
        rg->forward(&g, &s.pose, &bm, err, sizeof err);
        if (rc == RG_OK) {
            rg->quantise(&g, &t, &s, &q, err, sizeof err);
            rg->jacobian(&g, &s.pose, J, &cond, err, sizeof err);
        }
    }
    return 0;
}
