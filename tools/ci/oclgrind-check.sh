#!/usr/bin/env bash
# Runs every rendering kernel of every mode on tiny frames under Oclgrind (an OpenCL device
# simulator, Debian package oclgrind) with its out-of-bounds, API and data-race checks. Any
# report, or a render that fails, fails the check. Its uninitialised-value check is left out:
# Oclgrind 21.10 stops on LLVM's `freeze` and crashes inside that plugin on these kernels.
# Usage: tools/ci/oclgrind-check.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/../.."
build="${1:-build}"
bin="$build/pathreuse"
command -v oclgrind >/dev/null || { echo "oclgrind-check: oclgrind is not installed (apt-get install oclgrind)" >&2; exit 1; }
[ -x "$bin" ] || { echo "oclgrind-check: $bin not built" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# Oclgrind compiles with its own front end: keep its binaries apart from the real devices'.
export PATHREUSE_CACHE_DIR="$work/cache"
# Its LLVM lacks llvm.bitreverse: the kernels reverse bits by table instead (kernels/shared/rng.h).
export PATHREUSE_CL_OPTIONS="-DPR_BITREVERSE_TABLE"
unset PATHREUSE_DEVICE

fail=0
run() {
  local name=$1; shift
  local log="$work/$name.log"
  if ! oclgrind --check-api --data-races --log "$log" "$bin" render "$@" --quiet \
      --width 16 --height 12 --spp "${SPP:-1}" --out "$work/$name/f_%04d.exr" 2>"$work/$name.err"; then
    echo "oclgrind-check: $name: render failed: $(head -c 2000 "$work/$name.err")"
    fail=1
  elif [ -s "$log" ]; then
    echo "oclgrind-check: $name: Oclgrind reported:"
    head -n 40 "$log"
    fail=1
  else
    echo "oclgrind-check: $name: clean"
  fi
}

# Frames 0-2: the second and third frames invalidate and re-trace what the sphere disturbs.
# Reuse and retrace with eye paths, resampled (the default), and reuse without resampling; the
# connections alone (--no-eye-paths: eye_hit, next-event estimation, strategy E and the
# delta-chain extension in connect) further down.
for mode in pathtrace reuse retrace; do
  run "cornell-dynamic-$mode" scenes/cornell-dynamic.gltf --frames 0-2 --mode "$mode"
done
run "cornell-dynamic-reuse-no-resample" scenes/cornell-dynamic.gltf --frames 0-1 --mode reuse \
  --no-resample
run "cornell-orbit-reuse-connections" scenes/cornell-orbit.gltf --frames 0-1 --mode reuse \
  --no-eye-paths
# A skinned and a morphing mesh: deformed, BVH rebuilt and shading vertices uploaded per frame;
# resampling's temporal test traverses their previous shapes' BVHs.
run "cornell-skinned-reuse" scenes/cornell-skinned.gltf --frames 0-2 --mode reuse
# The light BVH's kernels and the choice by power (on the demo scenes --light-sampler auto
# weighs every light), the tree on the many-lights atrium too: a deep tree, point and spot
# lights, a moving emitter.
run "cornell-dynamic-pathtrace-lightbvh" scenes/cornell-dynamic.gltf --frames 0-1 --mode pathtrace \
  --light-sampler bvh
run "cornell-dynamic-pathtrace-power" scenes/cornell-dynamic.gltf --frames 0-1 --mode pathtrace \
  --light-sampler power
# Path resampling across pixels and frames: the paths' candidates in pt_shade and pt_shadow,
# pt_resample's reconnections (an environment too, for the escaped paths' candidates), and on the
# second frame the previous frame's reservoirs: through a moving camera, and past moving objects.
run "cornell-orbit-pathtrace-resample" scenes/cornell-orbit.gltf --frames 0-1 --mode pathtrace \
  --resample --env-color 0.4,0.5,0.6
run "cornell-dynamic-pathtrace-resample" scenes/cornell-dynamic.gltf --frames 0-1 \
  --mode pathtrace --resample
# With reuse and a neighbour: the eye paths' shares against the connections, rebuilt where a
# path moves to another x_1.
run "cornell-dynamic-reuse-resample" scenes/cornell-dynamic.gltf --frames 0-1 --mode reuse \
  --resample-neighbors 1
# Strategy T: camera_splat's atomics into the fixed-point sums, splat_film, and T's ratio in
# connect, pt_shade and the paths moved to another x_1 (a moving camera, a neighbour).
run "cornell-orbit-reuse-light-tracing" scenes/cornell-orbit.gltf --frames 0-1 --mode reuse \
  --light-tracing --resample-neighbors 1
# Auxiliary images (kernels/aov.cl): a skinned mesh's previous shape for the motion, and below,
# through an environment map.
run "cornell-skinned-reuse-aov" scenes/cornell-skinned.gltf --frames 0-1 --mode reuse --aov all
# Adaptive sampling (kernels/adaptive.cl): the plan after a pilot of two passes, then the masked
# passes over listed pixels in pt_generate, pt_resample (with a neighbour that may skip the
# pass, and the previous frame's records of skipped passes), connect, connect_shadow,
# accumulate, strategy T's splats by each pixel's count; and eye_hit's mask without eye paths.
SPP=6 run "cornell-dynamic-reuse-adaptive" scenes/cornell-dynamic.gltf --frames 0-2 --mode reuse \
  --noise-threshold 0.3 --adaptive-min-spp 2 --resample-neighbors 1 --light-tracing --aov samples
SPP=6 run "cornell-dynamic-pathtrace-adaptive" scenes/cornell-dynamic.gltf --frames 0-1 \
  --mode pathtrace --resample --noise-threshold 0.3 --adaptive-min-spp 2
SPP=6 run "cornell-dynamic-reuse-adaptive-connections" scenes/cornell-dynamic.gltf --frames 0-1 \
  --mode reuse --no-eye-paths --noise-threshold 0.3 --adaptive-min-spp 2
# Resampled connections (two shadow rays per eye vertex).
run "cornell-dynamic-reuse-ris" scenes/cornell-dynamic.gltf --frames 0-1 --mode reuse --connections 2 \
  --no-eye-paths
# The connection history, carried over frames, in both modes (retrace marks changed slots only).
for mode in reuse retrace; do
  run "cornell-dynamic-$mode-history" scenes/cornell-dynamic.gltf --frames 0-2 --mode "$mode" \
    --connections 1 --connection-history 20 --no-eye-paths
done
# The other BVH layouts (8 is what a CPU gets by default): 4, a GPU's, and 2.
for width in 2 4; do
  run "cornell-dynamic-reuse-bvh$width" scenes/cornell-dynamic.gltf --frames 0-1 --mode reuse \
    --bvh-width "$width"
done
python3 -m tools.scenes.gen_atrium --size 0.02 --light lanterns --out "$work/lanterns/atrium.gltf" >/dev/null
run "lanterns-pathtrace" "$work/lanterns/atrium.gltf" --frames 0-1 --mode pathtrace --light-sampler bvh
# Motion blur: the camera's and the instances' motion steps, emitters where they are at each
# sample's time, the auxiliary images at the frame's, a skinned mesh's steps blended.
run "lanterns-pathtrace-shutter" "$work/lanterns/atrium.gltf" --frames 0-1 --mode pathtrace \
  --light-sampler bvh --shutter 1
run "cornell-orbit-pathtrace-shutter" scenes/cornell-orbit.gltf --frames 0-1 --mode pathtrace \
  --shutter 0.5 --aov all
run "cornell-skinned-pathtrace-shutter" scenes/cornell-skinned.gltf --frames 0-1 \
  --mode pathtrace --shutter 0.5
# Path reuse over the shutter: light paths joined at the samples' times where they meet nothing
# that moves (the sweeps), strategy T at a time of its own with a moving camera; and resampling
# (off by default under a shutter, asked for on the skinned demo), from the previous frame (its
# sweeps too) and from neighbours at their own times.
run "lanterns-reuse-shutter" "$work/lanterns/atrium.gltf" --frames 0-1 --mode reuse \
  --light-sampler bvh --shutter 1
run "cornell-orbit-reuse-shutter" scenes/cornell-orbit.gltf --frames 0-1 --mode reuse --shutter 0.5
# Light paths that meet the moving sphere traced again at their own times, dropped the next frame;
# reuse's resampling with them.
run "cornell-dynamic-reuse-resample-shutter" scenes/cornell-dynamic.gltf --frames 0-2 --mode reuse \
  --resample --shutter 0.5
# Under the still camera, connections across the sphere's sweep at the light paths' own times,
# kept by the reservoirs of resampled connections (their rays' times).
run "cornell-dynamic-reuse-connections-shutter" scenes/cornell-dynamic.gltf --frames 0-1 \
  --mode reuse --connections 2 --shutter 0.5
run "cornell-skinned-resample-shutter" scenes/cornell-skinned.gltf --frames 0-2 --mode pathtrace \
  --resample --resample-neighbors 2 --shutter 0.5
run "lanterns-reuse-connections" "$work/lanterns/atrium.gltf" --frames 0-1 --mode reuse \
  --light-sampler bvh --no-eye-paths
# Eye paths weighted against the connections: with a history on the demo, and among many
# triangle, point and spot lights.
run "cornell-dynamic-reuse-eye-history" scenes/cornell-dynamic.gltf --frames 0-2 --mode reuse \
  --connections 1 --connection-history 20
run "lanterns-reuse-eye" "$work/lanterns/atrium.gltf" --frames 0-1 --mode reuse --light-sampler bvh
# Normal maps (generated tangents) in every kernel that shades, under an environment map too.
python3 -m tools.scenes.gen_atrium --size 0.02 --normal-maps --out "$work/bumps/atrium.gltf" >/dev/null
python3 - "$work/bumps/sky.hdr" <<'PY'
import sys
w, h = 8, 4  # flat RGBE scanlines: a bright texel in a dim sky
with open(sys.argv[1], "wb") as f:
    f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (h, w))
    for y in range(h):
        for x in range(w):
            f.write(bytes([200, 160, 120, 134] if (x, y) == (5, 1) else [100, 120, 160, 128]))
