#!/usr/bin/env bash
# Recordings made on a finer mesh (h = 4) than the model's (h = 6): the 5-chamber test actuator of
# tests/data/hidden with the same protocol and rig (seed 7), one hidden effect each, then diagnosed
# with all candidates on the h = 6 scene (BENCHMARKS.md §8, "A static-misfit test in the selection").
# Usage: run.sh PNEUFEM OUTDIR   (synth ~1-4 min per recording, diagnose ~1-3 min, one thread each)
set -euo pipefail
EXE=$1; OUT=$2; mkdir -p "$OUT"; cd "$OUT"
SCENE=(--set geometry.chambers=5 --set load.max_kPa=30 --set load.step_kPa=10 --set load.hold_s=4 --set load.trials=3)
RIG=(--pressure-rate 200 --angle-noise 0.05 --seed 7)
gen() { local name=$1 hidden=$2; shift 2
  [ -f "$name.csv" ] || "$EXE" synth --hidden "$hidden" "${SCENE[@]}" "${RIG[@]}" --set mesh.h_mm=4 --threads 1 "$@" --out "$name.csv"; }
gen none none
gen stiffness stiffness
gen viscoelastic viscoelastic
gen mullins mullins --set materials.silicone.mullins.m_MPa=0.001
gen fatigue fatigue --set materials.silicone.fatigue.W_th_MPa=0.008 --set materials.silicone.fatigue.tau_s=200.0 --set solver.max_iterations=30
for e in none stiffness viscoelastic mullins fatigue; do
  "$EXE" diagnose --data "$e.csv" --out "diag_$e" "${SCENE[@]}" --set mesh.h_mm=6 --threads 1 > "diag_$e.log" 2>&1
done
