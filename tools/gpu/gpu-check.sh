#!/usr/bin/env bash
# The checks for a machine with a GPU and no package registry, in one call: lists the OpenCL
# devices, times a cold compilation of each mode's kernels, runs the test suite on the GPU,
# compares the GPU's portability suite with the reference frames rendered on the CPU, times the
# demo, runs the connection strategies (tools/bench/bench_connections.py), the GPU with the machine's
# CPU in one render, and a short form of the evaluation; on request (steps rays, atrium) ray
# throughput and frame times at each BVH width, where the bundle has ray_bench.
# Everything goes to OUT. The programs come from a bundle made by tools/gpu/gpu-bundle.sh on the
# build machine and carried along (default: .gpu in the repository root).
# Usage: tools/gpu/gpu-check.sh OUT [BUNDLE] [DEVICE]   (DEVICE: a --device spec, default gpu)
# GPU_CHECK_STEPS picks the steps and their order (default: all, in the order of STEPS below), so
# that a short device lease spends its minutes on what matters most; GPU_CHECK_TAR=FILE packs
# OUT into FILE after each step, so that what ran comes back where few files may.
set -uo pipefail
cd "$(dirname "$0")/../.."
out="${1:?usage: tools/gpu/gpu-check.sh OUT [BUNDLE] [DEVICE]}"
bundle="$(cd "${2:-.gpu}" && pwd)"
device="${3:-gpu}"
mkdir -p "$out"
out="$(cd "$out" && pwd)"
summary="$out/summary.txt"
: >"$summary"
say() { echo "$*" | tee -a "$summary"; }

export LD_LIBRARY_PATH="$bundle/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
# The build's libstdc++ only where the machine's is older than the one it was built with.
if ! "$bundle/bin/pathreuse" --version >/dev/null 2>&1; then
  export LD_LIBRARY_PATH="$bundle/libstdcxx:$LD_LIBRARY_PATH"
fi
"$bundle/bin/pathreuse" --version >/dev/null || { say "gpu-check: the bundled pathreuse does not start"; exit 1; }

