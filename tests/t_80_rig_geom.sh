# t_80_rig_geom.sh -- the rig engine's geometry (src/rig/rg_cornea.c ... rg_verify.c)
# through its table (rig.h), checked against independent formulas and against the
# trace engine; normal and sanitizer builds of both modules.
for b in t_geom; do
    unit "$TOP/build/obj/rig_tests/$b"
    unit "$TOP/build/asan/rig_tests/$b"
done
check "lensmat-rig.so exports rig_get_api alone" sh -c \
    "test \"\$(nm -D --defined-only '$TOP/build/lib/lensmat-rig.so' | grep ' T ' | awk '{print \$3}')\" = rig_get_api"
