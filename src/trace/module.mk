# src/trace/module.mk -- the ray-tracing engine module (Embree 3): build/lib/lensmat-trace.so
# and its sanitizer twin build/asan/lib/lensmat-trace.so (our code instrumented, Embree
# not), the engine's own tests (tests/trace/t_*.c, both builds, run by
# tests/t_60_trace.sh) and benchmark (tests/trace/bench_*.c, scripts/bench_trace.sh).
# Everything in src/trace/*.c goes into the module; lensmat itself never links Embree.

TRACE_SRC   := $(wildcard src/trace/*.c)
# The outputs' shortest numbers: libfmt's Dragonbox (header-only), libdouble-conversion
# the fallback (C++, behind one C function: scene_dtoa.cpp); HDF5 outputs: libhdf5
# (Debian's serial build, its own folders).
TRACE_XSRC  := $(wildcard src/trace/*.cpp)
TRACE_OBJ   := $(patsubst src/%.c,build/obj/%.o,$(TRACE_SRC)) \
               $(patsubst src/%.cpp,build/obj/%.o,$(TRACE_XSRC))
TRACE_SOBJ  := $(patsubst src/%.c,build/asan/%.o,$(TRACE_SRC)) \
               $(patsubst src/%.cpp,build/asan/%.o,$(TRACE_XSRC))
TRACE_H5INC  = $(shell pkg-config --cflags hdf5 2>/dev/null || echo -I/usr/include/hdf5/serial)
TRACE_H5LIB  = $(shell pkg-config --libs hdf5 2>/dev/null || \
                 echo -L/usr/lib/$$(gcc -print-multiarch)/hdf5/serial -lhdf5)
TRACE_LIBS   = -lembree3 $(TRACE_H5LIB) -ldouble-conversion -lstdc++ -lm -pthread
TRACE_CXX    = -std=c++17 $(WARN) -fPIC -fvisibility=hidden -ffp-contract=off
TRACE_TESTS := $(wildcard tests/trace/t_*.c)
TRACE_BENCH := $(wildcard tests/trace/bench_*.c)
TRACE_TBIN  := $(patsubst tests/trace/%.c,build/obj/trace_tests/%,$(TRACE_TESTS)) \
               $(patsubst tests/trace/%.c,build/asan/trace_tests/%,$(TRACE_TESTS))
TRACE_BBIN  := $(patsubst tests/trace/%.c,build/obj/trace_tests/%,$(TRACE_BENCH))
# The scene front end names glasses: the paraxial engine's catalogue (src/paraxial,
# libc and libm only) goes into the module as a static archive of position-independent,
# hidden objects (only what glass.c needs is linked; nothing of it is exported).
TRACE_PX    := $(wildcard src/paraxial/*.c)
TRACE_PXA   := build/obj/trace/px/libpx.a
TRACE_SPXA  := build/asan/trace/px/libpx.a
build/obj/trace/px/%.o: src/paraxial/%.c $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -fPIC -fvisibility=hidden -MMD -MP -c $< -o $@
build/asan/trace/px/%.o: src/paraxial/%.c $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -fPIC -fvisibility=hidden -MMD -MP -c $< -o $@
$(TRACE_PXA): $(patsubst src/paraxial/%.c,build/obj/trace/px/%.o,$(TRACE_PX))
	rm -f $@; ar rcs $@ $^
$(TRACE_SPXA): $(patsubst src/paraxial/%.c,build/asan/trace/px/%.o,$(TRACE_PX))
	rm -f $@; ar rcs $@ $^

# The engine's own files (tr_*.c) are the hot loop of every trace: -O3, sqrt inlined
# without the errno call (-fno-math-errno: same values), and link-time optimisation
# so the geometry and optics inline into the trace loop across files.  Still
# -ffp-contract=off (from BASE): no fma, so every result keeps its bits and the trace
# rounds the same whatever the thread count or the build.
TRACE_HOT   := -O3 -fno-math-errno -flto=auto
build/obj/trace/tr_%.o: TRACE_XOPT := $(TRACE_HOT)
# The 4-lane base kernel, reached only through tr_isa.c's pointer, is built without
# LTO and without -Wpsabi (which the header's pragma does not reach in the clones GCC makes: GCC notes
# that 32-byte vectors pass differently without AVX; they never leave the file).
build/obj/trace/tr_pk_sse2x4.o: TRACE_XOPT := -O3 -fno-math-errno -Wno-psabi

# Module objects need -fPIC (the generic rules make position-independent executables).
build/obj/trace/%.o: src/trace/%.c $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) $(TRACE_XOPT) $(TRACE_H5INC) -fPIC -pthread -MMD -MP -c $< -o $@
build/asan/trace/%.o: src/trace/%.c $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) $(TRACE_H5INC) -fPIC -pthread -MMD -MP -c $< -o $@
build/obj/trace/%.o: src/trace/%.cpp | $(DEPS)
	@mkdir -p $(@D)
	$(CXX) $(TRACE_CXX) $(OPT) -O3 -MMD -MP -c $< -o $@
build/asan/trace/%.o: src/trace/%.cpp | $(DEPS)
	@mkdir -p $(@D)
	$(CXX) $(TRACE_CXX) $(SAN) -MMD -MP -c $< -o $@

build/lib/lensmat-trace.so: $(TRACE_OBJ) $(TRACE_PXA) $(LM_COMMON_PIC)
	@mkdir -p $(@D)
	$(CC) -shared $(OPT) $(TRACE_HOT) -ffp-contract=off -o $@ $(TRACE_OBJ) $(TRACE_PXA) $(LM_COMMON_PIC) \
	    $(TRACE_LIBS)
build/asan/lib/lensmat-trace.so: $(TRACE_SOBJ) $(TRACE_SPXA) $(LM_COMMON_SPIC)
	@mkdir -p $(@D)
	$(CC) -shared $(SAN) -o $@ $(TRACE_SOBJ) $(TRACE_SPXA) $(LM_COMMON_SPIC) $(TRACE_LIBS)

# Engine tests and benches talk to the module through trace.h only (linked to the .so).
build/obj/trace_tests/%: tests/trace/%.c build/lib/lensmat-trace.so src/trace/trace.h
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -pthread -Itests -o $@ $< build/lib/lensmat-trace.so \
	    -Wl,-rpath,$(abspath build/lib) -lembree3 -lm
build/asan/trace_tests/%: tests/trace/%.c build/asan/lib/lensmat-trace.so src/trace/trace.h
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -pthread -Itests -o $@ $< build/asan/lib/lensmat-trace.so \
	    -Wl,-rpath,$(abspath build/asan/lib) -lembree3 -lm

all: build/lib/lensmat-trace.so
MODULE_TEST_BINS  += build/lib/lensmat-trace.so build/asan/lib/lensmat-trace.so $(TRACE_TBIN)
# tests/t_71_hits.sh: the hit writer's digits, linked to scene_dtoa's object (its
# functions are hidden in the module)
build/obj/trace_tests/dtoa_check: tests/trace/dtoa_check.c build/obj/trace/scene_dtoa.o
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -o $@ $^ -ldouble-conversion -lstdc++ -lm
build/asan/trace_tests/dtoa_check: tests/trace/dtoa_check.c build/asan/trace/scene_dtoa.o
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -o $@ $^ -ldouble-conversion -lstdc++ -lm
MODULE_TEST_BINS  += build/obj/trace_tests/dtoa_check build/asan/trace_tests/dtoa_check
MODULE_BENCH_BINS += build/lib/lensmat-trace.so $(TRACE_BBIN)
# (t_polar's checks are also scripts/bench_wave.sh's polarization figures)
MODULE_BENCH_BINS += build/obj/trace_tests/t_polar
-include $(TRACE_OBJ:.o=.d) $(TRACE_SOBJ:.o=.d) \
    $(patsubst src/paraxial/%.c,build/obj/trace/px/%.d,$(TRACE_PX))

# Issue 13: the engine built for the x86-64 baseline (-march=x86-64: SSE2, no AVX
# outside the two kernels tr_isa.c chooses at load) in its own folder build/x86-64/,
# at -O1 without LTO to stay cheap; tests/t_61_trace_ports.sh runs its tests and
# checks its objects for AVX instructions.
ifeq ($(shell uname -m),x86_64)
TRACE_X86   := -O1 -march=x86-64 -mtune=generic
TRACE_XOBJ  := $(patsubst src/%.c,build/x86-64/%.o,$(TRACE_SRC)) \
               $(patsubst src/%.cpp,build/x86-64/%.o,$(TRACE_XSRC))
build/x86-64/trace/%.o: src/trace/%.c $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(TRACE_X86) $(TRACE_H5INC) -fPIC -pthread -MMD -MP -c $< -o $@
build/x86-64/trace/%.o: src/trace/%.cpp | $(DEPS)
	@mkdir -p $(@D)
	$(CXX) $(TRACE_CXX) $(TRACE_X86) -MMD -MP -c $< -o $@
build/x86-64/trace/px/%.o: src/paraxial/%.c $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(TRACE_X86) -fPIC -fvisibility=hidden -MMD -MP -c $< -o $@
build/x86-64/trace/px/libpx.a: $(patsubst src/paraxial/%.c,build/x86-64/trace/px/%.o,$(TRACE_PX))
	rm -f $@; ar rcs $@ $^
build/x86-64/lib/lensmat-trace.so: $(TRACE_XOBJ) build/x86-64/trace/px/libpx.a $(LM_COMMON_PIC)
	@mkdir -p $(@D)
	$(CC) -shared $(TRACE_X86) -o $@ $(TRACE_XOBJ) build/x86-64/trace/px/libpx.a $(LM_COMMON_PIC) \
	    $(TRACE_LIBS)
build/x86-64/trace_tests/%: tests/trace/%.c build/x86-64/lib/lensmat-trace.so src/trace/trace.h
	@mkdir -p $(@D)
	$(CC) $(BASE) $(TRACE_X86) -pthread -Itests -o $@ $< build/x86-64/lib/lensmat-trace.so \
	    -Wl,-rpath,$(abspath build/x86-64/lib) -lembree3 -lm
MODULE_TEST_BINS += $(patsubst tests/trace/%.c,build/x86-64/trace_tests/%,$(TRACE_TESTS))
-include $(TRACE_XOBJ:.o=.d) $(patsubst src/paraxial/%.c,build/x86-64/trace/px/%.d,$(TRACE_PX))
endif
