#!/usr/bin/env bash
# Installs the Debian packages that pathreuse's build, tests and PoCL need (python3-venv for
# tools/setup/intel-opencl.sh, the second platform of the tests, and for tools/setup/oidn.sh,
# Open Image Denoise, which it then installs; oclgrind for
# tools/ci/oclgrind-check.sh; clang-format for tools/ci/format-check.sh; clang for
# tools/ci/kernel-conformance.sh, the kernels' strict OpenCL C 1.2 gate; ccache, through which
# CMakeLists.txt compiles where it is present; Slurm and munge for tools/slurm/'s single-node
# test cluster; ffmpeg for --video, the demo's MP4).
# Idempotent: runs apt-get only when something is missing.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  ocl-icd-opencl-dev opencl-headers opencl-clhpp-headers pocl-opencl-icd
  libglm-dev libtinygltf-dev nlohmann-json3-dev libstb-dev
  libopenexr-dev libcli11-dev libgtest-dev zlib1g-dev libssl-dev
  assimp-testmodels python3
  python3-matplotlib python3-numpy
  python3-venv oclgrind clang-format clang ccache ffmpeg
  slurmctld slurmd slurm-client munge
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
else
  echo "install-deps: installing ${missing[*]}"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
# Open Image Denoise for --denoise, from PyPI into the user's cache (Debian 12 has none).
bash "$(dirname "$0")/oidn.sh" >/dev/null
