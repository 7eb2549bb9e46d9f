# sprc — the two commands: `make run` and `make test`. Both first make sure
# the toolchain is installed (tools/ensure-deps: Debian packages as root,
# fpm/numpy/pytest from PyPI into .venv when missing).

SHELL := /bin/bash
export PATH := $(CURDIR)/.venv/bin:$(PATH)
FPM ?= fpm
PROFILE ?= release

# Shared library and install (make lib, make install PREFIX=...). fpm 0.12's
# shared-library link drops the HDF5 -L path, so libsprc.so is linked here
# from the static archive fpm builds (its objects are compiled with -fPIC).
LIBDIR := build/lib
PREFIX ?= /usr/local
VERSION := $(shell sed -n 's/^version *= *"\(.*\)"/\1/p' fpm.toml)
HDF5_LDIR := $(shell pkg-config --libs-only-L hdf5 2>/dev/null || echo -L/usr/lib/x86_64-linux-gnu/hdf5/serial)
# Everything libsprc needs at link time: HDF5 (Fortran), SuiteSparse,
# LAPACK/BLAS (fpm.toml's link list), the gfortran and OpenMP run times.
# PETSc is not linked: src/shim/sprc_petsc.c loads it when first used.
DEP_LIBS := $(HDF5_LDIR) -lhdf5_fortran -lhdf5 -lcholmod -lumfpack -lsuitesparseconfig -llapack -lblas \
            -lgfortran -lgomp -lm

.PHONY: all deps build run test test-full memcheck bench clean help lib install fuzz doc

all: build

help:
	@echo "make run     install what is missing, build (release) and run the driver on its default scene"
	@echo "make test    install what is missing and run the whole test suite"
	@echo "make test-full  the expensive tiers make test leaves out: unit --full, test-driver --full, every scene under valgrind"
	@echo "make memcheck   every scene under valgrind (make test: a stratified subset)"
	@echo "make bench   benchmarks (sparse direct solvers, grid build, faceted solids, recovery on a caller's mesh)"
	@echo "make fuzz    5000 seeded mutants of the example scenes (check, run) and of geometry files (check) (FUZZ_COUNT, FUZZ_SEED)"
	@echo "make doc     the API reference and doc/ pages (FORD) in build/doc/index.html"
	@echo "make build   build the release profile"
	@echo "make lib     build/lib/libsprc.so and libsprc.a, Fortran modules in build/lib/mod"
	@echo "make install PREFIX=DIR   lib, include (sprc.h, modules in include/sprc), pkg-config, bin/sprc,"
	@echo "                          the example scenes in share/sprc/scenes"
	@echo "make clean   remove build outputs"

deps:
	@tools/ensure-deps

build: deps
	$(FPM) build --profile $(PROFILE)

run: deps
	$(FPM) run --profile $(PROFILE) sprc

test: deps
	@tools/run-tests

# The expensive tiers `make test` leaves out for its time limit: the unit
# tests' full variants (sprc_testsuite's full_tier), the driver tests' (the
# out-of-memory sweep) and valgrind over every scene (make test: the
# stratified subset of tools/memcheck-scenes).
test-full: deps
	$(FPM) test unit -- --full
	@tools/test-driver --full
	@tools/memcheck-scenes --all

memcheck: deps
	$(FPM) build
	@tools/memcheck-scenes --all

# The API reference (FORD): fails on a FORD warning about the public API.
doc: deps
	@tools/build-doc

# Long seeded fuzz of the scene input (make test runs 300 mutants, seed 1).
FUZZ_COUNT ?= 5000
FUZZ_SEED ?= 2
fuzz: deps
	$(FPM) build
	@tools/fuzz-scenes --count $(FUZZ_COUNT) --seed $(FUZZ_SEED)
	@tools/fuzz-facets --count $(FUZZ_COUNT) --seed $(FUZZ_SEED)

bench: deps
	@tools/bench-sparse
	$(FPM) run --profile release --example bench_grid
	$(FPM) run --profile release --example bench_facets
	$(FPM) run --profile release --example bench_mesh_recovery

