#!/usr/bin/env python3
"""Drives rastergi's web page in Chromium through chromedriver (the W3C WebDriver
protocol over HTTP, standard library only): turns the denoiser on with the panel's checkbox
(with --denoised), renders the Cornell box, saves the raw image and the denoised one of the
same iterations, moves the camera with a real pointer drag, loads files through the page's
file input.

Usage: web_test.py URL OUT.png [--iterations N] [--size W] [--seed S] [--gather G]
           [--denoised OUT.png] [--file SCENE_FILE]... [--bad-file FILE]

Prints one JSON object with what it saw; exits non-zero (with one line on stderr) when the
page failed. scripts/web-test.sh starts the server and calls it.
"""
import argparse
import base64
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request

W3C_ELEMENT = "element-6066-11e4-a52e-4f735466cecf"

# Chromium with WebGPU on a machine without a GPU: WebGPU is behind --enable-unsafe-webgpu on
# Linux; with Vulkan on SwiftShader (shipped with Debian's chromium) Dawn's adapter is
# SwiftShader and the canvas can present. Headless mode cannot: Chromium 156's headless
# compositor loses the WebGPU device as soon as a canvas presents ("A valid external Instance
# reference no longer exists", with a ten-line page of plain JavaScript too), so the browser
# runs in its normal mode on a virtual display (web-test.sh starts it under xvfb-run).
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-dev-shm-usage",
    "--no-first-run",
    "--no-default-browser-check",
    "--enable-unsafe-webgpu",
    "--enable-features=Vulkan",
    "--use-vulkan=swiftshader",
    "--disable-gpu-sandbox",
    # SwiftShader compiles and runs every shader on the GPU process's own threads: on a 2-core
    # machine a pipeline compile or a heavy submit can outlast Chromium's GPU watchdog, which
    # then kills the GPU process and the page loses its device ("A valid external Instance
    # reference no longer exists"; the browser's log says "GPU process exited unexpectedly").
    # Seen in CI when the denoiser was on while a scene loaded; the page itself is not at fault.
    "--disable-gpu-watchdog",
    "--window-size=1280,1000",
]


DRIVER = None


def fail(message):
    """Exits with `message` (and the browser console's last lines, where the page is open)."""
    if DRIVER is not None and getattr(DRIVER, "session", None):
        try:
            request = urllib.request.Request(DRIVER.base + f"{DRIVER.session}/se/log", method="POST",
                                             data=json.dumps({"type": "browser"}).encode())
            request.add_header("Content-Type", "application/json")
            with urllib.request.urlopen(request, timeout=30) as response:
                for entry in json.loads(response.read()).get("value", [])[-20:]:
                    print(f"web-test: console: {entry.get('message', '')[:400]}", file=sys.stderr)
        except Exception:
            pass
    print(f"web-test: {message}", file=sys.stderr)
    sys.exit(1)


class Driver:
    def __init__(self, chromedriver, chromium):
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            self.port = s.getsockname()[1]
        self.log = tempfile.NamedTemporaryFile(prefix="chromedriver-", suffix=".log", delete=False)
        self.process = subprocess.Popen(
            [chromedriver, f"--port={self.port}"], stdout=self.log, stderr=subprocess.STDOUT
        )
        self.base = f"http://127.0.0.1:{self.port}"
        for _ in range(100):
            try:
                self.call("GET", "/status")
                break
            except OSError:
                time.sleep(0.1)
        else:
            fail("chromedriver did not start")
        caps = {
            "browserName": "chrome",
            "goog:chromeOptions": {"binary": chromium, "args": CHROMIUM_ARGS},
            "goog:loggingPrefs": {"browser": "ALL"},
        }
        session = self.call("POST", "/session", {"capabilities": {"alwaysMatch": caps}})
        self.session = f"/session/{session['sessionId']}"
        self.call("POST", f"{self.session}/timeouts", {"script": 600_000})

    def call(self, method, path, body=None):
        data = None if body is None else json.dumps(body).encode()
        request = urllib.request.Request(self.base + path, data=data, method=method)
        request.add_header("Content-Type", "application/json")
        try:
            with urllib.request.urlopen(request, timeout=900) as response:
                return json.loads(response.read() or b"{}").get("value")
        except urllib.error.HTTPError as e:
            value = json.loads(e.read() or b"{}").get("value", {})
            fail(f"WebDriver {method} {path}: {value.get('error')}: {value.get('message', '').splitlines()[0:1]}")

    def run(self, script, *args):
        """Runs `script` (an async function body) in the page and returns its value."""
        wrapped = f"const done = arguments[arguments.length - 1];\n(async () => {{ {script} }})().then(done, (e) => done({{__error: String(e)}}));"
        value = self.call("POST", f"{self.session}/execute/async", {"script": wrapped, "args": list(args)})
        if isinstance(value, dict) and "__error" in value:
            fail(f"the page threw: {value['__error']}")
        return value

    def element(self, css):
        return self.call("POST", f"{self.session}/element", {"using": "css selector", "value": css})[W3C_ELEMENT]

    def quit(self):
        try:
            self.call("DELETE", self.session)
        finally:
            self.process.terminate()


def wait_for(driver, condition, what, timeout):
    """Polls the page until `condition` (a JS expression) is true."""
    start = time.time()
    while time.time() - start < timeout:
        state = driver.run(f"return {{ok: !!({condition}), error: rastergi.error(), samples: rastergi.samples()}};")
        if state["ok"]:
            return state
        time.sleep(0.5)
    fail(f"timed out after {timeout} s waiting for {what} (page error: {state['error'] or 'none'}, {state['samples']} iterations)")


