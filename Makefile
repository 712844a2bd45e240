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

# The viewer on the demo scene; without a display it falls back to a headless scripted run.
run: deps
	$(CARGO) run --release -- view

lint: deps
	$(CARGO) fmt --check
	$(CARGO) clippy --all-targets -- -D warnings

test: lint
	xvfb-run -a -s "-screen 0 1280x1024x24" $(CARGO) test --all-targets

bench: deps
	$(CARGO) bench --bench sampling

clean:
	$(CARGO) clean
