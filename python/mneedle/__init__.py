"""mneedle from Python: microneedle insertion, strength and screening (docs/python.md).

Every function runs the same C++ as the ``mneedle`` command of the same name and returns the
dict that command prints with ``--json`` (without its ``provenance`` key): the same keys, the
same numbers. Bad input raises :class:`InputError`, a solver that cannot deliver raises
:class:`SolverError`; their messages are the CLI's. The interpreter's lock is released while a
run works, so threads can run designs side by side.

Dimensional values are strings with units, as in scene files: ``"120 kPa"``, ``"300 um"``.
"""

import os
from os import PathLike
from typing import Any, Dict, Iterable, List, Optional, Union

import numpy as np

from . import _core
from ._core import InputError, SolverError, __version__

__all__ = [
    "InputError",
    "SolverError",
    "__version__",
    "read_scene",
    "scene_toml",
    "simulate",
    "strength",
    "screen",
    "fit",
    "curves",
]

Scene = Union[str, "PathLike[str]", Dict[str, Any]]

# Installed beside an installed mneedle (lib/python3/dist-packages/mneedle → lib/mneedle/plugins);
# in the build tree the C++ side finds the built plugins itself.
_INSTALLED_PLUGINS = os.path.normpath(
    os.path.join(os.path.dirname(__file__), "..", "..", "..", "mneedle", "plugins")
)


def _plugin_dirs(extra: Iterable[Union[str, "PathLike[str]"]]) -> List[str]:
    dirs = [os.fspath(d) for d in extra]
    if os.path.isdir(_INSTALLED_PLUGINS) and _INSTALLED_PLUGINS not in dirs:
        dirs.insert(0, _INSTALLED_PLUGINS)
    return dirs


def _scene_args(scene: Scene, source: Optional[str]):
    """(file, values, source) for the C++ side: a path is read there, a dict is checked there."""
    if isinstance(scene, dict):
        return "", scene, source if source is not None else "<scene dict>"
    if isinstance(scene, (str, PathLike)):
        return os.fspath(scene), {}, ""
    raise TypeError("scene: a file path or a dict of scene values, not " + type(scene).__name__)


def read_scene(file: Union[str, "PathLike[str]"]) -> Dict[str, Any]:
    """The scene file's values as a dict (STL paths made absolute), to change and run."""
    return _core.read_scene(os.fspath(file))


def scene_toml(scene: Dict[str, Any], source: str = "<scene dict>") -> str:
    """The dict as scene-file text (TOML), e.g. to save a changed scene."""
    return _core.scene_toml(scene, source)


def simulate(
    scene: Scene,
    *,
    fidelity: str = "",
    contact: str = "",
    criterion: str = "",
    model: str = "auto",
    axis: str = "",
    max_needles: int = 16,
    no_reductions: bool = False,
    plugin_dirs: Iterable[Union[str, "PathLike[str]"]] = (),
    source: Optional[str] = None,
) -> Dict[str, Any]:
    """``mneedle simulate SCENE --json``: the two-stage insertion of every needle in the scene.

    ``scene`` is a file or a dict (``read_scene``'s, changed); ``source`` names a dict in
    messages and anchors its relative STL paths (default: the working folder). Empty settings
    keep the scene's own choices.
    """
    file, values, name = _scene_args(scene, source)
    return _core.simulate(
        file, values, name, fidelity, contact, criterion, model, axis, int(max_needles),
        bool(no_reductions), _plugin_dirs(plugin_dirs),
    )


def strength(
    file: Union[str, "PathLike[str]", None] = None,
    *,
    plugin: str = "",
    set: Union[Dict[str, str], Iterable[str]] = (),
    unit: str = "mm",
    axis: str = "auto",
    material: str,
    end: str = "fixed-pinned",
    depth: str = "",
    lateral_ratio: float = 0.0,
    plugin_dirs: Iterable[Union[str, "PathLike[str]"]] = (),
) -> Dict[str, Any]:
    """``mneedle strength``: buckling and material capacity of a mesh file or a plugin shape.

    ``set`` gives plugin parameters as ``{"diameter": "200 um"}`` or ``["diameter=200um"]``.
    """
    settings = [f"{k}={v}" for k, v in set.items()] if isinstance(set, dict) else list(set)
    return _core.strength(
        "" if file is None else os.fspath(file), plugin, settings, unit, axis, material, end,
        depth, float(lateral_ratio), _plugin_dirs(plugin_dirs),
    )


def screen(
    designs: Iterable[Union[str, "PathLike[str]"]],
    scene: Union[str, "PathLike[str]"],
    *,
    fidelity: str = "fast",
    model: str = "auto",
    material: str = "",
    jobs: int = 1,
    unit: str = "mm",
    axis: str = "auto",
    repair: bool = False,
    plugin_dirs: Iterable[Union[str, "PathLike[str]"]] = (),
) -> Dict[str, Any]:
    """``mneedle screen DESIGNS… --scene SCENE --json``: every design ranked on the scene.

    A design that fails is a row with ``"ok": False`` and its error; the others still run.
    """
    return _core.screen(
        [os.fspath(d) for d in designs], os.fspath(scene), fidelity, model, material, int(jobs),
        unit, axis, bool(repair), _plugin_dirs(plugin_dirs),
    )


def fit(
    files: Iterable[Union[str, "PathLike[str]"]],
    *,
    depth_col: str = "",
    force_col: str = "",
    depth_unit: str = "",
    force_unit: str = "",
    speed: str = "",
    angle: str = "90deg",
    fix: Iterable[str] = (),
    free: Iterable[str] = (),
    layer_starts: Iterable[str] = (),
    detect_layers: int = 0,
    starts: int = 8,
) -> Dict[str, Any]:
    """``mneedle fit CURVES… --json``: paper B's tri-force model fitted to recordings jointly."""
    return _core.fit(
        [os.fspath(f) for f in files], depth_col, force_col, depth_unit, force_unit, speed,
        angle, list(fix), list(free), list(layer_starts), int(detect_layers), int(starts),
    )


def curves(result: Dict[str, Any]) -> Dict[str, Dict[str, np.ndarray]]:
    """A ``simulate`` result's force–depth curves as NumPy arrays.

    ``{needle name: {"depth_m": array, "force_N": array, "stage": array of "pre"/"post", ...}}``
    with every per-point number the JSON has for all of the needle's points; the sum of the
    needles' curves as ``"total"`` when the scene has more than one needle.
    """
    out: Dict[str, Dict[str, np.ndarray]] = {}

    def columns(points: List[Dict[str, Any]]) -> Dict[str, np.ndarray]:
        keys = [k for k in points[0] if all(k in p for p in points)] if points else []
        cols: Dict[str, np.ndarray] = {}
        for k in keys:
            values = [p[k] for p in points]
            if isinstance(values[0], str):
                cols[k] = np.array(values)
            elif isinstance(values[0], (int, float)):
                cols[k] = np.asarray(values, dtype=float)
        return cols

    for needle in result["needles"]:
        out[needle["name"]] = columns(needle["curve"])
    if len(result["needles"]) > 1:
        out["total"] = columns(result["total_curve"])
    return out
