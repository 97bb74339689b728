"""Builds the vola Python package with CMake: the extension vola/_vola*.so and the plugins it
loads at run time (libvola_gdal.so, libvola_proj.so, ...) land in the package folder, beside
the pure-Python files from python/vola. Metadata lives in pyproject.toml; the version is the
CMake project's.

VOLA_CMAKE_BUILD_DIR: a build tree to reuse (configured or not); default build-python/.
CMAKE_BUILD_PARALLEL_LEVEL: build jobs (default: every core).
"""
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


def cmake_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(vola VERSION ([0-9.]+)", text).group(1)


class CMakeExtension(Extension):
    def __init__(self):
        super().__init__("vola._vola", sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = Path(os.environ.get("VOLA_CMAKE_BUILD_DIR") or ROOT / "build-python").resolve()
        if not (build / "CMakeCache.txt").exists():
            subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release",
                            "-DPython_EXECUTABLE=" + sys.executable], check=True)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 2)
        subprocess.run(["cmake", "--build", str(build), "--target", "vola_python", "-j", jobs], check=True)
        built = sorted((build / "python" / "vola").glob("_vola*.so"))
        if not built:
            sys.exit(f"vola: CMake built no extension in {build}/python/vola")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built[0], target)
        # The plugins, found beside the extension at run time (src/plugin/plugin_loader.cpp).
        for plugin in sorted((build / "lib" / "vola").glob("libvola_*.so")):
            shutil.copy2(plugin, target.parent / plugin.name)


(ROOT / "build-python").mkdir(exist_ok=True)  # egg_base must exist before egg_info runs

setup(
    version=cmake_version(),
    packages=["vola"],
    package_dir={"vola": "python/vola"},
    package_data={"vola": ["*.pyi", "py.typed"]},
    ext_modules=[CMakeExtension()],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
    # setuptools' own scratch folders, away from CMake's build/ and out of the source tree.
    options={"build": {"build_base": "build-python/setuptools"}, "egg_info": {"egg_base": "build-python"}},
)
