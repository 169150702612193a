"""What the hapticsim view tests share (view_test.py, view_object_test.py): the processes they start
with a log each, failing with those logs, waiting for a condition, headless Chromium, and what a
screenshot shows outside the page's panel."""
import os
import subprocess
import sys
import time

from selenium import webdriver
from selenium.webdriver.chrome.service import Service

# The page's background colour (web/view/index.html).
BACKGROUND = (0x1d, 0x21, 0x27)


class Work:
    """A work folder: the processes started there, each with its log, and how a test fails."""

    def __init__(self, folder):
        self.folder = folder
        self.processes = []
        os.makedirs(folder, exist_ok=True)

    def start(self, args, log_name, **kwargs):
        log = open(os.path.join(self.folder, log_name), "w")
        p = subprocess.Popen(args, stdout=kwargs.pop("stdout", log), stderr=log, text=True,
                             **kwargs)
        self.processes.append(p)
        return p

    def fail(self, message):
        print("FAIL:", message)
        for name in sorted(os.listdir(self.folder)):
            if name.endswith(".log"):
                print(f"--- {name}:\n" + open(os.path.join(self.folder, name)).read()[-3000:])
        sys.exit(1)

    def wait_for(self, what, condition, timeout_s):
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            value = condition()
            if value:
                return value
            time.sleep(0.1)
        self.fail(f"timed out after {timeout_s} s waiting for {what}")

    def stop_all(self):
        for p in self.processes:
            if p.poll() is None:
                p.terminate()
        for p in self.processes:
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()


def headless_chromium(folder):
    """Debian's Chromium through chromedriver, headless, 1000 × 700, its console log kept."""
    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    for a in ["--headless=new", "--no-sandbox", "--use-angle=swiftshader",
              "--enable-unsafe-swiftshader", "--window-size=1000,700", "--disable-gpu-sandbox",
              f"--user-data-dir={folder}/chromium-profile"]:
        options.add_argument(a)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service("/usr/bin/chromedriver",
                                            log_path=os.path.join(folder, "chromedriver.log")),
                            options=options)


def panel_on_screenshot(browser):
    """The page's panel (left, top, right, bottom) in screenshot pixels."""
    panel = browser.execute_script(
        "const r = document.getElementById('panel').getBoundingClientRect();"
        "return [r.left, r.top, r.right, r.bottom];")
    scale = browser.execute_script("return window.devicePixelRatio")
    return [v * scale for v in panel], scale


def outside_panel(size, panel, step=1):
    """The pixels (x, y) of a screenshot of `size` that the panel does not cover (its text
    changes with every message), every step-th along each axis."""
    w, h = size
    for y in range(0, h, step):
        for x in range(0, w, step):
            if not (panel[0] <= x <= panel[2] and panel[1] <= y <= panel[3]):
                yield x, y


def changed_fraction(image, panel, background=BACKGROUND):
    """The share of pixels outside the panel that are not the page's background colour."""
    px = image.convert("RGB").load()
    pixels = list(outside_panel(image.size, panel, step=2))
    changed = sum(sum(abs(a - b) for a, b in zip(px[x, y], background)) > 30 for x, y in pixels)
    return changed / len(pixels)
