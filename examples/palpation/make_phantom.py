#!/usr/bin/env python3
"""Writes a palpation phantom as a labelled NIfTI-1 volume: a soft block (label 1) with a stiffer
spherical inclusion (label 2) under its front face z = 0, the face a tool presses.

Usage: make_phantom.py OUT.nii [--voxel-mm 2.5]

The block is 80 x 40 x 30 mm (x, y, z); the inclusion, radius 7.5 mm, is centred at
x = 40 mm, y = 20 mm, 11.25 mm below the front face (its top 3.75 mm deep). The header's sform
puts the block's lowest corner at the origin, in millimetres, so a support plane at z = 30 mm is
its back face. Written with the standard library only (the header is NIfTI-1's 348 bytes)."""
import argparse
import struct

BLOCK_MM = (80.0, 40.0, 30.0)
INCLUSION_CENTRE_MM = (40.0, 20.0, 11.25)
INCLUSION_RADIUS_MM = 7.5


def header(dims, voxel_mm):
    h = bytearray(348)
    struct.pack_into("<i", h, 0, 348)                      # sizeof_hdr
    struct.pack_into("<8h", h, 40, 3, *dims, 1, 1, 1, 1)   # dim: 3-D
    struct.pack_into("<hh", h, 70, 2, 8)                   # datatype uint8, bitpix 8
    struct.pack_into("<8f", h, 76, 1.0, voxel_mm, voxel_mm, voxel_mm, 1, 1, 1, 1)  # pixdim
    struct.pack_into("<f", h, 108, 352.0)                  # vox_offset: header + extension flag
    struct.pack_into("<f", h, 112, 1.0)                    # scl_slope 1, scl_inter 0: no scaling
    h[123] = 2                                             # xyzt_units: millimetres
    struct.pack_into("<hh", h, 252, 0, 1)                  # qform_code 0, sform_code 1 (scanner)
    half = voxel_mm / 2  # voxel centres at (i + ½)·voxel: the block's corner at the origin
    struct.pack_into("<4f", h, 280, voxel_mm, 0, 0, half)
    struct.pack_into("<4f", h, 296, 0, voxel_mm, 0, half)
    struct.pack_into("<4f", h, 312, 0, 0, voxel_mm, half)
    h[344:348] = b"n+1\0"
    return bytes(h)


def labels(dims, voxel_mm):
    out = bytearray()
    for z in range(dims[2]):
        for y in range(dims[1]):
            for x in range(dims[0]):
                centre = [(i + 0.5) * voxel_mm for i in (x, y, z)]
                d2 = sum((c - m) ** 2 for c, m in zip(centre, INCLUSION_CENTRE_MM))
                out.append(2 if d2 <= INCLUSION_RADIUS_MM ** 2 else 1)
    return bytes(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", help="the .nii file to write")
    parser.add_argument("--voxel-mm", type=float, default=2.5, help="voxel edge, mm (default 2.5)")
    args = parser.parse_args()
    dims = tuple(round(extent / args.voxel_mm) for extent in BLOCK_MM)
    with open(args.out, "wb") as f:
        f.write(header(dims, args.voxel_mm) + b"\0\0\0\0" + labels(dims, args.voxel_mm))
    print(f"{args.out}: {dims[0]} x {dims[1]} x {dims[2]} voxels of {args.voxel_mm} mm, "
          f"inclusion radius {INCLUSION_RADIUS_MM} mm at {INCLUSION_CENTRE_MM} mm")


if __name__ == "__main__":
    main()
