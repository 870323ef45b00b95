# src/rig/machine.mk -- the machine half's extra programs (the module itself is built
# by src/rig/module.mk): the rig-file fuzzer (libFuzzer, every src/rig/rg_*.c), the
# program tests/t_85_rig_gpio.sh runs inside the gpio-vm guest against the kernel's
# gpio-sim chip, and the heartbeat watchdog that stands for the external charge-pump
# circuit in the SIGKILL test (a separate process, so killing lensmat cannot stop it).

build/fuzz_rig_file: tests/rig/fuzz_rig_file.c $(wildcard src/rig/rg_*.c src/rig/*.h) | $(DEPS)
	@mkdir -p $(@D)
	$(CLANG) $(BASE) -O1 -g -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
	    -o $@ tests/rig/fuzz_rig_file.c $(wildcard src/rig/rg_*.c) src/common/lm_out.c \
	    $(wildcard src/paraxial/*.c) -lgpiod -lgsl \
	    -lgslcblas -lm -pthread

# (linked by absolute path: the module has no soname, and gpio-vm copies what ldd names)
build/obj/rig_vm/%: tests/rig/%.c build/lib/lensmat-rig.so src/rig/rig.h
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -Itests -o $@ $< $(abspath build/lib/lensmat-rig.so) \
	    -Wl,-rpath,$(abspath build/lib) -lgpiod -lm

fuzz-rig: build/fuzz_rig_file
	@mkdir -p build/fuzz-rig-corpus
	build/fuzz_rig_file -max_total_time=$${FUZZ_SECONDS:-600} -timeout=5 \
	    build/fuzz-rig-corpus tests/fuzz-rig

MODULE_TEST_BINS += build/fuzz_rig_file build/obj/rig_vm/vm_rig build/obj/rig_vm/rig_watchdog \
                    build/obj/rig_vm/vm_safety
fuzz: fuzz-rig
.PHONY: fuzz-rig
