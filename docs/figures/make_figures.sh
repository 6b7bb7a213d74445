#!/usr/bin/env bash
# Regenerates the figures of the user guide (docs/user_guide.md) and the README by running its
# tutorial on the small actuator of the test recordings: ParaView's views of the first simulation
# (when pvbatch is installed), a compare of the hidden-creep recording,
# a diagnose, and a compare of the fitted scene; and the Yeoh fit of the Ecoflex 00-50 tensile curve;
# and the verification manual's (docs/verification.md): the Ogden-3 fit of Treloar's data, the
# gmsh deck against CalculiX, the default actuator against CalculiX, and eight made from the lines
# their tests print (the cylinder's convergence, the creep block, the derivative battery's step,
# Mullins, fatigue's order, the explicit integrator's energy, the pressure lag, cycle jumping's rules). About 7 min on 2 cores (the diagnose about 5 of them). Needs the test
# executables test_solvers, test_creep, test_materials, test_damage, test_scales_lag and test_cycle_jump
# built beside pneufem (build/tests/...).
# Usage: docs/figures/make_figures.sh [path/to/pneufem]   (run from anywhere; writes out/tutorial)
set -euo pipefail
cd "$(dirname "$0")/../.."
EXE=${1:-build/app/pneufem}
TESTS=$(dirname "$EXE")/../tests
RUN=out/tutorial
DATA=tests/data/hidden/viscoelastic.csv
rm -rf "$RUN"
"$EXE" simulate scenes/examples/small_actuator.toml --out "$RUN/first"
if command -v pvbatch > /dev/null; then  # ParaView's standard views (scripts/install-paraview.sh)
  pvbatch viz/paraview/open_run.py "$RUN/first"
  cp "$RUN/first/views.png" docs/figures/tutorial_paraview_views.png
else
  echo "pvbatch not found: docs/figures/tutorial_paraview_views.png kept (scripts/install-paraview.sh)"
fi
"$EXE" compare scenes/examples/small_actuator.toml --data "$DATA" --out "$RUN/study"
cp "$RUN/study/fig_trial_1.svg" docs/figures/tutorial_compare_trial_1.svg
cp "$RUN/study/fig_trial_1.csv" docs/figures/tutorial_compare_trial_1.csv
"$EXE" diagnose scenes/examples/small_actuator.toml --data "$DATA" --out "$RUN/diagnosis"
"$EXE" compare "$RUN/diagnosis/fitted.toml" --data "$DATA" --out "$RUN/study"
cp "$RUN/study/fig_trial_1.svg" docs/figures/tutorial_fitted_trial_1.svg
cp "$RUN/study/fig_trial_1.csv" docs/figures/tutorial_fitted_trial_1.csv
cp "$RUN/study/fig_history.svg" docs/figures/tutorial_history.svg
cp "$RUN/study/fig_history.csv" docs/figures/tutorial_history.csv
"$EXE" fit-material uniaxial:tests/data/soro-materials-db/ecoflex_00-50.csv --max-strain 2 --out "$RUN/material"
cp "$RUN/material/fit.svg" docs/figures/fit_material_ecoflex.svg
cp "$RUN/material/fit.csv" docs/figures/fit_material_ecoflex.csv
# The verification manual's figure of TreloarOgden3: Treloar's three modes (tests/data/treloar1944,
# stretch and nominal stress in MPa) and the Ogden-3 fit of all three at once.
mkdir -p "$RUN/treloar"
for mode in uniaxial equibiaxial pureshear; do
  awk 'BEGIN { print "stretch,stress_MPa" } NF == 2 { print $1 "," $2 }' "tests/data/treloar1944/treloar_$mode.dat" > "$RUN/treloar/$mode.csv"
done
"$EXE" fit-material uniaxial:"$RUN/treloar/uniaxial.csv" biaxial:"$RUN/treloar/equibiaxial.csv" \
  planar:"$RUN/treloar/pureshear.csv" --model ogden3 --out "$RUN/treloar/fit"
cp "$RUN/treloar/fit/fit.svg" docs/figures/verification_treloar_ogden3.svg
cp "$RUN/treloar/fit/fit.csv" docs/figures/verification_treloar_ogden3.csv
# ... and of CalculixReference: the gmsh deck of tests/data/ccx_gmsh bent by pneufem against CalculiX.
"$EXE" simulate tests/data/ccx_gmsh/scene.toml --out "$RUN/ccx_gmsh"
/usr/bin/python3 docs/figures/calculix_gmsh.py "$RUN/ccx_gmsh/angles.csv" docs/figures/verification_calculix_gmsh.svg
# ... the default actuator on its own mesh against CalculiX (bench/results/ccx_h4, ccx_h2: committed);
# and eight tests' own series: CylinderInflation.ObservedConvergenceOrderOfTet10 (~2 s), the creep
# block in both moduli conventions, MaterialBattery.TangentDifferenceErrorIsAVInTheStep, Mullins against
# the 1-D Ogden-Roxburgh curve, fatigue's order of convergence, the explicit integrator's energy, the
# second-order pressure lag and cycle jumping's two rules (each < 1 s).
FIG=docs/figures/verification_figures.py
/usr/bin/python3 $FIG calculix docs/figures/verification_calculix_default.svg
"$TESTS/engine/test_solvers" --gtest_filter=CylinderInflation.ObservedConvergenceOrderOfTet10 > "$RUN/cylinder.txt"
/usr/bin/python3 $FIG cylinder "$RUN/cylinder.txt" docs/figures/verification_cylinder_convergence.svg
"$TESTS/engine/test_creep" --gtest_filter='Creep.HomogeneousBlock*:Creep.InstantaneousModuli*' > "$RUN/creep.txt"
/usr/bin/python3 $FIG creep "$RUN/creep.txt" docs/figures/verification_creep_sls.svg
"$TESTS/materials/test_materials" --gtest_filter='*TangentDifferenceErrorIsAVInTheStep*' > "$RUN/derivative.txt"
/usr/bin/python3 $FIG derivative "$RUN/derivative.txt" docs/figures/verification_derivative_step.svg
"$TESTS/damage/test_damage" --gtest_filter='Mullins.UniaxialLoadUnloadReload*:Fatigue.ConstantDriverMatches*:Fatigue.SaturatingLawSolves*' > "$RUN/damage.txt"
/usr/bin/python3 $FIG mullins "$RUN/damage.txt" docs/figures/verification_mullins_or1d.svg
/usr/bin/python3 $FIG fatigue "$RUN/damage.txt" docs/figures/verification_fatigue_order.svg
"$TESTS/engine/test_solvers" --gtest_filter=Explicit.UndampedFreeVibrationConservesEnergyWithoutDrift > "$RUN/energy.txt"
/usr/bin/python3 $FIG energy "$RUN/energy.txt" docs/figures/verification_explicit_energy.svg
"$TESTS/scenes/test_scales_lag" --gtest_filter=PressureLag2.BreakpointsMeetTheToleranceWithoutWaste > "$RUN/lag.txt"
/usr/bin/python3 $FIG lag "$RUN/lag.txt" docs/figures/verification_pressure_lag.svg
"$TESTS/engine/test_cycle_jump" --gtest_filter=CycleJump.ThreePointRuleBeatsTheLinearOneForGeometricIncrements > "$RUN/jump.txt"
/usr/bin/python3 $FIG jump "$RUN/jump.txt" docs/figures/verification_cycle_jump_rules.svg
echo "figures written to docs/figures (runs in $RUN)"
