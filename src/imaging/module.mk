# src/imaging/module.mk -- the imaging engine (OpenCV 4.6 behind a C shim):
#   build/lib/lensmat-imaging.so   every src/imaging/im_*.c (C11) and im_*.cpp (C++17):
#                                  pictures (im_draw*), frames and centroids (im_frame*,
#                                  im_centroid*, ...); OpenCV core, imgproc, imgcodecs; GSL
#   build/lib/lensmat-camera.so    src/imaging/camera.cpp: OpenCV videoio (FFmpeg,
#                                  GStreamer, V4L2), dlopen'ed by the imaging module only
#                                  when a live camera or a video file is opened
# and their sanitizer twins under build/asan/lib (our code instrumented, OpenCV not), the
# engine's tests (tests/imaging/t_*.c, both builds, run by tests/t_7x_imaging.sh), its
# benchmarks (tests/imaging/bench_*.c, scripts/bench_imaging.sh) and the frame-reader
# fuzzer (tests/imaging/fuzz_frame.c).  ./lensmat itself never links OpenCV.

IM_CSRC    := $(wildcard src/imaging/im_*.c)
IM_XSRC    := $(wildcard src/imaging/im_*.cpp)
IM_OBJ     := $(patsubst src/%.c,build/obj/%.o,$(IM_CSRC)) \
              $(patsubst src/%.cpp,build/obj/%.o,$(IM_XSRC))
IM_SOBJ    := $(patsubst src/%.c,build/asan/%.o,$(IM_CSRC)) \
              $(patsubst src/%.cpp,build/asan/%.o,$(IM_XSRC))
