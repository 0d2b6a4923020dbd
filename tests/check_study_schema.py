#!/usr/bin/python3
"""Checks `rvr study` as a user runs it, and docs/rvr-study-2.schema.json against its output.

1. The schema is a valid draft 2020-12 schema.
2. A small study (builtin:tessphere, --width 128, --budget 20) exits 0, writes study.json that
   the schema accepts (every renderer of the default set with a fit for tessphere, every point
   with its repetitions) and study.md with its sections, within the budget and a margin.
3. Bad input (an unknown family, --budget 0 or negative, an unknown renderer) exits 2 with one
   line starting "error: " and creates nothing.
4. A study stopped by Ctrl-C (SIGINT after 3 s) exits 130 and writes a study.json the schema
   accepts, marked interrupted, with at least one point.
5. --merge of the study with itself is refused (exit 2: a study is merged once); with a copy
   whose SIMD kernels say another machine type, it writes studies the schema accepts (one per
   machine type and comparison.md).

Usage: check_study_schema.py --rvr build/bin/rvr --source-dir . [--work-dir DIR]
Exits 1 with one line per failure.
"""

import argparse
import json
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from schema_check import load_validator, schema_errors

FAILURES = []


def failure(message):
    FAILURES.append(message)
    print("FAIL: " + message)


def run(cmd, timeout=100):
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)


def validate(validator, path):
    doc = json.loads(path.read_text())
    for err in schema_errors(validator, doc):
        failure(f"{path}: schema: {err}")
    return doc


def check_interrupted(rvr, validator, work):
    out = work / "interrupted"
    p = subprocess.Popen([rvr, "study", "builtin:tessphere", "--budget", "600", "--width", "128",
                          "--quiet", "-o", str(out)],
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    time.sleep(3)
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=60)
    if p.returncode != 130 or not err.startswith("rvr study: interrupted; wrote "):
        failure(f"interrupted study: want exit 130 and 'rvr study: interrupted; ...', got exit "
                f"{p.returncode}: {err.strip()}")
        return
    doc = validate(validator, out / "study.json")
    if doc.get("interrupted") is not True or len(doc.get("points", [])) < 1:
        failure(f"interrupted study: interrupted {doc.get('interrupted')}, "
                f"{len(doc.get('points', []))} points")


def check_merge(rvr, validator, work):
    study = work / "study"
    if not (study / "study.json").exists():
        return  # check_study has said why
    other = work / "other-machine"
    other.mkdir()
    doc = json.loads((study / "study.json").read_text())
    doc["machine"]["kernels"] = "sse (edited: another machine type)"
    (other / "study.json").write_text(json.dumps(doc))
    twice = run([rvr, "study", "--merge", str(study), str(study), "-o", str(work / "twice")])
    if twice.returncode != 2 or "merged once" not in twice.stderr:
        failure(f"--merge of a study with itself: want exit 2 and 'merged once', got exit "
                f"{twice.returncode}: {twice.stderr.strip()}")
    if (work / "twice").exists():
        failure("--merge of a study with itself wrote its output folder")
    out = work / "compared"
    r = run([rvr, "study", "--merge", str(study), str(other), "-o", str(out)])
    if r.returncode not in (0, 1):
        failure(f"--merge (compared): exit {r.returncode}: {r.stderr.strip()}")
        return
    written = sorted(out.glob("**/study.json"))
    if len(written) != 2:
        failure(f"--merge (compared): wrote {[str(p) for p in written]}")
    for path in written:
        validate(validator, path)
    if not (out / "comparison.md").exists():
        failure("--merge (compared): no comparison.md")


def check_study(rvr, validator, work):
    out = work / "study"
    start = time.monotonic()
    r = run([rvr, "study", "builtin:tessphere", "--budget", "20", "--width", "128", "--quiet",
             "-o", str(out)])
    seconds = time.monotonic() - start
    if r.returncode != 0:
        failure(f"rvr study: exit {r.returncode}: {r.stderr.strip()}")
        return
    if seconds > 40:
        failure(f"rvr study --budget 20 took {seconds:.0f} s")
    doc = validate(validator, out / "study.json")
    if doc["elapsed_seconds"] > 20:
        failure(f"study.json: {doc['elapsed_seconds']:.1f} s of measuring in a 20 s budget")
    kinds = {s["kind"] for s in doc["sessions"]}
    if kinds != {"process"} or len(doc["sessions"]) < 3:
        failure(f"study.json: sessions {len(doc['sessions'])} of kinds {kinds}: want >= 3 processes")
    for name in ["softraster", "raytrace", "hybrid_soft"]:
        if "tessphere" not in doc["renderers"].get(name, {}).get("fits", {}):
            failure(f"study.json: renderers.{name}.fits.tessphere missing")
    if len(doc["points"]) < 3 * 3:
        failure(f"study.json: only {len(doc['points'])} points")
    md = (out / "study.md").read_text()
    for section in ["**Scope.**", "**Method.**",
                    "## Where the pixel-major loop overtakes the triangle-major one",
                    "## Cost models", "## Scaling"]:
        if section not in md:
            failure(f"study.md: no '{section}' section")
    print(f"study: {len(doc['points'])} points in {seconds:.1f} s; "
          f"{len(doc['crossovers'])} crossovers, {len(doc['dominance'])} without")


def check_refused(rvr, work):
    cases = [
        ("an unknown family", ["builtin:cornell"], "builtin:cornell: "),
        ("budget 0", ["builtin:tessphere", "--budget", "0"], "--budget"),
        ("a negative budget", ["builtin:tessphere", "--budget=-3"], "--budget"),
        ("an unknown renderer", ["builtin:tessphere", "-r", "nosuch"], "nosuch"),
    ]
    for what, args, words in cases:
        out = work / "refused"
        shutil.rmtree(out, ignore_errors=True)
        r = run([rvr, "study", *args, "-o", str(out)])
        lines = r.stderr.strip().splitlines()
        if r.returncode != 2 or len(lines) != 1 or not lines[0].startswith("error: ") \
                or words not in lines[0]:
            failure(f"{what}: want exit 2 and one 'error: ...{words}...' line, got exit "
                    f"{r.returncode}: {r.stderr.strip()}")
        if out.exists():
            failure(f"{what}: the output folder was created")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rvr", required=True)
    ap.add_argument("--source-dir", required=True)
    ap.add_argument("--work-dir", help="default: a temporary folder")
    args = ap.parse_args()
    source = Path(args.source_dir).resolve()
    work = Path(args.work_dir or tempfile.mkdtemp(prefix="rvr-study-schema-"))
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    validator, problems = load_validator(source / "docs/rvr-study-2.schema.json")
    for problem in problems:
        failure(problem)
    if validator is None:
        return 1
    check_refused(args.rvr, work)
    check_study(args.rvr, validator, work)
    check_merge(args.rvr, validator, work)
    check_interrupted(args.rvr, validator, work)
    if FAILURES:
        print(f"{len(FAILURES)} failure(s)")
        return 1
    print("PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())
