#!/usr/bin/env bash
# Installs packages, builds, and runs the whole test suite (GoogleTest via ctest).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/build.sh
cd build
ctest --output-on-failure --timeout 1500 -j "$(nproc)"
