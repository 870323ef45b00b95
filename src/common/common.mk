# src/common/common.mk -- code every part of lensmat shares (src/common/*.c, libc only).
# The core links it as it is (Makefile CORE); each module that writes files links the
# position-independent, hidden twin below (LM_COMMON_PIC / LM_COMMON_SPIC), so a module
# never needs a symbol of the executable and exports none of these.
LM_COMMON_SRC  := $(wildcard src/common/*.c)
LM_COMMON_PIC  := $(patsubst src/common/%.c,build/obj/common/pic/%.o,$(LM_COMMON_SRC))
LM_COMMON_SPIC := $(patsubst src/common/%.c,build/asan/common/pic/%.o,$(LM_COMMON_SRC))
build/obj/common/pic/%.o: src/common/%.c src/common/lm_out.h | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(OPT) -fPIC -fvisibility=hidden -MMD -MP -c $< -o $@
build/asan/common/pic/%.o: src/common/%.c src/common/lm_out.h | $(DEPS)
	@mkdir -p $(@D)
	$(CC) $(BASE) $(SAN) -fPIC -fvisibility=hidden -MMD -MP -c $< -o $@
-include $(LM_COMMON_PIC:.o=.d) $(LM_COMMON_SPIC:.o=.d)
