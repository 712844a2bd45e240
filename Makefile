# Two entry points do all the set-up: `make run` (the viewer on the built-in demo scene) and
# `make test` (formatting, lints and the whole test suite on lavapipe, windowed tests under Xvfb).

CARGO ?= cargo
# Tests and headless runs use Mesa's lavapipe so results do not depend on the machine's GPU.
LAVAPIPE := /usr/share/vulkan/icd.d/lvp_icd.x86_64.json
export VK_DRIVER_FILES ?= $(LAVAPIPE)
export VK_ICD_FILENAMES ?= $(LAVAPIPE)

.PHONY: all deps build run test lint bench clean

all: build

deps:
	@scripts/install-deps.sh

build: deps
	$(CARGO) build --release

# The viewer on the demo scene. Without a display, a headless run of the demo with a scripted
# drag that writes a PNG (out/run/final.png) and a frame-time summary (out/run/summary.txt).
run: deps
	@if [ -n "$$DISPLAY" ]; then \
		$(CARGO) run --release -- view; \
	else \
		echo "no display (DISPLAY is unset): running the demo headless with a scripted drag"; \
		$(CARGO) run --release -- bench --scenario drag --frames 120 --warmup 10 --out out/run; \
	fi

lint: deps
	$(CARGO) fmt --check
	$(CARGO) clippy --all-targets -- -D warnings

# Every test runs (unit, integration, doc tests); none may skip: PRESPLINE_STRICT=1 turns a
# missing display, driver or tool into a failure (CI=1 does the same). Criterion benches are
# built, not run in test mode, where they would measure and assert nothing.
# Xvfb runs with -noreset: by default an X server resets when its last client leaves, and a
# viewer connecting during the reset fails with "Failed to open connection to X server" (six
# clients connecting in turn on a loaded 2-core host: 60 of 2,400 refused, none with -noreset).
# The import graph first: a circle between the top-level modules fails the run
# (docs/architecture.md).
test: export PRESPLINE_STRICT = 1
test: lint
	python3 scripts/import-graph.py src
	xvfb-run -a -s "-screen 0 1280x1024x24 -noreset" $(CARGO) test --lib --bins --tests
	$(CARGO) test --doc
	$(CARGO) build --benches

bench: deps
	$(CARGO) bench --bench sampling

clean:
	$(CARGO) clean
