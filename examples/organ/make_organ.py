#!/usr/bin/env python3
"""Writes an organ-like ellipsoid as a closed binary STL surface, in millimetres.

Usage: make_organ.py OUT.stl [--rings 24] [--sectors 48]

The ellipsoid's semi-axes are 50, 35 and 25 mm along x, y and z, its centre at (50, 35, 25) mm, so
its bounding box runs from the origin to (100, 70, 50) mm: the front (z = 0) is the point the
tool meets first, the back cap (z near 50 mm) is where the scene holds it. The surface is a
latitude-longitude mesh with triangle fans at the poles; every vertex is written from one table,
so the edges two triangles share match to the digit and the surface is closed (hapticsim refuses
an open one). Written with the standard library only."""
import argparse
import math
import struct

CENTRE_MM = (50.0, 35.0, 25.0)
RADII_MM = (50.0, 35.0, 25.0)


def vertices(rings, sectors):
    """rows[r][s]: ring r from the front pole (z = 0) to the back pole, sector s around z."""
    rows = []
    for r in range(rings + 1):
        theta = math.pi * r / rings
        sin_t = 0.0 if r in (0, rings) else math.sin(theta)
        row = []
        for s in range(sectors):
            phi = 2 * math.pi * s / sectors
            row.append((CENTRE_MM[0] + RADII_MM[0] * sin_t * math.cos(phi),
                        CENTRE_MM[1] + RADII_MM[1] * sin_t * math.sin(phi),
                        CENTRE_MM[2] - RADII_MM[2] * math.cos(theta)))
        rows.append(row)
    return rows


def triangles(rings, sectors):
    rows = vertices(rings, sectors)
    for r in range(rings):
        low, high = rows[r], rows[r + 1]
        for s in range(sectors):
            t = (s + 1) % sectors
            if r != 0:  # the poles' rings are one point: one triangle of the quad there
                yield low[s], high[t], low[t]
            if r != rings - 1:
                yield low[s], high[s], high[t]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", help="the STL file to write")
    parser.add_argument("--rings", type=int, default=24, help="latitude bands (default 24)")
    parser.add_argument("--sectors", type=int, default=48, help="longitude sectors (default 48)")
    args = parser.parse_args()
    faces = list(triangles(args.rings, args.sectors))
    with open(args.out, "wb") as out:
        out.write(b"organ-like ellipsoid, mm (examples/organ/make_organ.py)".ljust(80, b" "))
        out.write(struct.pack("<I", len(faces)))
        for triangle in faces:  # the normal left zero: readers take the winding's
            out.write(struct.pack("<12fH", 0, 0, 0, *(c for v in triangle for c in v), 0))
    count = len(faces)
    print("%s: an ellipsoid of %g x %g x %g mm, %d triangles" % (
        args.out, *(2 * r for r in RADII_MM), count))


if __name__ == "__main__":
    main()
