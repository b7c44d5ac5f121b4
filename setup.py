"""The Python module, built by CMake (`pip install --no-build-isolation .`, docs/python.md).

setuptools knows nothing of the C++ build: build_ext configures the project with CMake,
builds the one target `oocsimp_python` (the library and the module, nothing else) and
copies the module where the wheel wants it.

OOCSIMP_CMAKE_BUILD_DIR names a CMake build folder that is already configured (such as
the one scripts/build.sh makes): build_ext builds the target there, which costs nothing
when it is up to date, instead of configuring and compiling a folder of its own.
"""
import glob
import os
import re
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))
GIVEN_BUILD = os.environ.get("OOCSIMP_CMAKE_BUILD_DIR")


def project_version():
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        match = re.search(r"project\(oocsimp VERSION ([0-9.]+)", f.read())
    if not match:
        sys.exit("setup.py: no project(oocsimp VERSION ...) in CMakeLists.txt")
    return match.group(1)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        suffix = os.path.splitext(self.get_ext_filename(ext.name))[1]
        if GIVEN_BUILD:
            build = os.path.abspath(GIVEN_BUILD)
            if not os.path.isfile(os.path.join(build, "CMakeCache.txt")):
                sys.exit(f"setup.py: OOCSIMP_CMAKE_BUILD_DIR={GIVEN_BUILD} is no configured CMake build folder")
        else:
            build = os.path.abspath(os.path.join(self.build_temp, "cmake"))
            os.makedirs(build, exist_ok=True)
            # The interpreter pip runs is the one the module is for (it must have numpy).
            subprocess.run(["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
                            f"-DPython3_EXECUTABLE={sys.executable}"], check=True)
        jobs = str(self.parallel or os.cpu_count() or 1)
        built = subprocess.run(["cmake", "--build", build, "--target", "oocsimp_python", "-j", jobs])
        if built.returncode != 0:
            sys.exit("setup.py: building the CMake target oocsimp_python failed; the module needs "
                     "pybind11-dev, python3-dev and numpy for this interpreter (scripts/setup-deps.sh)")
        modules = glob.glob(os.path.join(build, "python", "oocsimp*" + suffix))
        if len(modules) != 1:
            found = glob.glob(os.path.join(build, "python", "oocsimp*"))
            sys.exit(f"setup.py: no module oocsimp*{suffix} for {sys.executable} in {build}/python "
                     f"(found {found or 'none'}): that build folder is for another Python")
        target = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(target), exist_ok=True)
        shutil.copyfile(modules[0], target)


# setuptools' own build folders, out of CMake's build/: in the given CMake folder, or
# in build-pip/ beside the sources.
work = os.path.join(os.path.abspath(GIVEN_BUILD), "pip") if GIVEN_BUILD else os.path.join(ROOT, "build-pip")
os.makedirs(work, exist_ok=True)  # egg_info wants its folder to exist
setup(
    version=project_version(),
    ext_modules=[Extension("oocsimp", sources=[])],
    packages=[],  # the module is the extension alone: no discovery over docs/, src/, tools/...
    py_modules=[],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": work}, "egg_info": {"egg_base": work}},
    zip_safe=False,
)
