# t_60_trace.sh -- the ray-tracing engine (src/trace/tr_*.c) through its table
# (trace.h): optics, meshes, lenses; normal and sanitizer builds of the module.
# The front end (scene files, the --trace dialogue) is tested in t_65_trace_front.sh.
for b in t_physics t_mesh t_lens t_extreme t_watertight t_isa; do
    unit "$TOP/build/obj/trace_tests/$b"
    unit "$TOP/build/asan/trace_tests/$b"
done
check "lensmat-trace.so exports trace_get_api" sh -c \
    "nm -D --defined-only '$TOP/build/lib/lensmat-trace.so' | grep -q ' T trace_get_api\$'"
