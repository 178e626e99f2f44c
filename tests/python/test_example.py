"""docs/examples/sweep_modulus.py runs as docs/python.md shows it, and says what physics says:
a stiffer phantom reaches the critical pressure at a smaller depth."""
import re
import subprocess
import sys

from conftest import SOURCE


def test_modulus_sweep_example_writes_its_plot_and_punctures_earlier_when_stiffer(tmp_path):
    out = tmp_path / "sweep.png"
    run = subprocess.run([sys.executable, str(SOURCE / "docs" / "examples" / "sweep_modulus.py"),
                          "--out", str(out)], capture_output=True, text=True, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert out.stat().st_size > 10_000
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    depths = [float(d) for d in re.findall(r"puncture at ([0-9.]+) um", run.stdout)]
    assert len(depths) == 5
    assert all(a > b for a, b in zip(depths, depths[1:]))
