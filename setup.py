"""Builds the atlas Python wheel from the tree (pyproject.toml holds the metadata).

The extension module is not compiled by setuptools: CMake builds the `atlas_python` target (the same
build `scripts/build.sh` makes) and this packs its output, the OpenImageIO module beside it, and the
pure-Python atlas_dask driver. ATLAS_BUILD_DIR names an existing CMake build to use (it is brought up
to date with `cmake --build DIR --target atlas_python`, or used as it is with ATLAS_WHEEL_NO_BUILD=1);
without it a Release build is configured in build-wheel/.
"""
import os
import pathlib
import re
import shutil
import subprocess

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.dist import Distribution

ROOT = pathlib.Path(__file__).resolve().parent


def version():
    m = re.search(r"project\(atlas VERSION ([0-9.]+)", (ROOT / "CMakeLists.txt").read_text())
    return m.group(1)


class BinaryDistribution(Distribution):
    """The wheel holds a compiled module: tag it for this Python and platform."""

    def has_ext_modules(self):
        return True


class BuildWithCMake(build_py):
    def run(self):
        super().run()
        build = pathlib.Path(os.environ.get("ATLAS_BUILD_DIR", ROOT / "build-wheel")).resolve()
        if not (build / "CMakeCache.txt").exists():
            subprocess.check_call(["cmake", "-S", str(ROOT), "-B", str(build), "-G", "Ninja", "-DCMAKE_BUILD_TYPE=Release",
                                   "-DATLAS_BUILD_TESTS=OFF", "-DATLAS_BUILD_BENCHMARKS=OFF", "-DATLAS_BUILD_PYTHON=ON"])
        if not os.environ.get("ATLAS_WHEEL_NO_BUILD"):
            subprocess.check_call(["cmake", "--build", str(build), "--target", "atlas_python", "atlas_oiio"])
        package = pathlib.Path(self.build_lib) / "atlas"
        modules = list((build / "python" / "atlas").glob("_atlas*.so"))
        oiio = list(build.glob("lib/atlas/libatlas_oiio.so")) or list(build.rglob("libatlas_oiio.so"))
        if len(modules) != 1 or not oiio:
            raise SystemExit(f"setup.py: {build} has no built atlas module ({modules}) or libatlas_oiio.so ({oiio})")
        shutil.copy2(modules[0], package / modules[0].name)
        shutil.copy2(oiio[0], package / "libatlas_oiio.so")  # found beside _atlas (libatlas/src/io/image.cpp)


setup(
    version=version(),
    packages=["atlas", "atlas_dask"],
    package_dir={"atlas": "python/atlas", "atlas_dask": "python/atlas_dask"},
    distclass=BinaryDistribution,
    cmdclass={"build_py": BuildWithCMake},
    # Not setuptools' default build/: that is the CMake build folder of scripts/build.sh.
    options={"build": {"build_base": "build-wheel/setuptools"}, "bdist_wheel": {"bdist_dir": "build-wheel/bdist"}},
    zip_safe=False,
)
