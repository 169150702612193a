#!/usr/bin/python3
"""hapticsim view in a real headless Chromium, on a real daemon and a real LCM bus.

Runs inside a private network namespace (tests/support/in_private_netns.sh): hapticsimd, the
view's server, a simulated device pressing and Chromium all talk on its loopback only.

Checks:
  - the page loads without console errors (the browser's log has no SEVERE entry);
  - a screenshot shows the object (most of the picture outside the panel is not background);
  - a second screenshot taken during a press differs where the tool is (around the tool tip's
    point on the screen, and the change is centred near it); with the tool and the arrow hidden,
    the dent alone still changes the picture there; the surface mesh drawn under the tool is at
    the tool's depth (the touched node is held there);
  - the primary region drawn is the one the daemon's hybrid mesh makes: the coarse cells that
    overlap the contact node ± primary_size (core/regions/hybrid_mesh.cpp, CellOverlaps, written again
    here), holding as many independent nodes as the daemon's status reports for its primary;
  - the server answers only itself: other paths 404, another Host or Origin 403;
  - Ctrl-C stops it cleanly, every message decoded.

Usage: view_test.py HAPTICSIMD HAPTICSIM WORK_DIR [HAPTICSIMD ARGUMENTS...]
(docs/view.png is WORK_DIR/during.png of a run with --error-map MAP)
"""
import http.client
import json
import math
import os
import signal
import subprocess
import sys
import time

from PIL import Image, ImageChops

from view_browser import Work, changed_fraction, headless_chromium, outside_panel, panel_on_screenshot

daemon_bin, cli, work = sys.argv[1:4]
daemon_args = sys.argv[4:]
folder = Work(work)
start, fail, wait_for = folder.start, folder.fail, folder.wait_for


def request(port, path, headers):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=5)
    c.request("GET", path, headers=headers)
    r = c.getresponse()
    r.read()
    c.close()
    return r.status


