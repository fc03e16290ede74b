#!/usr/bin/env bash
# Ray-throughput benchmark: builds ray_bench if needed, generates the large atrium,
# runs the benchmark on cornell-nvpro and the atrium on PoCL capped to 2 threads, and writes
# docs/ray-benchmark.md. The Embree column appears when libembree-dev was installed before
# cmake ran (apt-get install -y libembree-dev).
#
#   tools/bench/bench_rays.sh [--repeats N] [--build DIR]
set -euo pipefail

root="$(cd "$(dirname "$0")/../.." && pwd)"
build="$root/build"
repeats=5
while [[ $# -gt 0 ]]; do
  case "$1" in
    --repeats) repeats="$2"; shift 2 ;;
    --build) build="$2"; shift 2 ;;
    *) echo "bench_rays.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done

if [[ ! -x "$build/ray_bench" || ! -x "$build/pathreuse" ]]; then
  cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo
fi
cmake --build "$build" -j2 --target ray_bench pathreuse

atrium=/tmp/pathreuse-atrium/atrium.gltf
if [[ ! -f "$atrium" ]]; then
  (cd "$root" && python3 -m tools.scenes.gen_atrium --size 1 --out "$atrium")
fi
scenes=()
cornell="$root/../shared/scenes/cornell-nvpro/cornellBox.gltf"
[[ -f "$cornell" ]] && scenes+=("$cornell")
scenes+=("$atrium")

# PoCL 3.1's pthread driver takes its thread count from POCL_MAX_PTHREAD_COUNT.
export POCL_MAX_PTHREAD_COUNT=2
out="$root/docs/ray-benchmark.md"
mkdir -p "$root/docs"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

for scene in "${scenes[@]}"; do
  name="$(basename "$scene" .gltf)"
  echo "== $name" >&2
  "$build/ray_bench" "$scene" --repeats "$repeats" --json "$tmp/$name.json" >"$tmp/$name.txt" 2>"$tmp/$name.err"
  cat "$tmp/$name.txt" >&2
  # The other layouts (the default above is a CPU's, 8 wide), for the per-device choice.
  for w in 4 2; do
    "$build/ray_bench" "$scene" --repeats "$repeats" --bvh-width "$w" --no-embree \
      --json "$tmp/$name-w$w.json" >/dev/null 2>>"$tmp/$name.err"
  done
done

{
  echo "# Ray-throughput benchmark"
  echo
  echo "Written by \`tools/bench/bench_rays.sh\`. Closest hit for camera and diffuse bounce rays,"
  echo "any hit for shadow rays, on the SSG + DSG as the renderer builds them (frame time 0),"
  echo "640 x 480 camera rays through pixel centres of the scene's first camera; camera rays that"
  echo "miss are dropped from all sets. Our rate: kernel time from OpenCL profiling events,"
  echo "median of $repeats launches after a warm-up. Embree 3 (build quality high, 2 std::threads,"
  echo "wall time) traces the very same rays, alternating with ours: Embree-1 with rtcIntersect1 /"
  echo "rtcOccluded1, Embree-8 with 8-wide packets; ratio = ours / the better of the two."
  echo "\"agree\": rays with the same hit/miss (occluded) answer; \"same-prim\": same triangle and instance."
  echo
  echo "Our BVH (kernels/shared/bvh.h): binned SAH collapsed into 8-wide nodes (children's boxes"
  echo "structure-of-arrays, one float8 slab test per node), leaves of up to 4 triangles tested with"
  echo "float4 Moller-Trumbore; the last table compares the 4- and 2-wide layouts."
  echo
  echo "- date: $(date -u '+%Y-%m-%d %H:%M UTC')"
  echo "- machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')"
  echo "- device: \`$("$build/pathreuse" devices 2>/dev/null | head -1)\`"
  echo "- PoCL: $(dpkg-query -W -f='${Version}' libpocl2 2>/dev/null || echo unknown), POCL_MAX_PTHREAD_COUNT=2"
  echo "- commit: $(git -C "$root" rev-parse --short HEAD)$(git -C "$root" diff --quiet HEAD -- kernels host tools || echo ' (+ local changes)')"
  for scene in "${scenes[@]}"; do
    name="$(basename "$scene" .gltf)"
    echo
    echo "## $name"
    echo
    echo '```'
    grep -v '^device:' "$tmp/$name.txt"
    echo '```'
    echo
    python3 - "$tmp/$name.json" <<'EOF'
import json, sys
j = json.load(open(sys.argv[1]))
ref = "embree" in j
head = "| rays | query | count | ours Mrays/s (median [min-max]) |"
rule = "|---|---|---:|---:|"
if ref:
    head += " Embree-1 | Embree-8 | ours / Embree | agree |"
    rule += "---:|---:|---:|---:|"
print(head)
print(rule)
for name in ("camera", "shadow", "bounce"):
    s = j["sets"][name]
    o = s["ours_mrays"]
    row = f"| {name} | {s['query']} | {s['rays']} | {o['median']:.2f} [{o['min']:.2f}-{o['max']:.2f}] |"
    if ref:
        e1, e8 = s["embree1_mrays"]["median"], s["embree8_mrays"]["median"]
        best = max(e1, e8)
        row += f" {e1:.2f} | {e8:.2f} | {o['median'] / best if best else 0:.3f} | {100 * s['agree_hit']:.4f}% |"
    print(row)
ssg, dsg, mem = j["ssg"], j["dsg"], j["device_bytes"]
print()
print(f"BVH build: SSG {ssg['triangles']} triangles {ssg['build_ms']:.1f} ms (binary tree of {ssg['nodes']} nodes, depth {ssg['depth']}, "
      f"SAH cost {ssg['sah_cost']:.1f}, collapsed into {ssg.get('wide_nodes', 0)} nodes {ssg.get('width', 0)} wide); DSG meshes {dsg['mesh_triangles']} triangles {dsg['mesh_build_ms']:.2f} ms; "
      f"TLAS over {dsg['instances']} instances {dsg['tlas_build_ms']:.3f} ms.")
print(f"Device memory: SSG {mem['ssg'] / 2**20:.2f} MiB, DSG meshes {mem['dsg_meshes'] / 2**20:.2f} MiB, "
      f"per frame {mem['per_frame'] / 1024:.1f} KiB.", end="")
if ref:
    e = j["embree"]
    print(f" Embree {e['version']}: build {e['build_ms']:.1f} ms, {e['bytes'] / 2**20:.2f} MiB.")
else:
    print()
print()
print("BVH width (children per node; `--bvh-width`, 8 is a CPU's default, 4 a GPU's), our Mrays/s:")
print()
print("| width | camera | shadow | bounce | SSG device MiB |")
print("|---:|---:|---:|---:|---:|")
for w, path in ((8, sys.argv[1]), (4, sys.argv[1].replace(".json", "-w4.json")),
                (2, sys.argv[1].replace(".json", "-w2.json"))):
    try:
        jw = json.load(open(path))
    except OSError:
        continue
    c = [jw["sets"][k]["ours_mrays"]["median"] for k in ("camera", "shadow", "bounce")]
    print(f"| {w} | {c[0]:.2f} | {c[1]:.2f} | {c[2]:.2f} | {jw['device_bytes']['ssg'] / 2**20:.2f} |")
EOF
  done
} >"$out"
echo "wrote $out" >&2
