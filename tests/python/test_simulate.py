"""mneedle.simulate: the same dict as `mneedle simulate --json`, from a file or from values."""
import threading
import time

import numpy as np
import pytest

import mneedle
from conftest import strip_timing

PUNCH = "tests/assets/scenes/puncture_punch.toml"  # axisymmetric FE, punctures at fast fidelity


def test_file_scene_gives_the_cli_dict_number_for_number(cli, source):
    scene = source / PUNCH
    ours = mneedle.simulate(scene, fidelity="fast")
    theirs = cli.json("simulate", scene, "--fidelity", "fast")
    assert strip_timing(ours) == strip_timing(theirs)
    assert ours["needles"][0]["puncture"] is not None


def test_scene_values_run_as_the_file_they_came_from(source):
    scene = source / PUNCH
    values = mneedle.read_scene(scene)
    assert values["tissue"]["layers"][0]["material"]["E"] == "0.2 MPa"
    assert strip_timing(mneedle.simulate(values)) == strip_timing(mneedle.simulate(scene))


def test_a_changed_value_runs_as_the_cli_runs_the_changed_file(cli, source, tmp_path):
    values = mneedle.read_scene(source / PUNCH)
    values["tissue"]["layers"][0]["material"]["E"] = "0.4 MPa"
    changed = tmp_path / "stiffer.toml"
    changed.write_text(mneedle.scene_toml(values))
    ours = mneedle.simulate(values)
    assert strip_timing(ours) == strip_timing(cli.json("simulate", changed))
    # Twice the modulus, the same critical pressure: the criterion fires earlier.
    before = mneedle.simulate(source / PUNCH)
    assert (ours["needles"][0]["puncture"]["depth_m"]
            < before["needles"][0]["puncture"]["depth_m"])


def test_curves_are_numpy_arrays_of_the_json_points(source):
    result = mneedle.simulate(source / PUNCH)
    curve = mneedle.curves(result)["punch"]
    points = result["needles"][0]["curve"]
    assert isinstance(curve["depth_m"], np.ndarray)
    assert curve["depth_m"].tolist() == [p["depth_m"] for p in points]
    assert curve["force_N"].tolist() == [p["force_N"] for p in points]
    assert set(curve["stage"].tolist()) == {"pre", "post"}
    # Depth never goes back; it repeats once, where the post-puncture stage starts at the
    # puncture depth with the force after the drop.
    steps = np.diff(curve["depth_m"])
    assert np.all(steps >= 0)
    assert np.count_nonzero(steps == 0) == 1
    puncture = result["needles"][0]["puncture"]
    assert curve["depth_m"][np.argmin(steps)] == puncture["depth_m"]


def test_missing_file_raises_the_cli_message(cli, tmp_path):
    missing = tmp_path / "nowhere.toml"
    with pytest.raises(mneedle.InputError) as error:
        mneedle.simulate(missing)
    assert str(error.value) == cli.error("simulate", missing)


def test_a_bad_value_in_a_dict_names_its_key(source):
    values = mneedle.read_scene(source / PUNCH)
    values["tissue"]["layers"][0]["material"]["E"] = "0.2"  # no unit
    with pytest.raises(mneedle.InputError) as error:
        mneedle.simulate(values, source="my scene")
    assert str(error.value).startswith("my scene:")
    assert ': tissue.layers[0].material.E: "0.2" needs a unit: a pressure' in str(error.value)
    values["tissue"]["layers"][0]["material"]["E"] = None
    with pytest.raises(mneedle.InputError, match=r"tissue\.layers\[0\]\.material\.E"):
        mneedle.simulate(values)


def test_a_setting_outside_its_list_is_an_input_error(source):
    with pytest.raises(mneedle.InputError, match="fidelity 'fst' is not one of fast"):
        mneedle.simulate(source / PUNCH, fidelity="fst")


