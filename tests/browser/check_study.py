#!/usr/bin/python3
"""Opens the study.html of `rvr study` in headless Chromium and checks it as a person would see it.

Runs a tiny real study (builtin:tessphere, 32 wide, a budget of 4 s), loads study.html through
the Chrome DevTools protocol (devtools_page.py) and fails on what no page may do (console
errors, uncaught exceptions, error log entries, failed loads, any request other than the file
itself) and on what study.html must show, against the study.json written beside it: a chart per
scene (and one against pixels for each N measured at several pixel counts), in each chart every
renderer's points as marks on screen (as many as study.json has at that pixel count), each
fitted model's curve (dashed when it does not fit), every crossover's mark, the tables. Saves a
full-page screenshot.
"""

import argparse
import json
import subprocess
import sys
from pathlib import Path

from devtools_page import CheckFailed, add_common_arguments, check_page, run_check

# Evaluated in the page: each scene's charts, with per renderer its point marks (and whether
# they are drawn inside the chart) and its model curve, and the crossover marks.
PAGE_PROBE = r"""
(async () => {
  const inside = (el, box) => {
    const r = el.getBoundingClientRect();
    return r.width > 0 && r.left >= box.left - 1 && r.right <= box.right + 1 &&
           r.top >= box.top - 1 && r.bottom <= box.bottom + 1;
  };
  const chart = svg => {
    const box = svg.getBoundingClientRect();
    return {
      id: svg.id,
      width: box.width, height: box.height,
      series: Array.from(svg.querySelectorAll('g.series')).map(g => ({
        renderer: g.dataset.renderer,
        marks: g.querySelectorAll('circle.mark').length,
        marksInside: Array.from(g.querySelectorAll('circle.mark')).filter(
            c => inside(c, box)).length,
        spreads: g.querySelectorAll('line.spread').length,
        models: Array.from(g.querySelectorAll('path.model')).map(p => ({
          fits: p.classList.contains('fits'),
          dashed: (p.getAttribute('stroke-dasharray') || '') !== '',
          length: p.getTotalLength()})),
        notPositive: g.querySelectorAll('text.model-not-positive').length})),
      crossovers: Array.from(svg.querySelectorAll('g.crossover')).map(g => ({
        measured: g.dataset.measured === 'true',
        bands: g.querySelectorAll('rect.ci-band').length,
        lines: g.querySelectorAll('line.crossover-line').length})),
      decadeLabels: svg.querySelectorAll('text.tick tspan.exp').length
    };
  };
  return {
    title: document.title,
    scenes: Array.from(document.querySelectorAll('section.scene')).map(s => ({
      scene: s.dataset.scene,
      charts: Array.from(s.querySelectorAll('svg.study-chart')).map(chart),
      modelRows: s.querySelectorAll('table.models tr[data-renderer]').length})),
    scripts: document.scripts.length,
    text: document.body ? document.body.innerText : ''
  };
})()
"""


def run_study(rvr, out_dir, budget):
    cmd = [rvr, "study", "builtin:tessphere", "--width", "32", "--budget", str(budget), "-q",
           "-o", str(out_dir)]
    print("running:", " ".join(cmd))
    r = subprocess.run(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                       stderr=subprocess.STDOUT, timeout=120)
    # 1: the study concluded nothing (said in study.md and study.html); still a page to check.
    if r.returncode not in (0, 1):
        raise CheckFailed(f"rvr study exited with {r.returncode}:\n"
                          f"{r.stdout.decode(errors='replace')}")


def expected_charts(study, scene):
    """What study.html must draw for `scene`: [(label, pixels or None, n or None, points by
    renderer)], the main chart first, then one per N measured at two pixel counts or more."""
    main_pixels = study["width"] * study["height"]
    points = [p for p in study["points"] if p["scene"] == scene]
    if points and not any(p["pixels"] == main_pixels for p in points):
        counts = {}
        for p in points:
            counts[p["pixels"]] = counts.get(p["pixels"], 0) + 1
        main_pixels = max(counts, key=counts.get)

    def by_renderer(keep):
        out = {name: 0 for name in study["renderer_order"]}
        for p in points:
            if keep(p):
                out[p["renderer"]] = out.get(p["renderer"], 0) + 1
        return out

    charts = [("against N", main_pixels, None, by_renderer(lambda p: p["pixels"] == main_pixels))]
    pixel_counts = {p["pixels"] for p in points}
    if len(pixel_counts) > 1:
        for n in sorted({p["n"] for p in points}):
            if len({p["pixels"] for p in points if p["n"] == n}) >= 2:
                charts.append((f"against pixels at N = {n}", None, n,
                               by_renderer(lambda p, n=n: p["n"] == n)))
    return charts


