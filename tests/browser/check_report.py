#!/usr/bin/python3
"""Opens the report.html of `rvr compare` in headless Chromium and checks it as a person would see it.

Runs `rvr compare` at a small size, loads the report through the Chrome DevTools protocol and
fails on: console errors, uncaught exceptions, error log entries, failed loads, any request
other than the report file itself or a data: URI, an image that did not decode, fewer images
than the report must have, or a missing timing chart. Saves a full-page screenshot.

With --self-check it instead loads a deliberately broken page (an undecodable data URI image, a
JS exception, a console error, a request to the network) and passes only if every one of those
problems is reported: a check that never fails is worth nothing.

Chromium is Debian's package (make deps installs it); when it is missing the test fails.
The browser runs in its own process group and is killed whatever happens; a watchdog alarm
bounds the whole run so the test can never hang.
"""

import argparse
import base64
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

try:
    import websocket  # Debian package python3-websocket
except ImportError:
    print("FAIL: the Python module 'websocket' is missing (Debian package python3-websocket; "
          "run `make deps`)", file=sys.stderr)
    sys.exit(1)


class CheckFailed(Exception):
    pass


class Timeout(Exception):
    pass


def on_alarm(signum, frame):
    raise Timeout("the browser check took too long (watchdog)")


class Chromium:
    """A headless Chromium in its own process group, with a fresh profile."""

    def __init__(self, binary, work_dir, timeout):
        self.profile = Path(tempfile.mkdtemp(prefix="profile-", dir=work_dir))
        self.log_path = Path(work_dir) / "chromium.log"
        self.timeout = timeout
        args = [
            binary, "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
            "--remote-debugging-port=0", f"--user-data-dir={self.profile}",
            "--no-first-run", "--no-default-browser-check", "--disable-extensions",
            "--disable-background-networking", "--disable-component-update", "--disable-sync",
            "--disable-default-apps", "--mute-audio", "--hide-scrollbars",
            "--window-size=1400,1000", "about:blank",
        ]
        self.log = open(self.log_path, "wb")
        # A new session: killpg reaches the renderer, GPU and zygote children too.
        self.proc = subprocess.Popen(args, stdout=self.log, stderr=subprocess.STDOUT,
                                     stdin=subprocess.DEVNULL, start_new_session=True)

    def endpoint(self):
        """ws://... of the browser, from the DevToolsActivePort file Chromium writes."""
        port_file = self.profile / "DevToolsActivePort"
        deadline = time.monotonic() + self.timeout
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise CheckFailed(f"chromium exited with status {self.proc.returncode} before "
                                  f"opening its DevTools port; log:\n{self.log_tail()}")
            try:
                lines = port_file.read_text().split("\n")
                if len(lines) >= 2 and lines[0].strip() and lines[1].strip():
                    return int(lines[0]), lines[1].strip()
            except (FileNotFoundError, ValueError):
                pass
            time.sleep(0.05)
        raise CheckFailed(f"chromium did not write {port_file} within {self.timeout} s; "
                          f"log:\n{self.log_tail()}")

    def log_tail(self, lines=30):
        try:
            self.log.flush()
            return "\n".join(self.log_path.read_text(errors="replace").splitlines()[-lines:])
        except OSError:
            return "(no log)"

    def kill(self):
        if self.proc.poll() is None:
            for sig, wait in ((signal.SIGTERM, 3.0), (signal.SIGKILL, 5.0)):
                try:
                    os.killpg(self.proc.pid, sig)
                except ProcessLookupError:
                    break
                try:
                    self.proc.wait(timeout=wait)
                    break
                except subprocess.TimeoutExpired:
                    continue
        # Children that outlived the main process (same group).
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
        self.log.close()
        shutil.rmtree(self.profile, ignore_errors=True)


