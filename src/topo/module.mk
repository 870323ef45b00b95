# src/topo/module.mk -- the topography pipeline: build/lib/lensmat-topo.so (every
# src/topo/tp_*.c) and its sanitizer twin, which drive the rig, trace, imaging and
# cornea engines through the tables the caller hands in (it links none of them), and
# its tests (tests/topo/t_*.c, run by tests/t_93_topo.sh).  lensmat never links it.

TP_SRC   := $(wildcard src/topo/tp_*.c)
TP_OBJ   := $(patsubst src/%.c,build/obj/%.o,$(TP_SRC))
TP_SOBJ  := $(patsubst src/%.c,build/asan/%.o,$(TP_SRC))
TP_LIBS  := -lm -pthread

build/obj/topo/%.o: src/topo/%.c $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -fPIC -fvisibility=hidden -MMD -MP -c $< -o $@
build/asan/topo/%.o: src/topo/%.c $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -fPIC -fvisibility=hidden -MMD -MP -c $< -o $@

build/lib/lensmat-topo.so: $(TP_OBJ)
	@mkdir -p $(@D)
	$(CC) -shared $(OPT) -o $@ $(TP_OBJ) $(TP_LIBS)
build/asan/lib/lensmat-topo.so: $(TP_SOBJ)
	@mkdir -p $(@D)
	$(CC) -shared $(SAN) -o $@ $(TP_SOBJ) $(TP_LIBS)

all: build/lib/lensmat-topo.so
MODULE_TEST_BINS  += build/lib/lensmat-topo.so build/asan/lib/lensmat-topo.so
MODULE_BENCH_BINS += build/lib/lensmat-topo.so
-include $(TP_OBJ:.o=.d) $(TP_SOBJ:.o=.d)

# tests/topo/t_*.c: the engines through their tables (cornea, rig; trace for the rig)
TP_TESTS := $(filter-out tests/topo/t_drift.c,$(wildcard tests/topo/t_*.c))
TP_TBIN  := $(patsubst tests/topo/%.c,build/obj/topo_tests/%,$(TP_TESTS)) \
            $(patsubst tests/topo/%.c,build/asan/topo_tests/%,$(TP_TESTS))
build/obj/topo_tests/%: tests/topo/%.c build/lib/lensmat-cornea.so build/lib/lensmat-rig.so \
                        build/lib/lensmat-trace.so build/lib/lensmat-topo.so src/cornea/cornea.h \
                        src/rig/rig.h src/topo/topo.h tests/cornea/ct.h
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -Itests -o $@ $< build/lib/lensmat-cornea.so \
	    build/lib/lensmat-rig.so build/lib/lensmat-trace.so build/lib/lensmat-topo.so \
	    -Wl,-rpath,$(abspath build/lib) -lm
build/asan/topo_tests/%: tests/topo/%.c build/asan/lib/lensmat-cornea.so build/asan/lib/lensmat-rig.so \
                         build/asan/lib/lensmat-trace.so build/asan/lib/lensmat-topo.so \
                         src/cornea/cornea.h src/rig/rig.h src/topo/topo.h tests/cornea/ct.h
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -Itests -o $@ $< build/asan/lib/lensmat-cornea.so \
	    build/asan/lib/lensmat-rig.so build/asan/lib/lensmat-trace.so build/asan/lib/lensmat-topo.so \
	    -Wl,-rpath,$(abspath build/asan/lib) -lm
MODULE_TEST_BINS  += $(TP_TBIN)
MODULE_BENCH_BINS += build/obj/topo_tests/t_topo build/obj/topo_tests/t_zone

# tests/topo/t_drift.c: the pipeline itself (topo_api.measure on the simulated chip)
build/obj/topo_tests/t_drift: tests/topo/t_drift.c build/lib/lensmat-topo.so build/lib/lensmat-cornea.so \
                              build/lib/lensmat-rig.so src/topo/topo.h src/rig/rig.h
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -o $@ $< build/lib/lensmat-topo.so build/lib/lensmat-cornea.so \
	    build/lib/lensmat-rig.so -Wl,-rpath,$(abspath build/lib) -lm
build/asan/topo_tests/t_drift: tests/topo/t_drift.c build/asan/lib/lensmat-topo.so \
                               build/asan/lib/lensmat-cornea.so build/asan/lib/lensmat-rig.so \
                               src/topo/topo.h src/rig/rig.h
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -o $@ $< build/asan/lib/lensmat-topo.so build/asan/lib/lensmat-cornea.so \
	    build/asan/lib/lensmat-rig.so -Wl,-rpath,$(abspath build/asan/lib) -lm
MODULE_TEST_BINS  += build/obj/topo_tests/t_drift build/asan/topo_tests/t_drift
MODULE_BENCH_BINS += build/obj/topo_tests/t_drift
