#!/usr/bin/env bash
# Rewrites tests/slow_tests.txt from CTest's measured costs of the last release runs: every test
# of the current suite that averages over 0.5 s (docs/performance.md, "Test costs").
set -euo pipefail
cd "$(dirname "$0")/.."
costs=build/release/Testing/Temporary/CTestCostData.txt
[ -f "$costs" ] || { echo "no $costs: run ctest --preset release first" >&2; exit 1; }
current=$(mktemp)
ctest --preset release -N | sed -n 's/^ *Test *#[0-9]*: //p' > "$current"
{
  echo "# Tests over 0.5 s in the release build (CTest's measured average, ctest --preset release -j2,"
  echo "# $(date +%Y-%m-%d)): labelled 'slow' by cost_labels.cmake, skipped by the sanitised run (ctest --preset"
  echo "# debug). Regenerate with tests/update_slow_tests.sh after a release ctest run. Seconds after the name."
  awk 'NR==FNR {want[$1]=1; next} NF==3 && ($1 in want) {cost[$1]=$3}
       END {for (k in cost) if (cost[k] > 0.5) printf "%s %.2f\n", k, cost[k]}' "$current" "$costs" | sort
} > tests/slow_tests.txt
rm -f "$current"
echo "tests/slow_tests.txt: $(grep -vc '^#' tests/slow_tests.txt) slow tests"
