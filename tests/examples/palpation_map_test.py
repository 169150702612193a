#!/usr/bin/env python3
"""examples/palpation's error map as a new user makes it (at 5 mm voxels, as docs/error-map.md
does): the sweep over the inclusion's stiffness contrast runs, and what it records holds up
against what must hold whatever the code:

- contrast 1 is the phantom as one tissue: its samples are those of the same block swept with
  one material and no [[material]] tables, bit for bit;
- a stiffer inclusion makes the press stiffer, but less than stiffening the whole block would:
  the reference peak force rises with the contrast, by less than the contrast's ratio;
- the lookup between mapped contrasts lies between their errors;
- and what docs/error-map.md reports of it: a small primary with a 600 Hz secondary diverges at
  contrast 8, while the largest primary is within 1 % at every contrast.

Usage: palpation_map_test.py HAPTICSIM   (exit 0: passed; 1: what failed is printed)"""
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile

EXAMPLE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples",
                       "palpation")
ONE_TISSUE = """[geometry]
file = "phantom.nii"
[input]
amplitude = 0.003
[[support]]
plane_point = [0.0, 0.0, 0.03]
plane_normal = [0.0, 0.0, 1.0]
"""


def run(command):
    """The command's standard output; on failure, its standard error is raised with it."""
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError("%s exited %d: %s" % (" ".join(command), result.returncode,
                                                 result.stderr))
    return result.stdout


def sweep(hapticsim, work, scene, grid, name):
    out = os.path.join(work, name + ".hsmap")
    run([hapticsim, "sweep", "--scene", scene, "--set", "geometry.spacing_m=0.005", "--grid",
         grid, "--out", out])
    table = os.path.join(work, name + ".csv")
    run([hapticsim, "map", "export", out, "--csv", table])
    with open(table) as f:
        return out, list(csv.DictReader(f))


def lookup(hapticsim, path, contrast):
    answer = json.loads(run([hapticsim, "lookup", path, "--json", "--set", "primary_size=3",
                             "--set", "secondary_rate=1000", "--set",
                             "material_contrast=%g" % contrast]))
    return answer["error"]


def main():
    hapticsim = sys.argv[1]
    failures = []
    work = tempfile.mkdtemp(prefix="palpation-map-")
    try:
        check(hapticsim, work, failures)
    except RuntimeError as error:
        failures.append(str(error))
    finally:
        shutil.rmtree(work)
    for failure in failures:
        print("FAILED:", failure)
    return 1 if failures else 0


def check(hapticsim, work, failures):
    """Appends to `failures` what does not hold of the map made in `work`."""
    subprocess.run([sys.executable, os.path.join(EXAMPLE, "make_phantom.py"),
                    os.path.join(work, "phantom.nii")], check=True, capture_output=True)
    shutil.copy(os.path.join(EXAMPLE, "palpation.toml"), work)
    grid = os.path.join(EXAMPLE, "contrast.toml")
    path, rows = sweep(hapticsim, work, os.path.join(work, "palpation.toml"), grid, "contrast")
    if len(rows) != 18:
        failures.append("%d samples, not 18" % len(rows))
    one_scene = os.path.join(work, "one-tissue.toml")
    with open(one_scene, "w") as f:
        f.write(ONE_TISSUE)
    one_grid = os.path.join(work, "one-grid.toml")
    with open(one_grid, "w") as f:
        f.write("[axes]\nprimary_size = [1, 2, 3]\nsecondary_rate = [600.0, 1000.0]\n")
    _, one = sweep(hapticsim, work, one_scene, one_grid, "one-tissue")

    def rows_at(contrast):
        return [r for r in rows if float(r["material_contrast"]) == contrast]

    fields = ("primary_size", "secondary_rate_Hz", "status", "l2_percent",
              "max_magnitude_percent", "reference_peak_N")
    if [[r[k] for k in fields] for r in rows_at(1)] != [[r[k] for k in fields] for r in one]:
        failures.append("contrast 1 is not the one-tissue map: %s vs %s" % (rows_at(1), one))
    peak = {c: float(rows_at(c)[0]["reference_peak_N"]) for c in (1, 4, 8)}
    print("reference peak force at contrast 1, 4, 8: %s N" % peak)
    if not peak[1] < peak[4] < peak[8]:
        failures.append("the press does not stiffen with the inclusion: %s" % peak)
    if not (peak[4] < 4 * peak[1] and peak[8] < 2 * peak[4]):
        failures.append("the press stiffens more than the contrast: %s" % peak)
    for r in rows:
        if r["primary_size"] == "3" and not (r["status"] == "ok" and
                                             float(r["max_magnitude_percent"]) < 1):
            failures.append("primary size 3 is not within 1 %%: %s" % r)
    diverged = [r for r in rows_at(8) if r["status"] == "diverged"]
    if sorted((r["primary_size"], r["secondary_rate_Hz"]) for r in diverged) != \
            [("1", "600"), ("2", "600")]:
        failures.append("docs/error-map.md says r 1 and 2 at 600 Hz diverge at contrast 8: %s"
                        % [(r["primary_size"], r["secondary_rate_Hz"]) for r in diverged])
    at = {c: lookup(hapticsim, path, c) for c in (4, 6, 8)}
    print("lookup at contrast 4, 6, 8 (r 3, 1000 Hz): %s %%" % at)
    if not min(at[4], at[8]) < at[6] < max(at[4], at[8]):
        failures.append("the lookup at contrast 6 is not between 4's and 8's: %s" % at)


if __name__ == "__main__":
    sys.exit(main())
