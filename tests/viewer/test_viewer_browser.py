#!/usr/bin/python3
"""The viewer's page in headless Chromium (Selenium): the page loads, the first frame
appears, a mouse drag changes the picture, a drag in the transfer-function editor changes
a volume's picture, and the screenshot PNG equals the CLI render of the same view.

Usage: test_viewer_browser.py RTFACT_BINARY DATASETS_DIR OUTPUT_DIR
Exit 77 (skipped) when Chromium, chromedriver or Selenium is missing."""
import base64
import os
import shutil
import subprocess
import sys
import tempfile
import time

SKIP = 77


def skip(why):
    print("SKIPPED: " + why)
    sys.exit(SKIP)


try:
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait
except ImportError:
    skip("python3-selenium is not installed")

RTFACT, DATA, OUT = sys.argv[1], sys.argv[2], sys.argv[3]
CHROMIUM = shutil.which("chromium")
DRIVER = shutil.which("chromedriver")
IDIFF = shutil.which("idiff")
if not CHROMIUM or not DRIVER:
    skip("chromium / chromium-driver is not installed")
if not IDIFF:
    skip("idiff (openimageio-tools) is not installed")
os.makedirs(OUT, exist_ok=True)
SIZE = "320x240"


def serve(kind, path, *extra):
    """Starts `rtfact view KIND FILE`; returns (process, url)."""
    p = subprocess.Popen([RTFACT, "view", kind, path, "--no-browser", "--quiet", "--size", SIZE, "--max-samples", "2",
                          *extra], stdout=subprocess.PIPE, text=True)
    line = p.stdout.readline().strip()
    prefix = "rtfact: viewing at "
    if not line.startswith(prefix):
        p.kill()
        raise AssertionError("unexpected first line: %r" % line)
    return p, line[len(prefix):]


def browser():
    profile = tempfile.mkdtemp(prefix="rtfact-chromium-")
    o = webdriver.ChromeOptions()
    o.binary_location = CHROMIUM
    for flag in ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync",
                 "--user-data-dir=" + profile, "--window-size=1300,900"]:
        o.add_argument(flag)
    d = webdriver.Chrome(service=Service(DRIVER), options=o)
    d.set_script_timeout(120)
    return d, profile


def wait(d, cond, what, timeout=120):
    try:
        return WebDriverWait(d, timeout, poll_frequency=0.05).until(lambda drv: cond(drv))
    except Exception:
        raise AssertionError("timed out waiting for " + what + "; status: " +
                             str(d.execute_script("return document.getElementById('status').textContent")))


def canvas_pixels(d, id_="view"):
    return d.execute_script("return document.getElementById(arguments[0]).toDataURL('image/png')", id_)


def frames(d):
    return d.execute_script("return window.rtfactView.framesReceived")


def settled(d):
    """The last frame is refined to the limit (the view is still and complete)."""
    return d.execute_script(
        "const s = window.rtfactView; return s.lastFrame && !s.lastFrame.moving && "
        "s.lastFrame.samples >= s.hello.maxSamples && s.lastFrame.scale === 1")


def fmt(v):
    return ",".join(repr(float(x)) for x in v)


def test_points(d):
    p, url = serve("points", os.path.join(DATA, "points", "bunny_bun000.ply"))
    try:
        # The page needs the token: without it the server answers 401 and no frame comes.
        d.get(url)
        wait(d, lambda drv: frames(drv) > 0, "the first frame")
        assert "rtfact view" in d.title
        wait(d, settled, "the refined frame")
        before = canvas_pixels(d)
        cam0 = d.execute_script("return window.rtfactView.lastFrame.camera")
        view = d.find_element(By.ID, "view")
        ActionChains(d).move_to_element(view).click_and_hold().move_by_offset(60, 10).move_by_offset(60, 10) \
            .release().perform()
        wait(d, lambda drv: drv.execute_script("return window.rtfactView.lastFrame.camera") != cam0 and settled(drv),
             "a frame of the dragged camera")
        after = canvas_pixels(d)
        assert after != before, "the drag did not change the picture"

        # Screenshot: the server's full-resolution PNG equals the CLI render of the same view.
        cam = d.execute_script("return window.rtfactView.lastFrame.camera")
        d.find_element(By.ID, "shot").click()
        wait(d, lambda drv: drv.execute_script("return window.rtfactView.lastScreenshot !== null"), "the screenshot")
        b64 = d.execute_async_script(
            "const done = arguments[0]; const r = new FileReader();"
            "r.onload = () => done(r.result.split(',')[1]); r.readAsDataURL(window.rtfactView.lastScreenshot);")
        shot = os.path.join(OUT, "viewer_browser_screenshot.png")
        with open(shot, "wb") as f:
            f.write(base64.b64decode(b64))
        cli = os.path.join(OUT, "viewer_browser_cli.png")
        subprocess.run([RTFACT, "points", os.path.join(DATA, "points", "bunny_bun000.ply"), "--quiet", "--size", SIZE,
                        "--eye", fmt(cam["eye"]), "--at", fmt(cam["at"]), "--up", fmt(cam["up"]),
                        "--fov", repr(float(cam["fov"])), "-o", cli], check=True)
        # The image-regression tolerance of tests/common/image_compare.h: 8/255, 0.5% of the pixels.
        r = subprocess.run([IDIFF, "-fail", str(8 / 255), "-failpercent", "0.5", shot, cli],
                           capture_output=True, text=True)
        assert r.returncode == 0, "screenshot differs from the CLI render:\n" + r.stdout
        # The copy-camera flags are shown.
        d.find_element(By.ID, "copy").click()
        flags = d.find_element(By.ID, "camtext").get_attribute("value")
        assert flags.startswith("--eye ") and "--fov" in flags, flags
        print("points: first frame, drag, screenshot == CLI: ok")
    finally:
        p.terminate()
        p.wait(timeout=30)


def test_volume_tf_editor(d):
    p, url = serve("volume", os.path.join(DATA, "volumes", "tooth_103x94x161_uint8.mhd"))
    try:
        d.get(url)
        wait(d, lambda drv: drv.execute_script("return window.rtfactView.transfer !== null") and settled(drv),
             "the volume's frame and histogram")
        assert not d.find_element(By.ID, "tf").get_attribute("hidden")
        before = canvas_pixels(d)
        pts = d.execute_script("return window.rtfactView.tfEditor.points()")
        tf = d.find_element(By.ID, "tf-canvas")
        w, h = tf.size["width"], tf.size["height"]
        # The point with the highest opacity dragged down to transparent.
        i = max(range(len(pts)), key=lambda k: -pts[k][1])
        x, y = pts[i]
        n0 = frames(d)
        ActionChains(d).move_to_element_with_offset(tf, int(x - w / 2), int(y - h / 2)).click_and_hold() \
            .move_by_offset(0, 30).move_by_offset(0, 60).release().perform()
        wait(d, lambda drv: frames(drv) > n0 and settled(drv) and canvas_pixels(drv) != before,
             "a frame with the edited transfer function")
        after_pts = d.execute_script("return window.rtfactView.tfEditor.points()")
        assert after_pts[i][1] > y, "the editor point did not move"
        print("volume: TF editor drag changes the picture: ok")
    finally:
        p.terminate()
        p.wait(timeout=30)


def main():
    d, profile = browser()
    try:
        test_points(d)
        test_volume_tf_editor(d)
    finally:
        d.quit()
        shutil.rmtree(profile, ignore_errors=True)
    print("viewer browser test: ok")


if __name__ == "__main__":
    main()
