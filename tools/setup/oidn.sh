#!/usr/bin/env bash
# Installs Intel Open Image Denoise (for `pathreuse render --denoise`) from PyPI's pyoidn wheel,
# which carries the OIDN libraries, into a virtual environment under the user's cache; Debian 12
# packages none. Idempotent. Prints the folder of libOpenImageDenoise.so.2, where the renderer
# looks by default (PATHREUSE_OIDN names another library file). The renderer loads it at run
# time and builds and runs without it.
set -euo pipefail

version=2.5.1.0
root="${PATHREUSE_OPENCL_HOME:-${XDG_CACHE_HOME:-$HOME/.cache}/pathreuse}"
venv="$root/oidn-$version"
link="$root/oidn"

lib=$(ls "$venv"/lib/python3*/site-packages/pyoidn/oidn/lib/libOpenImageDenoise.so.2 2>/dev/null | head -n 1 || true)
if [ -z "$lib" ]; then
  echo "oidn: installing pyoidn $version (Open Image Denoise) into $venv" >&2
  rm -rf "$venv"
  python3 -m venv "$venv" >&2 || {
    echo "oidn: python3 -m venv failed (Debian: apt-get install python3-venv)" >&2
    exit 1
  }
  # The libraries alone: the wheel's Python bindings and their dependencies are not used.
  "$venv/bin/pip" install --quiet --disable-pip-version-check --no-deps "pyoidn==$version" >&2
  lib=$(ls "$venv"/lib/python3*/site-packages/pyoidn/oidn/lib/libOpenImageDenoise.so.2 2>/dev/null | head -n 1 || true)
  [ -n "$lib" ] || { echo "oidn: libOpenImageDenoise.so.2 missing after install" >&2; exit 1; }
fi
ln -sfn "$(dirname "$lib")" "$link.tmp" && mv -T "$link.tmp" "$link"
echo "$link"