class DevTools:
    """One DevTools protocol connection: commands by id, events queued."""

    def __init__(self, url, timeout):
        self.ws = websocket.create_connection(url, timeout=timeout, suppress_origin=True)
        self.timeout = timeout
        self.next_id = 0
        self.events = []

    def _recv(self, deadline):
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            raise CheckFailed("no answer from chromium in time")
        self.ws.settimeout(remaining)
        try:
            return json.loads(self.ws.recv())
        except websocket.WebSocketTimeoutException:
            raise CheckFailed("no answer from chromium in time")

    def call(self, method, **params):
        self.next_id += 1
        my_id = self.next_id
        self.ws.send(json.dumps({"id": my_id, "method": method, "params": params}))
        deadline = time.monotonic() + self.timeout
        while True:
            msg = self._recv(deadline)
            if msg.get("id") == my_id:
                if "error" in msg:
                    raise CheckFailed(f"{method} failed: {msg['error']}")
                return msg.get("result", {})
            if "method" in msg:
                self.events.append(msg)

    def wait_for(self, method, seconds):
        deadline = time.monotonic() + seconds
        while True:
            for e in self.events:
                if e["method"] == method:
                    return e
            msg = self._recv(deadline)
            if "method" in msg:
                self.events.append(msg)

    def drain(self, seconds):
        """Collect whatever events arrive in the next `seconds`."""
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            self.ws.settimeout(max(0.01, deadline - time.monotonic()))
            try:
                msg = json.loads(self.ws.recv())
            except websocket.WebSocketTimeoutException:
                break
            if "method" in msg:
                self.events.append(msg)

    def close(self):
        try:
            self.ws.close()
        except Exception:
            pass


# Evaluated in the page: every image decoded, the chart and the texts the report must show.
PAGE_PROBE = r"""
(async () => {
  const imgs = Array.from(document.images);
  const decoded = await Promise.all(imgs.map(i => i.decode().then(() => true, () => false)));
  const chart = document.querySelector('svg#timing-chart');
  return {
    title: document.title,
    images: imgs.map((i, k) => ({
      alt: i.alt, src: i.currentSrc.slice(0, 40), complete: i.complete,
      naturalWidth: i.naturalWidth, naturalHeight: i.naturalHeight, decoded: decoded[k]})),
    chart: !!chart,
    chartRows: chart ? Array.from(chart.querySelectorAll('g.bar-row')).map(g => ({
      renderer: g.dataset.renderer,
      phases: Array.from(g.querySelectorAll('rect[data-phase]')).map(r => r.dataset.phase),
      width: g.getBoundingClientRect().width})) : [],
    resources: performance.getEntriesByType('resource').map(e => e.name),
    text: document.body ? document.body.innerText : ''
  };
})()
"""


def describe_exception(details):
    exc = details.get("exception", {})
    return exc.get("description") or details.get("text", "exception")


def check_page(chromium_binary, html_path, screenshot, work_dir, timeout):
    """Loads html_path; returns (problems, probe). Raises CheckFailed on protocol trouble."""
    html_url = Path(html_path).resolve().as_uri()
    browser = Chromium(chromium_binary, work_dir, timeout)
    page = None
    try:
        port, browser_path = browser.endpoint()
        # A page of its own, reached directly (no session multiplexing needed).
        targets = DevTools(f"ws://127.0.0.1:{port}{browser_path}", timeout)
        target = targets.call("Target.createTarget", url="about:blank")["targetId"]
        targets.close()
        page = DevTools(f"ws://127.0.0.1:{port}/devtools/page/{target}", timeout)
        for domain in ("Runtime", "Log", "Network", "Page"):
            page.call(f"{domain}.enable")
        page.call("Emulation.setDeviceMetricsOverride", width=1400, height=1000,
                  deviceScaleFactor=1, mobile=False)
        nav = page.call("Page.navigate", url=html_url)
        if nav.get("errorText"):
            raise CheckFailed(f"cannot open {html_url}: {nav['errorText']}")
        page.wait_for("Page.loadEventFired", timeout)
        probe = page.call("Runtime.evaluate", expression=PAGE_PROBE, awaitPromise=True,
                          returnByValue=True)
        if "exceptionDetails" in probe:
            raise CheckFailed("the probe script failed: " +
                              describe_exception(probe["exceptionDetails"]))
        probe = probe["result"]["value"]
        page.drain(0.3)  # late console messages and failed loads

        problems = []
        for e in page.events:
            m, p = e["method"], e.get("params", {})
            if m == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
                text = " ".join(str(a.get("value", a.get("description", ""))) for a in p["args"])
                problems.append(f"console.{p['type']}: {text}")
            elif m == "Runtime.exceptionThrown":
                problems.append("uncaught exception: " + describe_exception(p["exceptionDetails"]))
            elif m == "Log.entryAdded" and p["entry"].get("level") == "error":
                entry = p["entry"]
                problems.append(f"log error ({entry.get('source')}): {entry.get('text')} "
                                f"{entry.get('url', '')}".rstrip())
            elif m == "Network.requestWillBeSent":
                url = p["request"]["url"]
                if url != html_url and not url.startswith("data:"):
                    problems.append(f"network request to {url} (only the file itself and data: "
                                    f"URIs are allowed)")
            elif m == "Network.loadingFailed":
                problems.append(f"load failed: {p.get('errorText')} ({p.get('type', '?')})")
        for url in probe["resources"]:
            if not url.startswith("data:") and url != html_url:
                problems.append(f"resource fetched from {url}")
        for i, img in enumerate(probe["images"]):
            if not (img["complete"] and img["naturalWidth"] > 0 and img["decoded"]):
                problems.append(f"image {i} (alt '{img['alt']}', src {img['src']}...) did not "
                                f"decode: complete={img['complete']}, "
                                f"naturalWidth={img['naturalWidth']}, decoded={img['decoded']}")

        # Full page: the layout's whole height, not just the window.
        metrics = page.call("Page.getLayoutMetrics")
        size = metrics.get("cssContentSize") or metrics["contentSize"]
        shot = page.call("Page.captureScreenshot", format="png", captureBeyondViewport=True,
                         clip={"x": 0, "y": 0, "width": size["width"],
                               "height": size["height"], "scale": 1})
        Path(screenshot).parent.mkdir(parents=True, exist_ok=True)
        Path(screenshot).write_bytes(base64.b64decode(shot["data"]))
        try:
            page.call("Browser.close")
        except Exception:
            pass  # killed below anyway
        return problems, probe
    finally:
        if page:
            page.close()
        browser.kill()


