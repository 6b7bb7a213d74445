#!/usr/bin/env bash
# Installs packages, builds, and runs the whole test suite (GoogleTest via ctest), then the
# readers' tests under AddressSanitizer + UBSan and the fuzzers for a bounded time
# (scripts/run-sanitizers.sh, a few minutes). Either failing fails the script.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/build.sh
(cd build && ctest --output-on-failure --timeout 1500 -j "$(nproc)")
./scripts/run-sanitizers.sh
