#!/usr/bin/env bash
# The kernels' conformance gate: every OpenCL program pathreuse builds, in every option variant
# (host/render/kernel_programs.cpp), expanded as the host expands it and checked by Debian's clang
# as strict OpenCL C 1.2 (-pedantic -Werror, the default OpenCL header), so that what NVIDIA's
# compiler refuses and PoCL's or Intel's accept fails here, without a GPU (docs/design.md
# section 7, "Portable kernels"). Each failure names the program, its options and the file and
# line of the first error.
# Usage: tools/ci/kernel-conformance.sh [BUILD_DIR]     every program (BUILD_DIR default build)
#        tools/ci/kernel-conformance.sh --files F.cl...  these files as they are (the gate's test)
set -euo pipefail
cd "$(dirname "$0")/../.."
clang=""
for c in clang clang-16 clang-15 clang-14; do
  if command -v "$c" >/dev/null; then clang=$c; break; fi
done
[ -n "$clang" ] || { echo "kernel-conformance: clang is not installed (tools/setup/install-deps.sh installs it)" >&2; exit 1; }
# Also clang's uninitialised-variable analysis: a private value left unset on some path is what
# one compiler forgives and another turns into wrong images (kernels/shared/bvh.h, PacketBlend).
flags=(-x cl -cl-std=CL1.2 -fsyntax-only -pedantic -Werror -ferror-limit=5 -Wuninitialized
  -Wsometimes-uninitialized -Wconditional-uninitialized)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# check LABEL FILE PATH_PREFIX OPTIONS...: 0 when clang accepts FILE.
check() {
  local label=$1 file=$2 prefix=$3
  shift 3
  if ! "$clang" "${flags[@]}" "$@" "$file" >"$work/log" 2>&1; then
    # The expanded programs' #line directives name files under kernels/.
    echo "kernel-conformance: $label: refused by strict OpenCL C 1.2 ($clang):"
    sed -E "s#^([A-Za-z0-9_./-]+\.(cl|h)):([0-9]+)#$prefix\1:\3#" "$work/log" | grep -E "error|note" | head -n 8 | sed 's/^/  /'
    return 1
  fi
}

fail=0
count=0
if [ "${1:-}" = --files ]; then
  shift
  for f in "$@"; do
    count=$((count + 1))
    check "$f" "$f" "" || fail=1
  done
else
  build="${1:-build}"
  [ -x "$build/kernel_programs" ] || { echo "kernel-conformance: $build/kernel_programs not built" >&2; exit 1; }
  "$build/kernel_programs" "$work/programs"
  while IFS=$'\t' read -r name src opts; do
    count=$((count + 1))
    # shellcheck disable=SC2086  # the options are words
    check "$src ${opts:-(no options)}" "$work/programs/$name" kernels/ $opts || fail=1
  done <"$work/programs/programs.tsv"
fi
if [ $fail -eq 0 ]; then
  echo "kernel-conformance: $count program(s), all strict OpenCL C 1.2 ($("$clang" --version | head -n 1))"
fi
exit $fail
