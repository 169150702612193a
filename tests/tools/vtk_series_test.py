#!/usr/bin/python3
"""hapticsim simulate --vtk read back with VTK's own reader (Debian's python3-vtk9).

Usage: vtk_series_test.py HAPTICSIM_CLI WORK_DIR

Runs the adaptive press of the default scene with --vtk, then checks each .vtu through
vtkXMLUnstructuredGridReader against what is independent of the writer: the press's own
trajectory at the touched node, the supports at zero, the von Mises stress recomputed here from
the points and displacements read back, the primary region around the touched node, and the
adaptive shape against the full-resolution reference's at the same times.

Then the same on examples/palpation's phantom (a NIfTI volume, two materials): its cells against
the voxels VTK's own NIfTI reader counts in the file, label by label, the held back face at zero,
the contact on the press, von Mises of each cell's own material.

And a stroke on the regions, whose primary follows the tool's proxy: frames of both runs at the
same times, the supports at zero, von Mises as recomputed, the dimple under the proxy within a
node spacing of the tool's own trajectory and inside the primary region, whose cells move along
with it, and the adaptive shape against the reference's.
"""
import json
import math
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ElementTree
from pathlib import Path

import numpy
import vtk
from vtk.util.numpy_support import vtk_to_numpy

N = 13            # the default cube: 13 nodes per axis, edge 0.25 m
EDGE = 0.25
TOUCHED = (6, 6, 0)
SUPPORTS = [(0, 0, 12), (12, 0, 12), (0, 12, 12), (12, 12, 12)]
E, NU = 10e3, 0.45
RATE = 20         # frames per simulated second


def point(ix, iy, iz):
    return (ix * N + iy) * N + iz


def fail(message):
    print("FAIL:", message)
    sys.exit(1)


def frames_of(pvd):
    root = ElementTree.parse(pvd).getroot()
    return [(float(d.get("timestep")), pvd.parent / d.get("file")) for d in root.iter("DataSet")]


def read(vtu, points=N ** 3, cells=(N - 1) ** 3):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(vtu))
    reader.Update()
    grid = reader.GetOutput()
    if grid.GetNumberOfPoints() != points or grid.GetNumberOfCells() != cells:
        fail(f"{vtu}: {grid.GetNumberOfPoints()} points, {grid.GetNumberOfCells()} cells")
    if any(grid.GetCellType(c) != vtk.VTK_HEXAHEDRON for c in range(grid.GetNumberOfCells())):
        fail(f"{vtu}: a cell is not a hexahedron")
    return {
        "points": vtk_to_numpy(grid.GetPoints().GetData()),
        "u": vtk_to_numpy(grid.GetPointData().GetArray("displacement_m")),
        "von_mises": vtk_to_numpy(grid.GetCellData().GetArray("von_mises_pa")),
        "region": vtk_to_numpy(grid.GetCellData().GetArray("region")),
        "material": vtk_to_numpy(grid.GetCellData().GetArray("material")),
        "cells": [[grid.GetCell(c).GetPointId(k) for k in range(8)]
                  for c in range(grid.GetNumberOfCells())],
    }


def von_mises(frame, youngs=None):
    """Recomputed here: the trilinear cell's strain at its centre from its 8 corners' values;
    `youngs[c]` the Young's modulus of cell c (default: E everywhere)."""
    out = []
    for c, corners in enumerate(frame["cells"]):
        e = E if youngs is None else youngs[c]
        lam = e * NU / ((1 + NU) * (1 - 2 * NU))
        mu = e / (2 * (1 + NU))
        x = frame["points"][corners]
        u = frame["u"][corners]
        lo, hi = x.min(axis=0), x.max(axis=0)
        # ∂N_k/∂x at the centre of the box [lo, hi] for corner k.
        grad = numpy.zeros((3, 3))
        for k in range(8):
            sign = numpy.where(x[k] > (lo + hi) / 2, 1.0, -1.0)
            dn = sign / (4.0 * (hi - lo))
            grad += numpy.outer(u[k], dn)
        strain = (grad + grad.T) / 2
        stress = 2 * mu * strain + lam * numpy.trace(strain) * numpy.eye(3)
        deviator = stress - numpy.trace(stress) / 3 * numpy.eye(3)
        out.append(math.sqrt(1.5 * numpy.sum(deviator * deviator)))
    return numpy.array(out)


