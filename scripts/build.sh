#!/usr/bin/env bash
# Configures and builds pneufem (Release) into ./build: every target (the executable, the tests,
# the benchmarks), or only the targets given, e.g. `./scripts/build.sh pneufem` (the main job's).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build build --parallel "$(nproc)" "${targets[@]}"
