/* fuzz_rig_file.c -- libFuzzer target for the rig-file reader (src/rig/rg_file.c,
 * with the geometry half's keys): any bytes must give 0 and a consistent rig, or an
 * error message naming the file; never a crash, a hang or a read past the input. */
#include <assert.h>
#include <stdint.h>
#include <string.h>
#include "rig/rig.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const rig_api *rg;
    static rg_rig rig;
    char err[RG_ERRMAX];
    int rc;
    if (!rg) rg = rig_get_api(RIG_ABI);
    err[0] = 0;
    rc = rg->rig_parse((const char *)data, size, "fuzz.rig", &rig, err, sizeof err);
    assert(memchr(err, 0, sizeof err));
    if (rc) {
        assert(rc == RG_EINVAL && !strncmp(err, "fuzz.rig", 8));
        return 0;
    }
    assert(rig.chip[0] && rig.laser.offset >= 0 && rig.interlock.offset >= 0);
    for (int j = 0; j < RG_NJOINTS; j++) {
        const rg_axis *x = &rig.axis[j];
        assert(x->min < x->max && x->steps_per > 0 && x->speed > 0 && x->accel > 0);
        assert(x->step.offset >= 0 && x->dir.offset >= 0);
        assert(x->step.offset != rig.laser.offset && x->dir.offset != rig.laser.offset);
    }
    return 0;
}
