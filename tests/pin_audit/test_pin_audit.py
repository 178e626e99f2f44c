"""pin_audit.py on a log written by hand: which comparisons it lists, and in what order."""
import pathlib
import subprocess
import sys

SCRIPT = pathlib.Path(__file__).with_name("pin_audit.py")


def audit(tmp_path, lines, *options):
    log = tmp_path / "pins.tsv"
    log.write_text("".join("\t".join(map(str, line)) + "\n" for line in lines))
    run = subprocess.run([sys.executable, str(SCRIPT), str(log), *options], capture_output=True,
                         text=True, check=True)
    return run.stdout


def test_a_pin_read_away_from_its_written_value_is_listed_and_an_exact_one_is_not(tmp_path):
    out = audit(tmp_path, [
        ("S.Moved", "depth", "100.03e-6", "0.01 * 100.03e-6", 100.237e-6, 100.03e-6, 1.0003e-6),
        ("S.Exact", "force", "0.107392", "1e-6", 0.107392, 0.107392, 1e-6),
    ])
    assert "S.Moved" in out and "off 0.207 %" in out and "0.21 of tolerance" in out
    assert "S.Exact" not in out


def test_ratios_to_one_and_computed_references_only_with_all(tmp_path):
    lines = [
        ("S.Ratio", "fe / closed", "1.0", "0.05", 1.03, 1.0, 0.05),
        ("S.Computed", "fe", "closed", "0.02 * closed", 1.03, 1.0 / 0.99, 0.02),
    ]
    assert "S.Ratio" not in audit(tmp_path, lines)
    everything = audit(tmp_path, lines, "--all")
    assert "ref " in everything and "S.Ratio" in everything and "S.Computed" in everything


def test_largest_share_of_the_tolerance_first_and_each_comparison_once_at_its_worst(tmp_path):
    out = audit(tmp_path, [
        ("S.Small", "a", "2.0", "0.1", 2.01, 2.0, 0.1),
        ("S.Large", "b", "3.0", "0.1", 3.09, 3.0, 0.1),
        ("S.Small", "a", "2.0", "0.1", 2.05, 2.0, 0.1),
    ])
    assert out.index("S.Large") < out.index("S.Small")
    assert out.count("S.Small") == 1 and "off 2.500 %" in out


def test_lines_that_are_not_seven_fields_or_not_numbers_are_skipped(tmp_path):
    log = tmp_path / "pins.tsv"
    log.write_text("broken line\nS.X\ta\t2.0\t0.1\tnan-ish\t2\t0.1\nS.Y\tb\t2.0\t0.1\t2.1\t2\t0.1\n")
    out = subprocess.run([sys.executable, str(SCRIPT), str(log)], capture_output=True, text=True,
                         check=True).stdout
    assert "S.Y" in out and "S.X" not in out
