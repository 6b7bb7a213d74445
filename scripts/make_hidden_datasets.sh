#!/usr/bin/env bash
# Regenerates the hidden-effect datasets of tests/app/diagnose/test_command.cpp with `pneufem synth`
# (full FEM, noise, controller overshoot, outlier frames). Small scene so the tests fit in CI;
# truth values chosen so each effect changes the angle well above the tracking noise on it.
# Usage: scripts/make_hidden_datasets.sh [path/to/pneufem]   (takes ~20 min on 2 cores)
set -euo pipefail
cd "$(dirname "$0")/.."
EXE=${1:-build/app/pneufem}
OUT=tests/data/hidden
mkdir -p "$OUT"
SCENE=(--set geometry.chambers=5 --set mesh.h_mm=6 --set load.max_kPa=30 --set load.step_kPa=10
       --set load.hold_s=4 --set load.trials=3)
RIG=(--pressure-rate 200 --angle-noise 0.05 --seed 7)
gen() {  # name hidden extra-sets...
  local name=$1 hidden=$2; shift 2
  echo "== $name"
  "$EXE" synth --hidden "$hidden" "${SCENE[@]}" "${RIG[@]}" "$@" --out "$OUT/$name.csv"
}
gen none none
gen stiffness stiffness
gen viscoelastic viscoelastic
# The same creep with the Yeoh constants as the instantaneous response (moduli = "instantaneous",
# Abaqus's default): the angle creeps beyond the elastic model's (test_effect_catalog.cpp).
gen viscoelastic_instantaneous viscoelastic_instantaneous
gen pressure_lag pressure_lag
gen gravity gravity
gen mullins mullins --set materials.silicone.mullins.m_MPa=0.001
gen fatigue fatigue --set materials.silicone.fatigue.W_th_MPa=0.008 --set materials.silicone.fatigue.tau_s=200.0 --set solver.max_iterations=30
# Two effects at once, as in the paper's recordings (creep in every hold, fatigue growing over the
# trials). W_th 4 kPa, not 8: the Prony term stiffens this actuator (peak 3.6 deg against 5.0) and
# lowers the wall energy, and at 8 kPa the fatigue moved the angle by < 0.07 deg in three trials.
gen viscoelastic_fatigue viscoelastic,fatigue --set materials.silicone.fatigue.W_th_MPa=0.004 --set materials.silicone.fatigue.tau_s=200.0 --set solver.max_iterations=30
# Fatigue without saturation (n = 1) beside a small instantaneous creep (gamma 0.1, tau 2 s): the
# saturating fatigue form stands in for the creep's rise in the first holds until the creep is in the
# model, then the joint re-fit prefers n = 1 (HiddenEffect.AFormPreferredInRoundOneIsSwappedWhenALaterEffectJoins).
gen viscoelastic_instantaneous_fatigue viscoelastic_instantaneous,fatigue --set "materials.silicone.viscoelastic.gamma=[0.1]" --set "materials.silicone.viscoelastic.tau_s=[2.0]" --set materials.silicone.fatigue.W_th_MPa=0.008 --set materials.silicone.fatigue.tau_s=200.0 --set solver.max_iterations=30
