#!/usr/bin/env bash
# `pneufem sweep --scheduler slurm` against a real SLURM (slurmctld + slurmd + munged of Debian's
# slurm-wlm and munge, started here on localhost in a temporary directory and stopped after:
# slurm_cluster.sh). A tiny scene, four points, one at a time (--max-parallel 1):
#   --dry-run prints the array script and submits nothing;
#   the first call submits one array of the four points; point 1 (tau_s < 0) fails on purpose and
#   task 4 is cancelled (scancel) while it waits;
#   a call while a job is queued (held) resubmits nothing of it;
#   the next call collects points 2 and 3, reports 1 (its error) and 4 (cancelled) and resubmits
#   exactly those two, leaving 2 and 3 untouched;
#   the last call collects point 4, resubmits only the failing point 1, writes the table, plots and
#   sweep.json, and every finished point equals the same point of a local --jobs sweep;
#   a local sweep of the directory is refused while a job has its points queued;
#   a reduced sweep submits the point that builds the offline part first and the others after it.
# Usage: test_slurm.sh PNEUFEM_BINARY. Exit 77 (ctest: skipped) only when SLURM is not installed.
set -uo pipefail
PNEUFEM="$1"
HERE="$(cd "$(dirname "$0")" && pwd)"
source "$HERE/slurm_cluster.sh"
if ! slurm_cluster_available; then
  echo "SKIPPED: SLURM is not installed (munged, slurmctld, slurmd, sbatch, squeue, scancel); scripts/install-deps.sh installs slurm-wlm and munge"
  exit 77
fi

T="$(mktemp -d "${TMPDIR:-/tmp}/pneufem_slurm.XXXXXX")"
fail() {
  echo "FAIL: $*"
  echo "---- last output:"; cat "$T/out" 2>/dev/null
  echo "---- slurmctld log:"; tail -20 "$T/cluster/log/slurmctld.log" 2>/dev/null
  exit 1
}
cleanup() { slurm_cluster_stop "$T/cluster"; rm -rf "$T"; }
trap cleanup EXIT
slurm_cluster_start "$T/cluster" || fail "the local SLURM cluster did not start"

D="$T/sweep"
TINY=(--set geometry.chambers=2 --set mesh.h_mm=6.0 --set load.max_kPa=10.0 --set load.trials=2
      --set materials.silicone.fatigue.enabled=true --set materials.silicone.fatigue.W_th_MPa=0.002)
TAU=materials.silicone.fatigue.tau_s
# tau_s = -200 (point 1) is refused by the fatigue law; 200, 600 and 1000 run (~2 s each).
SWEEP=(sweep --param "$TAU=-200:1000:4" "${TINY[@]}" --model full --threads-per-job 1)
sweep_slurm() { "$PNEUFEM" "${SWEEP[@]}" --scheduler slurm --max-parallel 1 --time 10 --out "$D" "$@" > "$T/out" 2>&1; }
# Waits until SLURM has no task of job $1 left (queued or running).
wait_job() {
  local i
  for i in $(seq 1 240); do
    [ -z "$(squeue --noheader --array --jobs="$1" --format=%i 2>/dev/null)" ] && return 0
    sleep 0.5
  done
  fail "job $1 did not finish in 120 s"
}
last_job() { tail -1 "$D/slurm/jobs.tsv" | cut -f1; }
last_points() { tail -1 "$D/slurm/jobs.tsv" | cut -f2; }
row() { grep "^$1," "$D/sweep.csv"; }

# --dry-run: the script, nothing submitted or written.
sweep_slurm --dry-run || fail "--dry-run exited $?"
grep -q '^#SBATCH --array=1-4%1$' "$T/out" || fail "--dry-run: no '#SBATCH --array=1-4%1'"
grep -q '^#SBATCH --time=10$' "$T/out" || fail "--dry-run: no '#SBATCH --time=10'"
grep -q '^  3) values=(.600.0.) ;;$' "$T/out" || fail "--dry-run: point 3's values"
grep -q 'exec .*simulate' "$T/out" || fail "--dry-run: no simulate command"
[ ! -e "$D" ] || fail "--dry-run wrote $D"
[ -z "$(squeue --noheader --format=%i)" ] || fail "--dry-run submitted a job"

# First call: one array of the four points; task 4 is cancelled while it waits its turn.
sweep_slurm || fail "the submitting call exited $?"
grep -q "submitted job .*: array 1-4%1 (4 point(s))" "$T/out" || fail "not one array of the 4 points"
J1=$(last_job)
[ "$(last_points)" = "1,2,3,4" ] || fail "jobs.tsv: $(last_points)"
scancel "${J1}_4" || fail "scancel ${J1}_4"
wait_job "$J1"

# Second call: 2 and 3 collected; 1 (failed) and 4 (cancelled) resubmitted, and nothing else.
sweep_slurm; code=$?
[ $code -eq 1 ] || fail "the collecting call exited $code (1: some point failed)"
grep -q "4 points, 2 ok, 2 failed" "$T/out" || fail "collection: not 2 ok, 2 failed"
grep -q "point 0001 $TAU=-200.0: failed: .*tau must be > 0" "$T/out" || fail "point 1's error is not reported"
grep -q "point 0004 $TAU=1000.0: failed: no result: the task ${J1}_4 ended without finishing (cancelled" "$T/out" ||
  fail "the cancelled point 4 is not reported"
