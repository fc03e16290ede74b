#!/usr/bin/env bash
# Test (ctest SlurmChunks, so CI runs it): starts a single-node Slurm cluster in a temporary
# folder (tools/slurm/local-cluster.sh), renders the demo's frames in 3 chunks as a job array
# (tools/slurm/render-array.sbatch), renders them again in one process, checks that every frame
# is the same file bit for bit, and stops what it started. Prints both wall times.
#   tools/slurm/test-slurm.sh [BUILD_DIR] [FRAMES] [render options]   (default build, 0-11)
# $PATHREUSE_TEST_DEVICE, where set, is the --device of both.
set -euo pipefail
cd "$(dirname "$0")/../.."
build="$(cd "${1:-build}" && pwd)"
frames="${2:-0-11}"
shift $(($# > 2 ? 2 : $#))
# Without path resampling: chunks that run at the same time start its history afresh.
opts=(--width 64 --height 48 --spp 2 --no-resample)
[ $# -gt 0 ] && opts=("$@")
[ -n "${PATHREUSE_TEST_DEVICE:-}" ] && opts+=(--device "$PATHREUSE_TEST_DEVICE")
work="$(mktemp -d /tmp/pathreuse-slurm-XXXXXX)"
cleanup() {
  bash tools/slurm/local-cluster.sh stop "$work/cluster" || true
  [ -n "${PATHREUSE_KEEP_TEST_FILES:-}" ] || rm -rf "$work"
}
trap cleanup EXIT
eval "$(bash tools/slurm/local-cluster.sh start "$work/cluster")"
scene=scenes/cornell-dynamic.gltf

t0=$(date +%s.%N)
PATHREUSE_BIN="$build/pathreuse" timeout 600 sbatch --wait --quiet --array=0-2 \
  --output="$work/task-%a.log" tools/slurm/render-array.sbatch "$scene" "$frames" \
  "$work/chunked/frame_%04d.exr" --exr-float --quiet --stats "$work/chunked/stats-{task}.jsonl" \
  "${opts[@]}" || { cat "$work"/task-*.log >&2; echo "test-slurm: the job array failed" >&2; exit 1; }
t1=$(date +%s.%N)
"$build/pathreuse" render "$scene" --frames "$frames" --out "$work/single/frame_%04d.exr" \
  --stats "$work/single/stats.jsonl" \
  --exr-float --quiet "${opts[@]}"
t2=$(date +%s.%N)

expected=$(( ${frames#*-} - ${frames%-*} + 1 ))
status=0
n=$(find "$work/single" -name 'frame_*.exr' | wc -l)
[ "$n" = "$expected" ] || { echo "test-slurm: one process wrote $n frames, not $expected" >&2; status=1; }
for f in "$work"/single/frame_*.exr; do
  c="$work/chunked/$(basename "$f")"
  if [ ! -f "$c" ]; then
    echo "test-slurm: the job array did not write $(basename "$f")" >&2; status=1
  elif ! cmp -s "$f" "$c"; then
    echo "test-slurm: $(basename "$f") differs between the chunks and one process" >&2; status=1
  fi
done
grep -h "^task" "$work"/task-*.log
awk -v a="$t0" -v b="$t1" -v c="$t2" -v f="$frames" 'BEGIN { printf "frames %s in 3 chunks: %.2f s wall (submission to completion); one process: %.2f s\n", f, b - a, c - b }'
[ "$status" = 0 ] && echo "test-slurm: all $expected frames identical"
exit $status
