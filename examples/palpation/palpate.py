#!/usr/bin/env python3
"""Palpates the phantom: presses the front face at every node of a line across it (a static press
of input.amplitude each, hapticsim static) and draws the force against the position, so the
stiffer inclusion shows as a bump.

Usage: palpate.py [--hapticsim PATH] [--scene FILE.toml] [--out DIR]

Writes DIR/palpation.csv (x in m, force on the user in N) and DIR/palpation.svg, and prints the
force over the inclusion's centre against the force over plain tissue (x = 15 and 65 mm).
Make the phantom first: python3 make_phantom.py phantom.nii (next to the scene)."""
import argparse
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def press(hapticsim, scene, node=None):
    command = [hapticsim, "static", "--scene", scene, "--json"]
    if node is not None:
        command += ["--set", "input.contact_node=%d,%d,%d" % node]
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        sys.exit("palpate: %s failed:\n%s" % (" ".join(command), result.stderr.strip()))
    return json.loads(result.stdout)


def svg(points, path, band_mm, title=None):
    """A line chart of (x mm, force N), the inclusion's extent shaded: the standard library only."""
    title = title or "Palpation: force against position (%d static presses)" % len(points)
    width, height, left, bottom, top, right = 640, 360, 70, 50, 30, 20
    xs = [p[0] for p in points]
    ys = [p[1] for p in points]
    x0, x1, y0, y1 = min(xs), max(xs), 0.0, max(ys) * 1.1

    def px(x):
        return left + (x - x0) / (x1 - x0) * (width - left - right)

    def py(y):
        return height - bottom - (y - y0) / (y1 - y0) * (height - top - bottom)

    parts = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" '
             'font-family="sans-serif" font-size="12">' % (width, height),
             '<rect width="100%" height="100%" fill="white"/>',
             '<text x="%d" y="18" font-size="14">%s</text>' % (left, title)]
    parts.append('<rect x="%.1f" y="%d" width="%.1f" height="%d" fill="#f4d03f" opacity="0.3"/>'
                 % (px(band_mm[0]), top, px(band_mm[1]) - px(band_mm[0]), height - top - bottom))
    parts.append('<text x="%.1f" y="%d" text-anchor="middle">inclusion</text>'
                 % ((px(band_mm[0]) + px(band_mm[1])) / 2, top + 14))
    for i in range(6):
        y = y0 + (y1 - y0) * i / 5
        parts.append('<line x1="%d" x2="%d" y1="%.1f" y2="%.1f" stroke="#ddd"/>'
                     % (left, width - right, py(y), py(y)))
        parts.append('<text x="%d" y="%.1f" text-anchor="end">%.3g</text>' % (left - 6, py(y) + 4, y))
    for i in range(9):
        x = x0 + (x1 - x0) * i / 8
        parts.append('<text x="%.1f" y="%d" text-anchor="middle">%.0f</text>'
                     % (px(x), height - bottom + 18, x))
    parts.append('<text x="%d" y="%d" text-anchor="middle">position along the face, x (mm)</text>'
                 % ((left + width - right) / 2, height - 10))
    parts.append('<text x="16" y="%d" transform="rotate(-90 16 %d)" text-anchor="middle">'
                 'force on the user (N)</text>' % (height / 2, height / 2))
    line = " ".join("%.1f,%.1f" % (px(x), py(y)) for x, y in points)
    parts.append('<polyline points="%s" fill="none" stroke="#c0392b" stroke-width="2"/>' % line)
    parts.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(parts) + "\n")


def parse_args(doc, out, daemon=False):
    """The examples' command line: which hapticsim (and hapticsimd, for `daemon`), which scene,
    where to write (made)."""
    parser = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    parser.add_argument("--hapticsim", default=os.path.join(ROOT, "build", "tools", "hapticsim"))
    if daemon:
        parser.add_argument("--hapticsimd", help="default: next to --hapticsim's build folder, "
                            "daemon/hapticsimd")
        parser.add_argument("--no-map", action="store_true",
                            help="serve without an error map (the error is then unknown, -1)")
        parser.add_argument("--order", choices=["threads", "substeps"], default="threads",
                            help="the order the map's sweep steps the regions in (hapticsim sweep "
                            "--order; threads: as hapticsimd's threads do)")
    parser.add_argument("--scene", default=os.path.join(HERE, "palpation.toml"))
    parser.add_argument("--out", default=out)
    args = parser.parse_args()
    if daemon and not args.hapticsimd:
        build = os.path.dirname(os.path.dirname(os.path.abspath(args.hapticsim)))
        args.hapticsimd = os.path.join(build, "daemon", "hapticsimd")
    os.makedirs(args.out, exist_ok=True)
    return args


def main():
    args = parse_args(__doc__, "palpation-out")

    first = press(args.hapticsim, args.scene)
    nx, ny, _ = first["lattice_nodes"]
    row = ny // 2
    points = []
    for ix in range(1, nx - 1):  # the face's edges are left out: a corner is not palpated
        result = press(args.hapticsim, args.scene, (ix, row, 0))
        normal = result["contact_normal"]
        # The force on the user along the press, pushing back out: positive.
        force = -sum(f * n for f, n in zip(result["feedback_force_N"], normal))
        points.append((result["contact_position_m"][0] * 1e3, force))
        print("x = %6.2f mm: %.4f N" % points[-1], file=sys.stderr)

    with open(os.path.join(args.out, "palpation.csv"), "w") as f:
        f.write("x_mm,force_N\n")
        for x, force in points:
            f.write("%.6g,%.9g\n" % (x, force))
    svg(points, os.path.join(args.out, "palpation.svg"), (32.5, 47.5))
    def at(x_mm):
        return min(points, key=lambda p: abs(p[0] - x_mm))[1]

    # Over the inclusion's centre, against plain tissue halfway between it and either end.
    centre = (40.0, at(40.0))
    plain = (at(15.0) + at(65.0)) / 2
    print(json.dumps({"presses": len(points), "force_over_inclusion_N": centre[1],
                      "force_over_plain_tissue_N": plain,
                      "ratio": centre[1] / plain,
                      "csv": os.path.join(args.out, "palpation.csv"),
                      "plot": os.path.join(args.out, "palpation.svg")}, indent=2))


if __name__ == "__main__":
    main()