J2=$(last_job)
[ "$J2" != "$J1" ] || fail "nothing resubmitted"
[ "$(last_points)" = "1,4" ] || fail "resubmitted $(last_points), not exactly 1,4"
grep -q '^#SBATCH --array=1,4%1$' "$D/slurm/array_2.sh" || fail "array_2.sh is not the array 1,4"
[ "$(row 2 | cut -d, -f3)" = ok ] && [ "$(row 3 | cut -d, -f3)" = ok ] || fail "sweep.csv: points 2 and 3 are not ok"
m2=$(stat -c %Y.%y "$D/points/0002/summary.json"); m3=$(stat -c %Y.%y "$D/points/0003/summary.json")

# A call while the job waits (held): its points are queued, nothing is submitted again.
scontrol hold "$J2" >/dev/null 2>&1 || fail "scontrol hold $J2"
sweep_slurm
grep -q "2 point(s) still queued or running" "$T/out" || fail "the held points are not seen as queued"
grep -q "submitted job" "$T/out" && fail "a call resubmitted points that were queued"
[ "$(last_job)" = "$J2" ] || fail "jobs.tsv grew while the job was queued"
# Nor does a local sweep of the directory run them under the queued job.
"$PNEUFEM" "${SWEEP[@]}" --jobs 2 --out "$D" > "$T/out" 2>&1; code=$?
[ $code -eq 2 ] || fail "a local sweep beside the queued job exited $code (2: refused)"
grep -q "2 point(s) of this sweep are queued or running on SLURM" "$T/out" || fail "the local sweep's refusal"
scontrol release "$J2" >/dev/null 2>&1 || fail "scontrol release $J2"
wait_job "$J2"

# Third call: 4 collected; only the failing point 1 is resubmitted; outputs written.
sweep_slurm; code=$?
[ $code -eq 1 ] || fail "the third call exited $code"
grep -q "4 points, 3 ok, 1 failed" "$T/out" || fail "third call: not 3 ok, 1 failed"
[ "$(last_points)" = "1" ] || fail "third call resubmitted $(last_points), not exactly 1"
[ "$(stat -c %Y.%y "$D/points/0002/summary.json")" = "$m2" ] || fail "point 2 ran again"
[ "$(stat -c %Y.%y "$D/points/0003/summary.json")" = "$m3" ] || fail "point 3 ran again"
[ "$(row 4 | cut -d, -f3)" = ok ] || fail "sweep.csv: point 4 is not ok"
grep -q '"scheduler": "slurm"' "$D/sweep.json" || fail "sweep.json does not record the scheduler"
grep -q '"ok": 3' "$D/sweep.json" || fail "sweep.json: not 3 ok"
grep -q '</svg>' "$D/sweep_$TAU.svg" || fail "no plot"
wait_job "$(last_job)"

# The same points run locally (--jobs) give the same metrics (the task is the local worker's run).
"$PNEUFEM" "${SWEEP[@]}" --jobs 2 --out "$T/local" > "$T/out" 2>&1
for p in 2 3 4; do
  slurm_row=$(row $p | cut -d, -f1-4,6-)   # all but wall_s
  local_row=$(grep "^$p," "$T/local/sweep.csv" | cut -d, -f1-4,6-)
  [ "$slurm_row" = "$local_row" ] || fail "point $p: SLURM '$slurm_row' != local '$local_row'"
done
# A reduced sweep: the point that builds the offline part runs first, the others as a second array
# that starts after it (--dependency=afterany) and read rom_cache/.
R="$T/reduced"
"$PNEUFEM" sweep --param "$TAU=100:1000:3:log" "${TINY[@]}" --model reduced --scheduler slurm --out "$R" > "$T/out" 2>&1 ||
  fail "the reduced sweep's submission exited $?"
RJ1=$(sed -n 2p "$R/slurm/jobs.tsv" | cut -f1)
[ "$(sed -n 2p "$R/slurm/jobs.tsv" | cut -f2)" = "1" ] || fail "the reduced sweep's first array is not point 1"
[ "$(sed -n 3p "$R/slurm/jobs.tsv" | cut -f2)" = "2,3" ] || fail "the reduced sweep's second array is not points 2,3"
grep -q "^#SBATCH --dependency=afterany:$RJ1\$" "$R/slurm/array_2.sh" || fail "the second array does not start after $RJ1"
wait_job "$RJ1"; wait_job "$(sed -n 3p "$R/slurm/jobs.tsv" | cut -f1)"
"$PNEUFEM" sweep --param "$TAU=100:1000:3:log" "${TINY[@]}" --model reduced --scheduler slurm --out "$R" > "$T/out" 2>&1 ||
  fail "the reduced sweep's collection exited $?"
grep -q "3 points, 3 ok, 0 failed, 0 queued or running" "$T/out" || fail "the reduced sweep: not 3 ok"
grep -q "submitted" "$T/out" && fail "the finished reduced sweep submitted again"
grep -q '"basis": "computed"' "$R/points/0001/summary.json" || fail "point 1 did not build the basis"
for p in 0002 0003; do
  grep -q "\"basis\": \"cache $R/rom_cache" "$R/points/$p/summary.json" || fail "point $p did not read the basis from rom_cache"
done

echo "PASS: dry run, one array, failed and cancelled points resubmitted exactly, queued points left alone (also by a local sweep), outputs equal to a local sweep, reduced builders first"
