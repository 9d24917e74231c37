"""`pip install .`: builds the brdf_factor module with the project's CMake
build (the same build folder as scripts/build.sh, so an up-to-date build is
reused) and packages python/brdf_factor with the extension it built.

Environment: BRDF_FACTOR_BUILD_DIR (default: build/ in the clone),
CMAKE_BUILD_PARALLEL_LEVEL (jobs, default 2). The module is built for the
interpreter CMake finds (Debian's /usr/bin/python3, whose pybind11 and numpy
it needs); pip's interpreter must be of the same version (a venv of it)."""
import glob
import os
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = os.path.dirname(os.path.abspath(__file__))


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = os.environ.get("BRDF_FACTOR_BUILD_DIR", os.path.join(ROOT, "build"))
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", "2")
        if not os.path.exists(os.path.join(build, "CMakeCache.txt")):
            gen = ["-G", "Ninja"] if shutil.which("ninja") else []
            subprocess.check_call(["cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
                                   "-DBRDF_FACTOR_BUILD_TESTS=OFF"] + gen)
        subprocess.check_call(["cmake", "--build", build, "-j", jobs, "--target", "bf_python_core"])
        built = glob.glob(os.path.join(build, "python", "brdf_factor", "_core*.so"))
        if len(built) != 1:
            sys.exit("setup.py: expected one brdf_factor/_core*.so in %s/python, found %s" % (build, built))
        ours = "." + ".".join(os.path.basename(self.get_ext_fullpath(ext.name)).split(".")[1:])
        theirs = "." + ".".join(os.path.basename(built[0]).split(".")[1:])
        if ours != theirs:
            sys.exit("setup.py: CMake built %s for another interpreter than this one (%s, wants %s): "
                     "run pip with Debian's python3 (or a venv of it)" % (built[0], sys.executable, ours))
        dest = self.get_ext_fullpath(ext.name)
        os.makedirs(os.path.dirname(dest), exist_ok=True)
        shutil.copyfile(built[0], dest)


# setup.cfg keeps setuptools' files (egg-info, build/lib, bdist) in build/setuptools.
os.makedirs(os.path.join(ROOT, "build", "setuptools"), exist_ok=True)

setup(
    packages=["brdf_factor"],
    package_dir={"": "python"},
    ext_modules=[Extension("brdf_factor._core", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
)
