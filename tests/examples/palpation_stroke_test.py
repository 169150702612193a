#!/usr/bin/env python3
"""examples/palpation/stroke.py as a new user runs it: the phantom made, a tool stroked 60 mm across
its front face on the asynchronous regions (the primary region following the sliding proxy), and
the stiffer inclusion found as a bump in the normal force. A control phantom whose inclusion is as
soft as the tissue shows no bump, so the bump is the inclusion's, not the block's or the moves'.

Usage: palpation_stroke_test.py HAPTICSIM   (exit 0: passed; 1: what failed is printed)"""
import sys

from phantom_example import check_bump


def check_rows(summary, rows):
    wrong = []
    # 2 s at 1 kHz, the last three quarters sliding: 1,500 periods.
    if rows[0] != "x_mm,normal_force_N,lateral_force_N" or len(rows) != 1 + 1500:
        wrong.append("the CSV has %d rows, not a header and the slide's 1500 periods" % len(rows))
    if not summary["primary_moves"] >= 20:
        wrong.append("the primary moved %s times over 60 mm of 2.5 mm voxels"
                     % summary["primary_moves"])
    return wrong


if __name__ == "__main__":
    sys.exit(check_bump(sys.argv[1], "stroke.py", check_rows, least_bump=0.10,
                        control_within=0.03))
