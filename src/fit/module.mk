# src/fit/module.mk -- the fit module: GSL least squares for the --fit dialogue,
# built as a dlopen'ed module so that ./lensmat itself links no GSL (start-up cost
# measured in README "Calculations").  `make` builds it with ./lensmat.
FIT_SRC := src/fit/fit.c src/fit/fit.h
build/lib/lensmat-fit.so: $(FIT_SRC) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -fPIC -shared -o $@ src/fit/fit.c -lgsl -lgslcblas -lm
build/asan/lib/lensmat-fit.so: $(FIT_SRC) | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -fPIC -shared -o $@ src/fit/fit.c -lgsl -lgslcblas -lm
all: build/lib/lensmat-fit.so
MODULE_TEST_BINS += build/lib/lensmat-fit.so build/asan/lib/lensmat-fit.so
