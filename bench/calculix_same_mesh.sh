#!/usr/bin/env bash
# Our solver against CalculiX on the same mesh (docs/performance.md, "CalculiX on our own mesh"):
# the bonded flat punch of bench_fe3d_convergence "a." (a = 200 um, 200 um down, 8 x 8 x 1 mm of
# E 1 MPa, nu 0.45) as a scene, exported at each fidelity (`mneedle export --format inp`, the
# planner's quarter model and the whole block) and solved by `ccx` (median of three runs,
# OMP_NUM_THREADS=2), beside our time for one solve of the same mesh (assembly and factorisation,
# from `simulate --model 3d --json`: its seconds_by_stage over its factorisations). The two
# reactions agree to CalculiX's printed digits (the same mesh, two linear solvers), so the ratio
# compares solvers, not meshes. Prints a Markdown table.
#   usage: bench/calculix_same_mesh.sh [BUILD_DIR (default build/release)]   (needs ccx on PATH)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${1:-$root/build/release}"
mneedle="$build/cli/mneedle"
command -v ccx > /dev/null || { echo "calculix_same_mesh: ccx not found (Debian's calculix-ccx)" >&2; exit 1; }
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cat > "$work/punch.toml" <<'TOML'
# The bonded flat punch of bench_fe3d_convergence "a.": no criterion fires within 200 um.
[tissue]
size = ["8 mm", "8 mm", "1 mm"]
boundary = "fixed"

[[tissue.layers]]
name = "block"
material = { model = "linear", E = "1 MPa", nu = 0.45 }

[tissue.fracture]
toughness = "1e9 N/mm"
critical_pressure = "1 GPa"

[[needles]]
name = "punch"
geometry = { plugin = "cylinder", diameter = "400 um", length = "2.5 mm" }
at = ["0 mm", "0 mm"]
material = "silicon"

[insertion]
depth = "200 um"
speed = "1 mm/s"
angle = "90 deg"

[model]
fidelity = "standard"
outputs = ["puncture", "force_curve"]
criterion = "pressure"
contact = "sticking"
TOML
echo "| level | model | nodes | held nodes | ccx (s) | ours: factorisation + assembly (s) | ccx / ours | F_z ccx (N) | F_z ours (N) |"
echo "|---|---|--:|--:|--:|--:|--:|--:|--:|"
for reduce in "" "--no-reductions"; do
  for level in fast standard fine; do
    "$mneedle" export "$work/punch.toml" --format inp -o "$work/model.inp" --fidelity "$level" \
      $reduce --json > "$work/export.json"
    for run in 1 2 3; do
      start=$(date +%s.%N)
      (cd "$work" && OMP_NUM_THREADS=2 ccx -i model > /dev/null)
      end=$(date +%s.%N)
      echo "$start $end" >> "$work/ccx_times.txt"
    done
    "$mneedle" simulate "$work/punch.toml" --fidelity "$level" --model 3d $reduce --json \
      2> /dev/null > "$work/simulate.json"
    python3 - "$work" "$level" <<'PY'
import json, re, statistics, sys
work, level = sys.argv[1], sys.argv[2]
times = [float(e) - float(s) for s, e in (l.split() for l in open(f"{work}/ccx_times.txt"))]
ccx = statistics.median(times)
exported = json.load(open(f"{work}/export.json"))
stages = json.load(open(f"{work}/simulate.json"))["seconds_by_stage"]
ours = (stages["factorization_s"] + stages["assembly_s"]) / stages["factorizations"]
dat = open(f"{work}/model.dat").read()
fz = float(re.search(r"total force.*?\n\s*\n?\s*\S+\s+\S+\s+(\S+)", dat, re.S).group(1))
model = ", ".join(exported["reductions"]) or "whole block"
print(f"| {level} | {model} | {exported['nodes']} | {exported['prescribed_nodes']} | {ccx:.2f} | "
      f"{ours:.3f} | {ccx / ours:.1f} | {fz:.7g} | {exported['reaction_N'][2]:.7g} |")
PY
    rm -f "$work/ccx_times.txt"
  done
done
