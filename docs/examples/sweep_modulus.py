#!/usr/bin/python3
"""Sweep one scene value from Python and plot what it does (docs/python.md).

Paper A's silicone phantom with its sharp bevel: the phantom's Young's modulus from 0.1 to
0.5 MPa, each scene run by mneedle.simulate; the force-depth curves and the puncture depth
against the modulus are drawn with matplotlib. The closed-form pre-puncture model runs in a
fraction of a second per scene; --model auto runs the 3-D model instead (seconds per scene).

    PYTHONPATH=build/release/python /usr/bin/python3 docs/examples/sweep_modulus.py --out sweep.png
"""
import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import mneedle  # noqa: E402

SCENE = Path(__file__).resolve().parents[2] / "designs" / "scenes" / "silicone_phantom.toml"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="sweep_modulus.png", help="PNG to write")
    parser.add_argument("--model", default="analytic", help="pre-puncture model (auto, 3d, ...)")
    parser.add_argument("--fidelity", default="fast")
    args = parser.parse_args()

    base = mneedle.read_scene(SCENE)
    moduli_MPa = np.linspace(0.1, 0.5, 5)
    depths_um, forces_mN = [], []
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    for E in moduli_MPa:
        scene = mneedle.read_scene(SCENE)  # a fresh copy of the values each time
        scene["tissue"]["layers"][0]["material"]["E"] = f"{E:.3f} MPa"
        result = mneedle.simulate(scene, model=args.model, fidelity=args.fidelity,
                                  source=f"silicone_phantom with E = {E:.3f} MPa")
        curve = mneedle.curves(result)["sharp_bevel"]
        left.plot(curve["depth_m"] * 1e6, curve["force_N"] * 1e3, label=f"E = {E:.2f} MPa")
        puncture = result["needles"][0]["puncture"]
        depths_um.append(np.nan if puncture is None else puncture["depth_m"] * 1e6)
        forces_mN.append(np.nan if puncture is None else puncture["force_N"] * 1e3)
        print(f"E = {E:.3f} MPa: puncture at {depths_um[-1]:.2f} um, {forces_mN[-1]:.3f} mN")
    assert base["tissue"]["layers"][0]["material"]["E"] == "0.2 MPa"  # the file is untouched

    left.set_xlabel("depth below the surface [um]")
    left.set_ylabel("force [mN]")
    left.set_title("sharp bevel in silicone")
    left.legend()
    right.plot(moduli_MPa, depths_um, "o-")
    right.set_xlabel("Young's modulus of the phantom [MPa]")
    right.set_ylabel("puncture depth [um]")
    right.set_title(f"pressure criterion, {args.model} pre-puncture model")
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
