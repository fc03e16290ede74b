#!/usr/bin/env bash
# Installs what is missing, builds the renderer alone (the tests are the test command's), and
# renders the default demo scene (the 5 s animation of scenes/cornell-dynamic.gltf at 320x240,
# denoised) into out/demo/: one EXR and one PNG per frame, and the sequence as an MP4.
set -euo pipefail
cd "$(dirname "$0")/../.."
bash tools/setup/install-deps.sh
BUILD_TARGETS=pathreuse bash tools/setup/build.sh
./build/pathreuse devices
./build/pathreuse render scenes/cornell-dynamic.gltf --width 320 --height 240 --spp 4 --denoise \
  --out out/demo/frame_%04d.exr --video out/demo/cornell-dynamic.mp4 --stats out/demo/stats.jsonl
echo "demo: $(pwd)/out/demo/cornell-dynamic.mp4 (frames: out/demo/frame_0000.png ... frame_0120.png, and .exr)"