def main():
    cli, work = sys.argv[1], Path(sys.argv[2])
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    run = subprocess.run([cli, "simulate", "--set", "adaptivity.primary_size=2", "--vtk",
                          str(work), "--vtk-rate", str(RATE)], capture_output=True, text=True)
    if run.returncode != 0:
        fail(f"simulate --vtk exited {run.returncode}: {run.stderr}")
    runs = {name: frames_of(work / f"{name}.pvd") for name in ("adaptive", "reference")}
    for name, frames in runs.items():
        # A 1 s press at 20 frames per second: t = 0, 0.05, …, 1.
        if [round(t, 9) for t, _ in frames] != [round(k / RATE, 9) for k in range(RATE + 1)]:
            fail(f"{name}: frame times {[t for t, _ in frames]}")
    worst_shape = 0.0
    for (t, adaptive_file), (_, reference_file) in zip(runs["adaptive"], runs["reference"]):
        adaptive, reference = read(adaptive_file), read(reference_file)
        depth = 0.01 * (1 - math.cos(2 * math.pi * t)) / 2  # the press, along +z at the front
        for name, frame in (("adaptive", adaptive), ("reference", reference)):
            expected_rest = numpy.array(TOUCHED) * EDGE / (N - 1)
            if not numpy.allclose(frame["points"][point(*TOUCHED)], expected_rest, atol=1e-15):
                fail(f"{name} t={t}: the touched node is not at its rest position")
            touched = frame["u"][point(*TOUCHED)]
            if abs(touched[2] - depth) > 1e-12 or abs(touched[0]) + abs(touched[1]) > 1e-15:
                fail(f"{name} t={t}: touched node at {touched}, the press is at {depth}")
            for s in SUPPORTS:
                if numpy.any(frame["u"][point(*s)] != 0):
                    fail(f"{name} t={t}: support {s} moved: {frame['u'][point(*s)]}")
            mine = von_mises(frame)
            scale = max(1e-9, float(numpy.max(mine)))
            if numpy.max(numpy.abs(mine - frame["von_mises"])) > 1e-9 * scale:
                fail(f"{name} t={t}: von Mises differs from the recomputation by "
                     f"{numpy.max(numpy.abs(mine - frame['von_mises']))} Pa")
        if numpy.any(reference["region"] != 0):
            fail("the reference has a region other than 0")
        # The touched node's cells are the primary's; the far back corner's a secondary's.
        touched_cell = (6 * (N - 1) + 6) * (N - 1) + 0
        far_cell = (0 * (N - 1) + 11) * (N - 1) + 11
        if adaptive["region"][touched_cell] != 0 or adaptive["region"][far_cell] < 1:
            fail(f"regions: touched cell {adaptive['region'][touched_cell]}, "
                 f"far cell {adaptive['region'][far_cell]}")
        if t > 0:
            difference = numpy.max(numpy.linalg.norm(adaptive["u"] - reference["u"], axis=1))
            largest = numpy.max(numpy.linalg.norm(reference["u"], axis=1))
            worst_shape = max(worst_shape, difference / largest)
    # The adaptive shape follows the reference's: its largest difference at any node, against
    # the reference's largest displacement at that time (the force error of this configuration
    # is a few %; measured 2-4 %).
    if worst_shape > 0.1:
        fail(f"the adaptive shape is {worst_shape:.1%} of the largest displacement from the "
             "reference's")
    print(f"vtk: {len(runs['adaptive'])} frames per run read back with VTK "
          f"{vtk.vtkVersion.GetVTKVersion()}; the touched node on the press, supports at zero, "
          f"von Mises as recomputed; adaptive shape within {worst_shape:.1%} of the reference's "
          f"largest displacement")


def nifti_labels(path):
    """The label of every voxel as VTK's own NIfTI reader reads it, indexed [z, y, x]."""
    reader = vtk.vtkNIFTIImageReader()
    reader.SetFileName(str(path))
    reader.Update()
    image = reader.GetOutput()
    nx, ny, nz = image.GetDimensions()
    return vtk_to_numpy(image.GetPointData().GetScalars()).reshape(nz, ny, nx)


