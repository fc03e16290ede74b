#!/usr/bin/env bash
# PoCL runs a work-group's items on one worker thread and keeps each item's private variables on
# that thread's stack, whose size is the process's default (`ulimit -s`; 2 MiB where unlimited),
# raised by pathreuse to 4 MiB where smaller (host/cl/device.cpp). A kernel whose group outgrows
# it writes into another thread's stack and crashes or corrupts a frame. Renders the demo in
# reuse mode, resampling and the shutter's sweeps included, under `ulimit -s 1024`: it passes
# where the threads get the 4 MiB and the groups that Context::launch1D gives PoCL (64 items) fit
# it; without the raise (1 MiB) or with 256 items, it crashes.
# Usage: tools/ci/pocl-stack-check.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/../.."
bin="${1:-build}/pathreuse"
[ -x "$bin" ] || { echo "pocl-stack-check: $bin not built" >&2; exit 1; }
device=$("$bin" devices | sed -nE 's/^\[([0-9]+)\].*\(Portable Computing Language\).*/\1/p' | head -n 1)
[ -n "$device" ] || { echo "pocl-stack-check: no PoCL device in '$bin devices'" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
ulimit -s 1024
for shutter in 0 0.5; do
  if ! "$bin" render scenes/cornell-dynamic.gltf --device "$device" --mode reuse --shutter "$shutter" \
      --spp 4 --width 160 --height 120 --frames 0-2 --quiet --out "$work/f_%04d.exr"; then
    echo "pocl-stack-check: reuse with --shutter $shutter failed under ulimit -s 1024" >&2
    exit 1
  fi
done
echo "pocl-stack-check: reuse renders under ulimit -s 1024"
