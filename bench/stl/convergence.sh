#!/usr/bin/env bash
# Mesh convergence of the STL path against the built-in mesher (issue 33 item 3): the 2-chamber
# actuator at 5 kPa, one thread. The STL is the built-in geometry's own surface, written by the
# test helper tests/scenes/stl/test_shapes.h (run test_stl_scene once: it leaves
# $TMPDIR/pneufem_test_stl_scene/two_chambers_uniform.stl). Usage:
#   bench/stl/convergence.sh PNEUFEM STL OUTDIR "h1 h2 ..." [builtin|uniform|uniform0]...
# prints one line per run: kind, h, nodes, elements, angle at 5 kPa (deg), wall time (s).
set -euo pipefail
exe=$1 stl=$2 out=$3 hs=$4
shift 4
P=(--set load.max_kPa=5.0 --set load.trials=1 --set load.output_every_s=0.0 --set geometry.chambers=2 --threads 1)
mkdir -p "$out"
for kind in "$@"; do
  for h in $hs; do
    dir=$out/$kind-h$h
    case $kind in
      builtin)  extra=() ;;
      uniform)  extra=(--set mesh.source=\"stl\" --set mesh.file=\"$stl\" --set mesh.feature_planes=false --set mesh.wall_cells=2) ;;
      uniform0) extra=(--set mesh.source=\"stl\" --set mesh.file=\"$stl\" --set mesh.feature_planes=false --set mesh.wall_cells=0) ;;
    esac
    t0=$(date +%s.%N)
    "$exe" simulate --out "$dir" --set mesh.h_mm=$h "${P[@]}" "${extra[@]}" > "$dir.log" 2>&1
    t1=$(date +%s.%N)
    angle=$(awk -F, '$3 == "5.000000" {a = $4} END {print a}' "$dir/angles.csv")
    size=$(/usr/bin/python3 -c "import json,sys; s=json.load(open('$dir/summary.json')); m=s.get('mesh', {}); print(m.get('nodes','?'), m.get('elements','?'))")
    echo "$kind h=$h nodes/elements=$size angle=$angle wall=$(echo "$t1 - $t0" | bc)"
  done
done