def check_phantom(cli, work):
    """The palpation phantom at 5 mm voxels: 16 x 8 x 6, an inclusion 8x stiffer (label 2)."""
    examples = Path(__file__).resolve().parents[2] / "examples" / "palpation"
    subprocess.run(["/usr/bin/python3", str(examples / "make_phantom.py"), str(work / "phantom.nii"),
                    "--voxel-mm", "5"], check=True, capture_output=True)
    shutil.copy(examples / "palpation.toml", work / "palpation.toml")
    scene = ["--scene", str(work / "palpation.toml")]
    static = subprocess.run([cli, "static", "--json"] + scene, capture_output=True, text=True)
    if static.returncode != 0:
        fail(f"static: {static.stderr}")
    facts = json.loads(static.stdout)
    nx, ny, nz = facts["lattice_nodes"]
    contact = facts["contact_node"]
    out = work / "phantom-vtk"
    run = subprocess.run([cli, "simulate"] + scene + ["--set", "adaptivity.primary_size=2",
                          "--set", "adaptivity.secondary_rate=1000", "--vtk", str(out),
                          "--vtk-rate", "5"], capture_output=True, text=True)
    if run.returncode != 0:
        fail(f"simulate --vtk on the phantom exited {run.returncode}: {run.stderr}")
    volume = nifti_labels(work / "phantom.nii")
    labels = numpy.bincount(volume.ravel())
    voxels = int(labels[1:].sum())
    spacing = 0.005
    for name in ("adaptive", "reference"):
        frames = frames_of(out / f"{name}.pvd")
        if [round(t, 9) for t, _ in frames] != [0.0, 0.2, 0.4, 0.6, 0.8, 1.0]:
            fail(f"phantom {name}: frame times {[t for t, _ in frames]}")
        for t, vtu in frames:
            frame = read(vtu, points=nx * ny * nz, cells=voxels)
            # Each cell is a voxel of the file, of its label's material ([[material]] label 1 is
            # material 0, label 2 material 1): the voxel at the cell's lowest corner.
            for c, corners in enumerate(frame["cells"]):
                x, y, z = numpy.rint(frame["points"][corners].min(axis=0) / spacing).astype(int)
                if frame["material"][c] != volume[z, y, x] - 1:
                    fail(f"phantom {name} t={t}: cell {c} at voxel {x, y, z} is material "
                         f"{frame['material'][c]}, the file's label there {volume[z, y, x]}")
            used = numpy.unique(numpy.array(frame["cells"]).ravel())
            back = used[numpy.isclose(frame["points"][used][:, 2], 0.03)]
            if len(back) == 0 or numpy.any(frame["u"][back] != 0):
                fail(f"phantom {name} t={t}: the held back face moved")
            depth = 0.003 * (1 - math.cos(2 * math.pi * t)) / 2
            touched = frame["u"][(contact[0] * ny + contact[1]) * nz + contact[2]]
            if abs(touched[2] - depth) > 1e-12:
                fail(f"phantom {name} t={t}: the contact at {touched}, the press at {depth}")
            youngs = numpy.where(frame["material"] == 1, 80e3, 10e3)
            mine = von_mises(frame, youngs)
            if numpy.max(numpy.abs(mine - frame["von_mises"])) > 1e-9 * max(1e-9, mine.max()):
                fail(f"phantom {name} t={t}: von Mises differs from the recomputation")
            if name == "adaptive" and not (numpy.any(frame["region"] == 0) and
                                           numpy.any(frame["region"] >= 1)):
                fail(f"phantom t={t}: regions {numpy.unique(frame['region'])}")
    print(f"vtk: the phantom's {voxels} voxels ({labels[2]} of the inclusion) read back as cells of "
          "their materials, the back face held, the contact on the press, von Mises per material")


