#!/usr/bin/env bash
# Formatting as .clang-format says, over the C++ and OpenCL sources (Debian's clang-format).
#   tools/ci/format-check.sh         report files that differ; exit 1 if any
#   tools/ci/format-check.sh --fix   rewrite them in place
set -euo pipefail
cd "$(dirname "$0")/../.."
command -v clang-format >/dev/null || { echo "format-check: clang-format is not installed (apt-get install clang-format)" >&2; exit 1; }
# Tracked files and new ones not yet added (but not ignored ones), so a check before the
# first commit of a file sees it too.
mapfile -t files < <(git ls-files --cached --others --exclude-standard 'host/*.cpp' 'host/*.h' \
  'kernels/*.cl' 'kernels/*.h' 'tests/*.cpp' 'tests/*.h' 'tools/*.cpp' 'tools/fuzz/*.cpp')
if [ "${1:-}" = --fix ]; then
  clang-format -i "${files[@]}"
  exit 0
fi
bad=0
for f in "${files[@]}"; do
  if ! clang-format --dry-run -Werror "$f" >/dev/null 2>&1; then
    echo "format-check: $f differs from .clang-format (tools/ci/format-check.sh --fix rewrites it)"
    bad=1
  fi
done
[ $bad -eq 0 ] && echo "format-check: ${#files[@]} files formatted"
exit $bad
