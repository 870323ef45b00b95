# t_90_cornea.sh -- the cornea analysis engine (src/cornea/): the fit against synthetic
# truth from the rig geometry's forward model (t_fit), the stiff and degenerate scans
# (t_stiff), the final parameters traced through the trace engine (t_trace); normal
# and sanitizer builds.
for b in t_fit t_stiff t_trace; do
    unit "$TOP/build/obj/cornea_tests/$b"
    unit "$TOP/build/asan/cornea_tests/$b"
done
check "lensmat-cornea.so exports cornea_get_api alone" sh -c \
    "test \"\$(nm -D --defined-only '$TOP/build/lib/lensmat-cornea.so' | grep ' T ' | awk '{print \$3}')\" = cornea_get_api"
