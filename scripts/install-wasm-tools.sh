#!/usr/bin/env bash
# Installs the wasm32 target and a wasm-bindgen CLI matching Cargo.lock's
# wasm-bindgen version into $1/bin (skipped when the right version is there).
# With --target-only, installs the wasm32 target (and the rustfmt and clippy
# components `make lint` runs) and stops.
set -euo pipefail
target_only=false
if [ "${1:-}" = "--target-only" ]; then
  target_only=true
  shift
fi
tools="$1"
rustup target list --installed | grep -qx wasm32-unknown-unknown || rustup target add wasm32-unknown-unknown
if $target_only; then
  for component in rustfmt clippy; do
    rustup component list --installed | grep -q "^$component" || rustup component add "$component"
  done
  exit 0
fi
version=$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/version = |"/, ""); print; exit }' Cargo.lock)
if [ -z "$version" ]; then
  echo "install-wasm-tools: wasm-bindgen not found in Cargo.lock" >&2
  exit 1
fi
if [ -x "$tools/bin/wasm-bindgen" ] && "$tools/bin/wasm-bindgen" --version | grep -q " $version\$"; then
  exit 0
fi
if command -v wasm-bindgen >/dev/null && wasm-bindgen --version | grep -q " $version\$"; then
  mkdir -p "$tools/bin"
  ln -sf "$(command -v wasm-bindgen)" "$tools/bin/wasm-bindgen"
  exit 0
fi
echo "install-wasm-tools: installing wasm-bindgen-cli $version into $tools (takes a few minutes, once)"
cargo install wasm-bindgen-cli --version "$version" --root "$tools"
