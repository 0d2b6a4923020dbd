"""A page in headless Chromium, checked as a person would see it: shared by the browser tests
(check_report.py for `rvr compare`'s report.html, check_study.py for `rvr study`'s study.html).

check_page() opens a local HTML file through the Chrome DevTools protocol, evaluates the
caller's probe script in it and reports: console errors, uncaught exceptions, error log entries,
failed loads, any request other than the file itself or a data: URI, and images that did not
decode. It saves a full-page screenshot. run_check() is the tests' main: Chromium present, a
fresh work folder, a watchdog alarm bounding the whole run, PASS or FAIL with the problems.

Chromium is Debian's package (make deps installs it); when it is missing the test fails.
The browser runs in its own process group and is killed whatever happens.
"""

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


# Evaluated in the page before the caller's probe: every image decoded, every resource loaded.
GENERIC_PROBE = r"""
(async () => {
  const imgs = Array.from(document.images);
  const decoded = await Promise.all(imgs.map(i => i.decode().then(() => true, () => false)));
  return {
    images: imgs.map((i, k) => ({
      alt: i.alt, src: i.currentSrc.slice(0, 40), complete: i.complete,
      naturalWidth: i.naturalWidth, naturalHeight: i.naturalHeight, decoded: decoded[k]})),
    resources: performance.getEntriesByType('resource').map(e => e.name)
  };
})()
"""


def describe_exception(details):
    exc = details.get("exception", {})
    return exc.get("description") or details.get("text", "exception")


def evaluate(page, script):
    """The value the (async) script returns in the page."""
    result = page.call("Runtime.evaluate", expression=script, awaitPromise=True,
                       returnByValue=True)
    if "exceptionDetails" in result:
        raise CheckFailed("the probe script failed: " +
                          describe_exception(result["exceptionDetails"]))
    return result["result"]["value"]


def event_problems(events, html_url):
    """What the page's events report: console errors, exceptions, error logs, foreign requests,
    failed loads."""
    problems = []
    for e in events:
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
    return problems


def resource_problems(generic, html_url):
    """Resources fetched from elsewhere, and images that did not decode."""
    problems = []
    for url in generic["resources"]:
        if not url.startswith("data:") and url != html_url:
            problems.append(f"resource fetched from {url}")
    for i, img in enumerate(generic["images"]):
        if not (img["complete"] and img["naturalWidth"] > 0 and img["decoded"]):
            problems.append(f"image {i} (alt '{img['alt']}', src {img['src']}...) did not "
                            f"decode: complete={img['complete']}, "
                            f"naturalWidth={img['naturalWidth']}, decoded={img['decoded']}")
    return problems


def save_screenshot(page, screenshot):
    """The full page: the layout's whole height, not just the window."""
    metrics = page.call("Page.getLayoutMetrics")
    size = metrics.get("cssContentSize") or metrics["contentSize"]
    shot = page.call("Page.captureScreenshot", format="png", captureBeyondViewport=True,
                     clip={"x": 0, "y": 0, "width": size["width"],
                           "height": size["height"], "scale": 1})
    Path(screenshot).parent.mkdir(parents=True, exist_ok=True)
    Path(screenshot).write_bytes(base64.b64decode(shot["data"]))


def open_page(browser, html_url, timeout):
    """A DevTools connection to a new page of `browser`, navigated to html_url and loaded."""
    port, browser_path = browser.endpoint()
    # A page of its own, reached directly (no session multiplexing needed).
    targets = DevTools(f"ws://127.0.0.1:{port}{browser_path}", timeout)
    target = targets.call("Target.createTarget", url="about:blank")["targetId"]
    targets.close()
    page = DevTools(f"ws://127.0.0.1:{port}/devtools/page/{target}", timeout)
    try:
        for domain in ("Runtime", "Log", "Network", "Page"):
            page.call(f"{domain}.enable")
        page.call("Emulation.setDeviceMetricsOverride", width=1400, height=1000,
                  deviceScaleFactor=1, mobile=False)
        nav = page.call("Page.navigate", url=html_url)
        if nav.get("errorText"):
            raise CheckFailed(f"cannot open {html_url}: {nav['errorText']}")
        page.wait_for("Page.loadEventFired", timeout)
    except BaseException:
        page.close()
        raise
    return page


def check_page(chromium_binary, html_path, screenshot, work_dir, timeout, probe_script):
    """Loads html_path; returns (problems, probe): what any page must not do, and the value of
    probe_script evaluated in it. Raises CheckFailed on protocol trouble."""
    html_url = Path(html_path).resolve().as_uri()
    browser = Chromium(chromium_binary, work_dir, timeout)
    page = None
    try:
        page = open_page(browser, html_url, timeout)
        generic = evaluate(page, GENERIC_PROBE)
        probe = evaluate(page, probe_script)
        page.drain(0.3)  # late console messages and failed loads
        problems = event_problems(page.events, html_url) + resource_problems(generic, html_url)
        save_screenshot(page, screenshot)
        try:
            page.call("Browser.close")
        except Exception:
            pass  # killed below anyway
        return problems, probe
    finally:
        if page:
            page.close()
        browser.kill()


def add_common_arguments(parser, watchdog):
    """The options every browser check takes."""
    parser.add_argument("--work-dir", required=True, help="scratch folder (emptied first)")
    parser.add_argument("--screenshot", required=True, help="where to save the full-page PNG")
    parser.add_argument("--chromium", default="/usr/bin/chromium")
    parser.add_argument("--timeout", type=float, default=30.0,
                        help="seconds for any one browser step")
    parser.add_argument("--watchdog", type=int, default=watchdog, help="seconds for everything")


def run_check(args, check):
    """The check's main: `check(work)` returns the problems found; 0 when there are none."""
    started = time.monotonic()
    if not (os.path.isfile(args.chromium) and os.access(args.chromium, os.X_OK)):
        print(f"FAIL: no chromium at {args.chromium} (Debian package chromium; run `make deps`)",
              file=sys.stderr)
        return 1
    work = Path(args.work_dir).resolve()
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)

    signal.signal(signal.SIGALRM, on_alarm)
    signal.alarm(args.watchdog)
    try:
        problems = check(work)
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
