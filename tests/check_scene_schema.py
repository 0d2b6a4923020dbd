#!/usr/bin/python3
"""Checks docs/rvr-scene-1.schema.json against the loader, the scene files and the exporter.

1. The schema is a valid draft 2020-12 schema (check_schema).
2. Every rvr-scene document under scenes/ (any *.json with a "format" or "camera" key) is valid.
3. Every built-in scene listed by `rvr scenes`, written by `rvr scenes --export NAME -o FILE`,
   is valid and loads back (a tiny render exits 0); a scene with no meshes gives the same
   document on stdout, one with meshes refuses stdout with exit 2.
4. Files the loader accepts at the edges of its rules (whole numbers as 640.0, -0 and values
   that round to -0 in colours, csg children without "type", ...) are valid: the schema must
   never be stricter than the loader.
5. A table of invalid files: the schema refuses each AND the loader refuses each (exit 2, one
   line starting "error: "). A second table holds rules JSON Schema cannot express (an
   unknown material name, far <= near, ...): there only the loader is required to refuse.

Usage: check_scene_schema.py --rvr build/bin/rvr --source-dir . [--work-dir DIR]
Exits 1 with one line per failure.
"""

import argparse
import copy
import json
import subprocess
import sys
import tempfile
from pathlib import Path

from schema_check import load_validator, schema_errors

FAILURES = []


def failure(message):
    FAILURES.append(message)
    print("FAIL: " + message)


def run(cmd, timeout=120):
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)


def render(rvr, path, work):
    """Loads `path` through the cheapest full load: an 8x8 ray-traced visibility image."""
    return run([rvr, "render", str(path), "-r", "raytrace", "--mode", "visibility",
                "-o", str(work / "render.png"), "--width", "8", "--height", "8", "--quiet"])


def loader_refuses(result):
    lines = result.stderr.strip().splitlines()
    return result.returncode == 2 and len(lines) == 1 and lines[0].startswith("error: ")


# A valid scene using every kind of key; the tables below mutate copies of it.
def base_scene(source_dir):
    return {
        "format": "rvr-scene/1",
        "image": {"width": 64, "height": 48, "background": [0, 0, 0], "samples_per_pixel": 1},
        "camera": {"eye": [0, 1, 4], "target": [0, 1, 0], "up": [0, 1, 0], "fov_y_deg": 45,
                   "near": 0.01, "far": 1000, "aperture_radius": 0, "focus_distance": 4},
        "ambient": [0.05, 0.05, 0.05],
        "materials": {
            "white": {"diffuse": [0.8, 0.8, 0.8]},
            "mirror": {"diffuse": [0.1, 0.1, 0.1], "specular": [0.9, 0.9, 0.9],
                       "shininess": 200, "mirror": 0.85},
            "glass": {"diffuse": [0, 0, 0], "transparency": 0.9, "ior": 1.5},
        },
        "lights": [
            {"type": "point", "position": [0, 3.9, 0], "intensity": [8, 8, 8]},
            {"type": "area", "corner": [-0.5, 3.99, -0.5], "edge_u": [1, 0, 0],
             "edge_v": [0, 0, 1], "intensity": [8, 8, 8], "samples": 2},
        ],
        "objects": [
            {"name": "ball", "type": "sphere", "center": [0, 1, 0], "radius": 1,
             "material": "mirror"},
            {"type": "plane", "point": [0, 0, 0], "normal": [0, 1, 0], "half_size": 10,
             "material": "white"},
            {"type": "triangle", "vertices": [[0, 0, 0], [1, 0, 0], [0, 1, 0]]},
            {"type": "mesh", "file": str(Path(source_dir) / "scenes/models/torus.obj"),
             "smooth": True, "material": "glass",
             "transform": {"scale": 0.5, "rotate_deg": [0, 30, 0], "translate": [1, 0, -1]}},
            {"type": "csg", "op": "difference", "material": "white",
             "a": {"type": "sphere", "center": [0, 1, 0], "radius": 1},
             "b": {"op": "union", "a": {"center": [0.5, 1.5, 0.5], "radius": 0.6},
                   "b": {"type": "sphere", "center": [0, 2, 0], "radius": 0.3}}},
        ],
    }


def setter(*path_and_value):
    """A mutation that sets doc[path...] = value (or deletes it when value is DELETE)."""
    *path, value = path_and_value

    def mutate(doc):
        target = doc
        for key in path[:-1]:
            target = target[key]
        if value is DELETE:
            del target[path[-1]]
        else:
            target[path[-1]] = value
    return mutate


