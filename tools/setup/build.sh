#!/usr/bin/env bash
# Configures and builds pathreuse into build/ (Release with debug info), using every core:
# every target (the tests too), or those $BUILD_TARGETS names (the demo: pathreuse alone).
set -euo pipefail
cd "$(dirname "$0")/../.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=RelWithDebInfo "$@" >/dev/null
# shellcheck disable=SC2086  # the names split into --target arguments
cmake --build build -j"$(nproc)" ${BUILD_TARGETS:+--target $BUILD_TARGETS}
