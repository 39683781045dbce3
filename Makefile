# archgram — build, run and test.
#
#   make / make run   install the build packages, build archgramd, archgram and the web client
#                     (run: then start archgramd with demo content)
#   make test         install the test packages too, then check-layers and every test tier
#   make test-asan    the unit and integration tiers against an ASan+UBSan build (build/asan)
#   make bench        benchmarks (print figures; not tests)
#
# Every target installs the Debian and npm packages it needs when they are missing,
# so a fresh clone on a fresh Debian 12 machine needs nothing but these commands.
# CI=true (or WERROR=1) builds with -Werror.

CC      ?= cc
BUILD   := build
CFLAGS  ?= -O2 -g
# SANITIZE is set by test-asan for its own build directory.
SANITIZE :=
WERROR  ?= $(if $(filter true,$(CI)),1,0)
ALL_CFLAGS := $(CFLAGS) $(SANITIZE) -std=c11 -D_GNU_SOURCE -Wall -Wextra -Wno-unused-parameter \
              $(if $(filter 1,$(WERROR)),-Werror) -MMD -MP -I/usr/include/suitesparse
ALL_LDFLAGS := $(LDFLAGS) $(SANITIZE)
# Tests and benchmarks find tests/data and ../shared relative to the checkout they are built in.
TEST_CFLAGS := -Iserver -DAG_REPO_DIR=\"$(CURDIR)\"

PORT    ?= 8080
DB      ?= var/archgram.db

# Debian packages: to build and run; in addition to test (and to run the sanitizer build);
# to benchmark.
DEB_BUILD := gcc make pkg-config libc6-dev libmicrohttpd-dev libjansson-dev libyajl-dev libwebsockets-dev \
             libsqlite3-dev libsuitesparse-dev libassimp-dev libssl-dev libsodium-dev libpng-dev
DEB_TEST  := libcmocka-dev chromium curl sqlite3 python3 binutils libasan8 libubsan1 libcgal-dev g++
DEB_BENCH := wrk

# --- layers -------------------------------------------------------------------------------
# One archive per layer, core → io → store → app → net; programs link them highest first, so
# a layer that reaches up fails to link. Which layers, headers and system libraries each layer
# may use is written once, in tools/check_layers.py (make check-layers).
LAYERS     := core io store app net
LIBDIR     := $(BUILD)/lib
layer_src   = $(shell find server/$(1) -name '*.c' | sort)
layer_obj   = $(patsubst %.c,$(BUILD)/obj/%.o,$(call layer_src,$(1)))
# Generated sources go with the layer that uses them: migrations → store, OpenAPI → net.
GEN_OBJ_store := $(BUILD)/gen/migrations.o
GEN_OBJ_net   := $(BUILD)/gen/openapi.o
GEN_SRC   := $(BUILD)/gen/migrations.c $(BUILD)/gen/openapi.c
ARCHIVES  := $(foreach l,$(LAYERS),$(LIBDIR)/libag_$(l).a)
# Link order: the highest layer first, each followed by what it may use.
LINK_ARCHIVES := $(foreach l,net app store io core,$(LIBDIR)/libag_$(l).a)
# The system libraries, in the same order: net's, app's, store's, io's, core's.
LDLIBS    := -lwebsockets -lmicrohttpd -lpthread -lsodium -lsqlite3 -lpng -ljansson -lyajl -lassimp -lcrypto \
             -lcholmod -lspqr -lsuitesparseconfig -lm
LIB_OBJ   := $(foreach l,$(LAYERS),$(call layer_obj,$(l)))

