# packd — build, test, sanitize, bench, run.
#   make          build build/packd and the benchmarks' binaries (installs missing
#                 Debian packages first; a bench binary is never left older than
#                 the code it measures)
#   make test     install the test tools (first time), build and run every unit
#                 and integration test (the benchmarks are built too, so they
#                 cannot rot, but not run)
#   make sanitize the same tests under AddressSanitizer + UBSan (build-san/)
#   make bench    build and run the benchmarks in bench/ (bench/service.sh wants
#                 wrk: sh deploy/install-deps.sh bench)
#   make run      build and start the daemon with its embedded defaults
#   make format   apply .clang-format to every C file (clang-format 14)
#
# Source files are found by wildcard: a new core/<method>/foo.c or
# tests/unit/test_foo.c needs no edit here.  Includes name their file from the
# tree's root ("core/base/par.h") unless it sits in the same folder; the
# compiler records which headers each object read (-MMD -MP, build/**/*.d).

BUILD   ?= build
# Build on every core (JOBS=N for fewer; -jN on the command line is not seen
# here): a fresh `make run` compiles ~200 files.  Sub-makes share the jobs.
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
ifeq ($(MAKELEVEL),0)
MAKEFLAGS += -j$(JOBS)
endif
CC      ?= cc
OPT     ?= -O2
# Functions start on a cache line: the hot contact loops otherwise run 1.6x
# slower or faster with where the linker places them (docs/perf/build.md).
ALIGN   ?= -falign-functions=64
SAN     ?=
VERSION := $(shell cat VERSION 2>/dev/null || echo 0.0.0)

PKGS    := hdf5 jansson libmicrohttpd sqlite3 libcrypto cairo fontconfig libcurl
DEPS_OK := $(BUILD)/.deps-ok
TEST_DEPS_OK := $(BUILD)/.test-deps-ok

WARN    := -Wall -Wextra -Werror -Wshadow -Wstrict-prototypes -Wno-unused-parameter
CSTD    := -std=c17 -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE
BASE_CFLAGS := $(CSTD) $(OPT) $(ALIGN) -g -MMD -MP $(WARN) $(SAN) -DPACKD_VERSION='"$(VERSION)"'

# core/ is plain C17 + libm: compiled with no include path but the tree's root.
CORE_CFLAGS := $(BASE_CFLAGS) -I.
EXT_CFLAGS   = $(BASE_CFLAGS) $(shell pkg-config --cflags $(PKGS) 2>/dev/null) -I/usr/include/suitesparse -I. -I$(BUILD)/gen
EXT_LIBS     = $(shell pkg-config --libs $(PKGS) 2>/dev/null) -lcholmod -lgomp -lm -lpthread

# MPI is optional: with Debian's OpenMPI (libopenmpi-dev, pkg-config ompi-c)
# `mpirun -np R packd run fe2.json` spreads the Gauss points over the ranks
# (api/par/mpi_world.c, docs/fe2.md); without it packd is one process and
# refuses a launch of several ranks.  `make MPI=0` builds without it anyway.
# Looked for when a recipe runs, so the first make of a fresh machine finds the
# OpenMPI its dependency step installed; only mpi_world.c includes <mpi.h>.
MPI     ?= auto
mpi_on   = $(if $(filter auto,$(MPI)),$(shell pkg-config --exists ompi-c 2>/dev/null && echo 1),$(filter 1,$(MPI)))
EXT_LIBS += $(if $(mpi_on),$(shell pkg-config --libs ompi-c))
$(BUILD)/obj/api/par/mpi_world.o: EXT_CFLAGS += $(if $(mpi_on),-DPK_HAVE_MPI $(shell pkg-config --cflags ompi-c))
# mpi_world.o is rebuilt when that changes: the stamp holds the choice and is
# rewritten (so newer) only when it differs — a name per choice would not do,
# as a missing .SECONDARY file without prerequisites forces nothing.
MPI_STAMP := $(BUILD)/.mpi

