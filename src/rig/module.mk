# src/rig/module.mk -- the cornea-rig engine module: build/lib/lensmat-rig.so (every
# src/rig/rg_*.c; libgpiod 1.6 for the machine, GSL for the geometry's linear
# algebra) and its sanitizer twin build/asan/lib/lensmat-rig.so, the engine's tests
# (tests/rig/t_*.c, both builds, run by tests/t_8x_rig*.sh) and benchmarks
# (tests/rig/bench_*.c, scripts/bench_rig.sh).  Tests and benches talk to the module
# through rig.h (and trace.h for the independent check) only.  lensmat never links it.

RIG_SRC   := $(wildcard src/rig/rg_*.c)
RIG_OBJ   := $(patsubst src/%.c,build/obj/%.o,$(RIG_SRC))
RIG_SOBJ  := $(patsubst src/%.c,build/asan/%.o,$(RIG_SRC))
RIG_LIBS  := -lgpiod -lgsl -lgslcblas -lm -pthread
RIG_TESTS := $(wildcard tests/rig/t_*.c)
RIG_BENCH := $(wildcard tests/rig/bench_*.c)
RIG_TBIN  := $(patsubst tests/rig/%.c,build/obj/rig_tests/%,$(RIG_TESTS)) \
             $(patsubst tests/rig/%.c,build/asan/rig_tests/%,$(RIG_TESTS))
RIG_BBIN  := $(patsubst tests/rig/%.c,build/obj/rig_tests/%,$(RIG_BENCH))
# The beam (rg_spots.c) calls the paraxial engine through paraxial.h: its objects come
# from the trace module's archive of hidden position-independent objects (rules in
# src/trace/module.mk; only what is called is linked, nothing of it is exported).
RIG_PXA   := build/obj/trace/px/libpx.a
RIG_SPXA  := build/asan/trace/px/libpx.a

# Module objects: -fPIC, internal symbols hidden (only rig_get_api is exported).
build/obj/rig/%.o: src/rig/%.c $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -fPIC -fvisibility=hidden -pthread -MMD -MP -c $< -o $@
build/asan/rig/%.o: src/rig/%.c $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -fPIC -fvisibility=hidden -pthread -MMD -MP -c $< -o $@

build/lib/lensmat-rig.so: $(RIG_OBJ) $(RIG_PXA) $(LM_COMMON_PIC)
	@mkdir -p $(@D)
	$(CC) -shared $(OPT) -o $@ $(RIG_OBJ) $(RIG_PXA) $(LM_COMMON_PIC) $(RIG_LIBS)
build/asan/lib/lensmat-rig.so: $(RIG_SOBJ) $(RIG_SPXA) $(LM_COMMON_SPIC)
	@mkdir -p $(@D)
	$(CC) -shared $(SAN) -o $@ $(RIG_SOBJ) $(RIG_SPXA) $(LM_COMMON_SPIC) $(RIG_LIBS)

# Tests link both modules (the trace engine checks the geometry independently).
build/obj/rig_tests/%: tests/rig/%.c build/lib/lensmat-rig.so build/lib/lensmat-trace.so \
                       src/rig/rig.h src/trace/trace.h $(wildcard tests/rig/*.h)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -pthread -Itests -o $@ $< build/lib/lensmat-rig.so \
	    build/lib/lensmat-trace.so -Wl,-rpath,$(abspath build/lib) -lm
build/asan/rig_tests/%: tests/rig/%.c build/asan/lib/lensmat-rig.so \
                        build/asan/lib/lensmat-trace.so src/rig/rig.h src/trace/trace.h \
                        $(wildcard tests/rig/*.h)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -pthread -Itests -o $@ $< build/asan/lib/lensmat-rig.so \
	    build/asan/lib/lensmat-trace.so -Wl,-rpath,$(abspath build/asan/lib) -lm

all: build/lib/lensmat-rig.so
MODULE_TEST_BINS  += build/lib/lensmat-rig.so build/asan/lib/lensmat-rig.so $(RIG_TBIN)
MODULE_BENCH_BINS += build/lib/lensmat-rig.so $(RIG_BBIN)
-include $(RIG_OBJ:.o=.d) $(RIG_SOBJ:.o=.d)

# libFuzzer target for the geometry (tests/rig/fuzz_rig_geom.c): rig-file geometry
# lines, then solve / quantise / Jacobian / forward on what they give; a short run in
# t_80, a long one in `make fuzz`.
build/fuzz_rig_geom: tests/rig/fuzz_rig_geom.c $(wildcard src/rig/rg_*.c src/rig/*.h) | $(DEPS)
	@mkdir -p $(@D)
	$(CLANG) $(BASE) -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
	    -o $@ tests/rig/fuzz_rig_geom.c $(wildcard src/rig/rg_*.c) src/common/lm_out.c \
	    $(wildcard src/paraxial/*.c) -lgpiod -lgsl \
	    -lgslcblas -lm -pthread
fuzz-rig-geom: build/fuzz_rig_geom
	@mkdir -p build/fuzz-rig-geom-corpus
	build/fuzz_rig_geom -max_total_time=$${FUZZ_SECONDS:-600} -timeout=5 \
	    build/fuzz-rig-geom-corpus tests/fuzz-rig-geom
MODULE_TEST_BINS += build/fuzz_rig_geom
fuzz: fuzz-rig-geom
.PHONY: fuzz-rig-geom
