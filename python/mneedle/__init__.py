"""mneedle from Python: microneedle insertion, strength and screening (docs/python.md).

Every function runs the same C++ as the ``mneedle`` command of the same name and returns the
dict that command prints with ``--json`` (without its ``provenance`` key): the same keys, the
same numbers. Bad input raises :class:`InputError`, a solver that cannot deliver raises
:class:`SolverError`; their messages are the CLI's. The interpreter's lock is released while a
run works, so threads can run designs side by side.

Dimensional values are strings with units, as in scene files: ``"120 kPa"``, ``"300 um"``.
"""

import os
import warnings
from os import PathLike
from typing import Any, Dict, Iterable, List, Optional, Union

import numpy as np

from . import _core
from ._core import InputError, SolverError, __version__
from ._paths import PLUGIN_DIR

# The package's own plugins (the build tree's, or the installed ones beside it): the C++ side
# cannot tell them from the executable, which is python3.
_core._set_plugin_folder(PLUGIN_DIR)

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

Paths = Union[str, "PathLike[str]", Iterable[Union[str, "PathLike[str]"]]]


def _list(values, what: str) -> List[str]:
    """A list of strings; one string or path alone is a list of one (never split into letters)."""
    if isinstance(values, (str, PathLike)):
        return [os.fspath(values)]
    try:
        return [os.fspath(v) if isinstance(v, PathLike) else str(v) for v in values]
    except TypeError:
        raise InputError(f"{what}: a string or a list of strings, not {type(values).__name__}")


def _count(value, name: str, low: int, high: int) -> int:
    """A whole number in [low, high], as the CLI's option checks; an InputError naming it
    otherwise (pybind11's TypeError listed every argument, the whole scene among them)."""
    try:
        number = int(value)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{name}: a whole number, not {value!r}") from None
    if number != value or not low <= number <= high:
        raise InputError(f"{name}: {value!r} is not a whole number from {low} to {high}")
    return number


def _plain(value, where: str):
    """Scene values as the C++ side reads them: NumPy scalars as Python numbers, paths as
    strings, tuples as lists; anything else that is no scene value is an InputError naming it."""
    if isinstance(value, dict):
        return {str(k): _plain(v, f"{where}.{k}" if where else str(k)) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v, f"{where}[{i}]") for i, v in enumerate(value)]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, PathLike):
        return os.fspath(value)
    if value is None or isinstance(value, (bool, int, float, str)):
        return value  # None: the C++ side names the key
    raise InputError(f"{where}: a {type(value).__name__} is not a scene value "
                     "(strings with units, numbers, booleans, lists and tables)")


def _scene_args(scene: Scene, source: Optional[str]):
    """(file, values, source) for the C++ side: a path is read there, a dict is checked there."""
    name = source if source is not None else "<scene dict>"
    if isinstance(scene, dict):
        return "", _plain(scene, ""), name
    if isinstance(scene, (str, PathLike)):
        return os.fspath(scene), {}, ""
    raise TypeError("scene: a file path or a dict of scene values, not " + type(scene).__name__)


def read_scene(file: Union[str, "PathLike[str]"]) -> Dict[str, Any]:
    """The scene file's values as a dict (STL paths made absolute), to change and run."""
    return _core.read_scene(os.fspath(file))


