"""`cmake --install` gives an importable package that finds the installed plugins."""
import os
import subprocess
import sys


def test_installed_package_imports_and_finds_its_plugins(tmp_path):
    prefix = tmp_path / "prefix"
    run = subprocess.run(
        ["cmake", "--install", os.environ["MNEEDLE_BUILD_DIR"], "--prefix", str(prefix)],
        capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    site = prefix / "lib" / "python3" / "dist-packages"
    code = ("import mneedle; print(mneedle.__file__); "
            "print(mneedle._plugin_dirs([])[0]); "
            "print(mneedle.strength(plugin='cone', set={'diameter': '200um', "
            "'length': '600um'}, material='pla')['governing'])")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(site)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                         cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    file, plugins, governing = out.stdout.split("\n")[:3]
    assert file.startswith(str(site))
    assert plugins == str(prefix / "lib" / "mneedle" / "plugins")
    assert governing in ("buckling", "strength")
