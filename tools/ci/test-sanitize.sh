#!/usr/bin/env bash
# Builds build-asan/ with AddressSanitizer and UndefinedBehaviorSanitizer (-DPATHREUSE_SANITIZE=ON)
# and runs the test suite there. Any report fails the test that triggers it: UBSan halts on the
# first error, ASan always does.
set -euo pipefail
cd "$(dirname "$0")/../.."
# -O1 -g1: quicker to compile than RelWithDebInfo, still line numbers in reports.
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=None -DCMAKE_CXX_FLAGS="-O1 -g1" -DCMAKE_C_FLAGS="-O1 -g1" \
  -DPATHREUSE_SANITIZE=ON -DPATHREUSE_TOOLS=OFF >/dev/null
cmake --build build-asan -j"$(nproc)"
# Leak checking is off: the OpenCL ICD loader and PoCL keep their allocations until exit.
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
cd build-asan
# PoCL only: the platforms are compared in tools/ci/test.sh (the portability and coverage tests),
# with the same host code. Left out here, and run in tools/ci/test.sh on both platforms:
# - the evaluation tool's quick form and the Slurm chunks, which run renders through Python and
#   a cluster whose host code the CLI tests cover here already (50 s);
# - the slowest statistical tests (over 10 s each), whose time is all in the kernels, with host
#   paths that quicker tests of the same options take here: the Resample, Reuse and material
#   tests at a few spp, resampling's error comparisons and the grazing-light prism (about 110 s
#   of the 2-core run).
# - denoising, whose time and memory are Open Image Denoise's, a library built without the
#   sanitizers (its missing-library error stays in);
# - the PoCL stack check, which measures the kernels' use of PoCL's thread stacks under a 1 MiB
#   `ulimit -s` that is no measure of sanitized host code.
skip="PortabilityCli.EveryPlatformAgrees|AlphaCoveragePlatforms"
skip+="|Evaluate.QuickFormWritesEveryOutputWithSaneNumbers"
skip+="|Denoise.TheColourIsDenoisedAndTheNoisyOneKept|PoclStack.ReuseRendersUnderAOneMiBStackLimit"
skip+="|SlurmChunks.EqualOneProcess|Environment.CoatedAndSpecularMaterialsAgreeInBothModes"
skip+="|MaterialFurnace.EveryClassAndRoughnessReflectsAllThatArrives|Resample.SlatsHideNeighboursPaths"
skip+="|Resample.WithReuseConvergesToThePathTracerRegionByRegion"
skip+="|Resample.ConvergesToThePathTracerRegionByRegion|Resample.WhiteFurnaceConvergesToLeOverOneMinusAlbedo"
skip+="|Reuse.ConvergesToThePathTracerOnCornellNvpro|Resample.DirectLightOfEveryKindConverges"
skip+="|Resample.NeighboursLowerTheError|Resample.HistoryLowersTheError"
skip+="|SmoothShadedPrism.AreaLightAtGrazingAnglesMatchesTheSmoothSurface"
ctest --output-on-failure -j"$(nproc)" --timeout 900 -E "$skip"
