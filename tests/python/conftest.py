"""Shared fixtures of the Python package's tests (tests/CMakeLists.txt runs them with pytest).

The environment gives the built package on PYTHONPATH, the CLI (MNEEDLE_EXE) and the source
folder (MNEEDLE_SOURCE_DIR): every test compares the package with the CLI on the same input.
"""
import json
import os
import subprocess
from pathlib import Path

import pytest

SOURCE = Path(os.environ["MNEEDLE_SOURCE_DIR"])
EXE = os.environ["MNEEDLE_EXE"]
# The test names what varies from run to run and nothing else: wall time and peak memory.
TIMING_KEYS = {"seconds", "seconds_by_stage", "peak_memory_bytes", "insertion_seconds", "provenance"}


def strip_timing(tree):
    if isinstance(tree, dict):
        return {k: strip_timing(v) for k, v in tree.items() if k not in TIMING_KEYS}
    if isinstance(tree, list):
        return [strip_timing(v) for v in tree]
    return tree


class Cli:
    def json(self, *args):
        run = subprocess.run([EXE, *map(str, args), "--json"], capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
        return json.loads(run.stdout)

    def error(self, *args):
        """The one error line the CLI prints, without its 'mneedle: error: ' prefix."""
        run = subprocess.run([EXE, *map(str, args)], capture_output=True, text=True)
        assert run.returncode != 0
        lines = [l for l in run.stderr.splitlines() if l.startswith("mneedle: error: ")]
        assert len(lines) == 1, run.stderr
        return lines[0][len("mneedle: error: "):]


@pytest.fixture
def cli():
    return Cli()


@pytest.fixture
def source():
    return SOURCE
