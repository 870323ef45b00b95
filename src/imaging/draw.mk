# src/imaging/draw.mk -- the pictures half's test tool: build/obj/imaging_tests/draw_pngcmp
# (golden-image comparison and finding a drawn tick's pixels, tests/t_76_draw.sh), on
# OpenCV like the module (src/imaging/module.mk, whose variables it uses).

build/obj/imaging_tests/draw_pngcmp: tests/imaging/draw_pngcmp.cpp | $(DEPS)
	@mkdir -p $(@D)
	$(CXX) -std=c++17 $(WARN) -O2 $(IM_CVFLAGS) -o $@ $< -lopencv_imgcodecs -lopencv_core

MODULE_TEST_BINS  += build/obj/imaging_tests/draw_pngcmp build/lib/lensmat-trace.so
MODULE_BENCH_BINS += build/lib/lensmat-imaging.so build/lib/lensmat-trace.so
