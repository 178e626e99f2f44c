#!/usr/bin/python3
"""Our FE against CalculiX on our own mesh (docs/validation.md, "CalculiX on the same mesh").

Runs `mneedle export SCENE --format inp -o WORK/model.inp --json` and `ccx` on the deck, and
compares CalculiX's total reaction at the nodes the needle holds with the reaction mneedle
reports for the same nodes. On one mesh, with the same elements and constraints, two correct
linear solvers agree to round-off: 1e-4 relative is the bound (the solvers' own tolerances are
1e-8 and below), so anything larger is a bug in one of them.
Usage: check_ccx.py MNEEDLE SCENE WORKDIR [extra mneedle export arguments...]
"""
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path


def fail(message):
    print("check_ccx: " + message, file=sys.stderr)
    sys.exit(1)


def main():
    mneedle, scene, work = sys.argv[1], sys.argv[2], Path(sys.argv[3])
    extra = sys.argv[4:]
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    deck = work / "model.inp"
    run = subprocess.run([mneedle, "export", scene, "--format", "inp", "-o", str(deck), "--json"]
                         + extra, capture_output=True, text=True)
    if run.returncode != 0:
        fail(f"export failed: {run.stderr}")
    ours = json.loads(run.stdout)
    if ours["prescribed_nodes"] == 0:
        fail("the needle holds no node at the exported depth: nothing to compare")
    ccx = shutil.which("ccx")
    if ccx is None:
        fail("ccx not found (Debian's calculix-ccx; .ci/install-deps.sh installs it)")
    solve = subprocess.run([ccx, "-i", "model"], cwd=work, capture_output=True, text=True,
                           env={"OMP_NUM_THREADS": "1", "PATH": "/usr/bin:/bin"})
    dat = work / "model.dat"
    if solve.returncode != 0 or not dat.exists():
        fail(f"ccx failed ({solve.returncode}): {solve.stdout[-2000:]} {solve.stderr[-2000:]}")
    if "*ERROR" in solve.stdout:
        fail(f"ccx reported an error: {solve.stdout[-2000:]}")
    text = dat.read_text()
    found = re.search(r"total force \(fx,fy,fz\).*?\n\s*\n?\s*([-+0-9.Ee]+)\s+([-+0-9.Ee]+)\s+"
                      r"([-+0-9.Ee]+)", text, re.S)
    if not found:
        fail(f"no total force in {dat}:\n{text[:2000]}")
    theirs = [float(v) for v in found.groups()]
    reaction = ours["reaction_N"]
    scale = max(abs(v) for v in reaction)
    worst = max(abs(a - b) for a, b in zip(theirs, reaction)) / scale
    print(f"check_ccx: {scene}: depth {ours['depth_m']} m, {ours['nodes']} nodes, "
          f"{ours['prescribed_nodes']} held; reaction mneedle {reaction} N, CalculiX {theirs} N, "
          f"largest difference {worst:.2e} of the force")
    if worst > 1e-4:
        fail("the two solvers disagree beyond round-off")


main()