PY
run "atrium-normal-maps-env-pathtrace" "$work/bumps/atrium.gltf" --frames 0-1 --mode pathtrace \
  --camera 1 --env "$work/bumps/sky.hdr" --env-rotate 40 --aov all
run "atrium-normal-maps-env-reuse-connections" "$work/bumps/atrium.gltf" --frames 0-1 --mode reuse \
  --camera 1 --env "$work/bumps/sky.hdr" --env-rotate 40 --no-eye-paths
run "atrium-normal-maps-env-eye" "$work/bumps/atrium.gltf" --frames 0-1 --mode reuse \
  --camera 1 --env "$work/bumps/sky.hdr" --env-rotate 40
# A sun and a sky: their light paths from the disk across their direction, in every strategy.
python3 -m tools.scenes.gen_atrium --size 0.02 --light sun --out "$work/sun/atrium.gltf" >/dev/null
run "atrium-sun-sky-eye" "$work/sun/atrium.gltf" --frames 0-1 --mode reuse \
  --env-color 0.5,0.6,0.8
run "atrium-sun-sky-reuse-shutter" "$work/sun/atrium.gltf" --frames 0-1 --mode reuse \
  --env-color 0.5,0.6,0.8 --shutter 1
# Every BSDF lobe and texture (sheen, a coat with its own normal map, anisotropy with a direction
# texture) in both integrators, and the glTF specification's model.
for mode in pathtrace reuse; do
  run "materials-extensions-$mode" tests/data/materials/extensions.gltf --frames 0 --mode "$mode"
  run "materials-gltf-model-$mode" tests/data/materials/zoo.gltf --frames 0 --mode "$mode" \
    --material-model gltf-reference
done
exit $fail
