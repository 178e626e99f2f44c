#!/usr/bin/python3
"""ParaView output read by an independent reader (docs/cli.md, "Fields").

Runs `mneedle simulate SCENE --vtu DIR --json` and reads what it wrote with meshio (Debian's
python3-meshio) and the .pvd collection with the standard XML parser: every step's tissue and
needle files, their fields, the whole block (a half model reflected back, every cell positive),
contact forces that add up to the force the JSON reports at the same depth, and the provenance
comment. Usage: check_fields.py MNEEDLE SCENE WORKDIR [axisymmetric]
"""
import hashlib
import json
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import meshio
import numpy as np


def fail(message):
    print("check_fields: " + message, file=sys.stderr)
    sys.exit(1)


def provenance_of(path):
    head = Path(path).read_bytes()[:8192].decode("utf-8", errors="replace")
    found = re.search(r"<!-- provenance: (.*?) -->", head)
    if not found:
        fail(f"{path}: no provenance comment")
    return json.loads(found.group(1))


def main():
    mneedle, scene, work = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
    axisymmetric = len(sys.argv) > 4 and sys.argv[4] == "axisymmetric"
    shutil.rmtree(work, ignore_errors=True)
    run = subprocess.run([mneedle, "simulate", str(scene), "--vtu", str(work), "--json"],
                         capture_output=True, text=True)
    if run.returncode != 0:
        fail(f"simulate failed: {run.stderr}")
    result = json.loads(run.stdout)
    force_at = {round(p["depth_m"] * 1e12): p["force_N"] for p in result["total_curve"]}

    entries = ET.parse(work / "steps.pvd").getroot().find("Collection").findall("DataSet")
    if not entries:
        fail("steps.pvd lists no files")
    tissue = [e for e in entries if e.get("part") == "0"]
    needles = [e for e in entries if e.get("part") == "1"]
    depths = [float(e.get("timestep")) for e in tissue]
    if depths != sorted(depths) or len(set(depths)) != len(depths):
        fail(f"tissue timesteps are not increasing depths: {depths}")
    if len(needles) != len(tissue):
        fail(f"{len(tissue)} tissue files but {len(needles)} needle files")

    scene_sha = hashlib.sha256(scene.read_bytes()).hexdigest()
    for entry in tissue:
        path = work / entry.get("file")
        depth = float(entry.get("timestep"))
        mesh = meshio.read(path)
        if float(mesh.field_data["depth_m"].ravel()[0]) != depth:
            fail(f"{path}: depth_m {mesh.field_data['depth_m']} is not the timestep {depth}")
        for name in ("displacement_m",) + (() if axisymmetric else (
                "contact_force_N", "contact_traction_Pa", "contact_pressure_Pa")):
            if name not in mesh.point_data:
                fail(f"{path}: no point data {name}")
        for name in ("von_mises_Pa", "principal_stress_Pa", "energy_density_J_per_m3", "layer"):
            if name not in mesh.cell_data:
                fail(f"{path}: no cell data {name}")
        for name, values in list(mesh.point_data.items()) + [
                (k, v[0]) for k, v in mesh.cell_data.items()]:
            if not np.all(np.isfinite(values)):
                fail(f"{path}: {name} is not finite")
        inputs = provenance_of(path)["inputs"]
        if inputs[0]["role"] != "scene" or inputs[0]["sha256"] != scene_sha:
            fail(f"{path}: provenance does not name the scene's SHA-256 {scene_sha}")
        if axisymmetric:
            if [c.type for c in mesh.cells] != ["triangle6"]:
                fail(f"{path}: cells {[c.type for c in mesh.cells]}, not triangle6")
            continue
        if [c.type for c in mesh.cells] != ["tetra10"]:
            fail(f"{path}: cells {[c.type for c in mesh.cells]}, not tetra10")
        # the whole block: as wide on -y as on +y, every tetrahedron positively oriented
        y = mesh.points[:, 1]
        if not np.isclose(y.min(), -y.max(), rtol=1e-12):
            fail(f"{path}: y from {y.min()} to {y.max()}: not the whole block")
        t = mesh.points[mesh.cells[0].data[:, :4]]
        volume = np.einsum("ij,ij->i", np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]),
                           t[:, 3] - t[:, 0])
        if not np.all(volume > 0):
            fail(f"{path}: {np.sum(volume <= 0)} cells are inverted")
        # every mid-edge node at the middle of its edge (VTK's order 01 12 20 03 13 23), the
        # mirrored cells included
        cells = mesh.cells[0].data
        for k, (i, j) in enumerate(((0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3))):
            middle = 0.5 * (mesh.points[cells[:, i]] + mesh.points[cells[:, j]])
            off = np.abs(mesh.points[cells[:, 4 + k]] - middle).max()
            if off > 1e-12:
                fail(f"{path}: mid-edge node {4 + k} is {off} m off its edge's middle")
        # the needle's force at this depth is the sum of the nodal contact forces (the solver's
        # residual, 1e-8 of the force, bounds the difference)
        force = force_at.get(round(depth * 1e12))
        if force is None:
            fail(f"{path}: depth {depth} is not a point of the JSON curve")
        total = -mesh.point_data["contact_force_N"][:, 2].sum()
        if abs(total - force) > 1e-7 * abs(force):
            fail(f"{path}: contact forces add up to {total} N, the JSON says {force} N")
        pressure = mesh.point_data["contact_pressure_Pa"]
        if force > 0 and not pressure.max() > 0:
            fail(f"{path}: no contact pressure under a force of {force} N")

    for entry in needles:
        path = work / entry.get("file")
        mesh = meshio.read(path)
        expected = "line" if axisymmetric else "triangle"  # the outline in the r-z plane
        if {c.type for c in mesh.cells} != {expected}:
            fail(f"{path}: needle cells {[c.type for c in mesh.cells]}, not {expected}")
        lowest = mesh.points[:, 2].min()
        if not np.isclose(lowest, -float(entry.get("timestep")), rtol=0, atol=1e-12):
            fail(f"{path}: the needle's tip is at z = {lowest}, not at minus the depth")
    print(f"check_fields: {len(tissue)} steps read with meshio {meshio.__version__}: fine")


main()
