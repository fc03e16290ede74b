#!/usr/bin/env bash
# Installs what is missing, builds, and runs the default demo.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install-deps.sh
bash tools/build.sh
./build/pathreuse devices
