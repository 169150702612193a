#!/usr/bin/env python3
"""Strokes the phantom: a tool with a 5 mm tip pressed input.amplitude deep into the front face and
slid 60 mm along x across the inclusion, on the asynchronous regions whose primary region follows
the sliding proxy (hapticsim simulate with input.waveform = "stroke"), and draws the force against
the tool's position, so the stiffer inclusion shows as a bump.

Usage: stroke.py [--hapticsim PATH] [--scene FILE.toml] [--out DIR]

Writes DIR/stroke.csv (the tool's x in mm, the normal and the lateral force on the user in N, one
row per millisecond of the slide) and DIR/stroke.svg, and prints the normal force over the
inclusion's centre against plain tissue (x = 15 and 65 mm; each the mean within 2.5 mm), with
the scene's friction.
Make the phantom first: python3 make_phantom.py phantom.nii (next to the scene)."""
import csv
import json
import math
import os
import subprocess
import sys

from palpate import parse_args, svg

# The stroke: from node 4 of the middle row (x = 10 mm), 60 mm along +x, over 2 s (the first
# quarter presses, the rest slides), with a 5 mm tip: on the phantom's 2.5 mm voxels a tip on one
# cell's nodes runs away (docs/model.md), a tip two voxels wide does not.
STROKE = ["input.waveform=stroke", "input.contact_node=4,8,0", "input.stroke_length=0.06",
          "input.frequency=0.5", "contact.radius=0.005", "adaptivity.primary_size=3"]


def main():
    args = parse_args(__doc__, "stroke-out")

    series = os.path.join(args.out, "simulate.csv")
    command = [args.hapticsim, "simulate", "--scene", args.scene, "--json", "--out", series]
    for setting in STROKE:
        command += ["--set", setting]
    print("stroke: " + " ".join(command), file=sys.stderr)
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit("stroke: hapticsim simulate failed:\n" + result.stderr.strip())
    run = json.loads(result.stdout)
    if run["outcome"] != "completed":
        sys.exit("stroke: the stroke did not complete: %s" % run["outcome"])

    # The tool starts at the contact node, 10 mm along x; the series gives its displacement.
    start_mm = 4 * 2.5
    points, lateral = [], []
    with open(series) as f:
        rows = csv.reader(f)
        next(rows)
        for row in rows:
            t, dx, _, _, fx, fy, fz = (float(v) for v in row)
            if dx <= 0:
                continue  # still pressing: the slide starts once the tool moves
            points.append((start_mm + dx * 1e3, -fz))  # the face's inward normal is +z
            lateral.append(math.hypot(fx, fy))
    with open(os.path.join(args.out, "stroke.csv"), "w") as f:
        f.write("x_mm,normal_force_N,lateral_force_N\n")
        for (x, normal), side in zip(points, lateral):
            f.write("%.6g,%.9g,%.9g\n" % (x, normal, side))
    plot = os.path.join(args.out, "stroke.svg")
    svg(points[::10], plot, (32.5, 47.5),
        "Stroke: normal force against the tool's position (a 5 mm tip sliding 60 mm)")

    def at(x_mm):
        # The mean over a voxel either side: one sample is one moment of stick and slip.
        near = [force for x, force in points if abs(x - x_mm) <= 2.5]
        return sum(near) / len(near)

    plain = (at(15.0) + at(65.0)) / 2
    print(json.dumps({"samples": len(points), "primary_moves": run.get("primary_moves"),
                      "force_over_inclusion_N": at(40.0), "force_over_plain_tissue_N": plain,
                      "ratio": at(40.0) / plain, "largest_lateral_N": max(lateral),
                      "csv": os.path.join(args.out, "stroke.csv"), "plot": plot}, indent=2))


if __name__ == "__main__":
    main()
