#!/bin/sh
# Lists the functions of the sources (tests, benchmarks, fuzzers and python/ left out) longer than
# a limit (default 100 lines), longest first: lines, file:line, name. Issue 34 item 4 asks that no
# function be longer than ~100 lines without a reason written beside it; this is the check.
# Uses Universal Ctags (its end-line field). Usage: scripts/long_functions.sh [LIMIT]
limit=${1:-100}
cd "$(dirname "$0")/.." || exit 1
ctags -x --_xformat='%N	%F	%n	%{end}' --c++-kinds=f --fields=+ne -R --languages=C++ \
      core materials damage engine fit scenes analysis viz app 2>/dev/null |
  awk -F'\t' -v limit="$limit" '$4 != "" { n = $4 - $3 + 1; if (n > limit) printf "%4d  %s:%s  %s\n", n, $2, $3, $1 }' |
  sort -rn