def run_compare(rvr, out_dir, renderers):
    cmd = [rvr, "compare", "builtin:cornell", "--width", "160", "--height", "120",
           "--renderers", renderers, "-o", str(out_dir)]
    print("running:", " ".join(cmd))
    r = subprocess.run(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, timeout=120)
    if r.returncode != 0:
        raise CheckFailed(f"rvr compare exited with {r.returncode}:\n"
                          f"{r.stdout.decode(errors='replace')}")


def check_report(args, work):
    if args.existing:  # an output folder made earlier (for trying the check by hand)
        out_dir = Path(args.existing).resolve()
    else:
        out_dir = work / "rvr-out"
        run_compare(args.rvr, out_dir, args.renderers)
    metrics = json.loads((out_dir / "metrics.json").read_text())
    renderers = list(metrics["renderers"])
    with_cost = sum(1 for r in metrics["renderers"].values() if "cost" in r)
    # Every render, the two in the flip view, diff, id_mismatch, depth_diff, each cost picture.
    expected_images = len(renderers) + 2 + 3 + with_cost

    problems, probe = check_page(args.chromium, out_dir / "report.html", args.screenshot, work,
                                 args.timeout)
    images = probe["images"]
    if len(images) < expected_images:
        problems.append(f"{len(images)} images on the page, expected at least {expected_images}")
    alts = {i["alt"] for i in images}
    for alt in ("colour difference heat map", "object id mismatches",
                "relative depth difference"):
        if alt not in alts:
            problems.append(f"no image with alt '{alt}'")
    if not probe["chart"]:
        problems.append("no timing chart (svg#timing-chart)")
    rows = {row["renderer"]: row for row in probe["chartRows"]}
    for name in renderers:
        row = rows.get(name)
        if row is None:
            problems.append(f"the timing chart has no bar for {name}")
            continue
        stats = metrics["renderers"][name]["stats"]
        # Phases the chart does not stack (apps/rvr/timing_chart.cpp): totals of others, and
        # parts of a phase the bar already shows.
        unstacked = {"time.bvh_build", "time.visibility"}
        if "time.render" in stats:
            unstacked.add("time.shade")
        if "time.trace" in stats:
            unstacked.add("time.render")
        for key in stats:
            if key.startswith("time.") and key not in unstacked and \
                    key[5:] not in row["phases"]:
                problems.append(f"the timing chart's bar for {name} lacks phase {key}")
        if row["width"] <= 0:
            problems.append(f"the timing chart's bar for {name} is not drawn")
    expected_text = [metrics["command"], "Work per pixel", "Timings", "mismatched_off_edge"]
    # The warnings box appears when some renderer warned (e.g. embree: no cost AOV), not always.
    if any(r.get("warnings") for r in metrics["renderers"].values()):
        expected_text.append("Warnings")
    for text in expected_text:
        if text not in probe["text"]:
            problems.append(f"the page does not show '{text}'")
    print(f"page '{probe['title']}': {len(images)} images "
          f"(expected at least {expected_images}), all decoded: "
          f"{all(i['decoded'] and i['naturalWidth'] > 0 for i in images)}; timing chart bars: "
          + ", ".join(f"{r['renderer']} [{' '.join(r['phases'])}]" for r in probe["chartRows"]))
    return problems


