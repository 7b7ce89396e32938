# libodhs - GNU Makefile (plain GNU make, no autotools/cmake).
#
# Main targets (`make help` prints this list):
#   all (default)   lib/libodhs.a, lib/libodhs.so.X.Y.Z + soname/dev symlinks
#   check           build and run the Check test runner, plus check-symbols,
#                   check-readme, check-link and check-python
#   check-asan      rebuild library + tests in build-asan/ with ASan/UBSan, run
#   check-allocfail rebuild in build-allocfail/ with allocation-failure
#                   injection (-DODHS_FAULT_INJECTION) + ASan/UBSan/LSan and
#                   run the allocfail suite (fail every allocation in turn)
#   check-tsan      rebuild library + tests in build-tsan/ with ThreadSanitizer,
#                   run the threads suite (must report no data race)
#   fuzz            build every tests/fuzz/fuzz_*.c with libFuzzer (clang)
#                   against the library rebuilt in build-fuzz/
#   fuzz-ci         run each fuzzer FUZZ_TIME (60) s on a copy of its corpus,
#                   fail on any crash; prints the number of executions
#   check-symbols   fail if lib/libodhs.so exports anything not named odhs_*
#   check-run       run the tests without deps-if-missing/check-symbols
#   check-link      stage, then link tests/pkgconfig_consumer.c by every link
#                   line of README.md and docs/guide.md and with pkg-config
#                   (shared, static libodhs.a, fully static), run each
#                   (tests/link_check.sh; a fully static link is skipped,
#                   naming them, when static libraries are missing); in a
#                   SuiteSparse build also against a SUITESPARSE=0 one
#                   (build/link-nos), which links fully statically on Debian
#   check-rheology  the rheology suite to strain 2 (fixed-pressure flow)
#   tests           only build the runner build/tests/run_tests
#   examples        stage-install into build/stage, build examples/*.c (and
#                   examples/mpi/sweep_mpi.c: sweep_serial, and sweep_mpi
#                   when mpicc exists) against it with pkg-config only, run
#                   pkgconfig-test; examples/lammps_coupling.c and its test
#                   when LAMMPS's C library interface is installed
#   pkgconfig-test  the same as check-link
#   print-libs      the libraries to link lib/libodhs.a with (system libraries
#                   shared): gcc ... lib/libodhs.a $(make -s print-libs)
#   check-mpi       build examples/mpi/sweep_mpi.c with mpicc and run a tiny
#                   campaign on 2 ranks, killed and resumed, against a serial
#                   run (skipped when MPI is absent)
#   stage           `make install` into build/stage (used by examples)
#   demo            deps-if-missing, all, examples, run build/examples/shear_flow
#   bench           build bench/*.c against lib/libodhs.a into build/bench/
#   python          stage, then build the Python package's cffi extension
#                   (python/odhs/_cffi*.so) against build/stage with
#                   pkg-config: PYTHONPATH=python imports odhs
#   check-python    python, then the pytest suite python/tests (skipped with
#                   a message when python3-cffi, -numpy, -pytest or the
#                   Python headers are missing; make deps installs them)
#   install, uninstall   honour PREFIX, DESTDIR, LIBDIR, INCLUDEDIR
#   deps, deps-if-missing   install the Debian build dependencies (apt-get)
#   clean           remove build/, build-asan/, build-allocfail/, build-tsan/,
#                   build-fuzz/, lib/*.a, lib/*.so*
#
# Knobs (set on the command line, e.g. `make SUITESPARSE=0 check`):
#   SUITESPARSE=auto|1|0   CHOLMOD/SPQR backends (auto: if cholmod.h exists)
#   CLP=auto|1|0           COIN-OR CLP for odhs_stepper_jam_lp (auto: if
#                          coin/Clp_C_Interface.h exists)
#   OPTFLAGS=-O2 -g        optimisation/debug flags
#   WARNFLAGS=...          warnings (default includes -Werror)
#   CC, CFLAGS, CPPFLAGS, LDFLAGS, LDLIBS   appended as usual
#   PREFIX, LIBDIR, INCLUDEDIR, DESTDIR     install locations
#   MPICC=mpicc, MPIRUN=mpirun             MPI compiler wrapper and launcher

# Disable the built-in implicit rules and variables: every rule is below.
MAKEFLAGS += --no-builtin-rules
.SUFFIXES:
# Delete a target whose recipe failed half-way (no truncated .o or .a left).
.DELETE_ON_ERROR:

.DEFAULT_GOAL := all

# ---------------------------------------------------------------------------
# Version: parsed from the public header, the single source of truth.
# ---------------------------------------------------------------------------
VERSION_HEADER := include/odhs/common.h
odhs_version_field = $(shell sed -n \
    's/^[[:space:]]*\#[[:space:]]*define[[:space:]]\{1,\}ODHS_VERSION_$(1)[[:space:]]\{1,\}\([0-9]\{1,\}\).*/\1/p' \
    $(VERSION_HEADER))
MAJOR := $(call odhs_version_field,MAJOR)
MINOR := $(call odhs_version_field,MINOR)
PATCH := $(call odhs_version_field,PATCH)
ifeq ($(strip $(MAJOR)),)
$(error could not parse ODHS_VERSION_MAJOR from $(VERSION_HEADER))
endif
ifeq ($(strip $(MINOR)),)
$(error could not parse ODHS_VERSION_MINOR from $(VERSION_HEADER))
endif
ifeq ($(strip $(PATCH)),)
$(error could not parse ODHS_VERSION_PATCH from $(VERSION_HEADER))
endif
VERSION := $(MAJOR).$(MINOR).$(PATCH)

# ---------------------------------------------------------------------------
# Tools and install locations
# ---------------------------------------------------------------------------
CC         ?= cc
AR         ?= ar
PKG_CONFIG ?= pkg-config
INSTALL    ?= install

PREFIX     ?= /usr/local
LIBDIR     ?= $(PREFIX)/lib
INCLUDEDIR ?= $(PREFIX)/include
DESTDIR    ?=

# ---------------------------------------------------------------------------
# Build directories. BUILD and OUT_LIBDIR are overridden by check-asan so that
# the sanitizer build lives entirely in build-asan/ and never touches build/
# or lib/.
# ---------------------------------------------------------------------------
BUILD      ?= build
OUT_LIBDIR ?= lib
OBJDIR     := $(BUILD)/obj

# ---------------------------------------------------------------------------
# Optional SuiteSparse (CHOLMOD + SPQR). Debian's SuiteSparse 5.x has no .pc
# files, so the header directory and library names are given by hand.
# ---------------------------------------------------------------------------
SUITESPARSE     ?= auto
SUITESPARSE_INC ?= /usr/include/suitesparse
SUITESPARSE_LIBS_LIST := -lspqr -lcholmod -lsuitesparseconfig