IM_HDR     := $(wildcard src/imaging/*.h)
# Recursive (=): evaluated when a recipe runs, i.e. after install-deps put pkg-config
# and OpenCV on a fresh machine.  Only the OpenCV modules the engine uses.
IM_CVFLAGS  = $(shell pkg-config --cflags opencv4 2>/dev/null || echo -I/usr/include/opencv4)
IM_CVLIBS   = $(filter-out -lopencv_%,$(shell pkg-config --libs opencv4 2>/dev/null)) \
              -lopencv_imgcodecs -lopencv_imgproc -lopencv_core
CAM_CVLIBS  = $(filter-out -lopencv_%,$(shell pkg-config --libs opencv4 2>/dev/null)) \
              -lopencv_videoio -lopencv_imgproc -lopencv_core
IM_LIBS     = $(IM_CVLIBS) -lgsl -lgslcblas -lz -ldl -lm -pthread
CXX        ?= g++
# C++: the same warnings, no exceptions leave the shim (every entry point catches).
# Internal symbols hidden: the module exports imaging_get_api (camera: camera_get_api).
IM_CXXBASE  = -std=c++17 -Isrc $(WARN) -fPIC -fvisibility=hidden -pthread \
              -ffp-contract=off $(IM_CVFLAGS)
IM_CBASE   := $(BASE) -D_DEFAULT_SOURCE -fPIC -fvisibility=hidden -pthread
IM_HOT     := -O3 -fno-math-errno

build/obj/imaging/%.o: src/imaging/%.c $(IM_HDR) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(IM_CBASE) $(OPT) $(IM_HOT) -MMD -MP -c $< -o $@
build/asan/imaging/%.o: src/imaging/%.c $(IM_HDR) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(IM_CBASE) $(SAN) -MMD -MP -c $< -o $@
build/obj/imaging/%.o: src/imaging/%.cpp $(IM_HDR) | $(DEPS)
	@mkdir -p $(@D)
	$(CXX) $(IM_CXXBASE) $(OPT) -MMD -MP -c $< -o $@
build/asan/imaging/%.o: src/imaging/%.cpp $(IM_HDR) | $(DEPS)
	@mkdir -p $(@D)
	$(CXX) $(IM_CXXBASE) $(SAN) -MMD -MP -c $< -o $@

build/lib/lensmat-imaging.so: $(IM_OBJ) $(LM_COMMON_PIC)
	@mkdir -p $(@D)
	$(CXX) -shared $(OPT) -o $@ $(IM_OBJ) $(LM_COMMON_PIC) $(IM_LIBS)
build/asan/lib/lensmat-imaging.so: $(IM_SOBJ) $(LM_COMMON_SPIC)
	@mkdir -p $(@D)
	$(CXX) -shared $(SAN) -o $@ $(IM_SOBJ) $(LM_COMMON_SPIC) $(IM_LIBS)
build/lib/lensmat-camera.so: build/obj/imaging/camera.o $(LM_COMMON_PIC)
	@mkdir -p $(@D)
	$(CXX) -shared $(OPT) -o $@ $^ $(CAM_CVLIBS) -pthread
build/asan/lib/lensmat-camera.so: build/asan/imaging/camera.o $(LM_COMMON_SPIC)
	@mkdir -p $(@D)
	$(CXX) -shared $(SAN) -o $@ $^ $(CAM_CVLIBS) -pthread

# Engine tests and benches talk to the module through imaging.h only (linked to the .so;
# the camera module is found beside it at run time).
IM_TESTS   := $(wildcard tests/imaging/t_*.c)
IM_BENCH   := $(wildcard tests/imaging/bench_*.c)
IM_TBIN    := $(patsubst tests/imaging/%.c,build/obj/imaging_tests/%,$(IM_TESTS)) \
              $(patsubst tests/imaging/%.c,build/asan/imaging_tests/%,$(IM_TESTS))
IM_BBIN    := $(patsubst tests/imaging/%.c,build/obj/imaging_tests/%,$(IM_BENCH))
build/obj/imaging_tests/%: tests/imaging/%.c build/lib/lensmat-imaging.so \
                           build/lib/lensmat-camera.so $(IM_HDR)
	@mkdir -p $(@D)
	$(CC) $(BASE) -D_DEFAULT_SOURCE $(OPT) -pthread -Itests -o $@ $< \
	    build/lib/lensmat-imaging.so -Wl,-rpath,$(abspath build/lib) -ldl -lm
build/asan/imaging_tests/%: tests/imaging/%.c build/asan/lib/lensmat-imaging.so \
                            build/asan/lib/lensmat-camera.so $(IM_HDR)
	@mkdir -p $(@D)
	$(CC) $(BASE) -D_DEFAULT_SOURCE $(SAN) -pthread -Itests -o $@ $< \
	    build/asan/lib/lensmat-imaging.so -Wl,-rpath,$(abspath build/asan/lib) -ldl -lm

# The load benchmark must not link the module it times.
build/obj/imaging_tests/bench_load: tests/imaging/bench_load.c $(IM_HDR) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -o $@ $< -ldl

# libFuzzer target for the frame readers (PNG, TIFF, raw): our decoding and checking
# code instrumented by clang, OpenCV's decoders as they ship.
IM_FUZZSRC := src/imaging/im_frame_io.cpp src/imaging/im_frame.c src/imaging/im_centroid.c \
              src/imaging/im_fit.c src/common/lm_out.c
IM_FUZZC   := $(filter %.c,$(IM_FUZZSRC))
build/fuzz_frame: tests/imaging/fuzz_frame.c $(IM_FUZZSRC) $(IM_HDR) | $(DEPS)
	@mkdir -p $(@D)/fuzz_frame.d
	for f in $(IM_FUZZC); do \
	  $(CLANG) $(BASE) -D_DEFAULT_SOURCE -DFUZZING_BUILD_MODE_UNSAFE_FOR_PRODUCTION \
	    -O1 -g -fsanitize=fuzzer-no-link,address,undefined \
	    -c $$f -o $(@D)/fuzz_frame.d/$$(basename $$f .c).o || exit 1; done
	$(CLANG)++ -std=c++17 -Isrc -O1 -g -fsanitize=fuzzer-no-link,address,undefined \
	    $(IM_CVFLAGS) -c src/imaging/im_frame_io.cpp -o $(@D)/fuzz_frame.d/im_frame_io.o
	$(CLANG)++ -O1 -g -fsanitize=fuzzer,address,undefined -Isrc -x c++ \
	    tests/imaging/fuzz_frame.c -x none $(addprefix $(@D)/fuzz_frame.d/,$(notdir $(IM_FUZZC:.c=.o))) \
	    $(@D)/fuzz_frame.d/im_frame_io.o -o $@ $(IM_CVLIBS) -lgsl -lgslcblas -lz -ldl -lm

all: build/lib/lensmat-imaging.so build/lib/lensmat-camera.so
MODULE_TEST_BINS  += build/lib/lensmat-imaging.so build/asan/lib/lensmat-imaging.so \
                     build/lib/lensmat-camera.so build/asan/lib/lensmat-camera.so \
                     build/fuzz_frame $(IM_TBIN) build/obj/imaging_tests/bench_load \
                     build/obj/imaging_tests/bench_centroid
MODULE_BENCH_BINS += build/lib/lensmat-imaging.so build/lib/lensmat-camera.so $(IM_BBIN) \
                     build/obj/imaging_tests/t_front
-include $(IM_OBJ:.o=.d) $(IM_SOBJ:.o=.d)
# t_front compiles the topography pipeline's photon transfer (src/topo/tp_shot.c) in.
build/obj/imaging_tests/t_front build/asan/imaging_tests/t_front: src/topo/tp_shot.c \
    src/topo/tp_int.h src/topo/topo.h