DELETE = object()
TINY = 2.0 ** -150  # the largest magnitude a 32-bit float rounds to zero

# Accepted by the loader at the edges of its rules: the schema must accept them too.
EDGE_VALID = [
    ("no format key", setter("format", DELETE)),
    ("width as 64.0", setter("image", "width", 64.0)),
    ("spp 4096", setter("image", "samples_per_pixel", 4096)),
    ("-0 in a colour", setter("ambient", [-0.0, 0, 0])),
    ("a colour component rounding to -0", setter("ambient", [-TINY, 0, 0])),
    ("mirror rounding to 1", setter("materials", "mirror", "mirror", 1 + 2.0 ** -24)),
    ("empty materials, lights, objects",
     lambda d: d.update(materials={}, lights=[], objects=[])),
    ("no image", setter("image", DELETE)),
    ("only the camera's required keys",
     setter("camera", {"eye": [0, 1, 4], "target": [0, 1, 0], "up": [0, 2, 0]})),
    ("FLT_MAX as far", setter("camera", "far", 3.4028234663852886e38)),
    ("scale per axis on a mesh", setter("objects", 3, "transform", "scale", [1, 2, -3])),
    ("transform on a sphere", setter("objects", 0, "transform", {"scale": [-2, 2, 2]})),
    ("csg child without type, with op",
     setter("objects", 4, "b", {"op": "intersection", "a": {"center": [0, 0, 0], "radius": 1},
                                "b": {"center": [0, 1, 0], "radius": 1}})),
    ("object name any string", setter("objects", 0, "name", "")),
    ("material name with spaces",
     lambda d: (d["materials"].update({"a b": {}}), d["objects"][0].update(material="a b"))),
    ("a mesh keeping its file's materials", setter("objects", 3, "material", "from_file")),
    ("a texture file that is missing (a warning)",
     setter("materials", "white", "texture", "no/such/image.png")),
    ("a texture with wrap per axis and a transform",
     setter("materials", "white", "texture",
            {"file": "img.png", "wrap": ["clamp", "mirror"],
             "transform": {"offset": [0.5, -1], "rotation": 0.3, "scale": [2, -1]}})),
    ("a triangle's uvs and colours",
     lambda d: d["objects"][2].update(uvs=[[0, 0], [1, 0], [0, 1]],
                                      colors=[[1, 0, 0], [0, 1, 0], [0, 0, 1]])),
]

# Refused by the schema AND by the loader.
INVALID = [
    ("wrong format string", setter("format", "rvr-scene/2")),
    ("format not a string", setter("format", 1)),
    ("missing camera", setter("camera", DELETE)),
    ("camera without up", setter("camera", "up", DELETE)),
    ("negative image width", setter("image", "width", -640)),
    ("image height too large", setter("image", "height", 16385)),
    ("fractional width", setter("image", "width", 64.5)),
    ("width as a string", setter("image", "width", "64")),
    ("spp 0", setter("image", "samples_per_pixel", 0)),
    ("fov 180", setter("camera", "fov_y_deg", 180)),
    ("near 0", setter("camera", "near", 0)),
    ("negative aperture", setter("camera", "aperture_radius", -0.1)),
    ("eye with two numbers", setter("camera", "eye", [0, 1])),
    ("eye component a string", setter("camera", "eye", [0, "1", 4])),
    ("number out of float range", setter("camera", "eye", [0, 1, 1e39])),
    ("up all zero", setter("camera", "up", [0, 0, 0])),
    ("negative colour", setter("ambient", [0.1, -0.1, 0.1])),
    ("colour with four numbers", setter("ambient", [0.1, 0.1, 0.1, 1])),
    ("unknown top-level key", setter("lighting", [])),
    ("unknown camera key", setter("camera", "fov", 45)),
    ("unknown material key", setter("materials", "white", "colour", [1, 1, 1])),
    ("materials as an array", setter("materials", [])),
    ("empty material name", setter("materials", "", {})),
    ("a material named from_file (reserved)", setter("materials", "from_file", {})),
    ("mirror above 1", setter("materials", "mirror", "mirror", 1.5)),
    ("negative shininess", setter("materials", "mirror", "shininess", -1)),
    ("ior below 1", setter("materials", "glass", "ior", 0.9)),
    ("bad light type", setter("lights", 0, "type", "spot")),
    ("light without type", setter("lights", 0, "type", DELETE)),
    ("point light without intensity", setter("lights", 0, "intensity", DELETE)),
    ("point light with samples", setter("lights", 0, "samples", 4)),
    ("area light samples 65", setter("lights", 1, "samples", 65)),
    ("area edge all zero", setter("lights", 1, "edge_u", [0, 0, 0])),
    ("bad object type", setter("objects", 0, "type", "cube")),
    ("object without type", setter("objects", 0, "type", DELETE)),
    ("sphere radius 0", setter("objects", 0, "radius", 0)),
    ("negative sphere radius", setter("objects", 0, "radius", -1)),
    ("sphere with a plane's key", setter("objects", 0, "normal", [0, 1, 0])),
    ("plane without normal", setter("objects", 1, "normal", DELETE)),
    ("plane half_size 0", setter("objects", 1, "half_size", 0)),
    ("triangle with two vertices", setter("objects", 2, "vertices", [[0, 0, 0], [1, 0, 0]])),
    ("mesh without file", setter("objects", 3, "file", DELETE)),
    ("mesh file empty", setter("objects", 3, "file", "")),
    ("smooth as a string", setter("objects", 3, "smooth", "yes")),
    ("scale 0", setter("objects", 3, "transform", "scale", 0)),
    ("unknown transform key", setter("objects", 3, "transform", "rotate", [0, 0, 0])),
    ("bad csg op", setter("objects", 4, "op", "xor")),
    ("csg child of type plane", setter("objects", 4, "a", "type", "plane")),
    ("material inside a csg tree", setter("objects", 4, "a", "material", "white")),
    ("csg child sphere without radius", setter("objects", 4, "a", "radius", DELETE)),
    ("material name a number", setter("objects", 0, "material", 3)),
    ("objects as an object", setter("objects", {})),
    ("null instead of a number", setter("camera", "far", None)),
    ("top level an array", lambda d: [d]),
]

