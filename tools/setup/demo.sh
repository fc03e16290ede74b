#!/usr/bin/env bash
# Installs what is missing, builds, and renders the default demo scene (the 5 s animation of
# scenes/cornell-dynamic.gltf at 320x240) into out/demo/: one EXR and one PNG per frame.
set -euo pipefail
cd "$(dirname "$0")/../.."
bash tools/setup/install-deps.sh
bash tools/setup/build.sh
./build/pathreuse devices
./build/pathreuse render scenes/cornell-dynamic.gltf --width 320 --height 240 --spp 4 \
  --out out/demo/frame_%04d.exr --png --stats out/demo/stats.jsonl
echo "demo frames: $(pwd)/out/demo/frame_0000.png ... frame_0120.png (and .exr)"
