#!/usr/bin/env bash
# Sets up a second OpenCL platform beside PoCL: Intel's OpenCL CPU runtime, from PyPI, in a
# virtual environment under the user's cache, plus an ICD folder that lists it and every
# system ICD. Idempotent. Prints the ICD folder; use it as
#   export OCL_ICD_VENDORS=$(bash tools/setup/intel-opencl.sh)
# Intel's wheel ships an ICD file naming a path that does not exist, hence our own. Its lib/
# must not go on LD_LIBRARY_PATH: the libOpenCL.so.1 there would shadow Debian's ICD loader.
set -euo pipefail

version=2026.2.0
root="${PATHREUSE_OPENCL_HOME:-${XDG_CACHE_HOME:-$HOME/.cache}/pathreuse}"
venv="$root/intel-opencl-$version"
icd="$root/opencl-vendors"
lib="$venv/lib/libintelocl.so"

if [ ! -f "$lib" ]; then
  echo "intel-opencl: installing intel-opencl-rt $version into $venv" >&2
  rm -rf "$venv"
  python3 -m venv "$venv" >&2 || {
    echo "intel-opencl: python3 -m venv failed (Debian: apt-get install python3-venv)" >&2
    exit 1
  }
  "$venv/bin/pip" install --quiet --disable-pip-version-check \
    "intel-opencl-rt==$version" "intel-cmplr-lib-rt==$version" >&2
  [ -f "$lib" ] || { echo "intel-opencl: $lib missing after install" >&2; exit 1; }
fi

mkdir -p "$icd"
printf '%s\n' "$lib" > "$icd/intel-cpu.icd.tmp" && mv "$icd/intel-cpu.icd.tmp" "$icd/intel-cpu.icd"
# OCL_ICD_VENDORS replaces the system folder: copy its entries so PoCL (and any GPU) stay listed.
for f in /etc/OpenCL/vendors/*.icd; do
  [ -f "$f" ] && cp -f "$f" "$icd/"
done
echo "$icd"
