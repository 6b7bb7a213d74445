#!/usr/bin/env bash
# The main job on built-in defaults: install packages, build, simulate the default pneu-net
# through the 0-45 kPa staircase, and write the run directory (default: out/default). It builds
# the pneufem executable alone, not the tests and benchmarks.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/build.sh pneufem  # only what it runs: the tests are built by ./scripts/run-tests.sh
OUT="${1:-out/default}"
./build/app/pneufem simulate --out "$OUT"
echo "Open $OUT/results.pvd in ParaView; bending angles are in $OUT/angles.csv"
