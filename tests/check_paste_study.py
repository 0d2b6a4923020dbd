#!/usr/bin/python3
"""Checks bench/paste_study.py, which `make study` runs to paste a study's study.md into
bench/README.md, and that the README stays a reference page.

1. A synthetic study.md (a title, the headline crossover, Crossovers, Scaling, Cost per triangle
   and per ray, Cost models, Predictions checked) pasted into a synthetic README: the headings
   moved down two levels, the Scaling, Cost per triangle and Cost models sections left out with
   a line pointing to study.md, every other line of the study kept in order, the README's text
   before the marker and from the next `## ` heading on kept byte for byte; pasting again
   changes nothing.
2. The repository's bench/README.md: at most 150 lines, and what paste_study.py makes of it with
   bench/study/study.md is the file itself (the README shows that study as generated).

Usage: check_paste_study.py --paste bench/paste_study.py --source-dir DIR [--work-dir DIR]
Exits 1 with one line per failure.
"""

import argparse
import os
import shutil
import subprocess
import sys
import tempfile

STUDY = """# rvr study

tessphere at 64×48; 3 repetitions per point.

## Where the pixel-major loop overtakes the triangle-major one

- at 64×48 on tessphere, the headline.

## Crossovers

- at 64×48 on tessphere, A is faster than B below 10 triangles.

## Scaling (log-log slope per decade)

- A on tessphere: time grows as N^0.50 from 100 to 1000.

## Cost per triangle and per ray

- A on tessphere at 100 triangles: 1 ms a frame.

## Cost models

- A on tessphere: t = a + b·P.

## Predictions checked

- at 30 triangles the check holds.
"""

BEFORE = "# bench\n\nReference text.\n\n## The study\n\n<!-- study.md -->\n"
STALE = "\n### an older study\n\n- stale line\n\n"
AFTER = "## Charts\n\nMore reference text.\n"


def paste(script, study_path, readme_path):
    subprocess.run([sys.executable, script, study_path, readme_path], check=True)
    with open(readme_path, encoding="utf-8") as f:
        return f.read()


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--paste", required=True)
    parser.add_argument("--source-dir", required=True)
    parser.add_argument("--work-dir")
    args = parser.parse_args()
    work = args.work_dir or tempfile.mkdtemp()
    os.makedirs(work, exist_ok=True)
    failures = []

    study_path = os.path.join(work, "study.md")
    readme_path = os.path.join(work, "README.md")
    with open(study_path, "w", encoding="utf-8") as f:
        f.write(STUDY)
    with open(readme_path, "w", encoding="utf-8") as f:
        f.write(BEFORE + STALE + AFTER)
    once = paste(args.paste, study_path, readme_path)
    if not once.startswith(BEFORE):
        failures.append("synthetic: the text up to the marker changed")
    if not once.endswith(AFTER):
        failures.append("synthetic: the text from the next section on changed")
    if "stale line" in once:
        failures.append("synthetic: the previous study was not replaced")
    for heading in ("### rvr study", "#### Where the pixel-major loop overtakes the "
                    "triangle-major one", "#### Crossovers", "#### Predictions checked"):
        if "\n" + heading + "\n" not in once:
            failures.append(f"synthetic: no '{heading}' (headings moved down two levels)")
    for gone in ("Scaling", "grows as", "Cost per triangle", "1 ms a frame", "Cost models",
                 "t = a + b·P."):
        if gone in once:
            failures.append(f"synthetic: '{gone}' should stay in study.md only")
    if "`bench/study/study.md`" not in once:
        failures.append("synthetic: no line pointing to study.md for the lists left out")
    kept = ["tessphere at 64×48; 3 repetitions per point.", "the headline.",
            "A is faster than B below 10", "the check holds."]
    positions = [once.find(k) for k in kept]
    if -1 in positions or positions != sorted(positions):
        failures.append("synthetic: the study's other lines are not all kept, in order")
    if paste(args.paste, study_path, readme_path) != once:
        failures.append("synthetic: pasting the same study again changed the README")

    readme = os.path.join(args.source_dir, "bench", "README.md")
    study = os.path.join(args.source_dir, "bench", "study", "study.md")
    with open(readme, encoding="utf-8") as f:
        text = f.read()
    lines = text.count("\n")
    if lines > 150:
        failures.append(f"bench/README.md: {lines} lines, more than 150 for a reference page")
    copy = os.path.join(work, "README.repo.md")
    shutil.copyfile(readme, copy)
    if paste(args.paste, study, copy) != text:
        failures.append("bench/README.md: not the last study as paste_study.py pastes it "
                        "(run make study, or bench/paste_study.py bench/study/study.md "
                        "bench/README.md)")

    for failure in failures:
        print("FAIL: " + failure)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
