#!/bin/bash
# Recordings made without pneufem (CalculiX's static curve of a gmsh deck + phenomenological hidden
# effects, make_recordings.py), diagnosed by pneufem with the deck's scene. Needs Debian's
# python3-numpy; writes the recordings here and the diagnoses under runs/.
# usage: run.sh [PNEUFEM] (default build/app/pneufem of this checkout)
set -euo pipefail
HERE="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
ROOT="$(cd "$HERE/../../.." && pwd)"
PNEUFEM="${1:-$ROOT/build/app/pneufem}"
cd "$HERE"
for e in none stiffness lag creep softening wear; do
  /usr/bin/python3 make_recordings.py --elastic "$ROOT/tests/data/ccx_gmsh/ccx_angles.csv" \
    --stiff ccx_angles_stiff125.csv --effect "$e" --out "$e.csv"
  rm -f "$e.truth.csv"  # 250 kB each; the generator re-makes it
done
mkdir -p runs
for e in none stiffness lag creep softening wear; do
  /usr/bin/time -f "%e s wall, %M kB" "$PNEUFEM" diagnose "$ROOT/tests/data/ccx_gmsh/scene.toml" --data "$e.csv" \
    --out "runs/$e" --threads 2 > "runs/$e.log" 2>&1 || echo "$e: exit $?" >> runs/failures.txt
done