ifeq ($(SUITESPARSE),auto)
  HAVE_SUITESPARSE := $(if $(wildcard $(SUITESPARSE_INC)/cholmod.h),1,0)
else ifneq ($(filter 1 yes on true,$(SUITESPARSE)),)
  HAVE_SUITESPARSE := 1
else ifneq ($(filter 0 no off false,$(SUITESPARSE)),)
  HAVE_SUITESPARSE := 0
else
  $(error SUITESPARSE must be auto, 1 or 0 (got '$(SUITESPARSE)'))
endif

ifeq ($(HAVE_SUITESPARSE),1)
  SUITESPARSE_CPPFLAGS := -I$(SUITESPARSE_INC) -DODHS_HAVE_SUITESPARSE=1
  SUITESPARSE_LIBS     := $(SUITESPARSE_LIBS_LIST)
else
  SUITESPARSE_CPPFLAGS :=
  SUITESPARSE_LIBS     :=
endif

# ---------------------------------------------------------------------------
# Optional COIN-OR CLP (the LP solver of odhs_stepper_jam_lp, the fast route
# to jammed packings; Debian coinor-libclp-dev). Its C interface is linked
# from C; CLP itself is C++, so a static link needs -lstdc++ too.
# ---------------------------------------------------------------------------
CLP     ?= auto
CLP_INC ?= /usr/include/coin
ifeq ($(CLP),auto)
  HAVE_CLP := $(if $(wildcard $(CLP_INC)/Clp_C_Interface.h),1,0)
else ifneq ($(filter 1 yes on true,$(CLP)),)
  HAVE_CLP := 1
else ifneq ($(filter 0 no off false,$(CLP)),)
  HAVE_CLP := 0
else
  $(error CLP must be auto, 1 or 0 (got '$(CLP)'))
endif
ifeq ($(HAVE_CLP),1)
  CLP_CPPFLAGS := -DODHS_HAVE_CLP=1
  CLP_LIBS     := -lClp -lCoinUtils
else
  CLP_CPPFLAGS :=
  CLP_LIBS     :=
endif

# LAPACKE/LAPACK/BLAS are always required.
MATH_LIBS := -llapacke -llapack -lblas -lm

# Everything the library itself links against, the system libraries being
# shared (`make print-libs` prints it for linking lib/libodhs.a).
ODHS_LIBS    := $(CLP_LIBS) $(SUITESPARSE_LIBS) $(MATH_LIBS)

# ---------------------------------------------------------------------------
# odhs.pc's static-link fields, what `pkg-config --static --libs odhs` adds
# after -lodhs: all a program linking libodhs.a needs, and with `cc -static`
# the dependencies of the system's static libraries too.
#  - Requires.private: those of lapacke, lapack, blas that have a .pc file
#    (Debian has all three).
#  - Libs.private: SuiteSparse 5.x has no .pc files, so its libraries are
#    named here with the static dependencies of libcholmod.a (AMD, CAMD,
#    COLAMD, CCOLAMD, METIS, OpenMP). Then the math libraries' -l flags once
#    more (from `pkg-config --static --libs-only-l`, each kept at its last
#    place) and -lquadmath after -lgfortran: a static libgfortran needs it,
#    and pkg-config puts Requires.private after Libs.private, so only here
#    can -lquadmath follow -lgfortran.
#  - The optional libraries (PC_OPTIONAL_LIBS) are listed only when $(CC)
#    finds them (as .so or .a): a library that the shared system libraries
#    load themselves (libmetis.so.5) may lack its development link. Those not
#    found are named in odhs.pc's variable static_missing (a fully static
#    link then fails; tests/link_check.sh skips it, naming them).
# Looked up once, when first used (by the odhs.pc rule and print-*), so that
# `make clean` or `make deps` need neither pkg-config nor the libraries.
# ---------------------------------------------------------------------------
PC_MATH_MODULES := lapacke lapack blas
PC_SUITESPARSE_STATIC := -lspqr -lcholmod -lccolamd -lcamd -lcolamd -lamd -lmetis \
                         -lsuitesparseconfig -lgomp
PC_CLP_STATIC := -lClp -lCoinUtils -lbz2 -lz -lstdc++
PC_OPTIONAL_LIBS := ccolamd camd colamd amd metis gomp quadmath bz2 z

# $(call pc_has,module): non-empty when pkg-config knows the module
pc_has = $(shell $(PKG_CONFIG) --exists $(1) 2>/dev/null && echo yes)
# $(call cc_finds,name): non-empty when $(CC) finds libname.so or libname.a
# (-print-file-name answers the bare name when it finds nothing)
cc_finds = $(filter /%,$(shell $(CC) -print-file-name=lib$(1).so) $(shell $(CC) -print-file-name=lib$(1).a))
# $(call uniq_last,words): each word once, at its last place
uniq_last = $(if $(1),$(if $(filter $(firstword $(1)),$(wordlist 2,$(words $(1)),$(1))),,$(firstword $(1))) \
            $(call uniq_last,$(wordlist 2,$(words $(1)),$(1))))

PC_REQUIRES_PRIVATE_ = $(foreach m,$(PC_MATH_MODULES),$(if $(call pc_has,$(m)),$(m)))
PC_MATH_STATIC_      = $(foreach m,$(PC_MATH_MODULES),$(if $(filter $(m),$(REQUIRES_PRIVATE)),$(shell \
                           $(PKG_CONFIG) --static --libs-only-l $(m)),-l$(m))) -lm
PC_STATIC_CANDIDATES_ = $(call uniq_last,$(if $(filter 1,$(HAVE_CLP)),$(PC_CLP_STATIC)) \
                           $(if $(filter 1,$(HAVE_SUITESPARSE)),$(PC_SUITESPARSE_STATIC)) \
                           $(PC_MATH_STATIC_) $(if $(filter -lgfortran,$(PC_MATH_STATIC_)),-lgfortran -lquadmath) \
                           -lpthread -lm)
PC_STATIC_MISSING_   = $(foreach l,$(filter $(PC_OPTIONAL_LIBS:%=-l%),$(PC_STATIC_CANDIDATES)), \
                           $(if $(call cc_finds,$(l:-l%=%)),,$(l)))

# The cached values (the $(eval) replaces each by its value on first use).
PC_STATIC_CANDIDATES = $(eval PC_STATIC_CANDIDATES := $(strip $(PC_STATIC_CANDIDATES_)))$(PC_STATIC_CANDIDATES)
REQUIRES_PRIVATE = $(eval REQUIRES_PRIVATE := $(strip $(PC_REQUIRES_PRIVATE_)))$(REQUIRES_PRIVATE)
STATIC_MISSING   = $(eval STATIC_MISSING := $(strip $(PC_STATIC_MISSING_)))$(STATIC_MISSING)
LIBS_PRIVATE     = $(eval LIBS_PRIVATE := $(filter-out $(STATIC_MISSING),$(PC_STATIC_CANDIDATES)))$(LIBS_PRIVATE)

