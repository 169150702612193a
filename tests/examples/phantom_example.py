"""What the palpation examples' tests share: an example script run as a new user runs it, on a
phantom made next to the scene, once with the example's inclusion and once on a control phantom
whose inclusion is as soft as the tissue (no bump there: the bump is the inclusion's, not the
block's shape or the method's)."""
import json
import os
import shutil
import subprocess
import sys
import tempfile

EXAMPLE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "examples",
                       "palpation")


def run_on_phantom(hapticsim, folder, scene_text, script, extra_args=()):
    """Makes the phantom and the scene in `folder`, runs examples/palpation/`script` on them (with
    `extra_args`) and returns its printed summary and its CSV's lines."""
    os.makedirs(folder)
    subprocess.run([sys.executable, os.path.join(EXAMPLE, "make_phantom.py"),
                    os.path.join(folder, "phantom.nii")], check=True, capture_output=True)
    scene = os.path.join(folder, "palpation.toml")
    with open(scene, "w") as f:
        f.write(scene_text)
    result = subprocess.run([sys.executable, os.path.join(EXAMPLE, script), "--hapticsim",
                             hapticsim, "--scene", scene, "--out", os.path.join(folder, "out"),
                             *extra_args],
                            capture_output=True, text=True)
    if result.returncode != 0:
        raise SystemExit("%s failed:\n%s" % (script, result.stderr))
    summary = json.loads(result.stdout)
    with open(summary["csv"]) as f:
        rows = f.read().splitlines()
    return summary, rows


def check_bump(hapticsim, script, check_rows, least_bump, control_within, extra_args=(),
               check_control=lambda summary: []):
    """The test: `check_rows(summary, rows)` returns what is wrong with the run's output, and
    `check_control(summary)` what is wrong with the control's; the inclusion must raise the force
    by more than `least_bump` (a fraction), the control's ratio stay within `control_within` of
    one. `extra_args` go to the script. Returns the exit status, printing what failed."""
    with open(os.path.join(EXAMPLE, "palpation.toml")) as f:
        scene_text = f.read()
    failures = []
    work = tempfile.mkdtemp(prefix="palpation-")
    try:
        summary, rows = run_on_phantom(hapticsim, os.path.join(work, "inclusion"), scene_text,
                                       script, extra_args)
        print("with the inclusion:", json.dumps(summary))
        failures += check_rows(summary, rows)
        if not summary["force_over_inclusion_N"] > (1 + least_bump) * summary[
                "force_over_plain_tissue_N"]:
            failures.append("no bump over the inclusion: %s" % summary)
        if not os.path.getsize(summary["plot"]) > 1000:
            failures.append("the plot %s is empty" % summary["plot"])
        control_text = scene_text.replace("youngs_modulus = 80000.0", "youngs_modulus = 10000.0")
        if control_text == scene_text:
            failures.append("the example's scene no longer sets the inclusion to 80000 Pa")
        control, _ = run_on_phantom(hapticsim, os.path.join(work, "control"), control_text, script,
                                    extra_args)
        print("inclusion as soft as the tissue:", json.dumps(control))
        failures += check_control(control)
        if not abs(control["ratio"] - 1) < control_within:
            failures.append("the control phantom shows a bump of %.3f" % control["ratio"])
    finally:
        shutil.rmtree(work)
    for failure in failures:
        print("FAILED:", failure)
    return 1 if failures else 0
