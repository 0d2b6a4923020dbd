#!/usr/bin/python3
"""Puts a study's generated study.md into bench/README.md, between the `<!-- study.md -->`
marker and the next second-level heading, its headings moved down two levels. The README then
shows the last `make study` run as generated, never edited by hand. Only the study's scope,
method and machine and its conclusions between loop orders (the headline crossover, every
crossover, the prediction checks, or why nothing could be concluded) are pasted; the long
per-renderer sections (dominance, the hybrids' split, builds, memory, cost models, counted work,
scaling) stay in study.md only, so that the README remains a reference page: a line in their
place points there.

usage: paste_study.py STUDY_MD README_MD
"""
import re
import sys

# Sections of study.md (second-level headings there) pasted into the README; every other one
# is left out.
KEPT = ("Where the pixel-major loop overtakes", "Crossovers", "Predictions checked",
        "No conclusion")


def without_long_lists(study):
    """study.md without the sections not in KEPT (each up to the next heading of its level or
    above), and whether any was left out."""
    kept, skipping, left_out = [], False, False
    for line in study.splitlines():
        heading = re.match(r"^(#+) (.*)", line)
        if heading and len(heading.group(1)) <= 2:
            skipping = len(heading.group(1)) == 2 and not heading.group(2).startswith(KEPT)
            left_out = left_out or skipping
        if not skipping:
            kept.append(line)
    return "\n".join(kept), left_out


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    study_path, readme_path = sys.argv[1], sys.argv[2]
    with open(study_path, encoding="utf-8") as f:
        study = f.read()
    with open(readme_path, encoding="utf-8") as f:
        readme = f.read()
    marker = "<!-- study.md -->\n"
    start = readme.find(marker)
    if start < 0:
        sys.exit(f"error: {readme_path}: no '{marker.strip()}' marker")
    start += len(marker)
    following = re.search(r"^## ", readme[start:], flags=re.M)
    end = start + following.start() if following else len(readme)
    study, left_out = without_long_lists(study)
    demoted = re.sub(r"^(#+) ", lambda m: "#" * (len(m.group(1)) + 2) + " ", study, flags=re.M)
    pasted = demoted.strip() + "\n"
    if left_out:
        pasted += ("\nWhere each renderer is faster, the hybrids' split, builds per scene, "
                   "memory, the cost models (from formulas and from counted work), the chapter's "
                   "claims checked on counts and the scaling of every renderer are in "
                   "`bench/study/study.md`.\n")
    readme = readme[:start] + "\n" + pasted + "\n" + readme[end:]
    with open(readme_path, "w", encoding="utf-8") as f:
        f.write(readme)


if __name__ == "__main__":
    main()