tree        = $(shell find $(1) -name '*.c' | sort)
CORE_SRC   := $(call tree,core)
API_SRC    := $(call tree,api)
DAEMON_SRC := $(filter-out daemon/cli/main.c,$(call tree,daemon))
SCHEMAS    := $(sort $(wildcard schemas/*.json))
WEB        := $(sort $(wildcard web/*)) $(sort $(wildcard examples/*.json examples/*/*.json))
UNIT_SRC   := $(wildcard tests/unit/test_*.c)
BENCH_SRC  := $(wildcard bench/*.c)

CORE_OBJ   := $(CORE_SRC:%.c=$(BUILD)/obj/%.o)
API_OBJ    := $(API_SRC:%.c=$(BUILD)/obj/%.o) $(BUILD)/obj/gen/schemas_embedded.o
DAEMON_OBJ := $(DAEMON_SRC:%.c=$(BUILD)/obj/%.o) $(BUILD)/obj/gen/web_embedded.o
LIB_OBJ    := $(DAEMON_OBJ) $(API_OBJ) $(CORE_OBJ)
UNIT_BIN   := $(UNIT_SRC:tests/unit/%.c=$(BUILD)/tests/%)
BENCH_BIN  := $(BENCH_SRC:bench/%.c=$(BUILD)/bench/%)

.PHONY: FORCE all deps test test-run sanitize bench bench-fe2 run clean check-schemas install format tradeoffs tradeoff-plots
.SECONDARY:

all: $(DEPS_OK) $(BUILD)/packd $(BENCH_BIN)

# Install missing Debian packages once per build directory
# (deploy/install-deps.sh checks each package and installs only what is missing):
# what the build and the daemon need for every target, the test tools for make test.
$(DEPS_OK): deploy/install-deps.sh
	@mkdir -p $(@D)
	@sh deploy/install-deps.sh run || exit 1
	@touch $@

$(TEST_DEPS_OK): deploy/install-deps.sh tests/tools/playwright.sh
	@mkdir -p $(@D)
	@sh deploy/install-deps.sh test || exit 1
	@sh tests/tools/playwright.sh $(BUILD)/node
	@touch $@

deps: $(DEPS_OK)

$(BUILD)/obj/core/%.o: core/%.c | $(DEPS_OK)
	@mkdir -p $(@D)
	$(CC) $(CORE_CFLAGS) -c $< -o $@

$(MPI_STAMP): FORCE | $(DEPS_OK)
	@mkdir -p $(@D)
	@v='$(or $(mpi_on),0)'; [ "$$(cat $@ 2>/dev/null)" = "$$v" ] || echo "$$v" >$@

FORCE:

$(BUILD)/obj/api/par/mpi_world.o: $(MPI_STAMP)

$(BUILD)/obj/api/%.o: api/%.c | $(DEPS_OK)
	@mkdir -p $(@D)
	$(CC) $(EXT_CFLAGS) -c $< -o $@

$(BUILD)/obj/daemon/%.o: daemon/%.c | $(DEPS_OK)
	@mkdir -p $(@D)
	$(CC) $(EXT_CFLAGS) -c $< -o $@

# The schemas are compiled into the binary so `packd validate` and the daemon
# serve exactly the files in schemas/, wherever packd is installed.
$(BUILD)/gen/schemas_embedded.c: $(SCHEMAS) tools/embed.sh
	@mkdir -p $(@D)
	sh tools/embed.sh api/schemas/schemas_embedded.h pk_embedded_schema pk_embedded_schemas char / $(SCHEMAS) > $@

$(BUILD)/obj/gen/schemas_embedded.o: $(BUILD)/gen/schemas_embedded.c | $(DEPS_OK)
	@mkdir -p $(@D)
	$(CC) $(BASE_CFLAGS) -I. -c $< -o $@

# The dashboard (web/) and the examples it offers are compiled in the same way.
$(BUILD)/gen/web_embedded.c: $(WEB) tools/embed.sh
	@mkdir -p $(@D)
	sh tools/embed.sh daemon/http/web_assets.h pk_web_asset pk_web_assets 'unsigned char' web/ $(WEB) > $@

$(BUILD)/obj/gen/web_embedded.o: $(BUILD)/gen/web_embedded.c | $(DEPS_OK)
	@mkdir -p $(@D)
	$(CC) $(BASE_CFLAGS) -I. -c $< -o $@

$(BUILD)/packd: $(BUILD)/obj/daemon/cli/main.o $(LIB_OBJ)
	$(CC) $(SAN) -o $@ $^ $(EXT_LIBS)

$(BUILD)/tests/%: tests/unit/%.c $(LIB_OBJ)
	@mkdir -p $(@D)
	$(CC) $(EXT_CFLAGS) -Itests -o $@ $< $(LIB_OBJ) $(EXT_LIBS)

$(BUILD)/bench/%: bench/%.c $(LIB_OBJ)
	@mkdir -p $(@D)
	$(CC) $(EXT_CFLAGS) -o $@ $< $(LIB_OBJ) $(EXT_LIBS)

# The test tools first, then a make of its own: the build sees what they brought
# (OpenMPI is looked for by pkg-config).
test: $(TEST_DEPS_OK)
	@$(MAKE) --no-print-directory test-run

test-run: $(DEPS_OK) $(BUILD)/packd $(UNIT_BIN) $(BENCH_BIN) fuzz-build
	@sh tests/run.sh $(BUILD)

sanitize:
	$(MAKE) BUILD=build-san OPT=-O1 SAN="-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all" test

bench: $(DEPS_OK) $(BUILD)/packd $(BENCH_BIN)
	@for b in $(BENCH_BIN); do echo "== $$b"; $$b || exit 1; done
	@echo "== bench/service.sh"; PACKD=$(BUILD)/packd sh bench/service.sh

# The trade study (docs/tradeoffs.md): `make tradeoffs` measures every trade
# (bench/tradeoff/run.py, ~7 CPU min on one core; the lines go to
# docs/tradeoffs/data/) and redraws; `make tradeoff-plots` only redraws the
# plots and tables from the kept lines.  TRADEOFF_STUDIES=... runs a subset.
# Debian's python3, which has python3-matplotlib (not a pyenv or venv one).
TRADEOFF_STUDIES ?=
PYTHON3 ?= /usr/bin/python3
tradeoffs: $(DEPS_OK) $(BUILD)/packd
	$(PYTHON3) bench/tradeoff/run.py --packd $(BUILD)/packd --data docs/tradeoffs/data $(TRADEOFF_STUDIES)
	$(MAKE) --no-print-directory tradeoff-plots

tradeoff-plots: $(DEPS_OK)
	$(PYTHON3) bench/tradeoff/plot.py --data docs/tradeoffs/data --out docs/tradeoffs --doc docs/tradeoffs.md >/dev/null

# Only the FE² bench (bench/fe2.c; the examples themselves: bench/fe2/run_examples.sh).
bench-fe2: $(DEPS_OK) $(BUILD)/bench/fe2
	$(BUILD)/bench/fe2

run: $(DEPS_OK) $(BUILD)/packd
	$(BUILD)/packd serve

# make install [PREFIX=/usr/local] [SYSCONFDIR=/etc] [DESTDIR=]: the binary,
# the systemd unit (paths rewritten to PREFIX and SYSCONFDIR), the example
# configuration as packd.conf unless one exists, the docs (docs/operations.md)
# and the example jobs.
PREFIX     ?= /usr/local
SYSCONFDIR ?= /etc
UNITDIR    ?= $(PREFIX)/lib/systemd/system
DOCDIR     ?= $(PREFIX)/share/doc/packd
install: $(BUILD)/packd
	install -d $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(UNITDIR) $(DESTDIR)$(SYSCONFDIR)/packd $(DESTDIR)$(DOCDIR)
	install -m 0755 $(BUILD)/packd $(DESTDIR)$(PREFIX)/bin/packd
	sed -e 's|/usr/local/bin/packd|$(PREFIX)/bin/packd|' -e 's|/etc/packd/|$(SYSCONFDIR)/packd/|' \
	    -e 's|/usr/local/share/doc/packd|$(DOCDIR)|' deploy/packd.service >$(DESTDIR)$(UNITDIR)/packd.service
	chmod 0644 $(DESTDIR)$(UNITDIR)/packd.service
	install -m 0644 deploy/packd.conf.example $(DESTDIR)$(SYSCONFDIR)/packd/packd.conf.example
	[ -e $(DESTDIR)$(SYSCONFDIR)/packd/packd.conf ] || \
	    install -m 0644 deploy/packd.conf.example $(DESTDIR)$(SYSCONFDIR)/packd/packd.conf
	install -m 0644 README.md docs/*.md $(DESTDIR)$(DOCDIR)/
	install -d $(DESTDIR)$(DOCDIR)/examples
	install -m 0644 examples/*.json $(DESTDIR)$(DOCDIR)/examples/

# Apply the house style (.clang-format) to every C file of the tree.
format:
	@command -v clang-format >/dev/null || { echo "format: apt-get install clang-format"; exit 1; }
	git ls-files '*.c' '*.h' | xargs clang-format -i

# Cross-check schemas and examples with an independent validator (python3-jsonschema).
check-schemas: $(DEPS_OK)
	sh tests/integration/test_schemas.sh

# ---- fuzzing: libFuzzer harnesses (tests/fuzz/) built by clang in build-fuzz/
#   make fuzz        run each harness FUZZ_SECONDS (default 60) from the
#                    committed corpus; new inputs go to build-fuzz/corpus/,
#                    crashes to build-fuzz/crash-*
#   make fuzz-build  only build them (make test does, then runs each for a
#                    few seconds); skipped with a message when clang's
#                    fuzzer runtime (libclang-rt-14-dev) is missing
FUZZ_BUILD   ?= build-fuzz
FUZZ_CC      ?= clang
FUZZ_SECONDS ?= 60
FUZZ_TARGETS := request gmsh tetgen h5_rve http
FUZZ_SAN     := -fsanitize=address,undefined -fno-sanitize-recover=undefined -fno-omit-frame-pointer
FUZZ_CFLAGS   = $(CSTD) -O1 -g -MMD -MP $(WARN) $(FUZZ_SAN) -fsanitize=fuzzer-no-link -DPACKD_VERSION='"$(VERSION)"' \
               $(shell pkg-config --cflags $(PKGS) 2>/dev/null) -I/usr/include/suitesparse -I. -I$(FUZZ_BUILD)/gen
FUZZ_OBJ     := $(CORE_SRC:%.c=$(FUZZ_BUILD)/obj/%.o) $(API_SRC:%.c=$(FUZZ_BUILD)/obj/%.o) \
               $(FUZZ_BUILD)/obj/gen/schemas_embedded.o \
               $(patsubst %.c,$(FUZZ_BUILD)/obj/%.o,$(filter-out daemon/cli/%,$(DAEMON_SRC))) \
               $(FUZZ_BUILD)/obj/gen/web_embedded.o
FUZZ_BIN     := $(FUZZ_TARGETS:%=$(FUZZ_BUILD)/fuzz_%)
FUZZ_OK      := $(FUZZ_BUILD)/.fuzzer-ok

.PHONY: fuzz fuzz-build

# Does this clang link libFuzzer and find the headers packd's sources include
# (<omp.h> is clang's own, from libomp-14-dev)?  Leaves the stamp only if so.
$(FUZZ_OK):
	@mkdir -p $(@D)
	@printf '#include <omp.h>\nint LLVMFuzzerTestOneInput(const char *d, unsigned long n) { return 0; }\n' > $(@D)/probe.c
	@if $(FUZZ_CC) -fsanitize=fuzzer $(@D)/probe.c -o $(@D)/probe 2>$(@D)/probe.err; then touch $@; \
	 else echo "fuzz: skipped: $(FUZZ_CC) -fsanitize=fuzzer does not build: $$(grep -m1 error $(@D)/probe.err)" \
	    "(apt-get install clang libclang-rt-14-dev libomp-14-dev)"; fi

$(FUZZ_BUILD)/obj/%.o: %.c | $(DEPS_OK)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -c $< -o $@

$(FUZZ_BUILD)/gen/schemas_embedded.c: $(SCHEMAS) tools/embed.sh
	@mkdir -p $(@D)
	sh tools/embed.sh api/schemas/schemas_embedded.h pk_embedded_schema pk_embedded_schemas char / $(SCHEMAS) > $@

$(FUZZ_BUILD)/gen/web_embedded.c: $(WEB) tools/embed.sh
	@mkdir -p $(@D)
	sh tools/embed.sh daemon/http/web_assets.h pk_web_asset pk_web_assets 'unsigned char' web/ $(WEB) > $@

$(FUZZ_BUILD)/obj/gen/%.o: $(FUZZ_BUILD)/gen/%.c | $(DEPS_OK)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -c $< -o $@

$(FUZZ_BUILD)/fuzz_%: tests/fuzz/fuzz_%.c $(FUZZ_OBJ)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -fsanitize=fuzzer -o $@ $< $(FUZZ_OBJ) $(EXT_LIBS)

fuzz-build: $(FUZZ_OK)
	@if [ -f $(FUZZ_OK) ]; then $(MAKE) --no-print-directory $(FUZZ_BIN); fi

fuzz: fuzz-build
	@[ -f $(FUZZ_OK) ] || exit 0; for t in $(FUZZ_TARGETS); do \
	    mkdir -p $(FUZZ_BUILD)/corpus/$$t; echo "== fuzz_$$t: $(FUZZ_SECONDS) s"; \
	    $(FUZZ_BUILD)/fuzz_$$t -max_total_time=$(FUZZ_SECONDS) -timeout=10 -rss_limit_mb=2048 \
	        -artifact_prefix=$(FUZZ_BUILD)/crash-$$t- $(FUZZ_BUILD)/corpus/$$t tests/fuzz/corpus/$$t || exit 1; \
	done

clean:
	rm -rf build build-san $(FUZZ_BUILD)

# The headers each object, test and bench binary read, as the compiler saw them.
-include $(shell find $(BUILD) $(FUZZ_BUILD) -name '*.d' 2>/dev/null)
