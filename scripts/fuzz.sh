#!/usr/bin/env bash
# Runs the libFuzzer targets of fuzz/ (a build configured with -DPNEUFEM_FUZZ=ON, e.g. by
# scripts/run-sanitizers.sh) over their seed corpus in fuzz/corpus/<target>/ and then on new inputs
# for a bounded time each, as many at a time as there are cores.
#
#   scripts/fuzz.sh BUILD_DIR SECONDS [TARGET...]     # TARGET: inp scene measurements deeplabcut (default: all)
#
# New inputs that reach new code are kept in BUILD_DIR/fuzz_work/<target>/ (so a later run starts
# from them; the seed corpus in the repository is only read); a finding is written to
# BUILD_DIR/fuzz_work/artifacts/<target>-crash-<sha1> (or -leak-, -timeout-, -oom-) and makes this
# script fail. Reproduce one with: BUILD_DIR/fuzz/fuzz_<target> <artifact>. Each input may take 10 s
# and 2 GiB; more is a finding (a hang or a reader that allocates without bound).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ $# -lt 2 ]; then
  echo "usage: scripts/fuzz.sh BUILD_DIR SECONDS [TARGET...]" >&2
  exit 2
fi
build=$1
seconds=$2
shift 2
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(inp scene measurements deeplabcut)
work="$build/fuzz_work"
mkdir -p "$work/artifacts" "$work/tmp"
# fuzz_inp's deck files go here, not to the shared /tmp.
case "$work" in /*) export TMPDIR="$work/tmp" ;; *) export TMPDIR="$PWD/$work/tmp" ;; esac
jobs=$(nproc)

run_one() {
  local t=$1 exe="$build/fuzz/fuzz_$1"
  [ -x "$exe" ] || { echo "fuzz: $exe not built (configure with -DPNEUFEM_FUZZ=ON)"; return 2; }
  mkdir -p "$work/$t"
  local dict=()
  [ -f "fuzz/$t.dict" ] && dict=(-dict="fuzz/$t.dict")
  # stdin from /dev/null: a deck that *INCLUDEs /dev/stdin must not wait for a terminal.
  "$exe" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 "${dict[@]}" \
    -artifact_prefix="$work/artifacts/$t-" "$work/$t" "fuzz/corpus/$t" </dev/null >"$work/$t.log" 2>&1
}

pids=()
names=()
status=0
for t in "${targets[@]}"; do
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do sleep 1; done
  run_one "$t" &
  pids+=($!)
  names+=("$t")
done
for i in "${!pids[@]}"; do
  t=${names[$i]}
  if wait "${pids[$i]}"; then
    runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/$t.log")
    echo "fuzz $t: ok, ${runs:-?} inputs in ${seconds} s (log $work/$t.log)"
  else
    status=1
    echo "fuzz $t: FAILED, a finding (log $work/$t.log):"
    grep -E "ERROR|runtime error|SUMMARY|what\(\)|Test unit written" "$work/$t.log" | head -n 20 || true
  fi
done
exit $status
