#!/usr/bin/env bash
# Installs what prespline needs on Debian/Ubuntu when it is missing: a C++ compiler (glslang is
# built from source by build.rs), the Vulkan loader, Mesa's lavapipe (software Vulkan), the
# Khronos validation layers, Xvfb for the windowed tests, strace (for the test that saves are
# fsynced), the X11 client libraries winit loads at run time, and Python 3 (make test runs the
# import-graph check, scripts/import-graph.py). Does nothing when everything is present.
set -euo pipefail

packages=(
  g++ libvulkan1 mesa-vulkan-drivers vulkan-validationlayers
  xvfb xauth strace python3 libx11-6 libx11-xcb1 libxcursor1 libxrandr2 libxi6 libxkbcommon-x11-0
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]})); then
  if ! command -v apt-get >/dev/null; then
    echo "missing system packages: ${missing[*]} (no apt-get here: install them with your package manager)" >&2
    exit 1
  fi
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  echo "installing: ${missing[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

if ! command -v cargo >/dev/null; then
  echo "cargo not found: install Rust 1.88 or newer with rustup (https://rustup.rs)" >&2
  exit 1
fi
if ! cargo fmt --version >/dev/null 2>&1; then rustup component add rustfmt; fi
if ! cargo clippy --version >/dev/null 2>&1; then rustup component add clippy; fi