def scene_toml(scene: Dict[str, Any], source: str = "<scene dict>") -> str:
    """The dict as scene-file text (TOML), e.g. to save a changed scene."""
    return _core.scene_toml(_plain(scene, ""), source)


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
    keep_reached: bool = False,
) -> Dict[str, Any]:
    """``mneedle simulate SCENE --json``: the two-stage insertion of every needle in the scene.

    ``scene`` is a file or a dict (``read_scene``'s, changed); ``source`` names a dict in
    messages and anchors its relative STL paths (default: the working folder). Empty settings
    keep the scene's own choices. A finite element run that stops part-way raises
    ``SolverError``; with ``keep_reached=True`` it returns what it reached instead, with
    ``"stopped"`` set, and warns (docs/cli.md, "A run whose solver stops").
    """
    file, values, name = _scene_args(scene, source)
    result = _core.simulate(
        file, values, name, fidelity, contact, criterion, model, axis,
        _count(max_needles, "max_needles", 1, 100_000),
        bool(no_reductions), _list(plugin_dirs, "plugin_dirs"), bool(keep_reached),
    )
    if result.get("stopped"):
        # The CLI's one-line error, as a warning: the curves end at the stop.
        warnings.warn(result["stopped"]["reason"], RuntimeWarning, stacklevel=2)
    check = result.get("energy_check")
    if check and not check["passes"]:
        # As the CLI warns on stderr (docs/model.md, "Energy check").
        warnings.warn(
            f"{file or name}: the tissue stores {100 * (1 + check['relative_difference']):.3g} % "
            f"of the work the needle did on it up to {check['depth_m']:.3g} m (more than "
            f"{100 * check['tolerance']:.3g} % apart: the contact or the mesh is not resolved)",
            RuntimeWarning, stacklevel=2)
    for text in result.get("warnings", []):
        # Where a criterion does not hold, or a linear stiff top layer was pushed past its
        # thickness, as the CLI says on stderr.
        warnings.warn(text, RuntimeWarning, stacklevel=2)
    return result


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
    settings = ([f"{k}={v}" for k, v in set.items()] if isinstance(set, dict)
                else _list(set, "set"))
    return _core.strength(
        "" if file is None else os.fspath(file), plugin, settings, unit, axis, material, end,
        depth, float(lateral_ratio), _list(plugin_dirs, "plugin_dirs"),
    )


def screen(
    designs: Paths,
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

    ``designs`` are mesh files, folders of them or design lists, as on the CLI (one path alone
    is a list of one). The scene is a file: write a changed dict with :func:`scene_toml` first.
    A design that fails is a row with ``"ok": False`` and its error; the others still run.
    """
    result = _core.screen(
        _list(designs, "designs"), os.fspath(scene), fidelity, model, material,
        _count(jobs, "jobs", 1, 1000),
        unit, axis, bool(repair), _list(plugin_dirs, "plugin_dirs"),
    )
    for text in result.get("warnings", []):
        # What holds for the whole run, as the CLI says on stderr.
        warnings.warn(text, RuntimeWarning, stacklevel=2)
    return result


def fit(
    files: Paths,
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
        _list(files, "files"), depth_col, force_col, depth_unit, force_unit, speed, angle,
        _list(fix, "fix"), _list(free, "free"), _list(layer_starts, "layer_starts"),
        _count(detect_layers, "detect_layers", 0, 10), _count(starts, "starts", 1, 1000),
    )


def curves(result: Dict[str, Any]) -> Dict[str, Dict[str, np.ndarray]]:
    """A ``simulate`` result's force–depth curves as NumPy arrays.

    ``{needle name: {"depth_m": array, "force_N": array, "stage": array of "pre"/"post", ...}}``
    with every per-point value the JSON has (a pair such as ``lateral_force_N`` as an n × 2
    array); a value a point does not have is NaN (the pre-puncture quantities after puncture,
    ``alpha_N`` before it). The sum of the needles' curves is ``"total"`` when the scene has more
    than one needle.
    """
    out: Dict[str, Dict[str, np.ndarray]] = {}

    def columns(points: List[Dict[str, Any]]) -> Dict[str, np.ndarray]:
        keys: List[str] = []
        for p in points:
            keys += [k for k in p if k not in keys]
        cols: Dict[str, np.ndarray] = {}
        for k in keys:
            present = [p[k] for p in points if k in p]
            if isinstance(present[0], str):
                cols[k] = np.array([p.get(k, "") for p in points])
            elif isinstance(present[0], list):
                width = len(present[0])
                cols[k] = np.array([p.get(k, [np.nan] * width) for p in points], dtype=float)
            elif isinstance(present[0], (int, float)) and not isinstance(present[0], bool):
                cols[k] = np.array([p.get(k, np.nan) for p in points], dtype=float)
        return cols

    for needle in result["needles"]:
        out[needle["name"]] = columns(needle["curve"])
    if len(result["needles"]) > 1:
        if "total" in out:
            raise InputError("curves: a needle is named 'total', the name of the needles' sum")
        out["total"] = columns(result["total_curve"])
    return out
