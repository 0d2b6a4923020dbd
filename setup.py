"""The build backend's side of the wheel (pyproject.toml): CMake builds the module rvr and the
plugins it opens at run time, and they go into the wheel together with the type stubs, side by
side at its root, as they are in build/python/ (docs/python.md, "Installing with pip").

rvr's own libraries are linked statically into the module; the system libraries it and the
plugins use (TBB, fmt, Assimp, Embree, OpenImageIO, libpng, OpenEXR, OSMesa, EGL) are Debian
12's and are not bundled: the wheel is for a Debian 12 machine with the packages of `make
deps-wheel`, and for the interpreter that built it.

Environment:
  RVR_CMAKE_BUILD_DIR  an existing CMake build folder, configured with RVR_BUILD_PYTHON=ON for
                       this interpreter, to take the module from (only its target rvr_python
                       is built; its options stay as they are), setuptools' own folders in its
                       wheel/; by default build-wheel/cmake, configured here (Release, no
                       tests, no benchmarks), setuptools' folders in build-wheel/
  RVR_BUILD_JOBS       parallel compile jobs (default: every core)
"""
import os
import pathlib
import re
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

SOURCE = pathlib.Path(__file__).resolve().parent
GIVEN_BUILD = os.environ.get("RVR_CMAKE_BUILD_DIR")
WHEEL_BUILD = (pathlib.Path(GIVEN_BUILD).resolve() / "wheel" if GIVEN_BUILD
               else SOURCE / "build-wheel")
# What lives beside the module in build/python/ (python/CMakeLists.txt): the plugins and stubs.
BESIDE = ["rvr.pyi", "librvr_image_codec.so", "librvr_image_writer.so",
          "librvr_model_import.so", "librvr_embree.so"]


def version():
    text = (SOURCE / "CMakeLists.txt").read_text()
    return re.search(r"project\(rvr VERSION ([0-9.]+)", text).group(1)


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def run(self):
        # setuptools keeps what earlier builds left in its build folder and would pack it too.
        if not self.inplace:
            shutil.rmtree(self.build_lib, ignore_errors=True)
        super().run()

    def build_extension(self, ext):
        build = pathlib.Path(GIVEN_BUILD).resolve() if GIVEN_BUILD else WHEEL_BUILD / "cmake"
        if not GIVEN_BUILD:
            subprocess.run(["cmake", "-S", str(SOURCE), "-B", str(build),
                            "-DCMAKE_BUILD_TYPE=Release", "-DRVR_BUILD_TESTS=OFF",
                            "-DRVR_BUILD_BENCH=OFF", "-DRVR_BUILD_PYTHON=ON",
                            f"-DPython3_EXECUTABLE={sys.executable}"], check=True)
        elif not (build / "CMakeCache.txt").exists():
            sys.exit(f"RVR_CMAKE_BUILD_DIR={GIVEN_BUILD}: not a configured CMake build folder")
        jobs = os.environ.get("RVR_BUILD_JOBS", str(os.cpu_count() or 1))
        subprocess.run(["cmake", "--build", str(build), "--target", "rvr_python", "-j", jobs],
                       check=True)
        built = build / "python" / ("rvr" + sysconfig.get_config_var("EXT_SUFFIX"))
        if not built.exists():
            sys.exit(f"{built} was not built: is {build} configured for {sys.executable}?")
        target = pathlib.Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built, target)
        for name in BESIDE:
            shutil.copy2(build / "python" / name, target.parent / name)


# setuptools' own folders go under WHEEL_BUILD (build/ is CMake's; the source tree stays clean).
egg_base = WHEEL_BUILD / "egg-info"
egg_base.mkdir(parents=True, exist_ok=True)
setup(
    version=version(),
    packages=[],  # no Python package: one extension module and the files beside it
    ext_modules=[CMakeExtension("rvr")],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": str(WHEEL_BUILD / "setuptools")},
             "egg_info": {"egg_base": str(egg_base)}},
    zip_safe=False,
)
