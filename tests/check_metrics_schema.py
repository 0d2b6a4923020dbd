#!/usr/bin/python3
"""Checks docs/rvr-metrics-2.schema.json against the metrics.json that `rvr compare` writes.

1. The schema is a valid draft 2020-12 schema.
2. A real three-renderer compare (builtin:cornell, raster,raytrace,softraster, 64x48) exits 0
   and writes metrics.json that the schema accepts: format rvr-metrics/2, one renderer entry
   per renderer with its depth format, the pairs (0,1), (0,2), (1,2) in that order with the
   first repeating the top level, and every file it names present.
3. A compare where nothing is visible (the near plane beyond the only object) writes a
   metrics.json with a warning per renderer that the schema also accepts.
4. A textured compare (builtin:textured, raster,softraster) writes the `lod` block (pixels
   textured in both, mean and p99 of |lod_a - lod_b|) that the schema accepts, with a
   plausible mean; the untextured cornell compare has none.
5. Documents the schema must refuse, each a copy of the real one with one thing wrong: the
   dropped mismatched_off_edge count back in `visibility`, a mismatch class missing, no pairs,
   an unknown depth format, a negative count, a lod block without its p99, a count stat that is
   not a whole number.
6. A full-mode compare (builtin:cornell, raster,raytrace) writes the `effects` block (the
   colour error over the pixels each effect touches, masks from the tracer's frame) that the
   schema accepts, with reflection and refraction; local mode writes none; an unknown effect
   is refused.
7. Every count stat of the real documents is written as a JSON integer (159305728, not
   159305728.0; JSON Schema cannot tell the two apart): a stat is a count unless the schema's
   patternProperties for stats name it (seconds, declared ratios).

Usage: check_metrics_schema.py --rvr build/bin/rvr --source-dir . [--work-dir DIR]
Exits 1 with one line per failure.
"""

import argparse
import copy
import json
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from schema_check import load_validator, schema_errors

FAILURES = []
RENDERERS = ["raster", "raytrace", "softraster"]


def failure(message):
    FAILURES.append(message)
    print("FAIL: " + message)


def compare(rvr, scene, renderers, out, extra=()):
    r = subprocess.run([rvr, "compare", scene, "-r", ",".join(renderers), "--width", "64",
                        "--height", "48", "-o", str(out), *extra],
                       capture_output=True, text=True, timeout=100)
    if r.returncode != 0:
        failure(f"rvr compare {scene}: exit {r.returncode}: {r.stderr.strip()}")
        return None
    return json.loads((out / "metrics.json").read_text())


def accepted(validator, doc, label):
    for err in schema_errors(validator, doc):
        failure(f"{label}: the schema refuses rvr's own metrics.json: {err}")


def check_three(rvr, validator, work):
    out = work / "three"
    doc = compare(rvr, "builtin:cornell", RENDERERS, out)
    if doc is None:
        return None
    accepted(validator, doc, "three renderers")
    if doc.get("format") != "rvr-metrics/2":
        failure(f"format {doc.get('format')!r}, want 'rvr-metrics/2'")
    if list(doc.get("renderers", {})) != RENDERERS:
        failure(f"renderers {list(doc.get('renderers', {}))}, want {RENDERERS}")
    want = [[RENDERERS[0], RENDERERS[1]], [RENDERERS[0], RENDERERS[2]],
            [RENDERERS[1], RENDERERS[2]]]
    pairs = doc.get("pairs", [])
    if [p.get("compared") for p in pairs] != want:
        failure(f"pairs compare {[p.get('compared') for p in pairs]}, want {want}")
    elif any(pairs[0][k] != doc[k] for k in ("compared", "visibility", "depth", "color")):
        failure("pairs[0] does not repeat the top level")
    named = [doc["files"][k] for k in doc.get("files", {})]
    named += [f for p in pairs for f in p.get("files", {}).values()]
    named += [r["image"] for r in doc.get("renderers", {}).values()]
    for name in named:
        if not (out / name).is_file():
            failure(f"metrics.json names {name}, which was not written")
    print(f"three renderers: {len(pairs)} pairs, {len(named)} files named, "
          f"classes of the first pair {doc['visibility']['mismatch_classes']}")
    return doc


def check_textured(rvr, validator, work, untextured):
    if untextured is not None and "lod" in untextured:
        failure("builtin:cornell (no textures): metrics.json has a lod block")
    doc = compare(rvr, "builtin:textured", ["raster", "softraster"], work / "textured")
    if doc is None:
        return None
    accepted(validator, doc, "textured")
    lod = doc.get("lod")
    if lod is None or lod["pixels"] < 64 * 48 // 4:
        failure(f"builtin:textured: want a lod block over most of the floor, got {lod}")
        return None
    if lod != doc["pairs"][0].get("lod"):
        failure("builtin:textured: pairs[0] does not repeat the lod block")
    if not (0 <= lod["mean_abs"] < 1.0 and lod["mean_abs"] <= lod["p99_abs"] + 1e-12):
        failure(f"builtin:textured: implausible lod difference {lod}")
    print(f"textured: lod {lod}")
    return doc


