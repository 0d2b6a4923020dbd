#!/usr/bin/python3
"""Puts a study's generated study.md into bench/README.md, between the `<!-- study.md -->`
marker and the next second-level heading, its headings moved down two levels. The README then
shows the last `make study` run as generated, never edited by hand.

usage: paste_study.py STUDY_MD README_MD
"""
import re
import sys


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
    demoted = re.sub(r"^(#+) ", lambda m: "#" * (len(m.group(1)) + 2) + " ", study, flags=re.M)
    readme = readme[:start] + "\n" + demoted.strip() + "\n\n" + readme[end:]
    with open(readme_path, "w", encoding="utf-8") as f:
        f.write(readme)


if __name__ == "__main__":
    main()
