#!/usr/bin/env python3
"""examples/palpation as a new user runs it: the phantom made, palpated along a line, and the
stiffer inclusion found as a bump in the force. A control phantom with the inclusion made of the
tissue's own material shows no bump, so the bump is the inclusion's, not the block's shape.

Usage: palpation_example_test.py HAPTICSIM   (exit 0: passed; 1: what failed is printed)"""
import json
import os
import shutil
import subprocess
import sys
import tempfile

EXAMPLE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples",
                       "palpation")


def palpate(hapticsim, folder, scene_text):
    os.makedirs(folder)
    subprocess.run([sys.executable, os.path.join(EXAMPLE, "make_phantom.py"),
                    os.path.join(folder, "phantom.nii")], check=True, capture_output=True)
    scene = os.path.join(folder, "palpation.toml")
    with open(scene, "w") as f:
        f.write(scene_text)
    out = os.path.join(folder, "out")
    result = subprocess.run([sys.executable, os.path.join(EXAMPLE, "palpate.py"), "--hapticsim",
                             hapticsim, "--scene", scene, "--out", out],
                            check=True, capture_output=True, text=True)
    summary = json.loads(result.stdout)
    with open(summary["csv"]) as f:
        rows = f.read().splitlines()
    return summary, rows


def main():
    hapticsim = sys.argv[1]
    with open(os.path.join(EXAMPLE, "palpation.toml")) as f:
        scene_text = f.read()
    failures = []
    work = tempfile.mkdtemp(prefix="palpation-")
    try:
        summary, rows = palpate(hapticsim, os.path.join(work, "inclusion"), scene_text)
        print("with the inclusion:", json.dumps(summary))
        if rows[0] != "x_mm,force_N" or len(rows) != 1 + summary["presses"] or summary["presses"] < 20:
            failures.append("the CSV has %d rows for %d presses" % (len(rows), summary["presses"]))
        if not summary["force_over_inclusion_N"] > 1.05 * summary["force_over_plain_tissue_N"]:
            failures.append("no bump over the inclusion: %s" % summary)
        if not os.path.getsize(summary["plot"]) > 1000:
            failures.append("the plot %s is empty" % summary["plot"])
        control_text = scene_text.replace("youngs_modulus = 80000.0", "youngs_modulus = 10000.0")
        if control_text == scene_text:
            failures.append("the example's scene no longer sets the inclusion to 80000 Pa")
        control, _ = palpate(hapticsim, os.path.join(work, "control"), control_text)
        print("inclusion as soft as the tissue:", json.dumps(control))
        if not 0.98 < control["ratio"] < 1.02:
            failures.append("the control phantom shows a bump of %.3f" % control["ratio"])
    finally:
        shutil.rmtree(work)
    for failure in failures:
        print("FAILED:", failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
