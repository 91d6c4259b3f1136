# The compiled half of the Python package for pip (pyproject.toml): CMake configures the project
# and builds the module _gyrodrift, which is copied where setuptools packs the wheel. The version
# and the rest of the metadata live in pyproject.toml; the build itself in CMakeLists.txt.
#
# GYRODRIFT_CMAKE_BUILD_DIR: an existing CMake build folder to build in (the test of `make test`
# reuses the suite's own build), else a folder below setuptools' build_temp.
import os
import pathlib
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).parent.resolve()


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = os.environ.get("GYRODRIFT_CMAKE_BUILD_DIR")
        build = pathlib.Path(build).resolve() if build else pathlib.Path(self.build_temp).resolve() / "cmake"
        if not (build / "CMakeCache.txt").exists():
            configure = ["cmake", "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                         "-DGYRODRIFT_BUILD_TESTS=OFF", "-DGYRODRIFT_BUILD_BENCH=OFF",
                         "-DGYRODRIFT_BUILD_PYTHON=ON", f"-DPython3_EXECUTABLE={sys.executable}"]
            if shutil.which("ninja"):
                configure += ["-G", "Ninja"]
            if shutil.which("ccache"):
                configure += ["-DCMAKE_CXX_COMPILER_LAUNCHER=ccache", "-DCMAKE_C_COMPILER_LAUNCHER=ccache"]
            subprocess.run(configure, check=True)
        subprocess.run(["cmake", "--build", str(build), "--target", "_gyrodrift", "-j",
                        str(os.cpu_count() or 1)], check=True)
        built = sorted((build / "python" / "gyrodrift").glob("_gyrodrift*.so"))
        if not built:
            raise RuntimeError(f"no _gyrodrift module in {build}/python/gyrodrift after the build")
        target = pathlib.Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built[-1], target)


setup(ext_modules=[Extension("gyrodrift._gyrodrift", sources=[])],
      cmdclass={"build_ext": CMakeBuild},
      options={"build": {"build_base": "build-pip"}, "egg_info": {"egg_base": "build-pip"}})
