# Thin targets over cargo and the tools. `make demo` and `make test` do all set-up themselves.

CARGO ?= cargo
DEMO := target/demo
BIN := target/release
TOOLS := $(notdir $(wildcard tools/*))
PREFIX ?= /usr/local

# wgpu warns when XDG_RUNTIME_DIR is unset; give it a private folder.
export XDG_RUNTIME_DIR ?= $(shell d=/tmp/xdg-runtime-$$(id -u); mkdir -p $$d && chmod 700 $$d && echo $$d)

.PHONY: setup setup-gpu setup-python setup-node setup-chromium setup-ktx setup-mitsuba three-cases three-example build install test test-data tests-skipped demo bake lint bench clean-demo fuzz fuzz-regressions

## setup: everything the tests need (setup-gpu, setup-python, setup-node, setup-chromium,
## setup-ktx). Idempotent.
setup: setup-gpu setup-python setup-node setup-chromium setup-ktx

## setup-gpu: the software Vulkan driver (lavapipe), for brdf-preview and the GPU tests on machines
## without a GPU driver, and Mesa's GL through EGL (llvmpipe), the adapter the portability test runs
## the previewer on. Installed only when missing; quiet.
setup-gpu:
	@if ! ls /usr/share/vulkan/icd.d/*.json >/dev/null 2>&1 || ! ls /usr/lib/*/libEGL_mesa.so.0 >/dev/null 2>&1; then \
	  echo "installing mesa-vulkan-drivers, libvulkan1 and Mesa's EGL (software Vulkan and GL drivers for the previewer and the GPU tests)"; \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq >/dev/null && \
	  DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq mesa-vulkan-drivers libvulkan1 libegl1 libegl-mesa0 libgl1-mesa-dri >/dev/null; \
	fi

## setup-python: numpy, for ../shared/tools/nbrdf2merl.py (the real-derived test materials).
setup-python:
	@python3 -c 'import numpy' 2>/dev/null || { echo "installing numpy (for ../shared/tools/nbrdf2merl.py)"; python3 -m pip install --quiet numpy; }

## setup-mitsuba: Mitsuba 3 (PyPI), the outside referee of make bench (the mitsuba benchmark of
## brdf-preview), and libLLVM 19 from Debian for its vectorized llvm_ad_rgb variant (Dr.Jit finds
## no usable backend in Debian 12's default libLLVM 14, and LLVM 15 and 16 abort on the referee's
## kernels; without it the referee falls back to scalar_rgb, about 20 times slower). Installed only
## when missing; quiet.
setup-mitsuba: setup-python
	@python3 -c 'import mitsuba' 2>/dev/null || { echo "installing mitsuba (the outside referee of make bench)"; python3 -m pip install --quiet mitsuba; }
	@if ! ls /usr/lib/*/libLLVM.so.19* /usr/lib/*/libLLVM-19.so* >/dev/null 2>&1; then \
	  echo "installing libllvm19 (for Mitsuba's llvm_ad_rgb variant)"; \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq >/dev/null && \
	  DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq libllvm19 >/dev/null; \
	fi

## setup-node: ktx-parse (the KTX2 parser three.js uses) in tests/ktx-parse, which the end-to-end
## tests run on the KTX2 files with node, the Khronos glTF validator in tests/gltf-validator (on
## brdf-fit's material.gltf), and engines/three's packages (three, ktx-parse,
## @noble/hashes and puppeteer-core, pinned by its lock file). Installs node and npm from Debian when missing.
setup-node:
	@if ! command -v npm >/dev/null 2>&1; then \
	  echo "installing nodejs and npm (to read the KTX2 outputs with ktx-parse in the tests)"; \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq >/dev/null && \
	  DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq nodejs npm >/dev/null; \
	fi
	@test -d tests/ktx-parse/node_modules/ktx-parse || npm ci --silent --prefix tests/ktx-parse
	@test -d tests/gltf-validator/node_modules/gltf-validator || npm ci --silent --prefix tests/gltf-validator
	@test -d engines/three/node_modules/puppeteer-core -a -d engines/three/node_modules/ktx-parse -a -d engines/three/node_modules/@noble/hashes || npm ci --silent --prefix engines/three

## setup-chromium: Debian's Chromium, the real browser tests/three.rs renders the three.js material
## in (headless, WebGL 2 on SwiftShader, driven by puppeteer-core from engines/three; no browser
## download). Installed only when missing; quiet.
setup-chromium:
	@if ! command -v chromium >/dev/null 2>&1; then \
	  echo "installing chromium (the browser the three.js tests render in)"; \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq >/dev/null && \
	  DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq chromium >/dev/null; \
	fi

## setup-ktx: Khronos' KTX2 validator, ktx2check (KTX-Software 4.0.0, whose sources the
## libktx-rs-sys crate carries: fetched from crates.io by cargo vendor), built with cmake into
## target/ktx2check/ once (about two minutes on 2 cores); the end-to-end tests run it on every KTX2
## output. Installs cmake from Debian when missing.
KTX2CHECK := target/ktx2check/ktx2check
setup-ktx: $(KTX2CHECK)
$(KTX2CHECK):
	@if ! command -v cmake >/dev/null 2>&1; then \
	  echo "installing cmake (to build Khronos' ktx2check for the tests)"; \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq >/dev/null && \
	  DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq cmake >/dev/null; \
	fi
	@echo "building ktx2check (Khronos' KTX2 validator) into target/ktx2check/"
	@rm -rf target/ktx2check/vendor target/ktx2check/build && mkdir -p target/ktx2check
	@$(CARGO) vendor -q --locked --manifest-path tests/ktx2check/Cargo.toml target/ktx2check/vendor >/dev/null
	@cmake -S target/ktx2check/vendor/libktx-rs-sys/build/KTX-Software -B target/ktx2check/build \
	  -DCMAKE_BUILD_TYPE=Release -DKTX_FEATURE_TOOLS=ON -DKTX_FEATURE_TESTS=OFF -DKTX_FEATURE_DOC=OFF \
	  -DKTX_FEATURE_LOADTEST_APPS=OFF -DKTX_FEATURE_STATIC_LIBRARY=ON > target/ktx2check/build.log 2>&1 \
	  || { tail -20 target/ktx2check/build.log; exit 1; }
	@cmake --build target/ktx2check/build --target ktx2check -j 2 >> target/ktx2check/build.log 2>&1 \
	  || { tail -20 target/ktx2check/build.log; exit 1; }
	@cp target/ktx2check/build/tools/ktx2check/ktx2check $@
	@rm -rf target/ktx2check/vendor target/ktx2check/build

## build: every tool, optimized, into target/release/.
build:
	$(CARGO) build --release

## install: the tools into $(PREFIX)/bin (e.g. make install PREFIX=$$HOME/.local).
install: build
	install -d $(PREFIX)/bin
	install -m 755 $(addprefix $(BIN)/,$(TOOLS)) $(PREFIX)/bin/

## test: every unit, property, GPU (lavapipe) and end-to-end test. The test data is made first
## (test-data), the tools and the tests are built once, and the end-to-end tests run those
## binaries. The tools and the tests are built by one cargo command: built apart, the tools would
## resolve their dependencies' features without the tests' dev-dependencies, and the tests would
## then build wgpu, naga and a hundred other crates a second time (five minutes on 2 cores).
## Without incremental compilation (a clean run gains nothing from it and it costs a gigabyte of
## disk; set CARGO_INCREMENTAL=1 to keep it).
## Without ../shared (the project's shared/ folder beside this checkout, which CI always has), no
## test data is made and cargo test runs with BRDF_TESTS_WITHOUT_SHARED=1: each test that needs
## the folder skips what needs it and appends its name and what it needed to $(SKIPPED), which
## is printed at the end with how to get the data; exit 0 when nothing failed. With ../shared,
## nothing may skip: data that is there but incomplete fails its tests (tests/support/shared_data.rs).
SKIPPED := target/tests-skipped.txt
SHARED_ABSENT := $(if $(wildcard ../shared),,1)
test: setup
	@rm -f $(SKIPPED)
ifdef SHARED_ABSENT
	@echo "make test: ../shared is absent: no test data is made, and the tests skip what needs it (listed at the end)"
else
	@$(MAKE) --no-print-directory -j2 test-data
endif
	CARGO_INCREMENTAL=$${CARGO_INCREMENTAL:-0} $(CARGO) build --workspace --bins --tests
	$(if $(SHARED_ABSENT),BRDF_TESTS_WITHOUT_SHARED=1 )CARGO_INCREMENTAL=$${CARGO_INCREMENTAL:-0} $(CARGO) test --workspace \
	  || { $(MAKE) -s tests-skipped; exit 1; }
	@$(MAKE) -s tests-skipped

## tests-skipped: what the last make test skipped for want of ../shared ($(SKIPPED)), if
## anything, and how to get it.
tests-skipped:
	@if [ -s $(SKIPPED) ]; then \
	  echo "make test: $$(wc -l < $(SKIPPED)) tests skipped what needs ../shared, which is absent:"; \
	  sort $(SKIPPED) | sed 's/^/  /'; \
	  echo "to run them, put the project's shared/ folder beside this checkout (../shared) and run make test again"; \
	fi

## test-data: the 20 real-derived MERL tables the tests read, made once under target/merl/ from
## ../shared/data/nbrdf (35 MB and about 1.5 s each on one core, two at a time under make test;
## kept between runs).
MATERIALS := color-changing-paint3 gold-paint red-metallic-paint green-metallic-paint blue-rubber \
  white-marble white-paint chrome nickel pink-fabric brass blue-acrylic gray-plastic yellow-paint \
  steel alum-bronze black-obsidian cherry-235 teflon silver-metallic-paint
MERL_TABLES := $(addprefix target/merl/,$(addsuffix .binary,$(MATERIALS)))
test-data: setup-python $(MERL_TABLES)

target/merl/%.binary: | setup-python
	@test -f ../shared/tools/nbrdf2merl.py || { echo "error: ../shared is missing: the tests need the project's shared/ folder beside this checkout"; exit 2; }
	@echo "making $@ (nbrdf2merl.py)"
	@python3 ../shared/tools/nbrdf2merl.py --out target/merl $* >/dev/null

## bench: every benchmark (scripts/benchmarks.py lists them: timings against baselines measured in
## the same run, the equal-quality benchmark of the adaptive modes on the GPU, lavapipe
## without one, the outside referee, the CPU renderer against Mitsuba 3, and the three.js
## material against three.js's own in Chromium), each report written into docs/benchmarks.md
## stamped with the commit and the machine; BENCH="stages atlas" runs some and keeps the other
## sections. About 100 minutes the first time on 2 cores (the adaptive and Mitsuba benchmarks
## keep their bakes, converged images and renders under target/bench-adaptive/ and
## target/bench-mitsuba/), 40 after.
bench: setup-gpu setup-mitsuba setup-node setup-chromium test-data
	python3 scripts/benchmarks.py $(BENCH)

## three-cases: the three.js material in headless Chromium against brdf-preview on six cases
## (white-paint, gold-paint, chrome under quarry_01 and potsdamer_platz, 128 x 128, both
## modes at brdf-preview's default samples) and against the converged estimate; prints the table.
## About 10 minutes on 2 cores (most of it SwiftShader's reference renders); pictures in
## target/three-cases/.
three-cases: setup test-data
	$(CARGO) test --test tests -- --ignored three::three_js_equals_brdf_preview_on_the_six_cases --nocapture

## demo: bake a built-in material (a synthetic GGX copper) under a built-in environment (the
## procedural calibration sky), then render previews (prefiltered; reference, validated against
## the CPU) and a contact sheet of the bake.
demo: setup-gpu build
	@mkdir -p $(DEMO)
	$(BIN)/merl-synth ggx --alpha 0.2 --f0 0.95,0.64,0.54 --out $(DEMO)/ggx-copper.binary
	$(BIN)/envmap-synth --out $(DEMO)/calibration-sky.exr
	$(BIN)/brdf-bake $(DEMO)/ggx-copper.binary --env $(DEMO)/calibration-sky.exr --pca-max-error 0.02 --out-dir $(DEMO)/bake
	$(BIN)/brdf-preview $(DEMO)/bake --out $(DEMO)/preview.png --mode prefiltered --size 384x384 --camera 200,15 --sheet $(DEMO)/sheet.png
	$(BIN)/brdf-preview $(DEMO)/bake --out $(DEMO)/preview-reference.png --size 384x384 --camera 200,15 --validate
	@echo "demo outputs are in $(DEMO)/: bake/ (the assets and manifest.json), preview.png, preview-reference.png (reference mode), preview-reference-difference.png (GPU against CPU, with its scale), sheet.png"

## three-example: the demo's material baked with the engine textures (brdf-bake --engine-textures)
## into its own folder, so that make demo leaves it whole, and engines/three's packages: what the
## three.js example page (engines/three/index.html) reads.
three-example: demo setup-node
	$(BIN)/brdf-bake $(DEMO)/ggx-copper.binary --env $(DEMO)/calibration-sky.exr --pca-max-error 0.02 --engine-textures --out-dir $(DEMO)/three-bake
	@echo "serve the repository root (python3 -m http.server) and open http://localhost:8000/engines/three/index.html?bake=/target/demo/three-bake/"

## bake: every MERL table in IN (*.binary) into OUT/<name>/, in parallel with -j; ENV=map.hdr adds
## the environment stages. E.g. make -j4 bake IN=target/merl OUT=target/bakes ENV=../shared/data/env/quarry_01_1k.hdr
ifdef IN
BAKES := $(patsubst $(IN)/%.binary,$(OUT)/%/manifest.json,$(wildcard $(IN)/*.binary))
endif
bake: build
	@test -n "$(IN)" -a -n "$(OUT)" || { echo "usage: make bake IN=DIR OUT=DIR [ENV=map.hdr] [-j N]"; exit 2; }
	@mkdir -p $(OUT)
	@$(MAKE) --no-print-directory $(BAKES)

# Exit 1 (a stage's validation found a problem; the bake is written and its manifest says what)
# does not stop the other bakes; exit 2 (an error) does.
$(OUT)/%/manifest.json: $(IN)/%.binary $(ENV) $(BIN)/brdf-bake
	@$(BIN)/brdf-bake $< $(if $(ENV),--env $(ENV)) --out-dir $(OUT)/$* --quiet || test $$? -eq 1

## lint: clippy on everything, warnings as errors; rustdoc on the libraries, warnings as errors
## (the tools' doc comments are their --help text, where rustdoc's markup does not apply).
lint:
	$(CARGO) fmt --all --check
	$(CARGO) clippy --workspace --all-targets -- -D warnings
	RUSTDOCFLAGS="-D warnings" $(CARGO) doc --workspace --no-deps --lib

clean-demo:
	rm -rf $(DEMO)

## fuzz: every fuzz target in fuzz/ (cargo-fuzz, nightly Rust) for FUZZ_SECONDS seconds each
## (default 60): timeout 2 s per input, 2 GiB RSS, the memory bound of crates/fuzzing. Seeds are
## read from fuzz/corpus/, fuzz/regressions/, fixtures/ and ../shared/data/hostile/, new inputs
## kept in fuzz/work-corpus/, crashes saved in fuzz/artifacts/
## (copy each into fuzz/regressions/<target>/). Prints each target's executions; exit 1 if any
## target found a crash. E.g. make fuzz FUZZ_SECONDS=600 FUZZ_TARGETS=asset
FUZZ_SECONDS ?= 60
FUZZ_TARGETS ?= merl asset envmap_exr envmap_hdr manifest obj
# Seeds every target reads besides its own: the committed fixtures and the shared hostile inputs
# (crates/fuzzing/tests/regressions.rs replays the same folders).
FUZZ_SHARED_SEEDS := fixtures ../shared/data/hostile
fuzz:
	@cargo +nightly fuzz --version >/dev/null 2>&1 || { \
	  echo "error: make fuzz needs nightly Rust and cargo-fuzz; install them with"; \
	  echo "  rustup toolchain install nightly"; \
	  echo "  cargo install cargo-fuzz"; \
	  exit 2; }
	cargo +nightly fuzz build
	@failed=""; for t in $(FUZZ_TARGETS); do \
	  mkdir -p fuzz/work-corpus/$$t fuzz/artifacts/$$t; \
	  echo "fuzzing $$t for $(FUZZ_SECONDS) s (log: fuzz/artifacts/$$t.log)"; \
	  seeds=""; for d in fuzz/corpus/$$t fuzz/regressions/$$t; do [ -d $$d ] && seeds="$$seeds $$d"; done; \
	  cargo +nightly fuzz run $$t fuzz/work-corpus/$$t $$seeds $(FUZZ_SHARED_SEEDS) -- -max_total_time=$(FUZZ_SECONDS) \
	    -timeout=2 -rss_limit_mb=2048 -print_final_stats=1 >fuzz/artifacts/$$t.log 2>&1 \
	    || { failed="$$failed $$t"; tail -n 40 fuzz/artifacts/$$t.log; }; \
	  awk -v t=$$t '/stat::number_of_executed_units/ {n=$$2} /stat::average_exec_per_sec/ {r=$$2} \
	    /stat::peak_rss_mb/ {m=$$2} /^fuzzing: largest peak so far/ {p=$$6} \
	    END {printf "%s: %s executions (%s per second), largest reader peak %s bytes, RSS %s MB\n", t, n, r, p, m}' \
	    fuzz/artifacts/$$t.log; \
	done; \
	if [ -n "$$failed" ]; then echo "crashes in:$$failed (inputs in fuzz/artifacts/<target>/)"; exit 1; fi

## fuzz-regressions: replay every reproducer (fuzz/regressions/, ../shared/data/hostile/) and seed (fuzz/corpus/, fixtures/) through the
## fuzz harnesses on stable Rust, under the memory bound (part of make test).
fuzz-regressions:
	$(CARGO) test -p fuzzing