# fpm names its build directories by hashes: remove every archive, build the
# profile verbosely and take the archive and module directory from the one
# `ar` line that recreates it.
lib: deps
	@mkdir -p $(LIBDIR)
	@rm -rf $(LIBDIR)/mod build/gfortran_*/sprc/libsprc.a
	@$(FPM) build --profile $(PROFILE) --no-prune --verbose >$(LIBDIR)/fpm-build.log 2>&1 \
	  || { tail -n 40 $(LIBDIR)/fpm-build.log; exit 1; }
	@set -e; \
	arline=$$(grep -E '^ *\+ ar -rs .*/libsprc\.a ' $(LIBDIR)/fpm-build.log | tail -n 1); \
	archive=$$(awk '{print $$4}' <<<"$$arline"); \
	obj=$$(grep -oE '[^ ]+/src_sprc\.f90\.o' <<<"$$arline"); \
	if [ -z "$$archive" ] || [ -z "$$obj" ]; then echo "make lib: no archive in $(LIBDIR)/fpm-build.log"; exit 1; fi; \
	moddir=$$(dirname "$$(dirname "$$obj")"); \
	cp "$$archive" $(LIBDIR)/libsprc.a; \
	mkdir -p $(LIBDIR)/mod; \
	for m in $$(grep -rhiE '^[[:space:]]*module[[:space:]]+[a-z0-9_]+[[:space:]]*(!.*)?$$' src \
	            | awk '{print tolower($$2)}'); do cp "$$moddir/$$m.mod" $(LIBDIR)/mod/; done; \
	gcc -shared -Wl,-soname,libsprc.so -o $(LIBDIR)/libsprc.so \
	  -Wl,--whole-archive $(LIBDIR)/libsprc.a -Wl,--no-whole-archive $(DEP_LIBS) -Wl,--no-undefined; \
	$(FPM) run --profile $(PROFILE) --runner echo sprc 2>/dev/null | tail -n 1 >$(LIBDIR)/driver-path; \
	echo "make lib: $(LIBDIR)/libsprc.so, $(LIBDIR)/libsprc.a, $(LIBDIR)/mod ($(PROFILE))"

install: lib
	@set -e; \
	prefix=$(abspath $(PREFIX)); \
	install -d "$(DESTDIR)$$prefix"/{bin,lib/pkgconfig,include/sprc,share/sprc/scenes}; \
	install -m 755 "$$(cat $(LIBDIR)/driver-path)" "$(DESTDIR)$$prefix/bin/sprc"; \
	install -m 755 $(LIBDIR)/libsprc.so "$(DESTDIR)$$prefix/lib/"; \
	install -m 644 $(LIBDIR)/libsprc.a "$(DESTDIR)$$prefix/lib/"; \
	install -m 644 include/sprc.h "$(DESTDIR)$$prefix/include/"; \
	install -m 644 $(LIBDIR)/mod/*.mod "$(DESTDIR)$$prefix/include/sprc/"; \
	install -m 644 example/scenes/*.nml "$(DESTDIR)$$prefix/share/sprc/scenes/"; \
	{ echo "prefix=$$prefix"; \
	  echo 'libdir=$${prefix}/lib'; \
	  echo 'includedir=$${prefix}/include'; \
	  echo 'moddir=$${includedir}/sprc'; \
	  echo; \
	  echo 'Name: sprc'; \
	  echo 'Description: SPR / SPR-C stress recovery and ZZ error estimation on cut Cartesian grids'; \
	  echo 'Version: $(VERSION)'; \
	  echo 'Cflags: -I$${includedir} -I$${moddir}'; \
	  echo 'Libs: -L$${libdir} -Wl,-rpath,$${libdir} -lsprc'; \
	  echo 'Libs.private: $(DEP_LIBS)'; \
	} >"$(DESTDIR)$$prefix/lib/pkgconfig/sprc.pc"; \
	echo "make install: installed into $(DESTDIR)$$prefix"

clean:
	$(FPM) clean --all 2>/dev/null || rm -rf build
