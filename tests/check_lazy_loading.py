"""Which shared libraries each kind of run loads (docs/design.md, "Start-up loads only what the
run needs"): neither `rvr` nor the Python module links Assimp or Embree; `rvr --version`, a bad
input and a render of a built-in scene load neither; the first model file loads the model-import
plugin and Assimp, the embree renderer the Embree plugin and Embree; each plugin exports only its
table (and the model importer its operator new and delete) and needs no rvr code from outside.
What is loaded is read from the dynamic loader's own trace (LD_DEBUG=files), not timed: the
start-up time is bench/startup.sh's.

    check_lazy_loading.py --rvr build/bin/rvr [--python-dir build/python] --work-dir DIR
"""
import argparse
import os
import pathlib
import re
import subprocess
import sys

ASSIMP = "libassimp.so"
EMBREE = "libembree3.so"
MODEL_PLUGIN = "librvr_model_import.so"
EMBREE_PLUGIN = "librvr_embree.so"
PLUGINS = {MODEL_PLUGIN: {"rvr_model_import_get"}, EMBREE_PLUGIN: {"rvr_embree_get"}}
# The model importer's operator new and delete forms (scene_io/src/allocation_budget_plugin.cpp).
OPERATORS = {"_Znwm", "_Znam", "_ZnwmRKSt9nothrow_t", "_ZnamRKSt9nothrow_t", "_ZdlPv", "_ZdaPv",
             "_ZdlPvm", "_ZdaPvm", "_ZdlPvRKSt9nothrow_t", "_ZdaPvRKSt9nothrow_t"}

failures = []


def check(condition, what):
    print(("ok   " if condition else "FAIL ") + what)
    if not condition:
        failures.append(what)


def loaded(command, env=None):
    """The file names of the shared objects the run's processes loaded (LD_DEBUG=files)."""
    env = dict(os.environ if env is None else env, LD_DEBUG="files")
    done = subprocess.run(command, capture_output=True, text=True, env=env, timeout=300)
    names = set()
    for line in done.stderr.splitlines():
        m = re.search(r"file=(\S+)\s+\[\d+\];\s+(needed by|dynamically loaded by)", line)
        if m:
            names.add(os.path.basename(m.group(1)))
    return done, names


def stderr_of(done):
    """What the run itself wrote to stderr, without the loader's trace."""
    return "\n".join(l for l in done.stderr.splitlines() if not re.match(r"^\s*\d+:", l))


def has(names, library):
    return any(n.startswith(library) for n in names)


