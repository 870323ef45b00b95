# src/design/module.mk -- the lens-design pipeline: build/lib/lensmat-design.so (every
# src/design/ds_*.c; GSL least squares) with the lens model (src/lens) and the paraxial
# engine (src/paraxial) inside as hidden position-independent objects (nothing of them
# exported), and its sanitizer twin; the real rays come from lensmat-trace.so through
# the trace_api table its caller hands in.  Tests: tests/design/t_*.c (both builds, run
# by tests/t_44_tol_tilt.sh, t_46_optimise.sh and t_47_tolerance.sh), linked to the two
# modules; t_toltilt is also a bench binary (bench_design.sh: tol_tilt_sens_rel_err).
DS_SRC   := $(wildcard src/design/ds_*.c)
DS_LX    := $(wildcard src/lens/*.c src/paraxial/*.c)
DS_OBJ   := $(patsubst src/%.c,build/obj/%.o,$(DS_SRC)) \
            $(patsubst src/%.c,build/obj/design/lx/%.o,$(DS_LX))
DS_SOBJ  := $(patsubst src/%.c,build/asan/%.o,$(DS_SRC)) \
            $(patsubst src/%.c,build/asan/design/lx/%.o,$(DS_LX))
DS_LIBS  := -lgsl -lgslcblas -lm
DS_TESTS := $(wildcard tests/design/t_*.c)
DS_TBIN  := $(patsubst tests/design/%.c,build/obj/design_tests/%,$(DS_TESTS)) \
            $(patsubst tests/design/%.c,build/asan/design_tests/%,$(DS_TESTS))

build/obj/design/%.o: src/design/%.c $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -fPIC -fvisibility=hidden -MMD -MP -c $< -o $@
build/asan/design/%.o: src/design/%.c $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -fPIC -fvisibility=hidden -MMD -MP -c $< -o $@
build/obj/design/lx/%.o: src/%.c $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -fPIC -fvisibility=hidden -MMD -MP -c $< -o $@
build/asan/design/lx/%.o: src/%.c $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -fPIC -fvisibility=hidden -MMD -MP -c $< -o $@

build/lib/lensmat-design.so: $(DS_OBJ)
	@mkdir -p $(@D)
	$(CC) -shared $(OPT) -o $@ $(DS_OBJ) $(DS_LIBS)
build/asan/lib/lensmat-design.so: $(DS_SOBJ)
	@mkdir -p $(@D)
	$(CC) -shared $(SAN) -o $@ $(DS_SOBJ) $(DS_LIBS)

build/obj/design_tests/%: tests/design/%.c build/lib/lensmat-design.so build/lib/lensmat-trace.so \
                          src/design/design.h $(wildcard tests/design/*.h)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -Itests -o $@ $< build/lib/lensmat-design.so build/lib/lensmat-trace.so \
	    -Wl,-rpath,$(abspath build/lib) -lm
build/asan/design_tests/%: tests/design/%.c build/asan/lib/lensmat-design.so \
                           build/asan/lib/lensmat-trace.so src/design/design.h \
                           $(wildcard tests/design/*.h)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -Itests -o $@ $< build/asan/lib/lensmat-design.so \
	    build/asan/lib/lensmat-trace.so -Wl,-rpath,$(abspath build/asan/lib) -lm

all: build/lib/lensmat-design.so
MODULE_TEST_BINS  += build/lib/lensmat-design.so build/asan/lib/lensmat-design.so $(DS_TBIN)
MODULE_BENCH_BINS += build/lib/lensmat-design.so build/obj/design_tests/t_toltilt
-include $(DS_OBJ:.o=.d) $(DS_SOBJ:.o=.d)