BROKEN_PAGE = """<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>broken</title>
</head><body><h1>deliberately broken</h1>
<img alt="good" src="data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8DwHwAFBQIAX8jx0gAAAABJRU5ErkJggg==">
<img alt="broken data uri" src="data:image/png;base64,iVBORw0KGgoAAAAthisisnotapng">
<img alt="from the network" src="http://127.0.0.1:9/nothing.png">
<script>console.error('deliberate console error');</script>
<script>undefinedFunctionCalledOnPurpose();</script>
</body></html>
"""


def self_check(args, work):
    """The check must catch each planted problem; returns the problems the check missed."""
    html = work / "broken.html"
    html.write_text(BROKEN_PAGE)
    problems, probe = check_page(args.chromium, html, args.screenshot, work, args.timeout)
    print("the check reported, as it should:\n  " + "\n  ".join(problems))
    expected = {
        "console error": lambda p: p.startswith("console.error") and "deliberate" in p,
        "uncaught exception": lambda p: p.startswith("uncaught exception") and
        "undefinedFunctionCalledOnPurpose" in p,
        "undecodable data URI image": lambda p: "alt 'broken data uri'" in p,
        "network request": lambda p: "network request to http://127.0.0.1:9/" in p,
    }
    missed = [name for name, hit in expected.items() if not any(hit(p) for p in problems)]
    if any("alt 'good'" in p for p in problems):
        missed.append("(false alarm on the good image)")
    return [f"the check did not catch the {name}" for name in missed]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--rvr", help="the rvr binary")
    parser.add_argument("--work-dir", required=True, help="scratch folder (emptied first)")
    parser.add_argument("--screenshot", required=True, help="where to save the full-page PNG")
    parser.add_argument("--chromium", default="/usr/bin/chromium")
    parser.add_argument("--renderers", default="raster,raytrace,softraster,embree")
    parser.add_argument("--timeout", type=float, default=30.0,
                        help="seconds for any one browser step")
    parser.add_argument("--watchdog", type=int, default=150, help="seconds for everything")
    parser.add_argument("--existing", metavar="DIR",
                        help="check DIR/report.html of an earlier run instead of running rvr")
    parser.add_argument("--self-check", action="store_true",
                        help="check that a deliberately broken page fails")
    args = parser.parse_args()

    started = time.monotonic()
    if not (os.path.isfile(args.chromium) and os.access(args.chromium, os.X_OK)):
        print(f"FAIL: no chromium at {args.chromium} (Debian package chromium; run `make deps`)",
              file=sys.stderr)
        return 1
    if not args.self_check and not args.rvr and not args.existing:
        parser.error("--rvr or --existing is required")
    work = Path(args.work_dir).resolve()
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)

    signal.signal(signal.SIGALRM, on_alarm)
    signal.alarm(args.watchdog)
    try:
        problems = self_check(args, work) if args.self_check else check_report(args, work)
    except (CheckFailed, Timeout, subprocess.TimeoutExpired, OSError,
            websocket.WebSocketException) as e:
        print(f"FAIL: {e}", file=sys.stderr)
        return 1
    finally:
        signal.alarm(0)
    print(f"screenshot: {Path(args.screenshot).resolve()}")
    print(f"took {time.monotonic() - started:.1f} s")
    if problems:
        print(f"FAIL: {len(problems)} problem(s):", file=sys.stderr)
        for p in problems:
            print(f"  - {p}", file=sys.stderr)
        return 1
    print("PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())
