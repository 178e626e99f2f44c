#!/usr/bin/env python3
"""Lists the pins of a logged test run whose value the code no longer reads exactly.

A pin is an EXPECT_NEAR whose expected value is a number written in the test (not 1, not a
computed reference): a measured value of our own code, held within a tolerance. A pin that
passes while the code reads it 0.2 % away with a 1 % tolerance hides a move; this lists every
such pin, largest share of its tolerance first. Comparisons against closed forms and ratios to 1
are listed apart with --all (their distance is a discretisation error, stated in each test).
A pin is recognised by the number written in the EXPECT_NEAR itself: a pin written through a
variable (a table of values looped over) is listed only with --all; a comparison made in a loop
is listed once, at its worst.

usage: pin_audit.py LOG [--min-deviation 5e-4] [--all]
"""
import argparse
import re
import sys

NUMBER = re.compile(r"-?[0-9]*\.?[0-9]+(e-?[0-9]+)?")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("log")
    parser.add_argument("--min-deviation", type=float, default=5e-4,
                        help="smallest relative distance from the pin to list (default 5e-4)")
    parser.add_argument("--all", action="store_true",
                        help="also list comparisons whose expected value is computed or 1")
    args = parser.parse_args()
    worst = {}
    for line in open(args.log, errors="replace"):
        fields = line.rstrip("\n").split("\t")
        if len(fields) != 7:
            continue
        test, actual_text, expected_text, tolerance_text = fields[:4]
        try:
            actual, expected, tolerance = map(float, fields[4:])
        except ValueError:
            continue
        if expected == 0 or tolerance <= 0:
            continue
        pin = bool(NUMBER.fullmatch(expected_text.strip())) and expected != 1.0
        if not (pin or args.all):
            continue
        deviation = abs(actual - expected) / abs(expected)
        key = (test, actual_text, expected_text)
        if key not in worst or deviation > worst[key][0]:
            worst[key] = (deviation, tolerance / abs(expected), actual, expected, pin)
    rows = [(abs(a - e) / (t * abs(e)) if t else 0.0, k, d, t, a, e, p)
            for k, (d, t, a, e, p) in worst.items() if d >= args.min_deviation]
    rows.sort(key=lambda r: -r[0])
    for share, (test, actual_text, expected_text), d, t, a, e, pin in rows:
        kind = "pin " if pin else "ref "
        print(f"{kind}{share:5.2f} of tolerance  off {d * 100:.3f} % (tolerance {t * 100:.2f} %)  "
              f"{test}\n      {actual_text[:80]} = {a:.7g}, written {expected_text[:40]}")
    print(f"{len(rows)} of {len(worst)} comparisons listed", file=sys.stderr)


if __name__ == "__main__":
    main()
