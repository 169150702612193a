#!/usr/bin/python3
"""hapticsim view of an object that leaves voxels of its lattice empty, in a real headless
Chromium, on a real daemon and a real LCM bus: examples/organ/ (an ellipsoid drawn as an STL,
voxelised at 5 mm), served by hapticsimd, pressed 4 mm at its middle by the simulated device.

Runs inside a private network namespace (tests/support/in_private_netns.sh).

Checks:
  - without --scene the page cannot know the organ's faces from its surface nodes: it says so,
    naming --scene, and counts the surface nodes it drew on no face;
  - with --scene (the daemon's scene) every surface node the daemon sends is on a face drawn, and
    the faces drawn close up: every edge is shared by an even number of them (two, or four where
    two voxels meet only along an edge);
  - a screenshot shows the object, and during the press the surface under the tool is drawn at
    the tool's depth; no console error.

Usage: view_object_test.py HAPTICSIMD HAPTICSIM EXAMPLES_DIR WORK_DIR
"""
import collections
import os
import signal
import subprocess
import sys
import time

from PIL import Image

from view_browser import Work, changed_fraction, headless_chromium, panel_on_screenshot

daemon_bin, cli, examples, work = sys.argv[1:5]
scene = os.path.join(examples, "organ", "organ.toml")
folder = Work(work)
start, fail, wait_for = folder.start, folder.fail, folder.wait_for


def start_view(extra, log_name):
    view = start([cli, "view", "--port", "0", "--open", "no", *extra], log_name,
                 stdout=subprocess.PIPE)
    line = view.stdout.readline()
    if "serving http://127.0.0.1:" not in line:
        fail(f"hapticsim view did not say where it serves: {line!r}")
    return view, line.split("serving ")[1].split()[0]


def open_page(browser, url):
    browser.get(url)
    wait_for("3 surface frames on the page",
             lambda: int(browser.find_element("tag name", "body").get_attribute("data-frames")) >= 3,
             30)
    return browser.execute_script("return window.hapticsimView.surfaceDrawn()")


try:
    config = os.path.join(work, "daemon.toml")
    with open(config, "w") as f:
        f.write(f'[scene]\nfile = "{scene}"\n')
    start([daemon_bin, "--config", config], "daemon.log")
    plain_view, plain_url = start_view([], "view-plain.log")
    scene_view, scene_url = start_view(["--scene", scene], "view-scene.log")

    browser = headless_chromium(work)
    try:
        plain = open_page(browser, plain_url)
        text = browser.find_element("id", "surface").text
        print(f"without --scene: {len(plain['quads']) // 4} squares drawn, "
              f"{plain['undrawnNodes']} of {len(plain['nodeIds'])} surface nodes on none: {text!r}")
        if plain["undrawnNodes"] < len(plain["nodeIds"]) // 2 or "--scene" not in text:
            fail("without --scene the page does not say it cannot draw the organ's faces")

        drawn = open_page(browser, scene_url)
        quads, ids = drawn["quads"], drawn["nodeIds"]
        edges = collections.Counter()
        for q in range(0, len(quads), 4):
            for k in range(4):
                a, b = quads[q + k], quads[q + (k + 1) % 4]
                edges[min(a, b), max(a, b)] += 1
        odd = sum(1 for count in edges.values() if count % 2)
        print(f"with --scene: {len(quads) // 4} faces drawn over {len(set(quads))} of the "
              f"{len(ids)} surface nodes; {len(edges)} edges, {odd} of them on an odd number "
              "of faces")
        if drawn["undrawnNodes"] != 0 or set(quads) != set(ids):
            fail("the faces drawn leave surface nodes out")
        if odd:
            fail("the faces drawn do not close up")
        time.sleep(0.5)
        shot = os.path.join(work, "organ.png")
        browser.save_screenshot(shot)
        panel, _ = panel_on_screenshot(browser)
        shown = changed_fraction(Image.open(shot), panel)
        print(f"{100 * shown:.1f} % of the picture outside the panel is the organ")
        if shown < 0.05:
            fail("the screenshot does not show the organ")

        # 4 mm presses at the organ's middle, 4 s each: the surface under the tool at its depth.
        device = start([cli, "device", "--scene", scene, "--input", "press", "--amplitude",
                        "0.004", "--frequency", "0.25", "--duration", "12"], "device.log")
        state_js = ("const v = window.hapticsimView, s = v.state; return {"
                    "contact: s.deformation && s.deformation.in_contact,"
                    "toolZ: s.toolPosition ? s.toolPosition[2] : null,"
                    "surface: v.surfaceAtTouchedNode()};")
        pressed = lambda: (lambda s: s["contact"] and s["toolZ"] is not None and s["toolZ"] > 0.0035 and s)(
            browser.execute_script(state_js))
        s = wait_for("the press to reach 3.5 mm on the page", pressed, 15)
        browser.save_screenshot(os.path.join(work, "organ-pressed.png"))
        mesh_z = [v[2] for v in s["surface"]]
        print(f"tool at {1e3 * s['toolZ']:.2f} mm; the surface mesh has the touched node in "
              f"{len(mesh_z)} vertices, at {1e3 * min(mesh_z, default=0):.2f}–"
              f"{1e3 * max(mesh_z, default=0):.2f} mm")
        if len(mesh_z) < 6 or any(abs(z - s["toolZ"]) > 1e-3 for z in mesh_z):
            fail("the surface under the tool is not drawn at the tool's depth")
        errors = [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
        if errors:
            fail(f"console errors: {errors}")
        device.terminate()
        device.wait(timeout=10)
    finally:
        browser.quit()
    for view in (plain_view, scene_view):
        view.send_signal(signal.SIGINT)
        out, _ = view.communicate(timeout=10)
        if view.returncode != 0 or "(0 undecodable)" not in out:
            fail(f"hapticsim view did not stop cleanly: exit {view.returncode}, {out!r}")
    print("PASS")
finally:
    folder.stop_all()
