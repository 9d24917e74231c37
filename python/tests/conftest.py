"""Fixtures of the brdf_factor tests: the module (from the build tree through
PYTHONPATH, as the CTest entry sets it), the CLI next to it, small sample sets."""
import os
import pathlib

import numpy as np
import pytest

import brdf_factor as bf


def cli_path():
    """The brdf-factor CLI of the same build: $BF_CLI_PATH, else
    <build>/experiments/brdf-factor next to <build>/python/brdf_factor."""
    p = os.environ.get("BF_CLI_PATH")
    if p:
        return p
    return str(pathlib.Path(bf.__file__).resolve().parent.parent.parent / "experiments" / "brdf-factor")


@pytest.fixture(scope="session")
def cli():
    p = cli_path()
    assert os.access(p, os.X_OK), "brdf-factor CLI not found at %s (set BF_CLI_PATH)" % p
    return p


@pytest.fixture(scope="session")
def bluepaint():
    return bf.brdf("bluepaint")


@pytest.fixture(scope="session")
def grid8(bluepaint):
    return bf.sample_grid(bluepaint, 8)


def random_pairs(n, seed=1):
    """n unit direction pairs in the upper hemisphere (numpy, (n, 3) each)."""
    rng = np.random.default_rng(seed)
    def hemi(k):
        v = rng.normal(size=(k, 3))
        v[:, 2] = np.abs(v[:, 2]) + 1e-3
        return v / np.linalg.norm(v, axis=1, keepdims=True)
    return hemi(n), hemi(n)
