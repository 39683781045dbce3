# Fuzzing (included by the Makefile). Every tests/fuzz/fuzz_<target>.c is a libFuzzer target
# built with Debian's clang against the whole library compiled with
# -fsanitize=fuzzer-no-link,address,undefined (build/fuzz); its corpus is
# tests/fuzz/<target>/ (seeds, read-only) plus build/fuzz/corpus/<target>/ (what a run finds).
#
#   make test-fuzz   every target for FUZZ_SECONDS (default 20) each: part of make test
#   make fuzz        the same for longer (FUZZ_SECONDS default 600)
#
# A target for a new reader is one file: tests/fuzz/fuzz_<name>.c and seeds in
# tests/fuzz/<name>/ (see tests/fuzz/README.md).

FUZZ_DIR     := $(BUILD)/fuzz
FUZZ_CC      := clang
FUZZ_SAN     := -fsanitize=address,undefined -fno-sanitize-recover=undefined \
                -fno-omit-frame-pointer
FUZZ_CFLAGS  := -O1 -g -std=c11 -D_GNU_SOURCE -Wall -Wextra -Wno-unused-parameter \
                -I/usr/include/suitesparse $(FUZZ_SAN)
FUZZ_LIB_SRC := $(foreach l,$(LAYERS),$(call layer_src,$(l)))
FUZZ_LIB_OBJ := $(FUZZ_LIB_SRC:%.c=$(FUZZ_DIR)/obj/%.o) \
                $(FUZZ_DIR)/gen/migrations.o $(FUZZ_DIR)/gen/openapi.o
FUZZ_LIB     := $(FUZZ_DIR)/libag_fuzz.a
FUZZ_SRC     := $(sort $(wildcard tests/fuzz/fuzz_*.c))
FUZZ_BIN     := $(FUZZ_SRC:tests/fuzz/%.c=$(FUZZ_DIR)/%)
DEB_FUZZ     := clang libclang-rt-14-dev

.PHONY: deps-fuzz fuzz-targets test-fuzz fuzz

deps-fuzz: deps
	$(call install_missing,$(DEB_FUZZ))

$(FUZZ_DIR)/obj/%.o: %.c | deps-fuzz
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer-no-link -MMD -MP -c $< -o $@

$(FUZZ_DIR)/gen/%.o: $(BUILD)/gen/%.c | deps-fuzz
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -c $< -o $@

$(FUZZ_LIB): $(FUZZ_LIB_OBJ)
	@rm -f $@
	ar rcs $@ $^

$(FUZZ_DIR)/fuzz_%: tests/fuzz/fuzz_%.c tests/fuzz/fuzz_check.h $(FUZZ_LIB)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -Iserver -fsanitize=fuzzer -o $@ $< \
	  -Wl,--start-group $(FUZZ_LIB) -Wl,--end-group $(LDLIBS)

fuzz-targets: $(FUZZ_BIN)

FUZZ_SECONDS ?= 20
test-fuzz: fuzz-targets
	@sh tests/fuzz/run.sh $(FUZZ_DIR) $(FUZZ_SECONDS) $(FUZZ_BIN)

fuzz: FUZZ_SECONDS = 600
fuzz: fuzz-targets
	@sh tests/fuzz/run.sh $(FUZZ_DIR) $(FUZZ_SECONDS) $(FUZZ_BIN)

-include $(shell find $(FUZZ_DIR)/obj -name '*.d' 2>/dev/null)
