"""Factorization.export() writes, for every registered method kind, what a
run writes with experiment.export on (the same code: factor/export.h
write_export), and bf.load() reads it back to the same evaluation."""
import os

import numpy as np
import pytest

import brdf_factor as bf
from brdf_factor import _core
from conftest import random_pairs

KINDS = _core._method_examples()


def test_every_registered_kind_is_a_python_method():
    assert sorted(KINDS) == sorted(bf.METHODS)


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_export_then_load_round_trips(tmp_path, kind, bluepaint, grid8):
    f = bf.factor(kind, brdf=bluepaint, samples=grid8, **KINDS[kind])
    files = f.export(str(tmp_path), "x")
    assert files["sidecar"] == str(tmp_path / "x.json") and os.path.isfile(files["sidecar"])
    assert files["glsl"] == str(tmp_path / "x.glsl") and os.path.isfile(files["glsl"])
    for t in files["textures"]:
        assert os.path.isfile(t)
    if kind in ("svd", "sh-k", "sh-r"):
        assert files["data"] == str(tmp_path / "x.f64") and os.path.isfile(files["data"])
    g = bf.load(files["sidecar"])
    wi, wo = random_pairs(500, seed=9)
    a, b = f.eval(wi, wo), g.eval(wi, wo)
    assert np.count_nonzero(a) > 100
    np.testing.assert_array_equal(a, b)
    # The file is also a BRDF spec, as on the command line.
    np.testing.assert_array_equal(bf.brdf(files["sidecar"]).eval(wi, wo), a)


def test_export_of_a_refined_fit(tmp_path, grid8):
    f = bf.mccool(grid8, texture_size=6, refine="linear", refine_iterations=2)
    g = bf.load(f.export(str(tmp_path), "r")["sidecar"])
    wi, wo = random_pairs(200, seed=3)
    np.testing.assert_array_equal(f.eval(wi, wo), g.eval(wi, wo))
