# Makefile -- lensmat.  `make` builds ./lensmat (installing missing Debian packages
# first, see scripts/install-deps.sh); `make check` runs every test, also under
# AddressSanitizer and UBSan; `make bench` prints BENCH lines; `make fuzz` fuzzes long.
# Engines that need big libraries (Embree, OpenCV, libgpiod) are built as modules
# under build/lib/ that lensmat loads only when a dialogue first uses them; each
# brings its own src/ENGINE/*.mk.

CC      ?= cc
CLANG   ?= clang
VERSION := 0.1
WARN    := -Wall -Wextra
# -ffp-contract=off: the classic dialogue must round like the original (no fma).
BASE    := -std=c11 -D_POSIX_C_SOURCE=200809L -DLENSMAT_VERSION=\"$(VERSION)\" \
           -ffp-contract=off -Isrc -Ibuild/gen $(WARN)
OPT     := -O2 -g
SAN     := -O1 -g -fsanitize=address,undefined -fno-sanitize-recover=all \
           -fno-omit-frame-pointer
LIBS    := -lreadline -lm

PROMPTS := $(wildcard prompts/*.txt)
GEN     := $(patsubst prompts/%.txt,build/gen/prompts_%.h,$(PROMPTS))
# The glass catalogue (data/glass.txt), compiled in like the prompts.
GEN     += build/gen/glass_data.h
# The core: the dialogue layer, paraxial engine, lens model (libc, libm, readline only).
# src/common: the output writer every part shares (lm_out.c).
CORE    := $(wildcard src/dialogue/*.c src/paraxial/*.c src/lens/*.c src/common/*.c)
LIBCORE := $(filter-out src/dialogue/main.c,$(CORE))
OBJ     := $(patsubst src/%.c,build/obj/%.o,$(CORE))
SANOBJ  := $(patsubst src/%.c,build/asan/%.o,$(CORE))
LIBOBJ  := $(patsubst src/%.c,build/obj/%.o,$(LIBCORE))
SANLIB  := $(patsubst src/%.c,build/asan/%.o,$(LIBCORE))
UNIT    := $(wildcard tests/unit_*.c)
DEPS    := build/.deps

all: lensmat

$(DEPS): scripts/install-deps.sh
	@mkdir -p build
	sh scripts/install-deps.sh
	@touch $@

build/gen/prompts_%.h: prompts/%.txt scripts/gen_prompts.sh
	@mkdir -p $(@D)
	sh scripts/gen_prompts.sh $* $< $@

build/gen/glass_data.h: data/glass.txt scripts/gen_glass.sh
	@mkdir -p $(@D)
	sh scripts/gen_glass.sh data/glass.txt $@

build/obj/%.o: src/%.c $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -MMD -MP -c $< -o $@

build/asan/%.o: src/%.c $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -MMD -MP -c $< -o $@

lensmat: $(OBJ)
	$(CC) $(OPT) -o $@ $(OBJ) $(LIBS)

build/asan/lensmat: $(SANOBJ)
	$(CC) $(SAN) -o $@ $(SANOBJ) $(LIBS)

# Unit tests: one program per tests/unit_*.c, linked with the core (not main.c).
build/obj/unit_%: tests/unit_%.c $(LIBOBJ)
	$(CC) $(BASE) $(OPT) -Itests -o $@ $< $(LIBOBJ) $(LIBS)
build/asan/unit_%: tests/unit_%.c $(SANLIB)
	$(CC) $(BASE) $(SAN) -Itests -o $@ $< $(SANLIB) $(LIBS)
# The paraxial engine's benchmark (scripts/bench_paraxial.sh), linked the same way.
build/obj/bench_paraxial: tests/bench_paraxial.c $(LIBOBJ)
	$(CC) $(BASE) $(OPT) -Itests -o $@ $< $(LIBOBJ) $(LIBS)
# The glass catalogue's achromat benchmark (scripts/bench_glass.sh).
build/obj/bench_glass: tests/bench_glass.c $(LIBOBJ)
	$(CC) $(BASE) $(OPT) -Itests -o $@ $< $(LIBOBJ) $(LIBS)

# libFuzzer target for the answer reader, the number parser and every dialogue of
# src/dialogue/table.c (clang from Debian): the core sources (not main.c) compiled
# with the fuzzer's instrumentation.
build/fuzz_answers: tests/fuzz_answers.c $(LIBCORE) $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CLANG) $(BASE) -O1 -g -fsanitize=fuzzer,address,undefined -o $@ \
	    tests/fuzz_answers.c $(LIBCORE) $(LIBS)

# libFuzzer target for the lens model's readers (src/lens: thickness prescriptions,
# .zmx), with the paraxial engine they build on.
LENSFUZZ_SRC := $(wildcard src/lens/*.c src/paraxial/*.c)
build/fuzz_lens: tests/fuzz_lens.c $(LENSFUZZ_SRC) $(GEN) | $(DEPS)
	@mkdir -p $(@D)
	$(CLANG) $(BASE) -O1 -g -fsanitize=fuzzer,address,undefined -o $@ \
	    tests/fuzz_lens.c $(LENSFUZZ_SRC) -lm

# The transcribed original program, for differential tests (built from ../shared,
# never copied into this tree).
ORIG_DIR := ../shared/original-lensmat
build/original/lensmat: | $(DEPS)
	@mkdir -p $(@D)
	if [ -f $(ORIG_DIR)/lensmat.cpp ]; then \
	  g++ -O2 -ffp-contract=off -w -o $@ $(ORIG_DIR)/lensmat.cpp; fi

TEST_BINS := lensmat build/asan/lensmat build/fuzz_answers build/original/lensmat \
             $(patsubst tests/%.c,build/obj/%,$(UNIT)) \
             $(patsubst tests/%.c,build/asan/%,$(UNIT))
TEST_BINS += build/fuzz_lens

-include $(wildcard src/*/*.mk)

