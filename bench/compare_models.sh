#!/usr/bin/env bash
# `pneufem compare` of one recording with the full FEM and with the reduced-order model, side by
# side in one run (the machine is noisy: the ratio holds, absolute times do not). Runs each model
# REPEATS times, alternating, after one untimed reduced run that fills the offline cache (so the
# reduced times are warm; the cold offline part is printed from that run's metrics.json).
#
#   bench/compare_models.sh [PNEUFEM] [REPEATS]
#
# Recording: tests/data/hidden/fatigue.csv (5-chamber actuator, h = 6 mm, three trials of a
# 0-30 kPa staircase, fatigue hidden), compared against the scene that made it.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
exe="${1:-$here/build/app/pneufem}"
repeats="${2:-3}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
scene=(--set geometry.chambers=5 --set mesh.h_mm=6 --set load.max_kPa=30 --set load.step_kPa=10 --set load.hold_s=4
       --set load.trials=3 --set materials.silicone.fatigue.enabled=true --set materials.silicone.fatigue.W_th_MPa=0.008
       --set materials.silicone.fatigue.tau_s=200 --set solver.reduced_check_deg=10)
data="$here/tests/data/hidden/fatigue.csv"
run() {  # model, output dir -> wall seconds
  local t0 t1
  t0=$(date +%s.%N)
  "$exe" compare --data "$data" "${scene[@]}" --model "$1" --cache "$work/cache" --out "$2" --threads 2 >/dev/null 2>&1
  t1=$(date +%s.%N)
  echo "$t1 - $t0" | bc
}
cold=$(run reduced "$work/cold")
offline=$(grep -o '"reduced_offline_s": [0-9.e+-]*' "$work/cold/metrics.json" | awk '{print $2}')
echo "cold reduced run: ${cold} s wall, offline part ${offline} s"
full_sum=0
reduced_sum=0
for i in $(seq "$repeats"); do
  f=$(run full "$work/full_$i")
  r=$(run reduced "$work/reduced_$i")
  echo "repeat $i: full ${f} s, reduced ${r} s"
  full_sum=$(echo "$full_sum + $f" | bc)
  reduced_sum=$(echo "$reduced_sum + $r" | bc)
done
echo "mean: full $(echo "scale=2; $full_sum / $repeats" | bc) s, reduced $(echo "scale=2; $reduced_sum / $repeats" | bc) s," \
     "ratio $(echo "scale=2; $full_sum / $reduced_sum" | bc)"
