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
  # The cross-platform tests (portability, coverage) compare every platform already: once is
  # enough. So do the tests whose subject is host code, a Python tool or a script, whose
  # kernels other tests run on both platforms: the kernel-build notice (a fresh build of every
  # kernel, 23 s on Intel's compiler), the evaluation tool's quick form, the Slurm chunks and the
  # kernels' conformance gate (clang's check, on no device); and the PoCL stack check, PoCL's
  # alone.
  skip=()
  [ "$device" = pocl ] || skip=(-E "PortabilityCli.EveryPlatformAgrees|AlphaCoveragePlatforms|Cli.KernelBuildsAreAnnouncedOnceAndTimedInTheFirstStatsLine|Evaluate.QuickFormWritesEveryOutputWithSaneNumbers|SlurmChunks.EqualOneProcess|KernelConformance|PoclStack")
  (cd build && PATHREUSE_TEST_DEVICE="$device" \
    ctest --output-on-failure -j"$(nproc)" --timeout 900 "${skip[@]}") || status=1
  # Each test skipped for want of a third-party scene says so once in ctest's log.
  skipped=$(grep -c '^third-party scene .* is not in .*; put ' build/Testing/Temporary/LastTest.log || true)
  [ "$skipped" -eq 0 ] || skips="${skips:+$skips, }$skipped on '$device'"
done
echo "== Oclgrind"
bash tools/ci/oclgrind-check.sh || status=1
if [ -n "${skips:-}" ]; then
  echo "test.sh: tests skipped for want of the third-party scenes ($skips): they are not in ${PATHREUSE_SCENES:-../shared/scenes}; put that folder beside the clone, or set PATHREUSE_SCENES to it, to run them"
fi
exit $status