# The command-line tool: a dispatcher (server/cli.c) and one file per subcommand.
CLI_SRC   := server/cli.c $(sort $(wildcard server/cli/*.c))
CLI_OBJ   := $(CLI_SRC:%.c=$(BUILD)/obj/%.o)
UNIT_SRC  := $(sort $(wildcard tests/unit/test_*.c))
UNIT_BIN  := $(UNIT_SRC:tests/unit/%.c=$(BUILD)/tests/%)
BENCH_SRC := $(sort $(wildcard bench/*.c))
BENCH_BIN := $(BENCH_SRC:bench/%.c=$(BUILD)/bench/%)
WEB_SRC   := $(shell find web -type f 2>/dev/null | sort)
NPM_STAMP := node_modules/.archgram-stamp

.PHONY: all deps deps-test deps-bench npm run test bench-programs test-unit test-integration test-browser \
        test-asan check-layers bench clean web programs unit-tests

# Running needs the two programs and the web client, nothing built for tests.
all: programs web

programs: $(BUILD)/archgramd $(BUILD)/archgram

# --- packages -----------------------------------------------------------------------------
# apt waits for a lock another apt holds (up to 10 minutes), and a failed round is tried again
# a few times: on a shared machine or a CI runner something else may be installing too.
APT_GET := apt-get -q -o DPkg::Lock::Timeout=600
define apt_install
	SUDO=; [ "$$(id -u)" = 0 ] || SUDO=sudo; \
	for try in 1 2 3 4 5; do \
	  $$SUDO $(APT_GET) update && \
	  DEBIAN_FRONTEND=noninteractive $$SUDO $(APT_GET) install -y --no-install-recommends $(1) && break; \
	  [ $$try = 5 ] && exit 1; echo "archgram: apt-get failed, trying again in 20 s"; sleep 20; \
	done
endef
define install_missing
	@missing=$$(for p in $(1); do \
	    dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q 'install ok installed' || echo $$p; \
	  done); \
	if [ -n "$$missing" ]; then \
	  echo "archgram: installing Debian packages:" $$missing; \
	  $(call apt_install,$$missing); \
	fi
endef

# deps (build and run packages, node and npm) is an order-only prerequisite of every object
# and generated source, and deps-test of every test binary, so under make -j no compile starts
# before the headers are installed. npm ci runs from one rule only (the stamp).
deps:
	$(call install_missing,$(DEB_BUILD))
	@# Node may come from Debian (nodejs + npm) or from a nodejs build that bundles npm and
	@# conflicts with Debian's npm package: ask for the commands, not the packages.
	@if ! command -v node >/dev/null || ! command -v npm >/dev/null; then \
	  echo "archgram: installing Node.js and npm"; \
	  $(call apt_install,nodejs npm); \
	fi

deps-test: deps
	$(call install_missing,$(DEB_TEST))

deps-bench: deps
	$(call install_missing,$(DEB_BENCH))

npm: $(NPM_STAMP)

$(NPM_STAMP): package.json package-lock.json | deps
	npm ci --no-audit --no-fund
	@touch $@

# --- C ------------------------------------------------------------------------------------
$(BUILD)/obj/%.o: %.c | deps
	@mkdir -p $(dir $@)
	$(CC) $(ALL_CFLAGS) -c $< -o $@

$(BUILD)/gen/migrations.c: $(sort $(wildcard migrations/*.sql)) server/embed.sh | deps
	@mkdir -p $(dir $@)
	sh server/embed.sh migrations $(sort $(wildcard migrations/*.sql)) > $@.tmp && mv $@.tmp $@

$(BUILD)/gen/openapi.c: schema/openapi.json server/embed.sh | deps
	@mkdir -p $(dir $@)
	sh server/embed.sh openapi schema/openapi.json > $@.tmp && mv $@.tmp $@

$(BUILD)/gen/%.o: $(BUILD)/gen/%.c | deps
	$(CC) $(ALL_CFLAGS) -c $< -o $@

define layer_archive
$(LIBDIR)/libag_$(1).a: $(call layer_obj,$(1)) $(GEN_OBJ_$(1))
	@mkdir -p $$(dir $$@)
	@rm -f $$@
	ar rcs $$@ $$^
endef
$(foreach l,$(LAYERS),$(eval $(call layer_archive,$(l))))

$(BUILD)/archgramd: $(BUILD)/obj/server/main.o $(ARCHIVES)
	$(CC) $(ALL_CFLAGS) $(ALL_LDFLAGS) -o $@ $< $(LINK_ARCHIVES) $(LDLIBS)

$(BUILD)/archgram: $(CLI_OBJ) $(ARCHIVES)
	$(CC) $(ALL_CFLAGS) $(ALL_LDFLAGS) -o $@ $(CLI_OBJ) $(LINK_ARCHIVES) $(LDLIBS)

unit-tests: $(UNIT_BIN)

$(BUILD)/tests/%: tests/unit/%.c $(ARCHIVES) | deps-test
	@mkdir -p $(dir $@)
	$(CC) $(ALL_CFLAGS) $(TEST_CFLAGS) $(ALL_LDFLAGS) -o $@ $< $(LINK_ARCHIVES) $(LDLIBS) -lcmocka

$(BUILD)/bench/%: bench/%.c $(ARCHIVES) | deps
	@mkdir -p $(dir $@)
	$(CC) $(ALL_CFLAGS) $(TEST_CFLAGS) $(ALL_LDFLAGS) -o $@ $< $(LINK_ARCHIVES) $(LDLIBS)

# --- web client ---------------------------------------------------------------------------
web: $(BUILD)/web/app.js

$(BUILD)/web/app.js: $(WEB_SRC) $(NPM_STAMP)
	@mkdir -p $(BUILD)/web
	cp web/index.html web/style.css $(BUILD)/web/
	node_modules/.bin/esbuild web/src/main.js --bundle --format=esm --minify --sourcemap \
	  --outfile=$@ --log-level=warning

# --- run ----------------------------------------------------------------------------------
run: all
	@mkdir -p $(dir $(DB))
	$(BUILD)/archgramd --port $(PORT) --db $(DB) --demo

# --- tests --------------------------------------------------------------------------------
# The tiers run one after the other (they share two cores); each is also a target of its own.
test: deps-test
	@$(MAKE) --no-print-directory check-layers bench-programs
	@$(MAKE) --no-print-directory test-unit
	@$(MAKE) --no-print-directory test-integration
	@$(MAKE) --no-print-directory test-browser
	@$(MAKE) --no-print-directory test-fuzz

check-layers: $(ARCHIVES) | deps-test
	python3 tools/check_layers.py --lib $(LIBDIR)
	node --test tests/tools/

# The CGAL straight-skeleton oracle of the extrusion tests and benchmark, built from
# ../shared/tools/cgal_skeleton when that exists (libcgal-dev, g++: test packages); tests
# that need it skip, naming it, when it is absent or could not be built.
ORACLE_SRC := $(wildcard ../shared/tools/cgal_skeleton/main.cpp)
ORACLE     := $(if $(ORACLE_SRC),$(BUILD)/oracle/cgal_skeleton)
$(BUILD)/oracle/cgal_skeleton: $(ORACLE_SRC)
	-$(MAKE) --no-print-directory -C $(dir $<) BUILD=$(CURDIR)/$(BUILD)/oracle

# Each suite gets 10 minutes: a hang is a failure with a name, not a stuck CI.
test-unit: $(UNIT_BIN) $(ORACLE)
	@pass=0; fail=0; for t in $(UNIT_BIN); do \
	  if timeout 600 $$t; then pass=$$((pass+1)); else fail=$$((fail+1)); echo "FAILED: $$t"; fi; \
	done; echo "unit: $$pass passed, $$fail failed"; [ $$fail = 0 ]

# ARCHGRAMD / ARCHGRAM point the tiers at other builds (test-asan sets them).
test-integration: programs $(NPM_STAMP) | deps-test
	ARCHGRAMD=$${ARCHGRAMD:-$(BUILD)/archgramd} ARCHGRAM=$${ARCHGRAM:-$(BUILD)/archgram} \
	  node --test --test-concurrency=1 tests/integration/

test-browser: $(BUILD)/archgramd web | deps-test
	node --test --test-concurrency=1 tests/browser/

# AddressSanitizer and UndefinedBehaviorSanitizer (any report fails: UB aborts, ASan and
# LeakSanitizer exit non-zero, the integration harness rejects a daemon that printed one).
ASAN_DIR   := $(BUILD)/asan
ASAN_FLAGS := -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined
test-asan: deps-test $(NPM_STAMP)
	@$(MAKE) --no-print-directory BUILD=$(ASAN_DIR) SANITIZE="$(ASAN_FLAGS)" CFLAGS="-O1 -g" \
	  programs unit-tests
	@ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 UBSAN_OPTIONS=print_stacktrace=1 \
	  $(MAKE) --no-print-directory BUILD=$(ASAN_DIR) SANITIZE="$(ASAN_FLAGS)" CFLAGS="-O1 -g" \
	  test-unit
	@ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 UBSAN_OPTIONS=print_stacktrace=1 \
	  ARCHGRAMD=$(ASAN_DIR)/archgramd ARCHGRAM=$(ASAN_DIR)/archgram \
	  $(MAKE) --no-print-directory BUILD=$(ASAN_DIR) SANITIZE="$(ASAN_FLAGS)" CFLAGS="-O1 -g" \
	  test-integration

# --- benchmarks ---------------------------------------------------------------------------
# make test builds them (bench-programs) so that they keep compiling; make bench runs them.
bench-programs: $(BENCH_BIN)

bench: deps-bench all $(BENCH_BIN) $(ORACLE)
	@for b in bench/*.sh; do [ -f "$$b" ] && sh "$$b"; done; true
	@for b in bench/*.js; do [ -f "$$b" ] && node "$$b"; done; true
	@for b in $(BENCH_BIN); do $$b; done

include tests/fuzz/fuzz.mk

clean:
	rm -rf $(BUILD)

-include $(shell find $(BUILD)/obj $(BUILD)/gen $(BUILD)/tests $(BUILD)/bench -name '*.d' 2>/dev/null)