def test_the_interpreter_runs_on_while_a_simulation_works(source):
    """The lock is released during the solve: the main thread counts on meanwhile."""
    done = threading.Event()
    results = []

    def work():
        # Runs for at least a second, however fast the machine (three runs once took 0.49 s):
        # long enough to tell the two cases apart.
        begin = time.perf_counter()
        while time.perf_counter() - begin < 1.0 and len(results) < 100:
            results.append(mneedle.simulate(source / PUNCH, fidelity="standard"))
        done.set()

    worker = threading.Thread(target=work)
    start = time.perf_counter()
    worker.start()
    count = 0
    while not done.is_set():
        count += 1
    worker.join()
    elapsed = time.perf_counter() - start
    assert results and results[0]["needles"][0]["puncture"] is not None
    # Held, the lock would let the main thread count only until the worker enters C++ (one
    # 5 ms switch interval, some 10^4 steps) and after it returns; released, it counts the
    # whole run at over 10^6 steps per second even on a shared core. The floor, one step per
    # 5 us of the run, lies between the two by a factor of 10 or more either way.
    assert elapsed > 0.5, "the runs were too short to tell"
    assert count > elapsed / 5e-6


def test_numpy_scalars_and_paths_are_scene_values(source):
    values = mneedle.read_scene(source / PUNCH)
    plain = strip_timing(mneedle.simulate(values))
    values["tissue"]["layers"][0]["material"]["nu"] = np.float64(0.45)
    values["tissue"]["size"] = [np.str_(v) for v in values["tissue"]["size"]]
    assert strip_timing(mneedle.simulate(values)) == plain
    values["tissue"]["layers"][0]["material"]["nu"] = object()
    with pytest.raises(mneedle.InputError, match=r"tissue\.layers\[0\]\.material\.nu: a object"):
        mneedle.simulate(values)


def test_read_scene_errors_are_the_cli_errors(cli, tmp_path):
    broken = tmp_path / "broken.toml"
    broken.write_text("[tissue\n")
    for file in (tmp_path / "missing.toml", broken):
        with pytest.raises(mneedle.InputError) as error:
            mneedle.read_scene(file)
        assert str(error.value) == cli.error("scene", "check", file)


def test_an_energy_check_that_passes_gives_no_warning(source, recwarn):
    # Only the passing side is checked here: no shipped fast scene fails the check, so the
    # RuntimeWarning path (a failing check) has no test yet.
    result = mneedle.simulate(source / PUNCH)
    assert result["energy_check"] is not None and result["energy_check"]["passes"]
    assert len(recwarn) == 0


def test_where_the_penetration_criterion_does_not_hold_python_warns_as_the_cli_does(cli, source):
    # A gel so brittle against the 230 um punch (toughness / (E r) = 4e-5) that the crack would
    # run wider than the table: F_p is an upper bound, the JSON and a RuntimeWarning say so.
    values = mneedle.read_scene(source / PUNCH)
    values["tissue"]["fracture"]["toughness"] = "0.001 J/m^2"
    with pytest.warns(RuntimeWarning, match="F_p is an upper bound"):
        result = mneedle.simulate(values, criterion="penetration", source="brittle gel")
    assert len(result["warnings"]) == 1
    assert result["warnings"][0].startswith("brittle gel: tissue.layers[0] 'silicone'")
    # Paper A's toughness: no warning, and an empty list.
    assert mneedle.simulate(source / PUNCH, criterion="penetration")["warnings"] == []


def test_a_stopped_run_raises_unless_asked_to_keep_what_it_reached(cli, source, tmp_path):
    # A sharp cone on a finite-strain stratum corneum inverts the element under its point after
    # the step at 40 um (fast): SolverError with the CLI's message, or with keep_reached the
    # curve to there, "stopped" set and a RuntimeWarning (docs/cli.md, "A run whose solver stops").
    values = mneedle.read_scene(source / "designs/scenes/human_skin.toml")
    values["needles"][0]["geometry"] = {"plugin": "cone", "diameter": "230 um",
                                        "length": "1000 um"}
    values["tissue"]["layers"][0]["material"]["model"] = "svk"
    scene = tmp_path / "stops.toml"
    scene.write_text(mneedle.scene_toml(values))
    with pytest.raises(mneedle.SolverError) as raised:
        mneedle.simulate(scene, fidelity="fast")
    assert str(raised.value) == cli.error("simulate", scene, "--fidelity", "fast")
    with pytest.warns(RuntimeWarning, match="inverted element"):
        kept = mneedle.simulate(scene, fidelity="fast", keep_reached=True)
    assert kept["stopped"]["depth_m"] == pytest.approx(40e-6, abs=1e-12)
    assert kept["needles"][0]["puncture"] is None
    assert kept["needles"][0]["curve"][-1]["depth_m"] == pytest.approx(40e-6, abs=1e-12)