def save_png(driver, path, raw=False):
    """Writes the page's "save PNG" image to `path` (whole, or not at all); with `raw`, the
    film's image unfiltered where the denoised one is shown."""
    png = base64.b64decode(driver.run(f"return await rastergi.png({'true' if raw else 'false'});"))
    with open(path + ".tmp", "wb") as f:
        f.write(png)
    os.replace(path + ".tmp", path)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("url")
    p.add_argument("out")
    p.add_argument("--iterations", type=int, default=64)
    p.add_argument("--size", type=int, default=128)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--gather", default="trace")
    p.add_argument("--file", action="append", default=[], help="a scene file to load through the file input, with the files it names after commas")
    p.add_argument("--bad-file", help="a file that is not a scene: the page must refuse it and keep its scene")
    p.add_argument("--timeout", type=int, default=600)
    p.add_argument("--screenshot", help="also save a screenshot of the whole page here, after the render")
    p.add_argument("--denoised", help="tick the panel's denoise box first and save the denoised image of the same iterations here (OUT.png: the raw one)")
    a = p.parse_args()
    chromium = shutil.which("chromium") or shutil.which("chromium-browser") or fail("chromium is not installed")
    chromedriver = shutil.which("chromedriver") or fail("chromedriver is not installed")
    global DRIVER
    report = {}
    driver = Driver(chromedriver, chromium)
    DRIVER = driver
    try:
        url = f"{a.url}/?width={a.size}&height={a.size}&seed={a.seed}&gather={a.gather}&iterations={a.iterations}"
        began = time.time()
        driver.call("POST", f"{driver.session}/url", {"url": url})
        driver.run("await rastergi.ready;")
        report["ready_seconds"] = round(time.time() - began, 1)
        error = driver.run("return rastergi.error();")
        if error:
            fail(f"the page could not start: {error}")
        report["adapter"] = driver.run("return rastergi.viewer.describe();")
        if a.denoised:
            # A real click on the panel's checkbox before the iterations: the denoiser's guides
            # start, so the image restarts; the same iterations then give both images, the
            # film's raw one and the denoised one.
            driver.call("POST", f"{driver.session}/element/{driver.element('#denoise')}/click", {})
            wait_for(driver, "rastergi.viewer.describe().includes('denoised') || rastergi.error()", "the denoiser to turn on", 60)
            if driver.run("return rastergi.error();"):
                fail(f"turning the denoiser on: {driver.run('return rastergi.error();')}")
            report["denoised"] = driver.run("return rastergi.viewer.describe();")
        start = time.time()
        wait_for(driver, f"rastergi.samples() >= {a.iterations} && rastergi.idle()", f"{a.iterations} iterations", a.timeout)
        report["seconds"] = round(time.time() - start, 1)
        save_png(driver, a.out, raw=True)
        if a.denoised:
            save_png(driver, a.denoised)
        if a.screenshot:
            with open(a.screenshot, "wb") as f:
                f.write(base64.b64decode(driver.call("GET", f"{driver.session}/screenshot")))

        # A real pointer drag across the canvas orbits the camera: the image restarts.
        canvas = driver.element("#view")
        before = driver.run("return rastergi.viewer.describe() && rastergi.samples();")
        driver.call("POST", f"{driver.session}/actions", {"actions": [{
            "type": "pointer", "id": "mouse", "parameters": {"pointerType": "mouse"},
            "actions": [
                {"type": "pointerMove", "origin": {W3C_ELEMENT: canvas}, "x": 0, "y": 0},
                {"type": "pointerDown", "button": 0},
                {"type": "pointerMove", "origin": "pointer", "x": 60, "y": 10, "duration": 200},
                {"type": "pointerUp", "button": 0},
            ]}]})
        after = driver.run("return rastergi.samples();")
        if after >= before:
            fail(f"a drag across the canvas did not restart the image ({before} iterations before, {after} after)")
        report["drag"] = {"before": before, "after": after}

        files = driver.element("#files")
        start = time.time()
        for group in a.file:
            paths = group.split(",")
            name = os.path.basename(paths[0])
            text = "\n".join(os.path.abspath(p) for p in paths)
            driver.call("POST", f"{driver.session}/element/{files}/value", {"text": text})
            state = wait_for(driver, f"rastergi.viewer.sceneName() === {json.dumps(name)} && rastergi.samples() >= 2 || rastergi.error()", f"{name} to load", a.timeout)
            if state["error"]:
                fail(f"loading {name}: {state['error']}")
            report.setdefault("loaded", []).append(driver.run("return rastergi.viewer.describe();"))
            report.setdefault("load_seconds", []).append(round(time.time() - start, 1))
        if a.bad_file:
            scene = driver.run("return rastergi.viewer.sceneName();")
            driver.call("POST", f"{driver.session}/element/{files}/value", {"text": os.path.abspath(a.bad_file)})
            state = wait_for(driver, "rastergi.error() !== ''", "the page to refuse a file that is not a scene", 60)
            kept = driver.run("return rastergi.viewer.sceneName();")
            if kept != scene:
                fail(f"a bad file replaced the scene {scene} with {kept}")
            lines = driver.run("return document.getElementById('error').textContent;")
            report["bad_file"] = {"error": lines, "scene_kept": kept}
        print(json.dumps(report, indent=1))
    finally:
        driver.quit()


if __name__ == "__main__":
    main()