def check_stroke(cli, work):
    """A stroke on the regions (the primary follows the proxy): 5 mm in, 60 mm along x."""
    out = work / "stroke-vtk"
    length, spacing = 0.06, EDGE / (N - 1)
    run = subprocess.run([cli, "simulate", "--set", "input.waveform=stroke", "--set",
                          "input.amplitude=0.005", "--set", f"input.stroke_length={length}",
                          "--set", "adaptivity.primary_size=3", "--vtk", str(out), "--vtk-rate",
                          str(RATE)], capture_output=True, text=True)
    if run.returncode != 0:
        fail(f"simulate --vtk of a stroke exited {run.returncode}: {run.stderr}")
    runs = {name: frames_of(out / f"{name}.pvd") for name in ("adaptive", "reference")}
    front = [point(ix, iy, 0) for ix in range(N) for iy in range(N)]
    primaries, worst_shape = [], 0.0
    for (t, adaptive_file), (t_reference, reference_file) in zip(runs["adaptive"],
                                                                 runs["reference"]):
        if round(t, 9) != round(t_reference, 9):
            fail(f"stroke: frames at {t} and {t_reference} s")
        frames = {"adaptive": read(adaptive_file), "reference": read(reference_file)}
        # The tool along x, by the stroke's own trajectory: in over the first quarter, then
        # L·(τ − sin 2πτ / 2π).
        tau = max(0.0, (t - 0.25) / 0.75)
        tool_x = EDGE / 2 + length * (tau - math.sin(2 * math.pi * tau) / (2 * math.pi))
        for name, frame in frames.items():
            for s in SUPPORTS:
                if numpy.any(frame["u"][point(*s)] != 0):
                    fail(f"stroke {name} t={t}: support {s} moved")
            if numpy.max(numpy.abs(von_mises(frame) - frame["von_mises"])) > \
                    1e-9 * max(1e-9, float(numpy.max(frame["von_mises"]))):
                fail(f"stroke {name} t={t}: von Mises differs from the recomputation")
            if t < 0.3:
                continue
            # The dimple under the proxy, which lags the tool by friction (μ_k × the depth): the
            # front face's deepest node within a spacing of the tool.
            deepest = max(front, key=lambda p: frame["u"][p][2])
            x = frame["points"][deepest][0]
            if abs(x - tool_x) > spacing:
                fail(f"stroke {name} t={t}: deepest front node at x = {x}, the tool at {tool_x}")
            if name == "adaptive":
                cells = [c for c, corners in enumerate(frame["cells"]) if deepest in corners]
                if any(frame["region"][c] != 0 for c in cells):
                    fail(f"stroke t={t}: the dimple at x = {x} is not in the primary region")
        if numpy.any(frames["reference"]["region"] != 0):
            fail("stroke: the reference has a region other than 0")
        adaptive_primary = frames["adaptive"]["region"] == 0
        primaries.append(numpy.mean([frames["adaptive"]["points"][frames["adaptive"]["cells"][c]]
                                     [:, 0].mean() for c in numpy.flatnonzero(adaptive_primary)]))
        if t > 0:
            difference = numpy.max(numpy.linalg.norm(frames["adaptive"]["u"] -
                                                     frames["reference"]["u"], axis=1))
            largest = numpy.max(numpy.linalg.norm(frames["reference"]["u"], axis=1))
            worst_shape = max(worst_shape, difference / largest)
    if len(primaries) != RATE + 1:
        fail(f"stroke: {len(primaries)} frames, not {RATE + 1}")
    if primaries[-1] - primaries[0] < spacing:
        fail(f"stroke: the primary region's cells stayed around x = {primaries[0]} m "
             f"(at the end {primaries[-1]} m)")
    if worst_shape > 0.1:
        fail(f"stroke: the adaptive shape is {worst_shape:.1%} of the largest displacement from "
             "the reference's")
    print(f"vtk: a stroke on the regions, {len(primaries)} frames per run; the dimple within a "
          f"spacing of the tool, in the primary; the primary's cells from x = {primaries[0]:.4f} "
          f"to {primaries[-1]:.4f} m; adaptive shape within {worst_shape:.1%} of the reference's")


if __name__ == "__main__":
    main()
    check_phantom(sys.argv[1], Path(sys.argv[2]))
    check_stroke(sys.argv[1], Path(sys.argv[2]))
