#!/usr/bin/env python3
"""examples/palpation as a new user runs it: the phantom made, palpated along a line, and the
stiffer inclusion found as a bump in the force. A control phantom with the inclusion made of the
tissue's own material shows no bump, so the bump is the inclusion's, not the block's shape.

Usage: palpation_example_test.py HAPTICSIM   (exit 0: passed; 1: what failed is printed)"""
import sys

from phantom_example import check_bump


def check_rows(summary, rows):
    if rows[0] != "x_mm,force_N" or len(rows) != 1 + summary["presses"] or summary["presses"] < 20:
        return ["the CSV has %d rows for %d presses" % (len(rows), summary["presses"])]
    return []


if __name__ == "__main__":
    sys.exit(check_bump(sys.argv[1], "palpate.py", check_rows, least_bump=0.05,
                        control_within=0.02))
