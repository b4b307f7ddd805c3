#!/usr/bin/env bash
# Renders every example scene under scenes/ to out/<group>/<name>.exr and .png (full size),
# and refreshes the README picture from the torus_egg render.
set -euo pipefail
cd "$(dirname "$0")/.."
for scene in scenes/*/*.ron; do
    group=$(basename "$(dirname "$scene")")
    mkdir -p "out/$group"
    cargo run --release --quiet -- render "$scene" -o "out/$group/$(basename "$scene" .ron).exr"
done
cp out/view_slices/torus_egg.png scenes/view_slices/torus_egg.png
