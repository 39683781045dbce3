# archgram — build, run and test.
#
#   make run    install what is missing, build, start archgramd with demo content
#   make test   every test tier: C unit, service integration, browser
#   make bench  benchmarks (print figures; not tests)
#
# Every target installs the Debian and npm packages it needs when they are missing,
# so a fresh clone on a fresh Debian 12 machine needs nothing but these commands.

CC      ?= cc
BUILD   := build
CFLAGS  ?= -O2 -g
CFLAGS  += -std=c11 -D_GNU_SOURCE -Wall -Wextra -Wno-unused-parameter -MMD -MP \
           -I/usr/include/suitesparse
# Tests and benchmarks find tests/data and ../shared relative to the checkout they are built in.
TEST_CFLAGS := -Iserver -DAG_REPO_DIR=\"$(CURDIR)\"
LDLIBS  := -lwebsockets -lmicrohttpd -ljansson -lsqlite3 -lcholmod -lspqr -lsuitesparseconfig \
           -lassimp -lcrypto -lpng -lpthread -lm

PORT    ?= 8080
DB      ?= var/archgram.db

# Debian packages: to build and run, and in addition to test.
DEB_BUILD := gcc make pkg-config libc6-dev libmicrohttpd-dev libjansson-dev libwebsockets-dev \
             libsqlite3-dev libsuitesparse-dev libassimp-dev libssl-dev libpng-dev
DEB_TEST  := libcmocka-dev chromium curl
DEB_BENCH := wrk

