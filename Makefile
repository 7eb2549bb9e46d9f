# sprc — the two commands: `make run` and `make test`. Both first make sure
# the toolchain is installed (tools/ensure-deps: Debian packages as root,
# fpm/numpy/pytest from PyPI into .venv when missing).

SHELL := /bin/bash
export PATH := $(CURDIR)/.venv/bin:$(PATH)
FPM ?= fpm
PROFILE ?= release

.PHONY: all deps build run test bench clean help

all: build

help:
	@echo "make run     install what is missing, build (release) and run the driver on its default scene"
	@echo "make test    install what is missing and run the whole test suite"
	@echo "make bench   benchmarks (sparse direct solvers, grid build)"
	@echo "make build   build the release profile"
	@echo "make clean   remove build outputs"

deps:
	@tools/ensure-deps

build: deps
	$(FPM) build --profile $(PROFILE)

run: deps
	$(FPM) run --profile $(PROFILE) sprc

test: deps
	@tools/run-tests

bench: deps
	@tools/bench-sparse
	$(FPM) run --profile release --example bench_grid

clean:
	$(FPM) clean --all 2>/dev/null || rm -rf build
