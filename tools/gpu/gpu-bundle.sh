#!/usr/bin/env bash
# Packs what tools/gpu/gpu-check.sh needs on a machine with a GPU but no package registry: the
# built programs (stripped), the shared libraries they load except the C library (from ldd),
# the portability suite's reference frames rendered here, on the CPU, and ../shared/scenes.
# Usage: tools/gpu/gpu-bundle.sh DIR [--device SPEC]   (after tools/setup/build.sh; SPEC default pocl)
#   e.g. GPU_BUNDLE_SCENES="cornell-nvpro BoxAnimated invalid FlightHelmet" for the tests and the
#   asset step, packed with tar cJf to fit one call.
set -euo pipefail
cd "$(dirname "$0")/../.."
dir="${1:?usage: tools/gpu/gpu-bundle.sh DIR [--device SPEC]}"
device=pocl
[ "${2:-}" = --device ] && device="${3:?--device needs a SPEC}"
rm -rf "$dir"
mkdir -p "$dir/bin" "$dir/lib" "$dir/libstdcxx"
progs=(build/pathreuse build/exr_compare build/*_test)
# The ray benchmark picks the GPU's BVH layout; linked with Embree (44 MB) it would not fit a
# carry, so it comes only from a build configured with -DCMAKE_DISABLE_FIND_PACKAGE_embree=ON.
if [ -x build/ray_bench ] && ! ldd build/ray_bench | grep -q embree; then
  progs+=(build/ray_bench)
elif [ -x build/ray_bench ]; then
  echo "gpu-bundle: build/ray_bench links Embree; left out (reconfigure with -DCMAKE_DISABLE_FIND_PACKAGE_embree=ON to carry it)" >&2
fi
for p in "${progs[@]}"; do
  [ -x "$p" ] || continue
  strip -o "$dir/bin/$(basename "$p")" "$p"
done
# Every library but glibc's own; libstdc++ and libgcc_s apart, used only where the machine's are
# older than the build's (gpu-check.sh decides).
ldd "${progs[@]}" 2>/dev/null | awk '$3 ~ /^\// {print $3}' | sort -u | while read -r lib; do
  case "$(basename "$lib")" in
    libc.so.*|libm.so.*|libpthread.so.*|libdl.so.*|librt.so.*|ld-linux*) ;;
    libstdc++.so.*|libgcc_s.so.*) cp -L "$lib" "$dir/libstdcxx/" ;;
    *) cp -L "$lib" "$dir/lib/" ;;
  esac
done
build/pathreuse portability --quiet --device "$device" --save-reference "$dir/reference" \
  --out "$dir/reference-worst" >/dev/null
rm -rf "$dir/reference-worst"
pwd >"$dir/source_dir"  # where the tests look for the binary and the sources
# The third-party test scenes (../shared/scenes), when they are beside the checkout: all, or the
# folders GPU_BUNDLE_SCENES names (a device call carries 64 MiB at most).
if [ -d ../shared/scenes ]; then
  mkdir -p "$dir/shared-scenes"
  for s in ${GPU_BUNDLE_SCENES:-$(ls ../shared/scenes)}; do cp -r "../shared/scenes/$s" "$dir/shared-scenes/"; done
fi
du -sh "$dir"
