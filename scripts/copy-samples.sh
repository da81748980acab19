#!/usr/bin/env bash
# Copies the shared test meshes the web app offers as one-click samples.
set -euo pipefail
src="$1"; dst="$2"
mkdir -p "$dst"
for m in stanford-bunny fandisk rocker-arm spot cow teapot suzanne beetle; do
  if [ -f "$src/$m.obj" ]; then
    cmp -s "$src/$m.obj" "$dst/$m.obj" || cp "$src/$m.obj" "$dst/$m.obj"
  else
    echo "copy-samples: $src/$m.obj not found; the sample will be missing" >&2
  fi
done
