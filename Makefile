# Quadrille — build, serve and test. Two commands matter (see README.md):
#   make run    install what the web app needs, build it, serve it on localhost
#   make test   install what the tests need, run every test (browser tests included)

SHELL := /bin/bash
PORT ?= 8080
MESHES ?= ../shared/meshes
TOOLS := $(CURDIR)/.tools
# Honours CARGO_TARGET_DIR (tests/e2e/run.mjs finds the static server the same way).
WASM := $(or $(CARGO_TARGET_DIR),target)/wasm32-unknown-unknown/release/quadrille.wasm

.PHONY: run test lint web wasm-target wasm-tools native-test wasm-check browser-test browser-tools samples serve clean bench bench-param bench-design quality scanlike

run: web
	cargo run --release --example serve -- www $(PORT)

# The browser tests build the library for wasm32 (release), which is also the
# wasm build check; `make wasm-check` alone does a quick debug build.
# The lint runs first: a formatting or clippy finding stops the run before
# the long tests.
test: lint
	$(MAKE) native-test browser-test

## Format and clippy (thresholds in clippy.toml, lints in Cargo.toml's
## [lints]), warnings are errors: natively with every target (tests,
## examples, the binary) and for the browser target (the library, where
## src/web/ is compiled).
lint: wasm-target
	cargo fmt --check
	cargo clippy --all-targets -- -D warnings
	cargo clippy --target wasm32-unknown-unknown --lib -- -D warnings

## Native: unit, integration and doc tests.
native-test:
	cargo test --all-targets
	cargo test --doc

## The library must build for the browser target.
wasm-check: wasm-tools
	cargo build --lib --target wasm32-unknown-unknown

## The wasm32 target alone (what the browser-target clippy needs).
wasm-target:
	@scripts/install-wasm-tools.sh --target-only "$(TOOLS)"

## Tools for the web build: the wasm32 target and the wasm-bindgen CLI whose
## version matches Cargo.lock's wasm-bindgen (installed under .tools/).
wasm-tools:
	@scripts/install-wasm-tools.sh "$(TOOLS)"

## The web app: wasm module + JS glue into www/pkg, sample meshes into www/samples.
web: wasm-tools samples
	cargo build --release --lib --target wasm32-unknown-unknown
	"$(TOOLS)/bin/wasm-bindgen" --target web --no-typescript --out-dir www/pkg $(WASM)

samples:
	@scripts/copy-samples.sh "$(MESHES)" www/samples

## Headless Chromium (Debian's package) driven by playwright-core from npm;
## pngjs decodes screenshots to check the canvas is not blank.
browser-tools:
	@scripts/install-browser-tools.sh

## Every browser test runs twice: on WebGL2 and on WebGPU (SwiftShader).
browser-test: web browser-tools
	cargo build --release --example serve
	cd tests/e2e && node run.mjs webgl2 webgpu

## Benchmarks (not part of `make test`; takes a while): native per stage on
## every shared mesh and on the bunny subdivided to ~278k and ~1.1M
## triangles, the same in headless Chromium (wasm in the worker), and the
## comparison with Instant Meshes and QuadriFlow (pip-installed into
## .tools/bench-venv). Writes target/bench/*.json, docs/RESULTS.md and the
## README's results block. BENCH_ARGS passes options to scripts/bench.py
## (e.g. BENCH_ARGS="--repeats 3 --skip-compare").
bench: web browser-tools
	cargo build --release --bin quadrille --example subdivide --example serve
	QUADRILLE_MESHES="$(MESHES)" python3 scripts/bench.py $(BENCH_ARGS)

## The global path's parametrization alone (`quadrille param` on the bunny,
## fandisk, rocker-arm and spot; `make bench` runs it too): rewrites only
## the "Parametrization (global path)" section of docs/RESULTS.md.
bench-param:
	cargo build --release --bin quadrille
	QUADRILLE_MESHES="$(MESHES)" python3 scripts/bench.py --only-param $(BENCH_ARGS)

## The design mode's responsiveness (not part of `make test`): hover,
## click, drag, grab, Enter and undo timed in headless Chromium the way a
## user triggers them, on the torus sample and the bunny (median, 95th
## percentile, max). Prints markdown tables (docs/RESULTS.md has them) and
## writes target/bench/design.json. BENCH_TRIALS / BENCH_HOVERS set the
## repetitions (see tests/e2e/bench_design.mjs).
bench-design: web browser-tools
	cargo build --release --example serve
	cd tests/e2e && node bench_design.mjs

## The ablation table (not part of `make test`): Instant Meshes, QuadriFlow,
## Quadrille in an Instant-Meshes-equivalent configuration, that plus each
## thesis/paper modification alone, and the defaults, on every shared mesh,
## measured by the same code. Writes docs/QUALITY.md. QUALITY_ARGS passes
## options to scripts/quality.py (e.g. QUALITY_ARGS="--names fandisk").
quality:
	cargo build --release --bin quadrille
	QUADRILLE_MESHES="$(MESHES)" python3 scripts/quality.py $(QUALITY_ARGS)

## Scan-like probes (not part of `make test`): the shared meshes with noise,
## occlusion holes and far-off units, remeshed and checked against the
## quality issue's bars. SCANLIKE_ARGS passes options to scripts/scanlike.py
## (e.g. SCANLIKE_ARGS="--mode global").
scanlike:
	cargo build --release --bin quadrille
	QUADRILLE_MESHES="$(MESHES)" python3 scripts/scanlike.py $(SCANLIKE_ARGS)

clean:
	cargo clean
	rm -rf www/pkg
	find www/samples -type f ! -name torus.obj -delete 2>/dev/null || true
