#!/usr/bin/env bash
# Installs what is missing, checks the sources' formatting, builds, and runs the whole test
# suite with ctest on two OpenCL platforms: PoCL, then Intel's OpenCL CPU runtime
# (tools/setup/intel-opencl.sh sets it up). Every kernel then also runs once under Oclgrind's
# out-of-bounds and data-race checks.
set -euo pipefail
cd "$(dirname "$0")/../.."
bash tools/setup/install-deps.sh
status=0
bash tools/ci/format-check.sh || status=1
# No function over 120 lines, host or kernel (docs/design.md section 7).
python3 tools/ci/function_length.py || status=1
bash tools/setup/build.sh
OCL_ICD_VENDORS=$(bash tools/setup/intel-opencl.sh)
export OCL_ICD_VENDORS
# The portability test fails, rather than skips, when fewer platforms than this are found.
export PATHREUSE_REQUIRE_PLATFORMS="${PATHREUSE_REQUIRE_PLATFORMS:-2}"
for device in pocl "intel(r) opencl"; do
  echo "== test suite on OpenCL device '$device'"
  # The cross-platform portability test compares every platform already: once is enough. So
  # do the tests whose subject is host code, a Python tool or a script, whose kernels other
  # tests run on both platforms: the kernel-build notice (a fresh build of every kernel, 23 s on
  # Intel's compiler), the evaluation tool's quick form and the Slurm chunks.
  skip=()
  [ "$device" = pocl ] || skip=(-E "PortabilityCli.EveryPlatformAgrees|Cli.KernelBuildsAreAnnouncedOnceAndTimedInTheFirstStatsLine|Evaluate.QuickFormWritesEveryOutputWithSaneNumbers|SlurmChunks.EqualOneProcess")
  (cd build && PATHREUSE_TEST_DEVICE="$device" \
    ctest --output-on-failure -j"$(nproc)" --timeout 900 "${skip[@]}") || status=1
done
echo "== Oclgrind"
bash tools/ci/oclgrind-check.sh || status=1
exit $status
