# src/cornea/module.mk -- the cornea analysis engine: build/lib/lensmat-cornea.so
# (every src/cornea/cn_*.c; GSL least squares and SVD) and its sanitizer twin, the
# engine's tests (tests/cornea/t_*.c, both builds, run by tests/t_90_cornea.sh) and
# benchmark (tests/cornea/bench_*.c, scripts/bench_cornea.sh).  Tests and benches
# reach the rig only through rig.h's table (lensmat-rig.so).  lensmat never links it.

CN_SRC   := $(wildcard src/cornea/cn_*.c)
CN_OBJ   := $(patsubst src/%.c,build/obj/%.o,$(CN_SRC))
CN_SOBJ  := $(patsubst src/%.c,build/asan/%.o,$(CN_SRC))
CN_LIBS  := -lgsl -lgslcblas -lm -pthread
CN_TESTS := $(wildcard tests/cornea/t_*.c)
CN_BENCH := $(wildcard tests/cornea/bench_*.c)
CN_TBIN  := $(patsubst tests/cornea/%.c,build/obj/cornea_tests/%,$(CN_TESTS)) \
            $(patsubst tests/cornea/%.c,build/asan/cornea_tests/%,$(CN_TESTS))
CN_BBIN  := $(patsubst tests/cornea/%.c,build/obj/cornea_tests/%,$(CN_BENCH))

build/obj/cornea/%.o: src/cornea/%.c $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -fPIC -fvisibility=hidden -MMD -MP -c $< -o $@
build/asan/cornea/%.o: src/cornea/%.c $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -fPIC -fvisibility=hidden -MMD -MP -c $< -o $@

build/lib/lensmat-cornea.so: $(CN_OBJ)
	@mkdir -p $(@D)
	$(CC) -shared $(OPT) -o $@ $(CN_OBJ) $(CN_LIBS)
build/asan/lib/lensmat-cornea.so: $(CN_SOBJ)
	@mkdir -p $(@D)
	$(CC) -shared $(SAN) -o $@ $(CN_SOBJ) $(CN_LIBS)

build/obj/cornea_tests/%: tests/cornea/%.c build/lib/lensmat-cornea.so build/lib/lensmat-trace.so \
                          build/lib/lensmat-rig.so src/cornea/cornea.h src/rig/rig.h \
                          $(wildcard tests/cornea/*.h)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -Itests -o $@ $< build/lib/lensmat-cornea.so \
	    build/lib/lensmat-rig.so build/lib/lensmat-trace.so -Wl,-rpath,$(abspath build/lib) -lm
build/asan/cornea_tests/%: tests/cornea/%.c build/asan/lib/lensmat-cornea.so build/asan/lib/lensmat-trace.so \
                           build/asan/lib/lensmat-rig.so src/cornea/cornea.h \
                           src/rig/rig.h $(wildcard tests/cornea/*.h)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -Itests -o $@ $< build/asan/lib/lensmat-cornea.so \
	    build/asan/lib/lensmat-rig.so build/asan/lib/lensmat-trace.so -Wl,-rpath,$(abspath build/asan/lib) -lm

all: build/lib/lensmat-cornea.so
MODULE_TEST_BINS  += build/lib/lensmat-cornea.so build/asan/lib/lensmat-cornea.so $(CN_TBIN)
MODULE_BENCH_BINS += build/lib/lensmat-cornea.so $(CN_BBIN)
-include $(CN_OBJ:.o=.d) $(CN_SOBJ:.o=.d)
# The scan bench's plot (scripts/bench_cornea_scan.sh): the imaging engine's plot call.
build/obj/cornea_tests/scan_plot: tests/cornea/scan_plot.c build/lib/lensmat-imaging.so \
                                  src/imaging/imaging.h
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -o $@ $< build/lib/lensmat-imaging.so \
	    -Wl,-rpath,$(abspath build/lib) -lm
MODULE_BENCH_BINS += build/obj/cornea_tests/scan_plot

# the many-eyes study's plot (scripts/cornea-study.sh), on the imaging engine
build/obj/cornea_tools/study_plot: tests/cornea/study_plot.c build/lib/lensmat-imaging.so \
                                   src/imaging/imaging.h
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -o $@ $< -L$(abspath build/lib) -l:lensmat-imaging.so \
	    -Wl,-rpath,$(abspath build/lib) -lm
all: build/obj/cornea_tools/study_plot
MODULE_TEST_BINS += build/obj/cornea_tools/study_plot