def check_effects(rvr, validator, work, local):
    """Full mode writes the per-effect block, masks from the tracer; local mode has none."""
    if local is not None and "effects" in local:
        failure("builtin:cornell in local mode: metrics.json has an effects block")
    doc = compare(rvr, "builtin:cornell", ["raster", "raytrace"], work / "effects",
                  ["--mode", "full"])
    if doc is None:
        return None
    accepted(validator, doc, "effects")
    effects = doc.get("effects")
    names = [e["effect"] for e in (effects or {}).get("by_effect", [])]
    if effects is None or effects.get("mask_from") != "raytrace" or names != ["reflection",
                                                                             "refraction"]:
        failure(f"builtin:cornell full: want reflection and refraction masked from raytrace, "
                f"got {effects}")
        return None
    if effects != doc["pairs"][0].get("effects"):
        failure("builtin:cornell full: pairs[0] does not repeat the effects block")
    picture = doc.get("files", {}).get("effects")
    if picture is None or not (work / "effects" / picture).is_file():
        failure(f"builtin:cornell full: the effect masks' picture {picture!r} was not written")
    print(f"effects: {effects}")
    return doc


def check_nothing_visible(rvr, validator, work):
    scene = work / "empty.json"
    scene.write_text(json.dumps({
        "camera": {"eye": [0, 0, 5], "target": [0, 0, 0], "up": [0, 1, 0], "near": 10,
                   "far": 100},
        "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1}]}))
    doc = compare(rvr, str(scene), ["softraster", "raytrace"], work / "empty")
    if doc is None:
        return
    accepted(validator, doc, "nothing visible")
    if len(doc.get("warnings", [])) != 2:
        failure(f"nothing visible: want a warning per renderer, got {doc.get('warnings')}")
    if doc["visibility"]["covered_pixels"] != 0:
        failure(f"nothing visible: covered_pixels {doc['visibility']['covered_pixels']}")


def count_stats_written_as_integers(schema, text, label):
    """Stats the schema does not name as seconds or ratios must be JSON integers in `text`."""
    patterns = [re.compile(p) for p in
                schema["$defs"]["renderer"]["properties"]["stats"]["patternProperties"]]
    doc = json.loads(text)  # "1.0" comes back a float, "1" an int
    counts = 0
    for name, renderer in doc.get("renderers", {}).items():
        for key, value in renderer.get("stats", {}).items():
            if value is None or any(p.search(key) for p in patterns):
                continue
            counts += 1
            if not isinstance(value, int):
                failure(f"{label}: {name}'s count {key} is written as {value!r}, not an integer")
    if counts == 0:
        failure(f"{label}: no count stat to check")


def check_refused(validator, doc):
    def off_edge(d):
        d["visibility"]["mismatched_off_edge"] = 0

    def no_class(d):
        del d["pairs"][1]["visibility"]["mismatch_classes"]["depth_precision"]

    def no_pairs(d):
        d["pairs"] = []

    def depth_format(d):
        d["renderers"]["raster"]["depth_format"] = "d16"

    def negative(d):
        d["visibility"]["mismatch_classes"]["occlusion"] = -1

    def fractional_count(d):
        d["renderers"]["raytrace"]["stats"]["rays.primary"] = 3072.5

    for what, mutate in [("mismatched_off_edge in visibility", off_edge),
                         ("a mismatch class missing in a pair", no_class),
                         ("no pairs", no_pairs), ("depth format d16", depth_format),
                         ("a negative class count", negative),
                         ("a count stat that is not whole", fractional_count)]:
        bad = copy.deepcopy(doc)
        mutate(bad)
        if not schema_errors(validator, bad):
            failure(f"the schema accepts a metrics.json with {what}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rvr", required=True)
    ap.add_argument("--source-dir", required=True)
    ap.add_argument("--work-dir", help="default: a temporary folder")
    args = ap.parse_args()
    source = Path(args.source_dir).resolve()
    work = Path(args.work_dir or tempfile.mkdtemp(prefix="rvr-metrics-schema-"))
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    validator, problems = load_validator(source / "docs/rvr-metrics-2.schema.json")
    for problem in problems:
        failure(problem)
    if validator is None:
        return 1
    doc = check_three(args.rvr, validator, work)
    textured = check_textured(args.rvr, validator, work, doc)
    schema = json.loads((source / "docs/rvr-metrics-2.schema.json").read_text())
    for label, folder in [("three renderers", "three"), ("textured", "textured")]:
        written = work / folder / "metrics.json"
        if written.is_file():
            count_stats_written_as_integers(schema, written.read_text(), label)
    effects = check_effects(args.rvr, validator, work, doc)
    check_nothing_visible(args.rvr, validator, work)
    if effects is not None:
        bad = copy.deepcopy(effects)
        bad["effects"]["by_effect"][0]["effect"] = "caustics"
        if not schema_errors(validator, bad):
            failure("the schema accepts an effect it does not know")
    if doc is not None:
        check_refused(validator, doc)
    if textured is not None:
        bad = copy.deepcopy(textured)
        del bad["lod"]["p99_abs"]
        if not schema_errors(validator, bad):
            failure("the schema accepts a metrics.json with a lod block without p99_abs")
    if FAILURES:
        print(f"{len(FAILURES)} failure(s)")
        return 1
    print("PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())
