"""`cmake --install` gives a package where the prefix's Python looks for it, importable from
there, that loads the installed plugins (not the build tree's)."""
import os
import site
import subprocess
import sys


def test_installed_package_is_on_the_prefixes_path_and_loads_its_own_plugins(tmp_path):
    prefix = tmp_path / "prefix"
    run = subprocess.run(
        ["cmake", "--install", os.environ["MNEEDLE_BUILD_DIR"], "--prefix", str(prefix)],
        capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    package = next(prefix.glob("lib/python3*/dist-packages/mneedle"))
    # Where this Python searches for packages installed under that prefix (Debian: the
    # prefix's lib/python3.X/dist-packages), so no PYTHONPATH is needed for /usr/local.
    assert str(package.parent) in site.getsitepackages([str(prefix)])
    code = ("import mneedle; print(mneedle.__file__); print(mneedle.PLUGIN_DIR); "
            "print(mneedle.strength(plugin='cone', set={'diameter': '200um', "
            "'length': '600um'}, material='pla')['governing'])")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(package.parent)  # a temporary prefix is on no default path
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                         cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    file, plugins, governing = out.stdout.split("\n")[:3]
    assert file == str(package / "__init__.py")
    # The installed plugins, and only they: the C++ side is given this folder and no other.
    assert plugins == str(prefix / "lib" / "mneedle" / "plugins")
    assert (prefix / "lib" / "mneedle" / "plugins" / "cone.so").exists()
    assert governing in ("buckling", "strength")
