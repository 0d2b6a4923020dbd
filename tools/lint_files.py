#!/usr/bin/env python3
"""The translation units `make lint` checks: every file of the build's compile_commands.json
whose path matches INCLUDE and not EXCLUDE (regular expressions; an empty EXCLUDE leaves
nothing out), one per line as an anchored regular expression for run-clang-tidy."""
import json
import re
import sys


def main():
    commands, include, exclude = sys.argv[1], sys.argv[2], sys.argv[3]
    with open(commands) as f:
        files = sorted({entry["file"] for entry in json.load(f)})
    for path in files:
        if re.search(include, path) and not (exclude and re.search(exclude, path)):
            print("^" + re.escape(path) + "$")


if __name__ == "__main__":
    main()
