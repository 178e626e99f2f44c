#!/usr/bin/env bash
# Screening throughput on one machine and over MPI ranks (docs/performance.md, "Screening on a
# cluster"): 40 3-D designs (sharp and blunt bevels, ten angles each, and 20 cones and cylinders
# run as STL files through the 3-D model) on human skin at fast fidelity, screened serially, with
# --jobs 2, and with mpirun -n 1 and -n 2. Prints a Markdown table of wall time and designs per
# minute, and checks that every run ranks the designs identically.
#   usage: bench/screen_mpi.sh [BUILD_DIR (default build/release)]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build/release}"
mneedle="$build/cli/mneedle"
scene="$root/designs/scenes/human_skin.toml"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

"$root/bench/screen_designs.sh" "$mneedle" "$work/designs"

run() {  # label, evaluating threads, then the command; prints a table row
  local label="$1" threads="$2"; shift 2
  local start end
  start=$(date +%s.%N)
  "$@" "$work/designs" "$work/designs/bevels.toml" --scene "$scene" --unit um --json \
    > "$work/$label.json" 2> /dev/null || true
  end=$(date +%s.%N)
  python3 - "$label" "$start" "$end" "$work/$label.json" "$work/serial.json" "$threads" <<'PY'
import json, sys
label, start, end, path, reference = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), sys.argv[4], sys.argv[5]
threads = int(sys.argv[6])
rows = json.load(open(path))["designs"]
names = [r["design"] for r in rows]
same = "reference" if label == "serial" else ("same" if names == [r["design"] for r in json.load(open(reference))["designs"]] else "DIFFERENT")
wall = end - start
# The model of an embarrassingly parallel batch dealt one design at a time: the wall time is at
# least the total work shared by the evaluating threads and at least the longest design.
seconds = [r.get("seconds", 0.0) for r in rows]
model = max(sum(seconds) / threads, max(seconds))
print(f"| {label} | {threads} | {len(rows)} | {wall:.1f} | {60 * len(rows) / wall:.0f} | "
      f"{sum(seconds):.1f} | {max(seconds):.1f} | {model:.1f} | {same} |")
PY
}

echo "| run | evaluating threads | designs | wall [s] | designs / min | Σ design time [s] | longest design [s] | model: max(Σ / threads, longest) [s] | ranking |"
echo "|---|---|---|---|---|---|---|---|---|"
run serial 1 "$mneedle" screen
run "serial --jobs 2" 2 "$mneedle" screen --jobs 2
run "mpirun -n 1 --bind-to none" 1 mpirun -n 1 --bind-to none "$mneedle" screen --mpi
run "mpirun -n 2" 2 mpirun -n 2 --oversubscribe "$mneedle" screen --mpi