def crossovers_expected(study, scene, pixels, n):
    return [c for c in study["crossovers"] if c["scene"] == scene and
            ((n is None and c["axis"] != "pixels" and c["pixels"] == pixels) or
             (n is not None and c["axis"] == "pixels" and c.get("n") == n))]


def chart_problems(study, scene, label, chart, counts, crossovers):
    """What one chart lacks: points, curves, crossover marks."""
    where = f"{scene}, chart {label}"
    problems = []
    series = {s["renderer"]: s for s in chart["series"]}
    if chart["width"] < 300 or chart["height"] < 150:
        problems.append(f"{where}: drawn {chart['width']}×{chart['height']}, too small")
    if chart["decadeLabels"] < 2:
        problems.append(f"{where}: fewer than two decade labels (10^k) on its axes")
    for name, count in counts.items():
        s = series.get(name)
        if s is None:
            problems.append(f"{where}: no series for {name}")
            continue
        if count == 0 or s["marks"] != count or s["marksInside"] != count:
            problems.append(f"{where}: {name} has {s['marks']} point marks "
                            f"({s['marksInside']} inside the chart), study.json {count} points")
        if s["spreads"] != s["marks"]:
            problems.append(f"{where}: {name} has {s['spreads']} spread bars for "
                            f"{s['marks']} points")
        fit = study["renderers"].get(name, {}).get("fits", {}).get(scene)
        fitted = fit and any(c.get("value") not in (None, 0)
                             for c in fit.get("coefficients", {}).values())
        if fitted:
            models = s["models"]
            # A model that does not fit may predict no positive time over this chart's range
            # (a negative slope from noise): the chart must then say so in place of the curve.
            if not models and not fit["fits"] and s["notPositive"] == 1:
                continue
            if len(models) != 1 or models[0]["length"] <= 0:
                problems.append(f"{where}: {name}'s model curve is missing or not drawn")
            elif models[0]["fits"] != fit["fits"] or models[0]["dashed"] == fit["fits"]:
                problems.append(f"{where}: {name}'s curve says fits={models[0]['fits']} "
                                f"(dashed={models[0]['dashed']}), study.json {fit['fits']}")
    if len(chart["crossovers"]) != len(crossovers):
        problems.append(f"{where}: {len(chart['crossovers'])} crossover marks, study.json "
                        f"{len(crossovers)}")
    for mark in chart["crossovers"]:
        if mark["lines"] != 1 or (mark["measured"] and mark["bands"] != 1):
            problems.append(f"{where}: a crossover without its line or its interval band")
    return problems


def check_study(args, work):
    if args.existing:  # an output folder made earlier (for trying the check by hand)
        out_dir = Path(args.existing).resolve()
    else:
        out_dir = work / "study"
        run_study(args.rvr, out_dir, args.budget)
    study = json.loads((out_dir / "study.json").read_text())
    problems, probe = check_page(args.chromium, out_dir / "study.html", args.screenshot, work,
                                 args.timeout, PAGE_PROBE)
    if probe["scripts"]:
        problems.append(f"{probe['scripts']} script elements: study.html needs none")
    sections = {s["scene"]: s for s in probe["scenes"]}
    for scene in (s["name"] for s in study["scenes"]):
        section = sections.get(scene)
        if section is None:
            problems.append(f"no section for scene {scene}")
            continue
        expected = expected_charts(study, scene)
        if len(section["charts"]) != len(expected):
            problems.append(f"{scene}: {len(section['charts'])} charts, expected "
                            f"{len(expected)}")
        for (label, pixels, n, counts), chart in zip(expected, section["charts"]):
            problems += chart_problems(study, scene, label, chart, counts,
                                       crossovers_expected(study, scene, pixels, n))
        if section["modelRows"] != len(study["renderer_order"]):
            problems.append(f"{scene}: {section['modelRows']} rows in the models table")
    for text in (study["command"], "Cost models", "Scope.", "Method.", "Machine",
                 study["machine"]["cpu"]):
        if text not in probe["text"]:
            problems.append(f"the page does not show '{text}'")
    print(f"page '{probe['title']}': " + "; ".join(
        f"{s['scene']}: " + ", ".join(
            f"chart {c['id']} [" + " ".join(f"{x['renderer']} {x['marks']} points"
                                            for x in c["series"]) +
            f", {len(c['crossovers'])} crossovers]" for c in s["charts"])
        for s in probe["scenes"]))
    return problems


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--rvr", help="the rvr binary")
    add_common_arguments(parser, watchdog=150)
    parser.add_argument("--budget", type=float, default=4, help="the study's budget (s)")
    parser.add_argument("--existing", metavar="DIR",
                        help="check DIR/study.html of an earlier run instead of running rvr")
    args = parser.parse_args()
    if not args.rvr and not args.existing:
        parser.error("--rvr or --existing is required")
    return run_check(args, lambda work: check_study(args, work))


if __name__ == "__main__":
    sys.exit(main())
