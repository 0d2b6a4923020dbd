"""The module as a user installs it (docs/python.md, "Installing with pip"): a wheel built by
Debian's python3-build (offline, --no-isolation) from this build's CMake folder, installed with
pip --no-index into a fresh venv (with the system site-packages, for Debian's numpy), and used
there with no PYTHONPATH: imported from the venv, a render by each kind of plugin it opens (the
PNG writer, OpenImageIO's reader, the model importer, Embree), the stubs beside it; then
uninstalled, which removes every file it installed.

    check_wheel.py --source-dir . --build-dir build --work-dir build/wheel-check
"""
import argparse
import os
import pathlib
import shutil
import subprocess
import sys
import zipfile

PLUGINS = ["librvr_image_codec.so", "librvr_image_writer.so", "librvr_model_import.so",
           "librvr_embree.so"]

# Run by the venv's python, in an empty folder, without PYTHONPATH.
USE = r"""
import os, pathlib, sys
import numpy as np
import rvr
here = pathlib.Path(rvr.__file__).parent
assert pathlib.Path(sys.prefix) in pathlib.Path(rvr.__file__).parents, rvr.__file__
assert (here / "rvr.pyi").exists()
scene = rvr.Scene("builtin:cornell", width=32, height=24)
traced = rvr.render(scene, "raytrace")
assert traced.color.shape == (24, 32, 3) and (traced.object_id >= 0).any()
embree = rvr.render(scene, "embree")
assert (embree.object_id == traced.object_id).mean() > 0.9
traced.save("cornell.png")
assert rvr.diff("cornell.png", "cornell.png")["verdict"] == "PASS"
pathlib.Path("triangle.ply").write_text(
    "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
    "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
model = rvr.render(rvr.Scene("triangle.ply", width=16, height=12), "raytrace")
assert (model.object_id == 0).any()
print("rvr", rvr.__version__, "from", rvr.__file__)
"""


def run(command, **kwargs):
    shown = ["USE" if c is USE else str(c) for c in command]  # the script above by its name
    print("$", " ".join(shown), flush=True)
    return subprocess.run([str(c) for c in command], check=True, **kwargs)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--source-dir", required=True)
    parser.add_argument("--build-dir", required=True, help="the CMake folder with rvr_python")
    parser.add_argument("--work-dir", required=True)
    args = parser.parse_args()
    source = pathlib.Path(args.source_dir).resolve()
    work = pathlib.Path(args.work_dir).resolve()
    shutil.rmtree(work, ignore_errors=True)
    (work / "use").mkdir(parents=True)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(RVR_CMAKE_BUILD_DIR=str(pathlib.Path(args.build_dir).resolve()),
               PIP_DISABLE_PIP_VERSION_CHECK="1", PIP_NO_INDEX="1")

    run([sys.executable, "-m", "build", "--no-isolation", "--wheel", "--outdir", work / "dist",
         source], env=env, cwd=source)
    wheels = list((work / "dist").glob("rvr-*.whl"))
    assert len(wheels) == 1, wheels
    names = set(zipfile.ZipFile(wheels[0]).namelist())
    files = {n for n in names if ".dist-info/" not in n}
    module = [n for n in files if n.startswith("rvr.cpython-") and n.endswith(".so")]
    assert len(module) == 1 and files == set(module + ["rvr.pyi"] + PLUGINS), sorted(names)

    venv = work / "venv"
    run([sys.executable, "-m", "venv", "--system-site-packages", venv], env=env)
    python = venv / "bin" / "python"
    run([python, "-m", "pip", "install", "--no-index", wheels[0]], env=env)
    run([python, "-c", USE], env=env, cwd=work / "use")
    site = pathlib.Path(subprocess.run(
        [python, "-c", "import sysconfig; print(sysconfig.get_paths()['platlib'])"],
        check=True, capture_output=True, text=True, env=env).stdout.strip())
    assert all((site / name).exists() for name in files)
    run([python, "-m", "pip", "uninstall", "-y", "rvr"], env=env)
    left = [name for name in files if (site / name).exists()]
    assert not left, f"pip uninstall left {left}"
    print("wheel", wheels[0].name, "installed, used and uninstalled")


if __name__ == "__main__":
    main()