# ---------------------------------------------------------------------------
# Compiler flags. ODHS_* are the fixed project flags; CFLAGS/CPPFLAGS/LDFLAGS
# stay free for the user and are appended last.
# ---------------------------------------------------------------------------
OPTFLAGS  ?= -O2 -g
WARNFLAGS ?= -Wall -Wextra -Wpedantic -Werror
SANFLAGS  ?=
# Set only by check-allocfail (-DODHS_FAULT_INJECTION): a test-only build.
FAULTFLAGS ?=
DEPFLAGS  := -MMD -MP

ODHS_CPPFLAGS := -Iinclude -Ilib $(SUITESPARSE_CPPFLAGS) $(CLP_CPPFLAGS) -DODHS_HAVE_LAPACKE=1 $(FAULTFLAGS)
ODHS_CFLAGS   := -std=c11 $(OPTFLAGS) $(WARNFLAGS) $(SANFLAGS) -fPIC -fvisibility=hidden

LIB_COMPILE = $(CC) $(ODHS_CPPFLAGS) $(CPPFLAGS) $(ODHS_CFLAGS) $(CFLAGS) $(DEPFLAGS)

# Check's flags are looked up lazily (only when a test target needs them) and
# then cached, so `make clean` or `make deps` work on a bare machine.
CHECK_CFLAGS = $(eval CHECK_CFLAGS := $(shell $(PKG_CONFIG) --cflags check))$(CHECK_CFLAGS)
CHECK_LIBS   = $(eval CHECK_LIBS := $(shell $(PKG_CONFIG) --libs check))$(CHECK_LIBS)

# ---------------------------------------------------------------------------
# Library sources and products (wildcards: new files are picked up).
# ---------------------------------------------------------------------------
LIB_SRCS := $(sort $(wildcard lib/*.c lib/*/*.c))
LIB_OBJS := $(LIB_SRCS:%.c=$(OBJDIR)/%.o)

STATIC_LIB     := $(OUT_LIBDIR)/libodhs.a
SONAME         := libodhs.so.$(MAJOR)
SHARED_REAL    := $(OUT_LIBDIR)/libodhs.so.$(VERSION)
SHARED_SONAME  := $(OUT_LIBDIR)/$(SONAME)
SHARED_DEVLINK := $(OUT_LIBDIR)/libodhs.so

