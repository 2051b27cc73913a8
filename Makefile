# Thin targets over cargo and the tools. `make demo` and `make test` do all set-up themselves.

CARGO ?= cargo
DEMO := target/demo
BIN := target/release

# wgpu warns when XDG_RUNTIME_DIR is unset; give it a private folder.
export XDG_RUNTIME_DIR ?= $(shell d=/tmp/xdg-runtime-$$(id -u); mkdir -p $$d && chmod 700 $$d && echo $$d)

.PHONY: setup build test demo lint bench clean-demo

## setup: install what the tests need and the machine lacks (numpy for the shared data tool,
## the software Vulkan driver lavapipe for the GPU tests). Idempotent.
setup:
	@python3 -c 'import numpy' 2>/dev/null || python3 -m pip install --quiet numpy
	@if ! ls /usr/share/vulkan/icd.d/lvp_icd.*.json >/dev/null 2>&1; then \
	  echo "installing the software Vulkan driver (mesa-vulkan-drivers libvulkan1)"; \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq mesa-vulkan-drivers libvulkan1; \
	fi

build:
	$(CARGO) build --release --workspace

## test: every unit, property, GPU (lavapipe) and end-to-end test.
test: setup
	$(CARGO) test --workspace

## bench: timings against baselines measured in the same run (benchmarks, not tests).
bench:
	$(CARGO) bench -p importance --bench build
	$(CARGO) bench -p envmap --bench load
	$(CARGO) bench -p bandwidth --bench bandwidth
	$(CARGO) bench -p prefilter --bench prefilter
	$(CARGO) bench -p brdf-atlas --bench atlas

lint:
	$(CARGO) clippy --workspace --all-targets -- -D warnings

## demo: make a synthetic material, validate and summarize it, write its info asset and check it,
## bake its importance-sampling tables (and a PNG of the samples over the lobe).
demo: setup
	$(CARGO) build --release -p merl-synth -p merl-info -p asset-info -p merl-importance
	@mkdir -p $(DEMO)
	$(BIN)/merl-synth ggx --alpha 0.2 --f0 0.95,0.64,0.54 --out $(DEMO)/ggx-copper.binary
	$(BIN)/merl-info $(DEMO)/ggx-copper.binary --asset $(DEMO)/ggx-copper.info.asset
	$(BIN)/asset-info $(DEMO)/ggx-copper.info.asset
	$(BIN)/merl-importance $(DEMO)/ggx-copper.binary --out $(DEMO)/ggx-copper.importance.asset --report
	@echo "demo outputs are in $(DEMO)/"

clean-demo:
	rm -rf $(DEMO)
