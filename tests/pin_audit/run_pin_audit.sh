#!/usr/bin/env bash
# Builds the suite with tests/pin_audit/ first on the include path (every EXPECT_NEAR logs what it
# compared), runs it, and lists the pins the code no longer reads exactly
# (docs/validation.md, "Pins and what the code reads"). About 10 min to build and 5 to run on two
# cores; the build lives in build/pin-audit and leaves the presets' builds alone.
# usage: tests/pin_audit/run_pin_audit.sh [pin_audit.py options]
set -euo pipefail
cd "$(dirname "$0")/../.."
root=$(pwd)
build=build/pin-audit
log=$build/pins.tsv
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DMNEEDLE_WERROR=OFF -DMNEEDLE_MPI=OFF \
  -DMNEEDLE_PYTHON=OFF -DMNEEDLE_BUILD_BENCH=OFF -DCMAKE_CXX_FLAGS="-I$root/tests/pin_audit" >/dev/null
cmake --build "$build" -j "$(nproc)" >/dev/null
rm -f "$log"
MNEEDLE_PIN_AUDIT="$root/$log" ctest --test-dir "$build" -j "$(nproc)" --output-on-failure >"$build/ctest.log" ||
  echo "some tests failed: $build/ctest.log" >&2
/usr/bin/python3 tests/pin_audit/pin_audit.py "$log" "$@"