PUBLIC_HEADERS := include/odhs.h $(sort $(wildcard include/odhs/*.h))

# ---------------------------------------------------------------------------
# Tests: one tests/check_<module>.c per module defining
# `Suite *make_<module>_suite(void);`, one runner tests/check_main.c.
# Every other tests/*.c (e.g. a future tests/testutil.c) is linked into the
# runner too, except the stand-alone pkg-config consumer.
# ---------------------------------------------------------------------------
TEST_RUNNER_MAIN := tests/check_main.c
TEST_STANDALONE  := tests/pkgconfig_consumer.c
TEST_SUITE_SRCS  := $(sort $(filter-out $(TEST_RUNNER_MAIN),$(wildcard tests/check_*.c)))
TEST_MODULES     := $(patsubst tests/check_%.c,%,$(TEST_SUITE_SRCS))
TEST_SRCS        := $(sort $(filter-out $(TEST_STANDALONE),$(wildcard tests/*.c)))
TEST_OBJS        := $(TEST_SRCS:%.c=$(OBJDIR)/%.o)
SUITES_INC       := $(BUILD)/tests/suites.inc
TEST_RUNNER      := $(BUILD)/tests/run_tests

TEST_COMPILE = $(CC) -I$(BUILD)/tests -Itests $(ODHS_CPPFLAGS) $(CPPFLAGS) \
               $(CHECK_CFLAGS) $(ODHS_CFLAGS) $(CFLAGS) $(DEPFLAGS)

# Environment for running the tests. Check reads CK_RUN_SUITE, CK_RUN_CASE,
# CK_FORK, CK_VERBOSITY, CK_DEFAULT_TIMEOUT itself. OpenBLAS is kept
# single-threaded: the test matrices are small, and a threaded OpenBLAS pool
# plus Check's fork-per-test is a known source of hangs.
TEST_ENV ?= CK_DEFAULT_TIMEOUT=600 OPENBLAS_NUM_THREADS=1

# Sanitizer configuration for check-asan.
ASAN_BUILD    := build-asan
ASAN_SANFLAGS := -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all
# (the rheology suite's runs shortened: its physics runs in check-run)
ASAN_TEST_ENV := CK_FORK=no CK_DEFAULT_TIMEOUT=600 OPENBLAS_NUM_THREADS=1 ODHS_RHEO_STRAIN=0.02 \
                 ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1

# Allocation-failure injection (check-allocfail): own tree, sanitizers with
# LeakSanitizer, only the allocfail suite, no fork (LSan and the per-case
# leak checks need the test in this process).
ALLOCFAIL_BUILD    := build-allocfail
ALLOCFAIL_TEST_ENV := CK_RUN_SUITE=allocfail CK_FORK=no CK_DEFAULT_TIMEOUT=600 \
                      OPENBLAS_NUM_THREADS=1 ASAN_OPTIONS=detect_leaks=1 \
                      UBSAN_OPTIONS=print_stacktrace=1

# ---------------------------------------------------------------------------
# Examples, pkg-config consumer, benchmarks
# ---------------------------------------------------------------------------
STAGE         := $(CURDIR)/build/stage
STAGE_LIBDIR  := $(STAGE)/lib
STAGE_PC_PATH := $(STAGE_LIBDIR)/pkgconfig
# pkg-config against the staged install only (PKG_CONFIG_LIBDIR would also
# hide lapacke/check; only odhs is looked up, so PKG_CONFIG_PATH suffices).
STAGE_PKG_CONFIG := PKG_CONFIG_PATH=$(STAGE_PC_PATH) $(PKG_CONFIG)
STAGE_RPATH      := -Wl,-rpath,$(STAGE_LIBDIR)

# Flags for programs built as outside consumers: no -I of our own, only
# what pkg-config says. Warnings on, so the public headers stay clean.
CONSUMER_CFLAGS ?= -std=c11 -O2 -g -Wall -Wextra -Wpedantic -Werror

EXAMPLE_SRCS := $(sort $(wildcard examples/*.c))
EXAMPLE_BINS := $(EXAMPLE_SRCS:examples/%.c=build/examples/%)

# Ensemble campaigns (examples/mpi/sweep_mpi.c): sweep_mpi is built with the
# MPI compiler wrapper when there is one; sweep_serial (the same source with
# -DSWEEP_NO_MPI, the serial fallback) is always built.
MPICC   ?= mpicc
MPIRUN  ?= mpirun
HAVE_MPI := $(if $(and $(shell command -v $(MPICC) 2>/dev/null),$(shell command -v $(MPIRUN) 2>/dev/null)),1,0)
SWEEP_SRC := examples/mpi/sweep_mpi.c
EXAMPLE_BINS += build/examples/sweep_serial
ifeq ($(HAVE_MPI),1)
EXAMPLE_BINS += build/examples/sweep_mpi
endif

# LAMMPS coupling (examples/lammps_coupling.c): built, and tested by
# tests/lammps_coupling.sh, only when LAMMPS's C library interface is there:
# its pkg-config file and header (Debian liblammps-dev: liblammps.pc,
# /usr/include/lammps/library.h).
LAMMPS_PC   ?= liblammps
HAVE_LAMMPS := $(if $(wildcard $(shell $(PKG_CONFIG) --variable=includedir $(LAMMPS_PC) 2>/dev/null)/lammps/library.h),1,0)
EXAMPLE_BINS := $(filter-out build/examples/lammps_coupling,$(EXAMPLE_BINS))
ifeq ($(HAVE_LAMMPS),1)
EXAMPLE_BINS += build/examples/lammps_coupling
endif

BENCH_SRCS := $(sort $(wildcard bench/*.c))
BENCH_BINS := $(BENCH_SRCS:bench/%.c=build/bench/%)

# ---------------------------------------------------------------------------
# Flag tracking: objects depend on a file holding the compile command, so
# changing SUITESPARSE/OPTFLAGS/CC/... rebuilds them. The file is rewritten
# only when its content changes (move-if-change).
# ---------------------------------------------------------------------------
FLAGS_STAMP := $(BUILD)/compile-flags.txt

# $(call write_if_changed,file,content)
define write_if_changed
	@mkdir -p $(dir $(1))
	@printf '%s\n' $(2) > $(1).tmp
	@if cmp -s $(1).tmp $(1); then rm -f $(1).tmp; else mv -f $(1).tmp $(1); fi
endef

.PHONY: FORCE
FORCE:

$(FLAGS_STAMP): FORCE
	$(call write_if_changed,$@,'$(LIB_COMPILE) | $(LDFLAGS) $(LDLIBS) | $(ODHS_LIBS)')

# Likewise the lists of linked objects, so that deleting a source file
# relinks the library / the test runner.
LIB_OBJS_STAMP  := $(BUILD)/lib-objects.txt
TEST_OBJS_STAMP := $(BUILD)/test-objects.txt

$(LIB_OBJS_STAMP): FORCE
	$(call write_if_changed,$@,$(LIB_OBJS))

$(TEST_OBJS_STAMP): FORCE
	$(call write_if_changed,$@,$(TEST_OBJS))

# ===========================================================================
# Library
# ===========================================================================
.PHONY: all lib static shared
all: static shared
lib: all
static: $(STATIC_LIB)
shared: $(SHARED_REAL) $(SHARED_SONAME) $(SHARED_DEVLINK)

$(OBJDIR)/lib/%.o: lib/%.c $(FLAGS_STAMP)
	@mkdir -p $(@D)
	$(LIB_COMPILE) -c -o $@ $<

# Recreate the archive from scratch so objects of deleted sources vanish.
$(STATIC_LIB): $(LIB_OBJS) $(LIB_OBJS_STAMP)
	@mkdir -p $(@D)
	@rm -f $@
	$(AR) rcs $@ $(LIB_OBJS)

# --no-undefined: every symbol must resolve against the listed libraries.
$(SHARED_REAL): $(LIB_OBJS) $(LIB_OBJS_STAMP)
	@mkdir -p $(@D)
	$(CC) -shared $(ODHS_CFLAGS) $(CFLAGS) $(LDFLAGS) -Wl,-soname,$(SONAME) \
	    -Wl,--no-undefined -o $@ $(LIB_OBJS) $(ODHS_LIBS) $(LDLIBS)

$(SHARED_SONAME): $(SHARED_REAL)
	ln -sf $(notdir $<) $@

$(SHARED_DEVLINK): $(SHARED_SONAME)
	ln -sf $(notdir $<) $@

# ===========================================================================
# Tests
# ===========================================================================
.PHONY: check check-run check-asan check-allocfail check-symbols check-readme check-link tests

# deps-if-missing runs first, then a fresh make instance does the work, so
# that SUITESPARSE=auto and the pkg-config lookups see freshly installed
# packages and `make -j check` cannot start compiling before apt-get is done.
check: deps-if-missing
	@$(MAKE) --no-print-directory check-symbols check-readme check-run check-link
	@$(MAKE) --no-print-directory check-python

# Build the runner only.
tests: $(TEST_RUNNER)

check-run: $(TEST_RUNNER)
	@echo "== running $(TEST_RUNNER) ($(TEST_ENV))"
	$(TEST_ENV) ./$(TEST_RUNNER)

# Same library and tests, separate tree, no -O2, sanitizers on, no fork.
check-asan: deps-if-missing
	@$(MAKE) --no-print-directory check-run \
	    BUILD=$(ASAN_BUILD) OUT_LIBDIR=$(ASAN_BUILD)/lib \
	    OPTFLAGS="-O1 -g" SANFLAGS="$(ASAN_SANFLAGS)" \
	    TEST_ENV="$(ASAN_TEST_ENV)"

# Every allocation of representative runs made to fail in turn (see
# tests/check_allocfail.c); separate tree, sanitizers and leak checks on.
check-allocfail: deps-if-missing
	@$(MAKE) --no-print-directory check-run \
	    BUILD=$(ALLOCFAIL_BUILD) OUT_LIBDIR=$(ALLOCFAIL_BUILD)/lib \
	    OPTFLAGS="-O1 -g" SANFLAGS="$(ASAN_SANFLAGS)" FAULTFLAGS=-DODHS_FAULT_INJECTION \
	    TEST_ENV="$(ALLOCFAIL_TEST_ENV)"

# Shear at fixed pressure to strain 2 (the rheology suite at the strain of
# issue 17; make check runs it to 0.1). 26 CPU minutes (2026-12-02).
.PHONY: check-rheology
check-rheology: deps-if-missing
	@$(MAKE) --no-print-directory check-run \
	    TEST_ENV="CK_RUN_SUITE=rheology CK_DEFAULT_TIMEOUT=7200 OPENBLAS_NUM_THREADS=1 ODHS_RHEO_STRAIN=2"

# The README's C example must be examples/minimal.c (built by `make examples`),
# so the example users copy is one that compiles and runs.
check-readme:
	@echo "== checking that README.md's C example is examples/minimal.c"
	@awk '/^```c$$/{f=1;next} /^```$$/{if(f)exit} f' README.md > $(BUILD)/readme_example.c.tmp
	@tail -n +2 examples/minimal.c | diff -u $(BUILD)/readme_example.c.tmp - \
	    && echo "check-readme: ok" || { echo "check-readme: README.md and examples/minimal.c differ"; exit 1; }

# Every dynamically exported, defined symbol must start with odhs_. nm type
# letters: T/t text, D/d data, B/b bss, R/r rodata, V/W weak, i ifunc, u
# unique; A (absolute, e.g. version nodes) is not a real export and is skipped.
check-symbols: $(SHARED_REAL)
	@echo "== checking exported symbols of $<"
	@nm -D --defined-only $< | awk ' \
	    NF >= 3 && $$2 !~ /^[AaNn]$$/ && $$3 !~ /^odhs_/ \
	        { print "  bad export: " $$0; bad = 1 } \
	    NF >= 3 && $$3 ~ /^odhs_/ { n++ } \
	    END { if (bad) { print "check-symbols: FAILED (only odhs_* may be exported)"; exit 1 } \
	          printf "check-symbols: ok (%d odhs_* symbols exported)\n", n }'

# suites.inc: one ODHS_SUITE(make_<module>_suite) line per tests/check_*.c.
# Regenerated on every run but only rewritten when the list changes.
$(SUITES_INC): FORCE
	$(call write_if_changed,$@,'/* generated by the Makefile from tests/check_*.c: do not edit */' \
	    $(foreach m,$(TEST_MODULES),'ODHS_SUITE(make_$(m)_suite)'))

$(OBJDIR)/tests/%.o: tests/%.c $(FLAGS_STAMP)
	@mkdir -p $(@D)
	$(TEST_COMPILE) -c -o $@ $<

# The runner includes the generated list (explicit: needed before the first
# .d file exists).
$(OBJDIR)/$(TEST_RUNNER_MAIN:.c=.o): $(SUITES_INC)

$(TEST_RUNNER): $(TEST_OBJS) $(STATIC_LIB) $(TEST_OBJS_STAMP)
	@mkdir -p $(@D)
	$(CC) $(ODHS_CFLAGS) $(CFLAGS) $(LDFLAGS) -o $@ $(TEST_OBJS) $(STATIC_LIB) \
	    $(ODHS_LIBS) $(CHECK_LIBS) -pthread $(LDLIBS)

# ===========================================================================
# Install / uninstall
# ===========================================================================
.PHONY: install uninstall

PC_FILE := $(BUILD)/odhs.pc

# Directories under PREFIX are written as ${prefix}/... in odhs.pc, so that
# `pkg-config --define-prefix` can relocate an installed tree.
pc_relative = $(patsubst $(PREFIX)/%,$${prefix}/%,$(1))

# Regenerated whenever the substituted values change (PREFIX, SUITESPARSE...);
# a Requires.private without modules (no lapacke.pc, lapack.pc, blas.pc) is
# left out.
$(PC_FILE): pkgconfig/odhs.pc.in FORCE
	@mkdir -p $(@D)
	@sed -e 's|@PREFIX@|$(PREFIX)|g' \
	     -e 's|@LIBDIR@|$(call pc_relative,$(LIBDIR))|g' \
	     -e 's|@INCLUDEDIR@|$(call pc_relative,$(INCLUDEDIR))|g' \
	     -e 's|@VERSION@|$(VERSION)|g' \
	     -e 's|@LIBS_PRIVATE@|$(LIBS_PRIVATE)|g' \
	     -e 's|@REQUIRES_PRIVATE@|$(REQUIRES_PRIVATE)|g' \
	     -e 's|@STATIC_MISSING@|$(STATIC_MISSING)|g' \
	     -e '/^Requires\.private: *$$/d' \
	     $< > $@.tmp
	@if cmp -s $@.tmp $@; then rm -f $@.tmp; else mv -f $@.tmp $@; fi

install: all $(PC_FILE)
	$(INSTALL) -d $(DESTDIR)$(INCLUDEDIR)/odhs $(DESTDIR)$(LIBDIR)/pkgconfig
	$(INSTALL) -m 644 include/odhs.h $(DESTDIR)$(INCLUDEDIR)/odhs.h
	$(INSTALL) -m 644 $(filter include/odhs/%,$(PUBLIC_HEADERS)) $(DESTDIR)$(INCLUDEDIR)/odhs/
	$(INSTALL) -m 644 $(STATIC_LIB) $(DESTDIR)$(LIBDIR)/libodhs.a
	$(INSTALL) -m 755 $(SHARED_REAL) $(DESTDIR)$(LIBDIR)/libodhs.so.$(VERSION)
	ln -sf libodhs.so.$(VERSION) $(DESTDIR)$(LIBDIR)/$(SONAME)
	ln -sf $(SONAME) $(DESTDIR)$(LIBDIR)/libodhs.so
	$(INSTALL) -m 644 $(PC_FILE) $(DESTDIR)$(LIBDIR)/pkgconfig/odhs.pc

uninstall:
	rm -f $(DESTDIR)$(INCLUDEDIR)/odhs.h
	rm -f $(addprefix $(DESTDIR)$(INCLUDEDIR)/odhs/,$(notdir $(filter include/odhs/%,$(PUBLIC_HEADERS))))
	-rmdir $(DESTDIR)$(INCLUDEDIR)/odhs 2>/dev/null || true
	rm -f $(DESTDIR)$(LIBDIR)/libodhs.a \
	      $(DESTDIR)$(LIBDIR)/libodhs.so.$(VERSION) \
	      $(DESTDIR)$(LIBDIR)/$(SONAME) \
	      $(DESTDIR)$(LIBDIR)/libodhs.so \
	      $(DESTDIR)$(LIBDIR)/pkgconfig/odhs.pc

# ===========================================================================
# Staged install, examples and the pkg-config consumer test
# ===========================================================================
.PHONY: stage examples examples-build pkgconfig-test demo

# Install into build/stage exactly as a user would (all locations given
# explicitly so a LIBDIR=... on the outer command line cannot leak in).
stage: all
	@$(MAKE) --no-print-directory install DESTDIR= PREFIX=$(STAGE) \
	    LIBDIR=$(STAGE_LIBDIR) INCLUDEDIR=$(STAGE)/include \
	    PC_FILE=build/stage-odhs.pc

examples: stage
	@$(MAKE) --no-print-directory examples-build pkgconfig-test-run
	bash tests/docs_samples.sh build/stage
	bash tests/examples_cli.sh build/examples
ifeq ($(HAVE_LAMMPS),1)
	bash tests/lammps_coupling.sh build/examples
endif

examples-build: $(EXAMPLE_BINS)
	@echo "examples: $(if $(EXAMPLE_BINS),built $(EXAMPLE_BINS),none in examples/)"
ifneq ($(HAVE_LAMMPS),1)
	@echo "lammps_coupling: SKIPPED: no LAMMPS C library interface ($(LAMMPS_PC).pc and lammps/library.h; apt-get install liblammps-dev, or make deps)"
endif

# Only pkg-config output (plus an rpath to the stage) - no -Iinclude here.
# -lm is the examples' own need (they call floor, ceil, ...), not libodhs's.
build/examples/%: examples/%.c examples/cli.h examples/plot.h $(STAGE_LIBDIR)/libodhs.so.$(VERSION) $(STAGE_PC_PATH)/odhs.pc
	@mkdir -p $(@D)
	$(CC) $(CONSUMER_CFLAGS) -o $@ $< \
	    $$($(STAGE_PKG_CONFIG) --cflags --libs odhs) -lm $(STAGE_RPATH)

# the odhs flags from the stage, LAMMPS's from its own pkg-config file
build/examples/lammps_coupling: examples/lammps_coupling.c examples/cli.h examples/plot.h $(STAGE_LIBDIR)/libodhs.so.$(VERSION) $(STAGE_PC_PATH)/odhs.pc
	@mkdir -p $(@D)
	$(CC) $(CONSUMER_CFLAGS) -o $@ $< \
	    $$($(STAGE_PKG_CONFIG) --cflags --libs odhs) $$($(PKG_CONFIG) --cflags --libs $(LAMMPS_PC)) -lm $(STAGE_RPATH)

build/examples/sweep_serial: $(SWEEP_SRC) examples/cli.h $(STAGE_LIBDIR)/libodhs.so.$(VERSION) $(STAGE_PC_PATH)/odhs.pc
	@mkdir -p $(@D)
	$(CC) $(CONSUMER_CFLAGS) -DSWEEP_NO_MPI -o $@ $< \
	    $$($(STAGE_PKG_CONFIG) --cflags --libs odhs) -lm $(STAGE_RPATH)

build/examples/sweep_mpi: $(SWEEP_SRC) examples/cli.h $(STAGE_LIBDIR)/libodhs.so.$(VERSION) $(STAGE_PC_PATH)/odhs.pc
	@mkdir -p $(@D)
	$(MPICC) $(CONSUMER_CFLAGS) -o $@ $< \
	    $$($(STAGE_PKG_CONFIG) --cflags --libs odhs) -lm $(STAGE_RPATH)

# The tiny campaign on 2 MPI ranks, killed and resumed, against a serial run
# (tests/campaign_mpi.sh). Skipped, with a message, without mpicc/mpirun.
.PHONY: check-mpi
check-mpi:
ifeq ($(HAVE_MPI),1)
	@$(MAKE) --no-print-directory stage
	@$(MAKE) --no-print-directory build/examples/sweep_mpi build/examples/sweep_serial
	bash tests/campaign_mpi.sh build/examples
else
	@echo "check-mpi: SKIPPED: no MPI ($(MPICC) and $(MPIRUN) not both found; Debian: apt-get install openmpi-bin libopenmpi-dev, or make deps)"
endif

# The stand-alone consumer linked by every link line of the documents and by
# pkg-config: shared, static libodhs.a, fully static (tests/link_check.sh
# says which, and skips a fully static link that lacks a static library).
# In a SuiteSparse build, check-link-nos then does the same against a build
# without it, whose fully static link needs only LAPACK, BLAS and gcc's own
# libraries (all there as .a on Debian, unlike METIS).
check-link: stage
	@$(MAKE) --no-print-directory pkgconfig-test-run
ifeq ($(HAVE_SUITESPARSE),1)
	@$(MAKE) --no-print-directory check-link-nos
endif

# SUITESPARSE=0 CLP=0 in build/link-nos (objects, libraries), installed into
# build/link-nos/stage; linked with the pkg-config lines only.
LINK_NOS := build/link-nos
.PHONY: check-link-nos
check-link-nos:
	@echo "== building and installing a SUITESPARSE=0 CLP=0 libodhs into $(LINK_NOS)/stage (log: $(LINK_NOS)/build.log)"
	@mkdir -p $(LINK_NOS)
	@$(MAKE) --no-print-directory install SUITESPARSE=0 CLP=0 BUILD=$(LINK_NOS) OUT_LIBDIR=$(LINK_NOS)/lib \
	    DESTDIR= PREFIX=$(CURDIR)/$(LINK_NOS)/stage LIBDIR=$(CURDIR)/$(LINK_NOS)/stage/lib \
	    INCLUDEDIR=$(CURDIR)/$(LINK_NOS)/stage/include PC_FILE=$(LINK_NOS)/stage-odhs.pc \
	    > $(LINK_NOS)/build.log 2>&1 || { tail -n 30 $(LINK_NOS)/build.log; exit 1; }
	@echo "== linking $(TEST_STANDALONE) against it with pkg-config"
	@CC="$(CC)" LINK_CHECK_CFLAGS="$(CONSUMER_CFLAGS)" LINK_CHECK_DIR=$(LINK_NOS)/link-check \
	    bash tests/link_check.sh $(LINK_NOS)/stage $(TEST_STANDALONE)

pkgconfig-test: stage
	@$(MAKE) --no-print-directory pkgconfig-test-run

.PHONY: pkgconfig-test-run print-libs
pkgconfig-test-run:
	@echo "== linking $(TEST_STANDALONE): the link lines of README.md and docs/guide.md, pkg-config"
	@CC="$(CC)" LINK_CHECK_CFLAGS="$(CONSUMER_CFLAGS)" LINK_CHECK_DIR=build/link-check \
	    bash tests/link_check.sh $(STAGE) $(TEST_STANDALONE) README.md docs/guide.md

# The libraries lib/libodhs.a needs, the system libraries being shared:
#   gcc -std=c11 -Iinclude prog.c lib/libodhs.a $(make -s print-libs) -lm
print-libs:
	@echo '$(strip $(ODHS_LIBS))'

demo:
	@$(MAKE) --no-print-directory deps-if-missing
	@$(MAKE) --no-print-directory all
	@$(MAKE) --no-print-directory examples
	./build/examples/shear_flow

# ===========================================================================
# Python bindings (python/: the odhs package, cffi in API mode)
# ===========================================================================
.PHONY: python check-python

# Debian's interpreter: it has the python3-* packages of make deps (a pyenv
# or virtualenv python3 earlier in PATH may not).
PYTHON ?= /usr/bin/python3
# the extension's file name suffix (.cpython-311-x86_64-linux-gnu.so), looked
# up once when first used
PY_EXT_SUFFIX = $(eval PY_EXT_SUFFIX := $(shell $(PYTHON) -c \
    'import sysconfig; print(sysconfig.get_config_var("EXT_SUFFIX"))' 2>/dev/null))$(PY_EXT_SUFFIX)
PY_EXT = python/odhs/_cffi$(PY_EXT_SUFFIX)

# what check-python needs: the interpreter's cffi, numpy, pytest and headers
PY_CHECK_DEPS := import cffi, numpy, pytest, os, sysconfig; \
    assert os.path.exists(os.path.join(sysconfig.get_paths()["include"], "Python.h")), "Python.h"
PY_TEST_ENV = OPENBLAS_NUM_THREADS=1 PYTHONPATH=$(CURDIR)/python ODHS_EXAMPLES=$(CURDIR)/build/examples \
              ODHS_REQUIRE_EXAMPLES=1 ODHS_STAGE=$(STAGE)

# The cffi declarations are generated from the headers (python/odhs_build.py),
# so the extension is rebuilt when they change; it links the staged library
# (pkg-config) with an RPATH to it.
python: stage
	@$(MAKE) --no-print-directory $(PY_EXT)

$(PY_EXT): python/odhs_build.py $(PUBLIC_HEADERS) $(SHARED_REAL)
	@mkdir -p build/python
	PKG_CONFIG_PATH=$(STAGE_PC_PATH) $(PYTHON) python/odhs_build.py --tmpdir build/python

# The pytest suite: the README's program, the examples shear_flow and minimal
# compared with the same runs in Python, bad input, callbacks, arrays,
# ownership, the docs' code blocks, pip install into a venv.
check-python:
	@if ! $(PYTHON) -c '$(PY_CHECK_DEPS)' >/dev/null 2>&1; then \
	    echo "check-python: SKIPPED: $(PYTHON) lacks python3-cffi, python3-numpy, python3-pytest or the Python headers (python3-dev); Debian: make deps"; \
	else \
	    $(MAKE) --no-print-directory python && \
	    $(MAKE) --no-print-directory build/examples/minimal build/examples/shear_flow && \
	    echo "== running the Python tests (python/tests, $(PYTHON))" && \
	    $(PY_TEST_ENV) $(PYTHON) -m pytest -q -p no:cacheprovider python/tests; \
	fi

# ===========================================================================
# Benchmarks (static library; may include internal.h)
# ===========================================================================
.PHONY: bench
bench: $(BENCH_BINS)
	@echo "bench: $(if $(BENCH_BINS),built $(BENCH_BINS),none in bench/)"

build/bench/%: bench/%.c $(STATIC_LIB) $(FLAGS_STAMP)
	@mkdir -p $(@D)
	$(CC) $(ODHS_CPPFLAGS) $(CPPFLAGS) $(ODHS_CFLAGS) $(CFLAGS) -MMD -MP \
	    $(LDFLAGS) -o $@ $< $(STATIC_LIB) $(ODHS_LIBS) $(LDLIBS)

# ===========================================================================
# Reliability: ThreadSanitizer run of the threads suite, libFuzzer targets
# ===========================================================================
.PHONY: check-tsan fuzz fuzz-ci

# check-tsan: library + tests in build-tsan/ with -fsanitize=thread, only the
# threads suite, no fork. OpenBLAS is kept single-threaded (its own pool is
# not instrumented); halt_on_error makes the first race report fail the run.
TSAN_BUILD    := build-tsan
TSAN_SANFLAGS := -fsanitize=thread -fno-omit-frame-pointer
TSAN_TEST_ENV := CK_RUN_SUITE=threads CK_FORK=no CK_DEFAULT_TIMEOUT=600 OPENBLAS_NUM_THREADS=1 \
                 TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1:history_size=4

check-tsan: deps-if-missing
	@$(MAKE) --no-print-directory check-run \
	    BUILD=$(TSAN_BUILD) OUT_LIBDIR=$(TSAN_BUILD)/lib \
	    OPTFLAGS="-O1 -g" SANFLAGS="$(TSAN_SANFLAGS)" \
	    TEST_ENV="$(TSAN_TEST_ENV)"

# Fuzzing with libFuzzer. Every tests/fuzz/fuzz_<name>.c is a target (new
# files are picked up), with seed corpus tests/fuzz/corpus_<name>/ and an
# optional dictionary tests/fuzz/fuzz_<name>.dict. The library sources are
# compiled again with the fuzzer's own flags into build-fuzz/ (never the gcc
# objects of build/). fuzz-ci runs each target FUZZ_TIME seconds on a copy of
# its corpus (the seeds stay untouched) and fails on any crash, leak,
# sanitizer report or input slower than FUZZ_UNIT_TIMEOUT seconds; crashing
# inputs are kept in build-fuzz/ci/<name>/artifacts/ and the targets' own
# temporary files go to build-fuzz/ci/<name>/tmp/ (TMPDIR).
FUZZ_CC           ?= clang
FUZZ_BUILD        := build-fuzz
FUZZ_SANFLAGS     := -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
                     -fno-omit-frame-pointer
FUZZ_CFLAGS       := -std=c11 -Wall -Wextra $(FUZZ_SANFLAGS)
FUZZ_TIME         ?= 60
FUZZ_UNIT_TIMEOUT ?= 25
FUZZ_ENV          := OPENBLAS_NUM_THREADS=1 ASAN_OPTIONS=detect_leaks=1 \
                     UBSAN_OPTIONS=print_stacktrace=1
FUZZ_SRCS         := $(sort $(wildcard tests/fuzz/fuzz_*.c))
FUZZ_NAMES        := $(FUZZ_SRCS:tests/fuzz/fuzz_%.c=%)
FUZZ_BINS         := $(FUZZ_SRCS:tests/fuzz/%.c=$(FUZZ_BUILD)/%)
FUZZ_LIB_OBJS     := $(LIB_SRCS:%.c=$(FUZZ_BUILD)/obj/%.o)
FUZZ_LIB          := $(FUZZ_BUILD)/libodhs-fuzz.a
FUZZ_STAMP        := $(FUZZ_BUILD)/compile-flags.txt

# keep the fuzz targets' objects (intermediate files otherwise)
.SECONDARY: $(FUZZ_SRCS:%.c=$(FUZZ_BUILD)/obj/%.o)

fuzz: $(FUZZ_BINS)
	@echo "fuzz: $(if $(FUZZ_BINS),built $(FUZZ_BINS),no tests/fuzz/fuzz_*.c)"

$(FUZZ_STAMP): FORCE
	$(call write_if_changed,$@,'$(FUZZ_CC) $(ODHS_CPPFLAGS) $(FUZZ_CFLAGS) | $(ODHS_LIBS)' $(FUZZ_LIB_OBJS))

$(FUZZ_BUILD)/obj/%.o: %.c $(FUZZ_STAMP)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(ODHS_CPPFLAGS) $(CPPFLAGS) $(FUZZ_CFLAGS) $(DEPFLAGS) -c -o $@ $<

$(FUZZ_LIB): $(FUZZ_LIB_OBJS) $(FUZZ_STAMP)
	@rm -f $@
	$(AR) rcs $@ $(FUZZ_LIB_OBJS)

$(FUZZ_BUILD)/fuzz_%: $(FUZZ_BUILD)/obj/tests/fuzz/fuzz_%.o $(FUZZ_LIB)
	$(FUZZ_CC) $(FUZZ_CFLAGS) -o $@ $< $(FUZZ_LIB) $(ODHS_LIBS)

fuzz-ci: fuzz
	@status=0; failed=; \
	for name in $(FUZZ_NAMES); do \
	    run=$(FUZZ_BUILD)/ci/$$name; \
	    rm -rf $$run; mkdir -p $$run/corpus $$run/artifacts $$run/tmp; \
	    if [ -d tests/fuzz/corpus_$$name ]; then cp -R tests/fuzz/corpus_$$name/. $$run/corpus/; fi; \
	    dict=; if [ -f tests/fuzz/fuzz_$$name.dict ]; then dict=-dict=tests/fuzz/fuzz_$$name.dict; fi; \
	    echo "== fuzz_$$name: $(FUZZ_TIME) s on a copy of tests/fuzz/corpus_$$name ($$(ls $$run/corpus | wc -l) seeds)"; \
	    if env $(FUZZ_ENV) TMPDIR=$$run/tmp $(FUZZ_BUILD)/fuzz_$$name $$dict -max_total_time=$(FUZZ_TIME) \
	        -timeout=$(FUZZ_UNIT_TIMEOUT) -rss_limit_mb=2048 -print_final_stats=1 \
	        -artifact_prefix=$$run/artifacts/ $$run/corpus > $$run/log.txt 2>&1; \
	    then result=ok; else result=FAILED; status=1; fi; \
	    execs=$$(sed -n 's/^stat::number_of_executed_units: *//p' $$run/log.txt | tail -n 1); \
	    echo "fuzz_$$name: $$result: $${execs:-?} executions, corpus $$(ls $$run/corpus | wc -l) inputs (log: $$run/log.txt)"; \
	    if [ $$result = FAILED ]; then \
	        tail -n 80 $$run/log.txt; echo "fuzz_$$name: reproducers:"; ls -l $$run/artifacts; \
	        failed="$$failed $$name"; \
	    fi; \
	done; \
	for name in $$failed; do \
	    run=$(FUZZ_BUILD)/ci/$$name; \
	    echo "fuzz_$$name: first error: $$(grep -m1 -E 'check failed|ERROR: |runtime error|Timeout|out-of-memory' $$run/log.txt)"; \
	    grep -m1 -A1 'check failed' $$run/log.txt | tail -n 1; \
	    for f in $$run/artifacts/*; do \
	        [ -f "$$f" ] && [ $$(wc -c < "$$f") -le 8192 ] || continue; \
	        echo "fuzz_$$name: reproducer $$(basename $$f), base64 on one line (base64 -d > repro):"; \
	        base64 -w 0 "$$f"; echo; \
	    done; \
	done; \
	if [ $$status -ne 0 ]; then echo "fuzz-ci: FAILED"; else echo "fuzz-ci: ok ($(words $(FUZZ_NAMES)) targets)"; fi; \
	exit $$status

-include $(FUZZ_LIB_OBJS:.o=.d) $(FUZZ_BUILD)/obj/tests/fuzz/*.d

# ===========================================================================
# Dependencies (Debian/Ubuntu)
# ===========================================================================
.PHONY: deps deps-if-missing
# clang and libclang-rt-14-dev (libFuzzer, sanitizer runtimes): make fuzz.
# openmpi-bin and libopenmpi-dev (mpicc, mpirun): sweep_mpi and make check-mpi.
# lammps (lmp), python3-ase, python3-numpy: tests/examples_cli.sh reads the
# examples' files with LAMMPS, ASE and numpy (skipped with a message without them).
# liblammps-dev (LAMMPS's C library interface): examples/lammps_coupling.c.
# python3-cffi, python3-dev (Python.h: the cffi extension is compiled),
# python3-numpy, python3-pytest, python3-setuptools, python3-pip,
# python3-venv, python3-wheel and python3-matplotlib: the Python bindings
# (make python, make check-python: pytest, pip install into a venv, the
# examples' plots).
DEPS_PACKAGES := libsuitesparse-dev liblapacke-dev liblapack-dev libopenblas-dev coinor-libclp-dev \
                 check pkg-config gcc make \
                 clang libclang-rt-14-dev \
                 openmpi-bin libopenmpi-dev \
                 lammps python3-ase python3-numpy \
                 liblammps-dev \
                 python3-cffi python3-dev python3-pytest python3-setuptools python3-pip \
                 python3-venv python3-wheel python3-matplotlib

deps:
	@if [ "$$(id -u)" -eq 0 ]; then SUDO=; else SUDO=sudo; fi; \
	set -x; \
	$$SUDO env DEBIAN_FRONTEND=noninteractive apt-get update && \
	$$SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y $(DEPS_PACKAGES)

# The CHOLMOD and CLP headers are only required unless SUITESPARSE=0 or
# CLP=0 was asked for.
deps-if-missing:
	@missing=; \
	command -v $(PKG_CONFIG) >/dev/null 2>&1 || missing="$$missing pkg-config"; \
	command -v $(firstword $(CC)) >/dev/null 2>&1 || missing="$$missing $(firstword $(CC))"; \
	for m in check lapacke lapack blas; do \
	    $(PKG_CONFIG) --exists $$m 2>/dev/null || missing="$$missing $$m"; \
	done; \
	if [ "$(filter 0 no off false,$(SUITESPARSE))" = "" ] && \
	   [ ! -f $(SUITESPARSE_INC)/cholmod.h ]; then missing="$$missing cholmod.h"; fi; \
	if [ "$(filter 0 no off false,$(CLP))" = "" ] && \
	   [ ! -f $(CLP_INC)/Clp_C_Interface.h ]; then missing="$$missing Clp_C_Interface.h"; fi; \
	if [ -n "$$missing" ]; then \
	    echo "deps-if-missing: missing:$$missing -> running make deps"; \
	    $(MAKE) --no-print-directory deps; \
	fi

# ===========================================================================
# Housekeeping
# ===========================================================================
.PHONY: clean help

clean:
	rm -rf build build-asan $(ALLOCFAIL_BUILD)
	rm -rf $(TSAN_BUILD) $(FUZZ_BUILD)
	rm -f lib/*.a lib/*.so lib/*.so.*
	rm -rf python/odhs/_cffi*.so python/build python/odhs.egg-info

# Prints the comment block at the top of this file.
help:
	@awk 'NR > 2 && !/^#/ { exit } NR > 2 { sub(/^# ?/, ""); print }' $(firstword $(MAKEFILE_LIST))

# Header dependencies (-MMD -MP) of everything compiled so far.
-include $(LIB_OBJS:.o=.d) $(TEST_OBJS:.o=.d) $(BENCH_BINS:=.d)