# NVIDIA's OpenCL: its ICD file, else a folder with a one-line .icd naming its library.
if [ -z "${OCL_ICD_VENDORS:-}" ] && ! grep -qs nvidia /etc/OpenCL/vendors/*.icd; then
  lib=$(ldconfig -p 2>/dev/null | awk '/libnvidia-opencl\.so\.1/ {print $NF; exit}')
  [ -n "$lib" ] || lib=$(find / -xdev -name 'libnvidia-opencl.so.1*' 2>/dev/null | head -n 1)
  if [ -n "$lib" ]; then
    mkdir -p /tmp/pathreuse-icd
    cp /etc/OpenCL/vendors/*.icd /tmp/pathreuse-icd/ 2>/dev/null
    echo "$lib" >/tmp/pathreuse-icd/nvidia.icd
    export OCL_ICD_VENDORS=/tmp/pathreuse-icd
    say "gpu-check: NVIDIA OpenCL from $lib"
  fi
fi
"$bundle/bin/pathreuse" devices >"$out/devices.txt" 2>&1
cat "$out/devices.txt" >>"$summary"
export PATHREUSE_CACHE_DIR=/tmp/pathreuse-cache

# The tests find the binary and the sources where they were built: make those paths hold.
src=$(cat "$bundle/source_dir")
if [ "$src" != "$PWD" ] && [ ! -e "$src" ]; then mkdir -p "$(dirname "$src")" && ln -s "$PWD" "$src"; fi
if [ -d "$bundle/shared-scenes" ] && [ ! -e "$(dirname "$src")/shared/scenes" ]; then
  mkdir -p "$(dirname "$src")/shared" && ln -s "$bundle/shared-scenes" "$(dirname "$src")/shared/scenes"
fi
if [ ! -x "$src/build/pathreuse" ]; then mkdir -p "$src/build" && cp "$bundle"/bin/* "$src/build/"; fi

# The evaluation's smoke test and the short evaluation need a Python with numpy and matplotlib;
# a GPU machine's system Python may lack them where another one has them.
for py in /usr/bin/python3 python3; do
  if "$py" -c 'import numpy, matplotlib' 2>/dev/null; then export PATHREUSE_PYTHON="$py"; break; fi
done
say "python for the evaluation: ${PATHREUSE_PYTHON:-none with numpy and matplotlib}"

exe="$src/build/pathreuse"
median_wall() {  # median wall seconds per frame of a --stats file, after skipping its first N lines
  python3 -c 'import json,sys,statistics; L=[json.loads(l) for l in open(sys.argv[1])][int(sys.argv[2]):]; print(round(statistics.median(l["wall_s"] for l in L), 4))' "$1" "${2:-0}" 2>/dev/null
}
atrium=/tmp/pathreuse-atrium-gpu/atrium.gltf
ensure_atrium() {  # generated here (7 MB) rather than carried
  [ -f "$atrium" ] || ${PATHREUSE_PYTHON:-python3} -m tools.scenes.gen_atrium --size 1 --out "$atrium" >/dev/null 2>>"$summary"
  [ -f "$atrium" ]
}

# What a first render costs on this device: each mode's kernels compiled from source (the
# driver's own cache off), seconds per program from --stats. It also fills the kernel cache
# that the tests then load from.
step_compile() {
  say "== kernel compilation on --device $device (cold, 48x36, seconds per program)"
  local mode cold
  cold=$(mktemp -d)
  for mode in pathtrace reuse; do  # reuse's programs serve with and without eye paths
    PATHREUSE_CACHE_DIR="$cold" CUDA_CACHE_DISABLE=1 timeout "${GPU_CHECK_COMPILE_S:-300}" "$exe" render \
      scenes/cornell-dynamic.gltf --device "$device" --mode "$mode" --width 48 --height 36 --spp 2 --frames 0 \
      --quiet --out "/tmp/pathreuse-compile/$mode-%04d.exr" --stats "$out/stats-compile-$mode.jsonl" 2>>"$summary"
    say "$mode: exit $?, $(python3 -c 'import json,sys; b=json.loads(open(sys.argv[1]).readline()).get("build_s", {}); print("%.1f s in all:" % sum(b.values()), " ".join("%s %.1f" % (k, v) for k, v in sorted(b.items(), key=lambda kv: -kv[1])))' "$out/stats-compile-$mode.jsonl" 2>/dev/null)"
  done
  mkdir -p "$PATHREUSE_CACHE_DIR/kernels" && cp -n "$cold"/kernels/* "$PATHREUSE_CACHE_DIR/kernels/" 2>/dev/null
  rm -rf "$cold"
}

# A real asset on the GPU: the FlightHelmet (94,722 triangles, 15 textures) at 1280x720 under the
# default environment, seconds per frame in each mode; the first frame apart (it builds the
# asset's kernel variant, timed in build_s).
step_asset() {
  local scene mode f
  scene="$(dirname "$src")/shared/scenes/FlightHelmet/FlightHelmet.gltf"
  [ -f "$scene" ] || { say "== asset: $scene is absent"; return; }
  say "== FlightHelmet on --device $device (1280x720, 4 spp, frames 0-8, wall s per frame)"
  for mode in pathtrace reuse; do
    f="$out/stats-asset-$mode.jsonl"
    timeout "${GPU_CHECK_ASSET_S:-200}" "$exe" render "$scene" --device "$device" --mode "$mode" \
      --width 1280 --height 720 --spp 4 --frames 0-8 --quiet --out "/tmp/pathreuse-asset/$mode-%04d.exr" \
      --stats "$f" 2>>"$summary"
    say "$mode: exit $?, first frame $(python3 -c 'import json,sys; l=json.loads(open(sys.argv[1]).readline()); print("%.2f s (kernel builds %.1f s)" % (l["wall_s"], sum(l.get("build_s", {}).values())))' "$f" 2>/dev/null), frames 1-8 median $(median_wall "$f" 1) s"
  done
}

step_tests() {
  say "== tests on --device $device"
  rm -f /tmp/gpu-check-rc
  local tests=("$src"/build/*_test)
  export PATHREUSE_TEST_DEVICE="$device"
  printf '%s\n' "${tests[@]}" | xargs -P 8 -I{} sh -c \
    'timeout 240 "{}" --gtest_brief=1 >"/tmp/$(basename "{}").log" 2>&1; echo "$? $(basename "{}")" >>/tmp/gpu-check-rc'
  for t in "${tests[@]}"; do
    n=$(basename "$t")
    { echo "### $n"; cat "/tmp/$n.log"; } >>"$out/tests.log"
  done
  local failed
  failed=$(awk '$1 != 0 {print $2 " (exit " $1 ")"}' /tmp/gpu-check-rc)
  say "test programs: ${#tests[@]}, failed: ${failed:-none}"
  grep -h "FAILED  \]\|SKIPPED \]" "$out/tests.log" | sort -u | head -n 40 >>"$summary"
  grep -h "^\[  PASSED  \]" "$out/tests.log" | awk '{n += $4} END {print "tests passed: " n}' | tee -a "$summary"
}

step_portability() {
  say "== portability: --device $device against the CPU's reference frames"
  "$exe" portability --quiet --device "$device" --reference "$bundle/reference" \
    --out /tmp/pathreuse-portability >"$out/portability.txt" 2>&1
  say "portability exit code: $?"
  tail -n 2 "$out/portability.txt" >>"$summary"
}

step_demo() {
  say "== demo timing on --device $device (320x240, 4 spp, frames 0-23)"
  for mode in pathtrace reuse; do
    "$exe" render scenes/cornell-dynamic.gltf --device "$device" --mode "$mode" \
      --width 320 --height 240 --spp 4 --frames 0-23 --quiet --out "/tmp/pathreuse-demo/$mode-%04d.exr" \
      --stats "$out/stats-$mode.jsonl" 2>>"$summary"
    say "$mode: exit $?, median frame wall seconds $(median_wall "$out/stats-$mode.jsonl")"
  done
}

# Which BVH layout suits the GPU: ray throughput at each width (auto gives a GPU width 4).
step_rays() {
  [ -x "$bundle/bin/ray_bench" ] || { say "== rays: the bundle has no ray_bench"; return; }
  local scene w
  scene="$(dirname "$src")/shared/scenes/cornell-nvpro/cornellBox.gltf"
  [ -f "$scene" ] || scene=scenes/cornell-dynamic.gltf
  say "== ray throughput on --device $device by BVH width ($(basename "$scene"), Mrays/s camera shadow bounce)"
  for w in 2 4 8; do
    "$bundle/bin/ray_bench" "$scene" --device "$device" --repeats 3 --bvh-width "$w" >"$out/rays-w$w.txt" 2>&1
    say "width $w: exit $?, $(awk '/^(camera|shadow|bounce) /{printf "%s ", $6}' "$out/rays-w$w.txt")"
  done
  ensure_atrium || return
  say "== ray throughput on --device $device by BVH width (atrium, 1280x720, Mrays/s camera shadow bounce)"
  for w in 2 4 8; do
    "$bundle/bin/ray_bench" "$atrium" --device "$device" --repeats 5 --width 1280 --height 720 \
      --bvh-width "$w" >"$out/rays-atrium-w$w.txt" 2>&1
    say "width $w: exit $?, $(awk '/^(camera|shadow|bounce) /{printf "%s ", $6}' "$out/rays-atrium-w$w.txt")"
  done
}

# The atrium's frame times at each BVH width.
step_atrium() {
  ensure_atrium || { say "== atrium: could not be generated"; return; }
  say "== atrium frame times on --device $device by BVH width (640x360, 16 spp, frames 0-11, median wall s)"
  local w mode line
  for w in 2 4 8; do
    line="width $w:"
    for mode in pathtrace reuse; do
      "$exe" render "$atrium" --device "$device" --mode "$mode" --bvh-width "$w" \
        --width 640 --height 360 --spp 16 --frames 0-11 --quiet --out "/tmp/pathreuse-atrium-gpu/$mode-%04d.exr" \
        --stats "$out/stats-atrium-$mode-w$w.jsonl" 2>>"$summary"
      line="$line $mode $(median_wall "$out/stats-atrium-$mode-w$w.jsonl")"
    done
    say "$line"
  done
}

# Connection strategies against the path tracer on the GPU (frames large enough to fill it).
step_connections() {
  ensure_atrium || { say "== connections: the atrium could not be generated"; return; }
  say "== connection strategies on --device $device (tools/bench/bench_connections.py, 640 wide, 16 spp)"
  timeout "${GPU_CHECK_CONNECTIONS_S:-150}" python3 -m tools.bench.bench_connections --build "$src/build" --device "$device" \
    --width 640 --atrium "$atrium" --scenes cornell-dynamic,atrium \
    --configs "pathtrace,reuse K=2,eye all,eye K=1,eye K=2,eye all C1" >"$out/connections.md" 2>>"$summary"
  say "bench_connections: exit $?"
  grep '^|\|^##' "$out/connections.md" >>"$summary"
}

# Several devices in one render: the GPU, the machine's CPU and both, rows balanced by
# throughput (README: several devices). Needs a CPU OpenCL implementation on the GPU machine.
step_multi() {
  if ! "$exe" devices 2>/dev/null | grep -q " CPU,"; then
    say "== several devices: skipped, this machine has no CPU OpenCL device ($(ls /etc/OpenCL/vendors 2>/dev/null | tr '\n' ' '))"
    return
  fi
  say "== several devices: demo 640x480, 8 spp, frames 0-8, median wall s per frame (frames 1-8)"
  local mode devs d tag line args
  for mode in pathtrace reuse; do
    line="$mode:"
    for devs in "$device" cpu "$device cpu"; do
      args=()
      for d in $devs; do args+=(--device "$d"); done
      tag=$(echo "$devs" | tr ' ' '_')
      timeout 120 "$exe" render scenes/cornell-dynamic.gltf "${args[@]}" --mode "$mode" \
        --width 640 --height 480 --spp 8 --frames 0-8 --quiet --out "/tmp/pathreuse-multi/$mode-$tag-%04d.exr" \
        --stats "$out/stats-multi-$mode-$tag.jsonl" 2>>"$summary"
      line="$line $tag $(median_wall "$out/stats-multi-$mode-$tag.jsonl" 1) rows $(python3 -c 'import json,sys; L=[json.loads(l) for l in open(sys.argv[1])]; print("/".join(str(d["rows"]) for d in L[-1].get("devices", [])))' "$out/stats-multi-$mode-$tag.jsonl" 2>/dev/null);"
    done
    say "$line"
  done
}

# A short form of the evaluation (relMSE against a reference, equal-time comparisons) on the GPU.
step_evaluation() {
  [ -n "${PATHREUSE_PYTHON:-}" ] || { say "== evaluation: no Python with numpy and matplotlib"; return; }
  ensure_atrium || return
  say "== short evaluation on --device $device, results in evaluation/"
  PATHREUSE_DEVICE="$device" timeout "${GPU_CHECK_EVALUATION_S:-150}" "$PATHREUSE_PYTHON" -m tools.bench.evaluate --quiet \
    --out-dir "$out/evaluation" --build "$src/build" --cache /tmp/pathreuse-eval-cache --atrium "$atrium" \
    --frames 9 --atrium-frames 9 --timing-frames 25 --atrium-timing-frames 13 --seeds 1,2 --repeats 2 \
    --ref-spp 256 --atrium-ref-spp 128 --equal-time-rounds 1 >"$out/evaluation.log" 2>&1
  say "evaluation: exit $?"
  sed -n '/^## Goals/,/^## /p' "$out/evaluation/results.md" 2>/dev/null | head -n 30 >>"$summary"
}

# The default fits one call of under 8 minutes on an H200 (2026-11-27: compile about 2 minutes,
# the tests 1 with a warm cache); the BVH-width sweeps (rays, atrium) and the real asset (asset,
# which needs ../shared/scenes/FlightHelmet in the bundle) only when named.
STEPS="compile tests portability demo connections multi evaluation"
ALL="$STEPS asset rays atrium"
start=$SECONDS
for s in ${GPU_CHECK_STEPS:-$STEPS}; do
  case " $ALL " in *" $s "*) ;; *) say "gpu-check: no step '$s' (steps: $ALL)"; exit 2 ;; esac
  t0=$SECONDS
  "step_$s"
  say "-- step $s: $((SECONDS - t0)) s"
  # Where only a few files may come back from the machine: all of OUT in one archive, after
  # every step, so that a run cut short still returns what it measured.
  [ -n "${GPU_CHECK_TAR:-}" ] && tar czf "$GPU_CHECK_TAR" -C "$out" .
done
say "gpu-check: $((SECONDS - start)) s in all"
