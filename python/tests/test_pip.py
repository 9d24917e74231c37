"""`pip install .` from the clone with Debian's tools (docs/python.md, "pip"):
a venv of Debian's python3 with its site packages, pip without build
isolation and without an index, the build folder of this very module (an
up-to-date build is reused); the installed module imports from outside the
clone and computes what the build tree's does."""
import os
import pathlib
import subprocess
import sys

import pytest

import brdf_factor as bf

SOURCE = pathlib.Path(__file__).resolve().parents[2]


def test_pip_install_from_the_clone(tmp_path):
    build = pathlib.Path(bf.__file__).resolve().parents[2]  # <build>/python/brdf_factor/__init__.py
    if not (build / "CMakeCache.txt").exists():
        pytest.skip("brdf_factor is not imported from a CMake build tree")
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)], check=True)
    env = dict(os.environ, BRDF_FACTOR_BUILD_DIR=str(build), PIP_NO_INDEX="1")
    env.pop("PYTHONPATH", None)
    r = subprocess.run([str(venv / "bin" / "pip"), "install", "--no-build-isolation", "--no-deps", str(SOURCE)],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stdout + r.stderr
    code = ("import brdf_factor as bf; s = bf.sample_grid(bf.brdf('bluepaint'), 6); "
            "print(bf.__file__); print(repr(bf.mccool(s, texture_size=6).metrics['rel_mse']))")
    r = subprocess.run([str(venv / "bin" / "python"), "-c", code], capture_output=True, text=True, env=env,
                       cwd=str(tmp_path))
    assert r.returncode == 0, r.stderr
    where, rel_mse = r.stdout.split()
    assert where.startswith(str(venv))
    s = bf.sample_grid(bf.brdf("bluepaint"), 6)
    assert float(rel_mse) == bf.mccool(s, texture_size=6).metrics["rel_mse"]
