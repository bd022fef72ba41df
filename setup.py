"""Builds the Python module with CMake for `pip install .` (pyproject.toml holds the metadata).

CMake configures a Release build of the library, the OMPL plugin and the module (no tests, tools or
benchmarks) for the Python that runs this, then `cmake --install --component python_wheel` lays out what
the wheel holds: the module, its type stubs, and libclearway and libclearway_ompl in clearway.libs/,
which the module finds through its RUNPATH $ORIGIN/clearway.libs. Each library is copied once, under the
name the module loads it by (its SONAME); wheels hold no symbolic links. CMake builds in
build-pip/cmake-<python> (CLEARWAY_BUILD_DIR chooses another folder: CI shares a compiler cache between
builds laid out alike), with os.cpu_count() jobs (CMAKE_BUILD_PARALLEL_LEVEL chooses another count).
"""
import os
import pathlib
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).resolve().parent


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        tag = f"cmake-{sys.implementation.cache_tag}"
        build = pathlib.Path(os.environ.get("CLEARWAY_BUILD_DIR") or ROOT / "build-pip" / tag).resolve()
        stage = build / "wheel-stage"
        configure = ["cmake", "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                     "-DCLEARWAY_BUILD_TESTS=OFF", "-DCLEARWAY_BUILD_BENCHMARKS=OFF", "-DCLEARWAY_BUILD_TOOLS=OFF",
                     "-DCLEARWAY_BUILD_PYTHON=ON", "-DCLEARWAY_PYTHON_WHEEL=ON",
                     f"-DPython3_EXECUTABLE={sys.executable}"]
        try:  # pybind11 from pip (an isolated build) when there is one; else CMake finds Debian's pybind11-dev
            import pybind11
            configure.append(f"-Dpybind11_DIR={pybind11.get_cmake_dir()}")
        except ImportError:
            pass
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
        subprocess.run(configure, check=True)
        subprocess.run(["cmake", "--build", str(build), "--target", "clearway_python", "-j", jobs], check=True)
        shutil.rmtree(stage, ignore_errors=True)
        subprocess.run(["cmake", "--install", str(build), "--component", "python_wheel", "--prefix", str(stage)],
                       check=True)

        module = pathlib.Path(self.get_ext_fullpath(ext.name))
        module.parent.mkdir(parents=True, exist_ok=True)
        built = [p for p in stage.glob("clearway.*.so")]
        if len(built) != 1:
            raise RuntimeError(f"expected one module in {stage}, found {built}")
        shutil.copyfile(built[0], module)
        shutil.copyfile(stage / "clearway.pyi", module.parent / "clearway.pyi")
        libs = module.parent / "clearway.libs"
        shutil.rmtree(libs, ignore_errors=True)
        libs.mkdir()
        # The SONAME links (libclearway.so.0 -> libclearway.so.0.1.0), each copied as the file it names.
        for link in sorted((stage / "clearway.libs").iterdir()):
            if link.is_symlink():
                shutil.copyfile(link.resolve(), libs / link.name)
        if not any(libs.iterdir()):
            raise RuntimeError(f"no libraries in {stage / 'clearway.libs'}")


setup(
    ext_modules=[Extension("clearway", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    # setuptools' own folders; build/ is the Release build of scripts/main.sh.
    options={"build": {"build_base": "build-pip"}},
)