try:
    start([daemon_bin, *daemon_args], "daemon.log")
    view = start([cli, "view", "--port", "0", "--open", "no"], "view.log", stdout=subprocess.PIPE)
    line = view.stdout.readline()
    if "serving http://127.0.0.1:" not in line:
        fail(f"hapticsim view did not say where it serves: {line!r}")
    url = line.split("serving ")[1].split()[0]
    port = int(url.rsplit(":", 1)[1].strip("/"))
    print("view at", url)

    # The server answers its own page only.
    host = {"Host": f"127.0.0.1:{port}"}
    assert request(port, "/", host) == 200
    assert request(port, "/three.module.js", host) == 200
    for path in ["/../../etc/passwd", "/etc/passwd", "/view.js/../x", "/node_modules/three"]:
        status = request(port, path, host)
        if status != 404:
            fail(f"GET {path} answered {status}, not 404")
    if request(port, "/", {"Host": "evil.example:80"}) != 403:
        fail("a request for another Host was not refused (DNS rebinding)")
    ws = {**host, "Upgrade": "websocket", "Connection": "Upgrade", "Sec-WebSocket-Version": "13",
          "Sec-WebSocket-Key": "dGhlIHNhbXBsZSBub25jZQ==", "Origin": "http://evil.example"}
    if request(port, "/feed", ws) != 403:
        fail("a WebSocket from another web site's Origin was not refused")

    browser = headless_chromium(work)
    try:
        browser.get(url)
        wait_for("5 surface frames on the page",
                 lambda: int(browser.find_element("tag name", "body").get_attribute("data-frames")) >= 5,
                 30)
        time.sleep(0.5)
        before_path = os.path.join(work, "before.png")
        browser.save_screenshot(before_path)
        panel, scale = panel_on_screenshot(browser)
        before = Image.open(before_path)
        shown = changed_fraction(before, panel)
        print(f"before the press: {100 * shown:.1f} % of the picture outside the panel is the object")
        if shown < 0.05:
            fail(f"the screenshot does not show the object ({100 * shown:.1f} % not background)")

        # The primary region the page draws against the daemon's rule, from the frame it drew,
        # and against the daemon's own count of the primary's nodes (status_t).
        wait_for("the daemon's status on the page",
                 lambda: browser.execute_script("return window.hapticsimView.state.status !== null"), 10)
        d, extent, status = browser.execute_script(
            "const v = window.hapticsimView;"
            "return [v.state.deformation, v.primaryExtent(), v.state.status];")
        n, k, r = d["nodes_per_axis"], max(1, d["secondary_lod"]), d["primary_size"]
        expected = {"lo": [], "hi": []}
        for c in d["contact_node"]:
            box_lo, box_hi = max(0, c - r), min(n - 1, c + r)
            cells = [j for j in range((n - 1) // k) if j * k < box_hi and (j + 1) * k > box_lo]
            expected["lo"].append(cells[0] * k)
            expected["hi"].append((cells[-1] + 1) * k)
        print(f"primary region drawn over lattice {extent}, the hybrid mesh's {expected}")
        if extent != expected:
            fail("the page draws another primary region than the daemon's")
        # Its independent nodes: every lattice node in the extent but those hanging on a face it
        # shares with the coarser secondary (there only the coarse lattice's nodes are its own).
        def independent(i, j, l):
            point = (i, j, l)
            on_interface = any(point[a] in (extent["lo"][a], extent["hi"][a]) and
                               point[a] not in (0, n - 1) for a in range(3))
            return not on_interface or all(v % k == 0 for v in point)
        counted = sum(independent(i, j, l)
                      for i in range(extent["lo"][0], extent["hi"][0] + 1)
                      for j in range(extent["lo"][1], extent["hi"][1] + 1)
                      for l in range(extent["lo"][2], extent["hi"][2] + 1))
        reported = next(r["nodes"] for r in status["regions"] if r["name"] == "primary")
        print(f"the primary drawn holds {counted} independent nodes; the daemon reports {reported}")
        if counted != reported:
            fail("the primary region drawn is not the daemon's")

        # 10 mm presses at the front face's centre, 8 s each, above 8 mm for 2.3 s of each: the
        # screenshots are taken in one of them; on a loaded machine that misses, in the next.
        device = start([cli, "device", "--input", "press", "--amplitude", "0.01",
                        "--frequency", "0.125", "--duration", "17"], "device.log")
        state_js = ("const v = window.hapticsimView, s = v.state; return {"
                    "tool: v.toolOnScreen(), contact: s.deformation && s.deformation.in_contact,"
                    "force: s.force ? Math.hypot(...s.force.force_n) : 0,"
                    "toolZ: s.toolPosition ? s.toolPosition[2] : null, drawnZ: v.touchedNodeDrawn(),"
                    "surface: v.surfaceAtTouchedNode()};")
        pressed = lambda: (lambda s: s["contact"] and s["toolZ"] is not None and s["toolZ"] > 0.008 and s)(
            browser.execute_script(state_js))
        during_path = os.path.join(work, "during.png")
        surface_path = os.path.join(work, "during-surface-only.png")

        def screenshots_in_one_press():
            """Both screenshots while the tool is beyond 8 mm; the state at the first, or None."""
            wait_for("the press to reach 8 mm on the page", pressed, 10)
            browser.save_screenshot(during_path)
            s = pressed()
            # The same moment without the tool and the arrow: only the surface changed.
            drawn = browser.execute_script(
                "window.hapticsimView.showTool(false); return window.hapticsimView.framesDrawn()")
            wait_for("two frames drawn without the tool",
                     lambda: browser.execute_script("return window.hapticsimView.framesDrawn()") >= drawn + 2,
                     5)
            browser.save_screenshot(surface_path)
            browser.execute_script("window.hapticsimView.showTool(true)")
            return s if s and pressed() else None

        s = screenshots_in_one_press()
        if not s:
            print("the press left 8 mm during the screenshots (a loaded machine?): the next press")
            wait_for("the press to leave 8 mm", lambda: not pressed(), 10)
            s = screenshots_in_one_press()
        if not s:
            fail("two presses left 8 mm while the screenshots were taken")
        print(f"during the press: tool at {1e3 * s['toolZ']:.2f} mm, the surface under it drawn at "
              f"{1e3 * s['drawnZ'][2]:.2f} mm, force {s['force']:.3f} N, tool on screen at "
              f"({s['tool']['x']:.0f}, {s['tool']['y']:.0f}) px")
        # The touched node is held at the tool's depth; the page's frame is up to ~1/60 s older.
        if abs(s["drawnZ"][2] - s["toolZ"]) > 1.5e-3:
            fail("the lattice under the tool is not drawn at the tool's depth")
        mesh_z = [v[2] for v in s["surface"]]
        print(f"the surface mesh has the touched node in {len(mesh_z)} vertices, at "
              f"{1e3 * min(mesh_z):.2f}–{1e3 * max(mesh_z):.2f} mm" if mesh_z else "no vertices")
        if len(mesh_z) < 6 or any(abs(z - s["toolZ"]) > 1.5e-3 for z in mesh_z):
            fail("the surface mesh under the tool is not drawn at the tool's depth")
        if not 0.2 < s["force"] < 5:
            fail(f"the page shows {s['force']:.3f} N during a 10 mm press")

        tx, ty = s["tool"]["x"] * scale, s["tool"]["y"] * scale

        def change_near_tool(after_path, radius_px):
            """Mean change within radius of the tool and elsewhere outside the panel, the share of pixels that changed by more than 5 of 255 there and
            elsewhere, and how far from the tool the change is centred, in px."""
            diff = ImageChops.difference(before.convert("L"), Image.open(after_path).convert("L"))
            r = radius_px * scale
            box = (tx - r, ty - r, tx + r, ty + r)
            px = diff.load()
            near_sum = near_n = far_sum = far_n = near_changed = far_changed = 0
            sx = sy = weight = 0.0
            for x, y in outside_panel(diff.size, panel):
                v = px[x, y]
                if box[0] <= x < box[2] and box[1] <= y < box[3]:
                    near_sum, near_n, near_changed = near_sum + v, near_n + 1, near_changed + (v > 5)
                else:
                    far_sum, far_n, far_changed = far_sum + v, far_n + 1, far_changed + (v > 5)
                if v > 20:
                    sx, sy, weight = sx + x * v, sy + y * v, weight + v
            offset = math.hypot(sx / weight - tx, sy / weight - ty) / scale if weight else math.inf
            return (near_sum / near_n, far_sum / far_n, near_changed / near_n,
                    far_changed / far_n, offset)

        near, far, _, _, offset = change_near_tool(during_path, 25)
        print(f"change within 25 px of the tool: {near:.1f} of 255 on average, elsewhere "
              f"{far:.2f}; the change is centred {offset:.0f} px from the tool")
        if near < 5 or near < 5 * far:
            fail("the picture does not change where the tool is")
        if offset > 150:
            fail("the picture changes mostly away from the tool")
        _, _, near, far, _ = change_near_tool(surface_path, 25)
        print(f"the surface alone (tool and arrow hidden): {100 * near:.0f} % of the pixels within "
              f"25 px of the tool changed, {100 * far:.1f} % elsewhere")
        if near < 0.2 or near < 4 * far:
            fail("the dent does not show where the tool presses")

        errors = [e for e in browser.get_log("browser") if e["level"] == "SEVERE"]
        if errors:
            fail("console errors: " + json.dumps(errors, indent=1))
        device.terminate()  # its run is not what is tested here
        device.wait(timeout=10)
    finally:
        browser.quit()

    view.send_signal(signal.SIGINT)
    out, _ = view.communicate(timeout=10)
    if view.returncode != 0 or "(0 undecodable)" not in out:
        fail(f"hapticsim view did not stop cleanly: exit {view.returncode}, {out!r}")
    print(out.strip())
    print("PASS")
finally:
    folder.stop_all()