# Rules JSON Schema cannot express: the loader alone refuses these.
LOADER_ONLY = [
    ("unknown material reference", setter("objects", 0, "material", "gold")),
    ("far <= near", setter("camera", "far", 0.001)),
    ("eye == target", setter("camera", "target", [0, 1, 4])),
    ("up parallel to the view", setter("camera", "up", [0, 0, 1])),
    ("mirror + transparency > 1", setter("materials", "glass", "mirror", 0.5)),
    ("area edges parallel", setter("lights", 1, "edge_v", [2, 0, 0])),
    ("degenerate triangle", setter("objects", 2, "vertices", [[0, 0, 0], [1, 0, 0], [2, 0, 0]])),
    ("non-uniform scale on a sphere", setter("objects", 0, "transform", {"scale": [1, 2, 1]})),
    ("missing mesh file", setter("objects", 3, "file", "no/such/file.obj")),
    ("from_file on a sphere", setter("objects", 0, "material", "from_file")),
    ("texture not a string or object", setter("materials", "white", "texture", 3)),
    ("texture without file", setter("materials", "white", "texture", {"wrap": "clamp"})),
    ("unknown wrap mode", setter("materials", "white", "texture", {"file": "a.png", "wrap": "tile"})),
    ("texture scale 0",
     setter("materials", "white", "texture", {"file": "a.png", "transform": {"scale": [0, 1]}})),
    ("a triangle with 2 uvs", setter("objects", 2, "uvs", [[0, 0], [1, 0]])),
    ("a negative vertex colour",
     setter("objects", 2, "colors", [[0, 0, 0], [0, -1, 0], [0, 0, 0]])),
]