def needed(path):
    out = subprocess.run(["readelf", "-d", str(path)], capture_output=True, text=True, check=True)
    return set(re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", out.stdout))


def dynamic_symbols(path, undefined):
    flag = "--undefined-only" if undefined else "--defined-only"
    out = subprocess.run(["nm", "-D", flag, str(path)], capture_output=True, text=True, check=True)
    symbols = []
    for line in out.stdout.splitlines():
        parts = line.split()
        if len(parts) >= 2 and (undefined or parts[-2] in ("T", "D", "B", "R")):
            symbols.append(parts[-1].split("@")[0])
    return symbols


def write_ply(path):
    path.write_text("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                    "property float y\nproperty float z\nelement face 1\n"
                    "property list uchar int vertex_indices\nend_header\n"
                    "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--rvr", required=True)
    parser.add_argument("--python-dir", help="the folder of the module rvr, when it is built")
    parser.add_argument("--work-dir", required=True)
    parser.add_argument("--python-preload", default="",
                        help="LD_PRELOAD of python3 with the module (make sanitize: libasan)")
    args = parser.parse_args()
    rvr = pathlib.Path(args.rvr)
    work = pathlib.Path(args.work_dir)
    work.mkdir(parents=True, exist_ok=True)
    binaries = [rvr]
    if args.python_dir:
        binaries.append(next(pathlib.Path(args.python_dir).glob("rvr.cpython-*.so")))

    for binary in binaries:
        libs = needed(binary)
        check(not has(libs, ASSIMP) and not has(libs, EMBREE),
              f"{binary.name} does not link Assimp or Embree (needs {sorted(libs)})")

    for name, exported in PLUGINS.items():
        plugin = rvr.parent / name
        check(plugin.exists(), f"{name} is built beside rvr")
        if args.python_dir:
            check((pathlib.Path(args.python_dir) / name).exists(), f"{name} is beside the module")
        if not plugin.exists():
            continue
        defined = set(dynamic_symbols(plugin, False))
        allowed = exported | (OPERATORS if name == MODEL_PLUGIN else set())
        check(exported <= defined and defined <= allowed,
              f"{name} exports its table only (exports {sorted(defined)})")
        outside = [s for s in dynamic_symbols(plugin, True) if "3rvr" in s]
        check(not outside, f"{name} needs no rvr code from outside ({outside})")

    done, names = loaded([str(rvr), "--version"])
    check(done.returncode == 0, "rvr --version runs")
    check(not {n for n in names if n.startswith(("librvr_", ASSIMP, EMBREE))},
          f"rvr --version loads no plugin, Assimp or Embree ({sorted(names)})")

    done, names = loaded([str(rvr), "render", "builtin:nope", "-r", "raytrace", "-q",
                          "-o", str(work / "bad.png")])
    check(done.returncode == 2, "a bad input exits 2")
    check(not {n for n in names if n.startswith(("librvr_", ASSIMP, EMBREE))},
          "a bad input loads no plugin, Assimp or Embree")

    done, names = loaded([str(rvr), "render", "builtin:cornell", "-r", "raytrace", "--width", "16",
                          "--height", "12", "-q", "-o", str(work / "cornell.png")])
    check(done.returncode == 0, "a render of a built-in scene runs")
    check(not has(names, ASSIMP) and not has(names, EMBREE) and not has(names, MODEL_PLUGIN),
          "a render of a built-in scene with raytrace loads neither Assimp nor Embree")

    ply = work / "triangle.ply"
    write_ply(ply)
    done, names = loaded([str(rvr), "render", str(ply), "-r", "raytrace", "--width", "16",
                          "--height", "12", "-q", "-o", str(work / "ply.png")])
    check(done.returncode == 0, f"a render of a model file runs {stderr_of(done)}")
    check(has(names, MODEL_PLUGIN) and has(names, ASSIMP) and not has(names, EMBREE),
          "a model file loads the model-import plugin and Assimp, not Embree")

    done, names = loaded([str(rvr), "render", "builtin:spheres", "-r", "embree", "--width", "16",
                          "--height", "12", "-q", "-o", str(work / "embree.png")])
    check(done.returncode == 0, "a render with embree runs")
    check(has(names, EMBREE_PLUGIN) and has(names, EMBREE) and not has(names, ASSIMP),
          "the embree renderer loads the Embree plugin and Embree, not Assimp")

    check_missing_plugins(rvr, work, ply)
    if args.python_dir:
        check_module(args.python_dir, args.python_preload, ply)

    if failures:
        print(f"{len(failures)} check(s) failed")
        return 1
    return 0


def check_missing_plugins(rvr, work, ply):
    """rvr copied alone to a folder without its plugins: what needs none runs, what needs one
    is an internal error (exit 3) naming the plugin, not a crash nor the file's error."""
    lonely = work / "lonely"
    lonely.mkdir(exist_ok=True)
    alone = lonely / "rvr"
    alone.write_bytes(rvr.read_bytes())
    alone.chmod(0o755)
    done = subprocess.run([str(alone), "--version"], capture_output=True, text=True)
    check(done.returncode == 0, "rvr without its plugins still starts")
    for what, args, plugin in [
            ("the embree renderer", ["builtin:spheres", "-r", "embree"], EMBREE_PLUGIN),
            ("a model file", [str(ply), "-r", "raytrace"], MODEL_PLUGIN)]:
        done = subprocess.run([str(alone), "render", *args, "--width", "8", "--height", "6",
                               "-q", "-o", str(lonely / "out.exr")],
                              capture_output=True, text=True)
        check(done.returncode == 3 and "cannot load" in done.stderr and plugin in done.stderr,
              f"without {plugin}, {what} is an internal error naming it "
              f"(exit {done.returncode}: {done.stderr.strip()[:200]})")


def check_module(python_dir, preload, ply):
    env = dict(os.environ, PYTHONPATH=python_dir)
    if preload:
        env["LD_PRELOAD"] = preload
    script = ("import rvr; s = rvr.Scene('builtin:cornell', width=8, height=6); "
              "rvr.render(s, 'raytrace')")
    done, names = loaded([sys.executable, "-c", script], env)
    check(done.returncode == 0, f"the module renders {stderr_of(done)}")
    check(not has(names, ASSIMP) and not has(names, EMBREE),
          "import rvr and a render of a built-in scene load neither Assimp nor Embree")
    done, names = loaded([sys.executable, "-c", f"import rvr; rvr.Scene({str(ply)!r})"], env)
    check(done.returncode == 0 and has(names, ASSIMP) and has(names, MODEL_PLUGIN),
          "the module loads the model-import plugin and Assimp for a model file")


if __name__ == "__main__":
    sys.exit(main())
