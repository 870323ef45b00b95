# src/trace/front.mk -- the trace front end's fuzzer: the scene, triangle, media and
# OBJ readers (SCENE_READERS below, scene_geom.c) built alone with libFuzzer (no
# Embree).  Included by src/trace/module.mk.  `make check` runs it briefly
# (tests/t_65_trace_front.sh); `make fuzz` long, from the seed corpus tests/fuzz-trace.

# (with the paraxial engine's glass catalogue, which the scene reader names glasses by)
SCENE_READERS := src/trace/scene_lex.c src/trace/scene_mesh.c src/trace/scene_read.c \
                 src/trace/scene_fields.c \
                 src/trace/scene_axial.c src/trace/scene_polar.c
build/fuzz_trace_scene: tests/fuzz_trace_scene.c $(SCENE_READERS) \
                        src/trace/scene_geom.c src/trace/scene.h $(wildcard src/paraxial/*.c) \
                        $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CLANG) $(BASE) -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
	    -o $@ tests/fuzz_trace_scene.c $(SCENE_READERS) src/trace/scene_geom.c \
	    $(wildcard src/paraxial/*.c) -lm

fuzz-trace: build/fuzz_trace_scene
	@mkdir -p build/fuzz-trace-corpus
	build/fuzz_trace_scene -max_total_time=$${FUZZ_SECONDS:-600} -timeout=5 \
	    build/fuzz-trace-corpus tests/fuzz-trace

MODULE_TEST_BINS += build/fuzz_trace_scene
fuzz: fuzz-trace
.PHONY: fuzz-trace