def mutated(base, mutate):
    doc = copy.deepcopy(base)
    result = mutate(doc)
    return result if isinstance(result, list) else doc


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rvr", required=True)
    ap.add_argument("--source-dir", required=True)
    ap.add_argument("--schema", help="default: SOURCE_DIR/docs/rvr-scene-1.schema.json")
    ap.add_argument("--work-dir", help="default: a temporary folder")
    args = ap.parse_args()
    source = Path(args.source_dir).resolve()
    schema_path = Path(args.schema or source / "docs/rvr-scene-1.schema.json")
    work = Path(args.work_dir or tempfile.mkdtemp(prefix="rvr-scene-schema-"))
    work.mkdir(parents=True, exist_ok=True)

    validator, problems = load_validator(schema_path)
    for problem in problems:
        failure(problem)
    if validator is None:
        return 1

    # 2. Scene files in the repository.
    count = 0
    for path in sorted((source / "scenes").rglob("*.json")):
        doc = json.loads(path.read_text())
        if not isinstance(doc, dict) or not ("format" in doc or "camera" in doc):
            print(f"skip {path}: not an rvr-scene document")
            continue
        count += 1
        for err in schema_errors(validator, doc):
            failure(f"{path}: schema refuses a shipped scene: {err}")
    if count == 0:
        failure("no scene files found under scenes/")
    print(f"scenes/: {count} files checked")

    # 3. Built-in scenes through the exporter.
    listing = run([args.rvr, "scenes"])
    names = [line.split()[0].removeprefix("builtin:").split(":")[0]
             for line in listing.stdout.splitlines() if line.startswith("builtin:")]
    if listing.returncode != 0 or not names:
        failure(f"rvr scenes: exit {listing.returncode}, no scene names")
    for name in names + ["tessphere:300", "soup:40", "occluders:2"]:
        out = work / "export" / (name.replace(":", "_") + ".json")
        out.parent.mkdir(parents=True, exist_ok=True)
        r = run([args.rvr, "scenes", "--export", name, "-o", str(out)])
        if r.returncode != 0:
            failure(f"export {name}: exit {r.returncode}: {r.stderr.strip()}")
            continue
        doc = json.loads(out.read_text())
        for err in schema_errors(validator, doc):
            failure(f"export {name}: schema refuses the exported scene: {err}")
        has_meshes = any(o.get("type") == "mesh" for o in doc.get("objects", []))
        stdout = run([args.rvr, "scenes", "--export", name])
        if has_meshes:
            if not loader_refuses(stdout):
                failure(f"export {name} to stdout: a scene with meshes must exit 2 with one "
                        f"error line, got exit {stdout.returncode}")
        elif stdout.returncode != 0 or stdout.stdout != out.read_text():
            failure(f"export {name} to stdout: exit {stdout.returncode} or a different document")
        r = render(args.rvr, out, work)
        if r.returncode != 0:
            failure(f"export {name}: the exported file does not load: exit {r.returncode}: "
                    f"{r.stderr.strip()}")
    print(f"built-in scenes: {len(names)} names exported")
    r = run([args.rvr, "scenes", "--export", "nosuchscene"])
    if not loader_refuses(r) or not r.stderr.startswith("error: builtin:nosuchscene: "):
        failure(f"export of an unknown name: want exit 2 and 'error: builtin:nosuchscene: ...', "
                f"got exit {r.returncode}: {r.stderr.strip()}")

    # 4-5. The tables.
    base = base_scene(source)
    cases = work / "cases"
    cases.mkdir(exist_ok=True)

    def write(kind, i, doc):
        path = cases / f"{kind}{i:02d}.json"
        path.write_text(json.dumps(doc, indent=2))
        return path

    for i, (what, mutate) in enumerate([("the base scene", lambda d: None)] + EDGE_VALID):
        doc = mutated(base, mutate)
        path = write("valid", i, doc)
        r = render(args.rvr, path, work)
        if r.returncode != 0:
            failure(f"valid case '{what}' ({path.name}): the loader refuses it "
                    f"(fix the case): {r.stderr.strip()}")
        for err in schema_errors(validator, doc):
            failure(f"valid case '{what}' ({path.name}): the schema is stricter than the "
                    f"loader: {err}")
    for i, (what, mutate) in enumerate(INVALID):
        doc = mutated(base, mutate)
        path = write("invalid", i, doc)
        if not schema_errors(validator, doc):
            failure(f"invalid case '{what}' ({path.name}): the schema accepts it")
        r = render(args.rvr, path, work)
        if not loader_refuses(r):
            failure(f"invalid case '{what}' ({path.name}): the loader does not refuse it with "
                    f"exit 2 and one 'error: ' line: exit {r.returncode}: {r.stderr.strip()}")
    for i, (what, mutate) in enumerate(LOADER_ONLY):
        doc = mutated(base, mutate)
        path = write("loader_only", i, doc)
        r = render(args.rvr, path, work)
        if not loader_refuses(r):
            failure(f"loader-only case '{what}' ({path.name}): the loader does not refuse it: "
                    f"exit {r.returncode}: {r.stderr.strip()}")
    print(f"tables: {len(EDGE_VALID) + 1} valid, {len(INVALID)} invalid, "
          f"{len(LOADER_ONLY)} loader-only cases")

    if FAILURES:
        print(f"{len(FAILURES)} failure(s)")
        return 1
    print("PASS")
    return 0


if __name__ == "__main__":
    sys.exit(main())