# Sources: every .c below a layer directory is part of the library, except the two mains.
LIB_SRC   := $(shell find server/core server/io server/store server/app server/net -name '*.c' | sort)
LIB_OBJ   := $(LIB_SRC:%.c=$(BUILD)/obj/%.o)
GEN_SRC   := $(BUILD)/gen/migrations.c $(BUILD)/gen/openapi.c
GEN_OBJ   := $(GEN_SRC:%.c=%.o)
LIB       := $(BUILD)/libarchgram.a
# The command-line tool: a dispatcher (server/cli.c) and one file per subcommand.
CLI_SRC   := server/cli.c $(sort $(wildcard server/cli/*.c))
CLI_OBJ   := $(CLI_SRC:%.c=$(BUILD)/obj/%.o)
UNIT_SRC  := $(sort $(wildcard tests/unit/test_*.c))
UNIT_BIN  := $(UNIT_SRC:tests/unit/%.c=$(BUILD)/tests/%)
BENCH_SRC := $(sort $(wildcard bench/*.c))
BENCH_BIN := $(BENCH_SRC:bench/%.c=$(BUILD)/bench/%)
WEB_SRC   := $(shell find web -type f 2>/dev/null | sort)

.PHONY: all deps deps-test deps-bench npm run test test-unit test-integration test-browser \
        bench clean web

all: deps $(BUILD)/archgramd $(BUILD)/archgram $(UNIT_BIN) $(BENCH_BIN) web

# --- packages -----------------------------------------------------------------------------
define install_missing
	@missing=$$(for p in $(1); do \
	    dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q 'install ok installed' || echo $$p; \
	  done); \
	if [ -n "$$missing" ]; then \
	  echo "archgram: installing Debian packages:" $$missing; \
	  SUDO=; [ "$$(id -u)" = 0 ] || SUDO=sudo; \
	  $$SUDO apt-get update -q && \
	  DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y --no-install-recommends $$missing; \
	fi
endef

deps:
	$(call install_missing,$(DEB_BUILD))
	@# Node may come from Debian (nodejs + npm) or from a nodejs build that bundles npm and
	@# conflicts with Debian's npm package: ask for the commands, not the packages.
	@if ! command -v node >/dev/null || ! command -v npm >/dev/null; then \
	  echo "archgram: installing Node.js and npm"; \
	  SUDO=; [ "$$(id -u)" = 0 ] || SUDO=sudo; \
	  $$SUDO apt-get update -q && \
	  DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y --no-install-recommends nodejs npm; \
	fi
	@$(MAKE) --no-print-directory npm

deps-test: deps
	$(call install_missing,$(DEB_TEST))

deps-bench: deps
	$(call install_missing,$(DEB_BENCH))

npm: node_modules/.archgram-stamp

node_modules/.archgram-stamp: package.json package-lock.json
	npm ci --no-audit --no-fund
	@touch $@

# --- C ------------------------------------------------------------------------------------
$(BUILD)/obj/%.o: %.c
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -c $< -o $@

$(BUILD)/gen/migrations.c: $(sort $(wildcard migrations/*.sql)) server/embed.sh
	@mkdir -p $(dir $@)
	sh server/embed.sh migrations $(sort $(wildcard migrations/*.sql)) > $@

$(BUILD)/gen/openapi.c: schema/openapi.json server/embed.sh
	@mkdir -p $(dir $@)
	sh server/embed.sh openapi schema/openapi.json > $@

$(BUILD)/gen/%.o: $(BUILD)/gen/%.c
	$(CC) $(CFLAGS) -c $< -o $@

$(LIB): $(LIB_OBJ) $(GEN_OBJ)
	@rm -f $@
	ar rcs $@ $^

$(BUILD)/archgramd: $(BUILD)/obj/server/main.o $(LIB)
	$(CC) $(CFLAGS) -o $@ $^ $(LDLIBS)

$(BUILD)/archgram: $(CLI_OBJ) $(LIB)
	$(CC) $(CFLAGS) -o $@ $^ $(LDLIBS)

$(BUILD)/tests/%: tests/unit/%.c $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(TEST_CFLAGS) -o $@ $< $(LIB) $(LDLIBS) -lcmocka

$(BUILD)/bench/%: bench/%.c $(LIB)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(TEST_CFLAGS) -o $@ $< $(LIB) $(LDLIBS)

# --- web client ---------------------------------------------------------------------------
web: $(BUILD)/web/app.js

$(BUILD)/web/app.js: $(WEB_SRC) node_modules/.archgram-stamp
	@mkdir -p $(BUILD)/web
	cp web/index.html web/style.css $(BUILD)/web/
	node_modules/.bin/esbuild web/src/main.js --bundle --format=esm --minify --sourcemap \
	  --outfile=$@ --log-level=warning

# --- run ----------------------------------------------------------------------------------
run: all
	@mkdir -p $(dir $(DB))
	$(BUILD)/archgramd --port $(PORT) --db $(DB) --demo

# --- tests --------------------------------------------------------------------------------
test: deps-test all
	@$(MAKE) --no-print-directory test-unit
	@$(MAKE) --no-print-directory test-integration
	@$(MAKE) --no-print-directory test-browser

# Each suite gets 10 minutes: a hang is a failure with a name, not a stuck CI.
test-unit: $(UNIT_BIN)
	@pass=0; fail=0; for t in $(UNIT_BIN); do \
	  if timeout 600 $$t; then pass=$$((pass+1)); else fail=$$((fail+1)); echo "FAILED: $$t"; fi; \
	done; echo "unit: $$pass passed, $$fail failed"; [ $$fail = 0 ]

test-integration: $(BUILD)/archgramd $(BUILD)/archgram
	node --test --test-concurrency=1 tests/integration/

test-browser: $(BUILD)/archgramd web
	node --test --test-concurrency=1 tests/browser/

# --- benchmarks ---------------------------------------------------------------------------
bench: deps-bench all
	@for b in bench/*.sh; do [ -f "$$b" ] && sh "$$b"; done; true
	@for b in bench/*.js; do [ -f "$$b" ] && node "$$b"; done; true
	@for b in $(BENCH_BIN); do $$b; done

clean:
	rm -rf $(BUILD)

-include $(shell find $(BUILD)/obj $(BUILD)/tests $(BUILD)/bench -name '*.d' 2>/dev/null)
