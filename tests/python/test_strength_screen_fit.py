"""mneedle.strength, screen and fit: the same dicts as the CLI's --json."""
import pytest

import mneedle
from conftest import strip_timing


def test_strength_of_a_plugin_shape_is_the_cli_number_for_number(cli):
    ours = mneedle.strength(plugin="cone", set={"diameter": "200um", "length": "600um"},
                            material="pla")
    theirs = cli.json("strength", "--plugin", "cone", "--set", "diameter=200um",
                      "--set", "length=600um", "--material", "pla")
    assert strip_timing(ours) == strip_timing(theirs)
    assert ours["capacity_N"] == min(ours["buckling_N"], ours["strength_N"])


def test_strength_of_a_mesh_file(cli, source):
    stl = source / "designs" / "cone.stl"
    ours = mneedle.strength(stl, material="silicon", depth="300um")
    theirs = cli.json("strength", stl, "--material", "silicon", "--depth", "300um")
    assert strip_timing(ours) == strip_timing(theirs)


def test_strength_errors_are_the_cli_errors(cli):
    with pytest.raises(mneedle.InputError) as error:
        mneedle.strength(plugin="cone", set={"diameter": "200"}, material="pla")
    assert str(error.value) == cli.error("strength", "--plugin", "cone", "--set", "diameter=200",
                                         "--material", "pla")
    with pytest.raises(mneedle.InputError, match="either a mesh file or plugin"):
        mneedle.strength(material="pla")


def test_screen_ranks_as_the_cli_ranks(cli, source):
    designs = [source / "designs" / n for n in ("cylinder.stl", "cone.stl", "sharp_bevel.stl")]
    scene = source / "designs" / "scenes" / "silicone_phantom.toml"
    ours = mneedle.screen(designs, scene, model="analytic", jobs=2)
    theirs = cli.json("screen", *designs, "--scene", scene, "--model", "analytic",
                      "--jobs", "2")
    assert strip_timing(ours) == strip_timing(theirs)
    assert [d["design"] for d in ours["designs"]] == [d["design"] for d in theirs["designs"]]
    assert all(d["ok"] for d in ours["designs"])


def test_one_folder_alone_is_screened_as_the_cli_screens_it(cli, source):
    scene = source / "designs" / "scenes" / "silicone_phantom.toml"
    folder = source / "designs"  # a str or a path alone is one input, never its letters
    ours = mneedle.screen(str(folder), scene, model="analytic")
    theirs = cli.json("screen", folder, "--scene", scene, "--model", "analytic")
    assert strip_timing(ours) == strip_timing(theirs)
    assert len(ours["designs"]) == 4


def test_screen_warns_of_a_small_strain_stiff_top_layer_as_the_cli_does(cli, source):
    # Paper A's skin: the linear stratum corneum is pushed 7 times its thickness before the
    # cylinder punctures it (docs/validation.md, "Finite strain in a stiff top layer").
    design = source / "designs" / "cylinder.stl"
    scene = source / "designs" / "scenes" / "human_skin.toml"
    with pytest.warns(RuntimeWarning, match="membrane tension"):
        ours = mneedle.screen(design, scene)
    theirs = cli.json("screen", design, "--scene", scene)
    assert strip_timing(ours) == strip_timing(theirs)
    assert len(ours["warnings"]) == 1 and "design 'cylinder" in ours["warnings"][0]


def test_fit_is_the_cli_fit(cli, source):
    curve = source / "tests" / "assets" / "curves" / "loading_hold_retraction.csv"
    ours = mneedle.fit([curve], starts=2)
    theirs = cli.json("fit", curve, "--starts", "2")
    assert strip_timing(ours) == strip_timing(theirs)
    assert ours["model"] == "triforce" and "K0_N" in ours["params"]


def test_fit_of_a_bad_recording_is_the_cli_error(cli, source):
    bad = source / "tests" / "assets" / "curves" / "text_in_number.csv"
    with pytest.raises(mneedle.InputError) as error:
        mneedle.fit([bad])
    assert str(error.value) == cli.error("fit", bad)
    assert "text_in_number.csv:" in str(error.value)


def test_counts_out_of_range_are_input_errors_naming_the_argument(source):
    # As the CLI's --jobs 1..1000 and --starts 1..1000; pybind11's TypeError listed every
    # argument (the whole scene), and jobs=0 was accepted.
    scene = source / "designs" / "scenes" / "human_skin.toml"
    with pytest.raises(mneedle.InputError, match=r"^jobs: 0 is not a whole number from 1 to 1000"):
        mneedle.screen(source / "designs" / "cone.stl", scene, jobs=0)
    with pytest.raises(mneedle.InputError, match=r"^max_needles: -1 is not"):
        mneedle.simulate(scene, max_needles=-1)
    with pytest.raises(mneedle.InputError, match=r"^starts: 100000000000000000000 is not"):
        mneedle.fit([], starts=10**20)
