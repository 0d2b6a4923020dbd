#!/usr/bin/python3
"""Opens the report.html of `rvr compare` in headless Chromium and checks it as a person would see it.

Runs `rvr compare` at a small size, loads the report through the Chrome DevTools protocol and
fails on: console errors, uncaught exceptions, error log entries, failed loads, any request
other than the report file itself or a data: URI, an image that did not decode, fewer images
than the report must have, a missing timing chart, anything cut off (a box whose content is
wider than the box: its scroll width above its client width), or a depth-outlier table showing
more than 10 rows before it is unfolded. Saves a full-page screenshot.

With --self-check it instead loads a deliberately broken page (an undecodable data URI image, a
JS exception, a console error, a request to the network, a card whose text runs past its edge)
and passes only if every one of those problems is reported: a check that never fails is worth
nothing.

The browser plumbing and the checks any page must pass are in devtools_page.py; a watchdog
alarm bounds the whole run so the test can never hang.
"""

import argparse
import json
import subprocess
import sys
from pathlib import Path

from devtools_page import CheckFailed, add_common_arguments, check_page, run_check


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
    text: document.body ? document.body.innerText : '',
    // Every box inside main whose content is wider than the box itself: cut off at its edge
    // (overflow hidden), drawn past it (overflow visible), or behind a scroll bar.
    clipped: Array.from(document.querySelectorAll('main, main *')).filter(e => {
      const display = getComputedStyle(e).display;
      if (display === 'inline' || display === 'none' || display === 'contents') return false;
      return e.clientWidth > 0 && e.scrollWidth > e.clientWidth + 1;
    }).map(e => ({
      box: e.tagName.toLowerCase() + (e.id ? '#' + e.id : '') +
           (typeof e.className === 'string' && e.className ? '.' + e.className : ''),
      scrollWidth: e.scrollWidth, clientWidth: e.clientWidth,
      text: (e.innerText || e.textContent || '').trim().slice(0, 60)})),
    pageWidth: document.documentElement.scrollWidth,
    windowWidth: window.innerWidth,
    // Rows of depth-outlier tables a reader sees before unfolding anything.
    outlierRowsShown: Array.from(document.querySelectorAll('table')).filter(t =>
        t.querySelector('th') && t.querySelector('th').textContent === 'x' &&
        t.checkVisibility({contentVisibilityAuto: true, visibilityProperty: true}))
      .reduce((n, t) => n + t.querySelectorAll('tbody tr').length, 0)
  };
})()
"""

# A depth-outlier table shows at most this many rows until it is unfolded.
MAX_OUTLIER_ROWS_SHOWN = 10


def layout_problems(probe):
    """What is cut off or too long on the page as laid out."""
    problems = [f"cut off: {c['box']} is {c['clientWidth']} px wide but its content "
                f"{c['scrollWidth']} px ('{c['text']}')" for c in probe.get("clipped", [])]
    if probe.get("pageWidth", 0) > probe.get("windowWidth", 0):
        problems.append(f"the page is {probe['pageWidth']} px wide in a "
                        f"{probe['windowWidth']} px window")
    if probe.get("outlierRowsShown", 0) > MAX_OUTLIER_ROWS_SHOWN:
        problems.append(f"the depth outliers show {probe['outlierRowsShown']} rows before "
                        f"unfolding, more than {MAX_OUTLIER_ROWS_SHOWN}")
    return problems


def run_compare(rvr, out_dir, renderers):
    # Full mode: the mirror and the glass give the report its effect masks too.
    cmd = [rvr, "compare", "builtin:cornell", "--width", "160", "--height", "120", "--mode", "full",
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
    pairs = metrics.get("pairs", [])
    # Every render, the two in the flip view, diff, id_mismatch, depth_diff, each cost picture,
    # and the mismatch-class picture of every pair (the first pair's among the differences).
    expected_images = len(renderers) + 2 + 3 + with_cost + max(len(pairs), 1)

    problems, probe = check_page(args.chromium, out_dir / "report.html", args.screenshot, work,
                                 args.timeout, PAGE_PROBE)
    problems += layout_problems(probe)
    images = probe["images"]
    if len(images) < expected_images:
        problems.append(f"{len(images)} images on the page, expected at least {expected_images}")
    alts = {i["alt"] for i in images}
    for alt in ("colour difference heat map", "object id mismatches",
                "relative depth difference", "mismatch classes"):
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
    # The mismatch classes in the legend, and the table of the pairs after the first.
    expected_text = [metrics["command"], "Work per pixel", "Timings", "depth_precision",
                     "occlusion", "coverage"]
    if len(pairs) > 1:
        expected_text.append("Every pair")
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
<main><figure style="width:200px;overflow:hidden"><figcaption><span style="white-space:nowrap">a
legend line much too long for its card, cut off at the card's edge</span></figcaption></figure>
<table><thead><tr><th>x</th></tr></thead><tbody>""" + "<tr><td>1</td></tr>" * 11 + """
</tbody></table></main>
</body></html>
"""


def self_check(args, work):
    """The check must catch each planted problem; returns the problems the check missed."""
    html = work / "broken.html"
    html.write_text(BROKEN_PAGE)
    problems, probe = check_page(args.chromium, html, args.screenshot, work, args.timeout,
                                 PAGE_PROBE)
    problems += layout_problems(probe)
    print("the check reported, as it should:\n  " + "\n  ".join(problems))
    expected = {
        "console error": lambda p: p.startswith("console.error") and "deliberate" in p,
        "uncaught exception": lambda p: p.startswith("uncaught exception") and
        "undefinedFunctionCalledOnPurpose" in p,
        "undecodable data URI image": lambda p: "alt 'broken data uri'" in p,
        "network request": lambda p: "network request to http://127.0.0.1:9/" in p,
        "card cut off": lambda p: p.startswith("cut off: figure") and "legend line" in p,
        "unfolded outlier table": lambda p: "depth outliers show 11 rows" in p,
    }
    missed = [name for name, hit in expected.items() if not any(hit(p) for p in problems)]
    if any("alt 'good'" in p for p in problems):
        missed.append("(false alarm on the good image)")
    return [f"the check did not catch the {name}" for name in missed]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--rvr", help="the rvr binary")
    add_common_arguments(parser, watchdog=150)
    parser.add_argument("--renderers", default="raster,raytrace,softraster,embree")
    parser.add_argument("--existing", metavar="DIR",
                        help="check DIR/report.html of an earlier run instead of running rvr")
    parser.add_argument("--self-check", action="store_true",
                        help="check that a deliberately broken page fails")
    args = parser.parse_args()
    if not args.self_check and not args.rvr and not args.existing:
        parser.error("--rvr or --existing is required")
    return run_check(args, lambda work: self_check(args, work) if args.self_check
                     else check_report(args, work))


if __name__ == "__main__":
    sys.exit(main())
