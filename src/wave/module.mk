# src/wave/module.mk -- the wave-optics engine: build/lib/lensmat-wave.so (every
# src/wave/wv_*.c; FFTW 3 for the PSF and MTF, GSL for the Zernike least squares,
# Gauss-Legendre nodes and, in the tests, Bessel functions) and its sanitizer twin,
# the engine's tests (tests/wave/t_*.c, both builds, run by tests/t_94_wave.sh) and
# benchmark (tests/wave/bench_*.c, scripts/bench_wave.sh).  lensmat never links it.

WV_SRC   := $(wildcard src/wave/wv_*.c)
WV_OBJ   := $(patsubst src/%.c,build/obj/%.o,$(WV_SRC))
WV_SOBJ  := $(patsubst src/%.c,build/asan/%.o,$(WV_SRC))
WV_LIBS  := -lfftw3 -lgsl -lgslcblas -lm
WV_TESTS := $(wildcard tests/wave/t_*.c)
WV_BENCH := $(wildcard tests/wave/bench_*.c)
WV_TBIN  := $(patsubst tests/wave/%.c,build/obj/wave_tests/%,$(WV_TESTS)) \
            $(patsubst tests/wave/%.c,build/asan/wave_tests/%,$(WV_TESTS))
WV_BBIN  := $(patsubst tests/wave/%.c,build/obj/wave_tests/%,$(WV_BENCH))

build/obj/wave/%.o: src/wave/%.c | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -fPIC -fvisibility=hidden -MMD -MP -c $< -o $@
build/asan/wave/%.o: src/wave/%.c | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -fPIC -fvisibility=hidden -MMD -MP -c $< -o $@

build/lib/lensmat-wave.so: $(WV_OBJ)
	@mkdir -p $(@D)
	$(CC) -shared $(OPT) -o $@ $(WV_OBJ) $(WV_LIBS)
build/asan/lib/lensmat-wave.so: $(WV_SOBJ)
	@mkdir -p $(@D)
	$(CC) -shared $(SAN) -o $@ $(WV_SOBJ) $(WV_LIBS)

# Tests and benches link the module, GSL (Bessel functions for the closed forms) and
# FFTW (the bench times bare transforms as its baseline).
build/obj/wave_tests/%: tests/wave/%.c build/lib/lensmat-wave.so src/wave/wave.h \
                        $(wildcard tests/wave/*.h)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -Itests -o $@ $< build/lib/lensmat-wave.so \
	    -Wl,-rpath,$(abspath build/lib) -lfftw3 -lgsl -lgslcblas -lm
build/asan/wave_tests/%: tests/wave/%.c build/asan/lib/lensmat-wave.so src/wave/wave.h \
                         $(wildcard tests/wave/*.h)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -Itests -o $@ $< build/asan/lib/lensmat-wave.so \
	    -Wl,-rpath,$(abspath build/asan/lib) -lfftw3 -lgsl -lgslcblas -lm

all: build/lib/lensmat-wave.so
MODULE_TEST_BINS  += build/lib/lensmat-wave.so build/asan/lib/lensmat-wave.so $(WV_TBIN)
MODULE_BENCH_BINS += build/lib/lensmat-wave.so $(WV_BBIN)
-include $(WV_OBJ:.o=.d) $(WV_SOBJ:.o=.d)
# t_opd checks the trace module's rx_opd (the wavefront this engine is fed): it links
# lensmat-trace.so alone.
build/obj/wave_tests/t_opd: tests/wave/t_opd.c build/lib/lensmat-trace.so src/trace/trace.h
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -Itests -o $@ $< build/lib/lensmat-trace.so \
	    -Wl,-rpath,$(abspath build/lib) -lm
build/asan/wave_tests/t_opd: tests/wave/t_opd.c build/asan/lib/lensmat-trace.so src/trace/trace.h
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -Itests -o $@ $< build/asan/lib/lensmat-trace.so \
	    -Wl,-rpath,$(abspath build/asan/lib) -lm