# make check builds in parallel by itself (one job per core) unless the caller gave
# -j: the test binaries are many independent builds, the tests then run in order.
NPROC     := $(shell nproc 2> /dev/null || echo 2)
CHECK_J    = $(if $(filter -j%,$(MAKEFLAGS)),,-j$(NPROC))
check:
	@$(MAKE) --no-print-directory $(CHECK_J) check-bins
	@sh tests/run.sh
check-bins: $(TEST_BINS) $(MODULE_TEST_BINS)

build/bench/%: tests/bench/%.c | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) -O2 -o $@ $<

bench: lensmat build/original/lensmat build/bench/benchrun build/bench/baseline \
       build/obj/bench_paraxial \
       build/obj/bench_glass \
       build/obj/unit_published \
       $(MODULE_BENCH_BINS)
	@sh scripts/bench.sh

fuzz: build/fuzz_answers build/fuzz_lens
	@mkdir -p build/fuzz-corpus
	build/fuzz_answers -max_total_time=$${FUZZ_SECONDS:-600} build/fuzz-corpus \
	    tests/fuzz-corpus
	@mkdir -p build/fuzz-lens-corpus
	build/fuzz_lens -max_total_time=$${FUZZ_SECONDS:-600} build/fuzz-lens-corpus \
	    tests/fuzz-lens

# The set-up command: ./lensmat and every engine module whose libraries are there
# (make -k: a module that cannot be built is skipped; its dialogues say so).
EXAMPLE_MODULES = $(sort $(filter build/lib/lensmat-%.so,$(MODULE_TEST_BINS) $(MODULE_BENCH_BINS)))
example: lensmat
	-$(MAKE) -k $(EXAMPLE_MODULES) || echo "make example: a module could not be built; the dialogues that need it will say so"
	./lensmat --example example.rec

# Installing: PREFIX/bin/lensmat finds its modules in PREFIX/lib/lensmat (engine.c
# looks in EXEDIR/../lib/lensmat); DESTDIR is prepended to every path (packaging).
PREFIX  ?= /usr/local
BINDIR  := $(PREFIX)/bin
MODDIR  := $(PREFIX)/lib/lensmat
MANDIR  := $(PREFIX)/share/man/man1
DOCDIR  := $(PREFIX)/share/doc/lensmat
# The examples' data files, under their names in the tree (main.c finds them in
# EXEDIR/../share/lensmat when they are not in the current folder).
DATADIR := $(PREFIX)/share/lensmat
EXAMPLE_DATA := doc/triplet.rx doc/pupil-triplet.rx golden/rig/example.rig
install: all
	install -d $(DESTDIR)$(BINDIR) $(DESTDIR)$(MODDIR) $(DESTDIR)$(MANDIR) $(DESTDIR)$(DOCDIR)
	install -m 755 lensmat $(DESTDIR)$(BINDIR)/lensmat
	for m in build/lib/lensmat-*.so; do [ -f "$$m" ] || continue; \
	    install -m 644 "$$m" $(DESTDIR)$(MODDIR)/; done
	install -m 644 doc/lensmat.1 $(DESTDIR)$(MANDIR)/lensmat.1
	install -m 644 README.md $(DESTDIR)$(DOCDIR)/README.md
	install -d $(DESTDIR)$(DOCDIR)/doc/img
	install -m 644 doc/*.md $(DESTDIR)$(DOCDIR)/doc/
	install -m 644 doc/img/*.png $(DESTDIR)$(DOCDIR)/doc/img/
	for f in $(EXAMPLE_DATA); do install -d $(DESTDIR)$(DATADIR)/$${f%/*} && \
	    install -m 644 $$f $(DESTDIR)$(DATADIR)/$$f || exit 1; done
uninstall:
	rm -f $(DESTDIR)$(BINDIR)/lensmat $(DESTDIR)$(MODDIR)/lensmat-*.so \
	    $(DESTDIR)$(MANDIR)/lensmat.1 $(DESTDIR)$(DOCDIR)/README.md
	rm -f $(DESTDIR)$(DOCDIR)/doc/*.md $(DESTDIR)$(DOCDIR)/doc/img/*.png
	for f in $(EXAMPLE_DATA); do rm -f $(DESTDIR)$(DATADIR)/$$f; done
	-rmdir $(DESTDIR)$(DOCDIR)/doc/img $(DESTDIR)$(DOCDIR)/doc $(DESTDIR)$(MODDIR) \
	    $(DESTDIR)$(DOCDIR) $(DESTDIR)$(DATADIR)/doc \
	    $(DESTDIR)$(DATADIR)/golden/rig $(DESTDIR)$(DATADIR)/golden $(DESTDIR)$(DATADIR) 2> /dev/null

clean:
	rm -rf build lensmat example.rec

.PHONY: check-bins all check bench fuzz example clean install uninstall
.SECONDARY:
-include $(OBJ:.o=.d) $(SANOBJ:.o=.d)
