"""Every method kind from Python: results and their metrics, planted
solutions, keyword options checked by the configs' rules, export and reload."""
import os

import numpy as np
import pytest

import brdf_factor as bf
from conftest import random_pairs

METRICS = {"rel_mse", "rel_mae", "rel_max", "lin_rmse", "lin_mae", "lin_max", "cos_rmse", "samples"}


def check_report(f, samples, method, nonnegative=True):
    assert isinstance(f, bf.Factorization) and isinstance(f, bf.Brdf)
    assert f.method == method
    assert set(f.metrics) == METRICS and f.metrics["samples"] == samples.valid_count
    assert all(np.isfinite(v) and v >= 0 for v in f.metrics.values())
    # The reported metrics are the scoring of the factorization on the samples.
    assert f.score(samples) == f.metrics
    assert f.storage_floats > 0 and f.seconds >= 0
    wi, wo = random_pairs(500)
    v = f.eval(wi, wo)
    assert v.shape == (500, 3) and np.all(np.isfinite(v))
    # SH series ring (negative lobes, factor/sh_baseline.h pitfall P1); the others clamp at 0.
    assert np.all(v >= 0) or not nonnegative


def test_mccool_recovers_a_planted_mccool_form():
    # f = p(wi) q(h) p(wo) is exactly McCool's form: the fit reaches it up to
    # interpolation, far below its error on a BRDF that is not of that form.
    planted = bf.brdf("mccool-form")
    s = bf.sample_grid(planted, 12)
    f = bf.mccool(s, texture_size=16)
    check_report(f, s, "mccool")
    other = bf.sample_grid(bf.brdf("bluepaint"), 12)
    g = bf.mccool(other, texture_size=16)
    assert f.metrics["rel_mse"] < 1e-3
    assert f.metrics["rel_mse"] < 0.05 * g.metrics["rel_mse"]
    assert len(f.errors_after_term) == 2 and f.errors_after_term[-1] <= f.errors_after_term[0]
    assert [t.shape for t in f.textures()] == [(16, 16, 3), (16, 16, 3)]


def test_fit_with_named_matrix_and_dict_projections(grid8):
    wi = [[1, 0, 0, 0], [0, 1, 0, 0]]
    a = bf.fit(grid8, projections=["wi", "wo"], texture_size=8)
    b = bf.fit(grid8, projections=[np.array(wi, float), {"name": "wo"}], texture_size=8)
    check_report(a, grid8, "fit")
    assert a.metrics == b.metrics
    one = bf.fit(grid8, projections=["wi", "wo"], terms=1, texture_size=8)
    assert len(one.errors_after_term) == 1 and one.metrics["rel_mse"] >= a.metrics["rel_mse"]
    with pytest.raises(ValueError, match=r"^fit: projections\[0\].matrix: .*rows must be orthonormal"):
        bf.fit(grid8, projections=[[[1, 1, 0, 0], [0, 1, 0, 0]]])
    # Both alternatives given: one problem, stated once.
    with pytest.raises(ValueError) as e:
        bf.fit(grid8, projections=[{"name": "wi", "matrix": np.eye(2, 4)}], texture_size=8)
    assert str(e.value) == "fit: projections[0].name: matrix and name are alternatives: give one of them, found both"
    with pytest.raises(ValueError, match=r"^fit: terms: terms = 3 but only 2 projections are given"):
        bf.fit(grid8, projections=["wi", "wo"], terms=3)


def test_search_is_deterministic_and_no_worse_than_its_first_term(grid8):
    opts = dict(terms=2, texture_size=8, restarts=2, threads=1, seed=3)
    f = bf.search(grid8, **opts)
    check_report(f, grid8, "search")
    g = bf.search(grid8, **opts)
    assert f.metrics == g.metrics
    assert len(f.info["terms"]) == 2 and f.evaluations > 0
    assert f.errors_after_term[1] <= f.errors_after_term[0] + 1e-12


def test_search_tolerance_stops_early(grid8):
    loose = bf.search(grid8, terms=4, texture_size=8, restarts=1, threads=1,
                      tolerance={"metric": "rel_mse", "value": 10.0})
    assert len(loose.errors_after_term) == 1
    assert loose.info["size_choice"]["reached"] is True


def test_svd_of_a_rank_one_brdf_is_exact_at_rank_one():
    # Lambert is constant: a rank-1 matrix; linear SVD reproduces it to rounding.
    b = bf.brdf("lambert", kd=(0.3, 0.5, 0.7))
    s = bf.sample_grid(b, 8)
    f = bf.svd(b, s, terms=1, texture_size=8)
    check_report(f, s, "svd")
    assert f.metrics["rel_max"] < 1e-9
    assert len(f.errors_after_term) == 1
    # Without samples there is nothing to score.
    assert bf.svd(b, terms=1, texture_size=8).metrics is None


def test_sh_k_and_sh_r(grid8, bluepaint):
    k2 = bf.sh_k(bluepaint, grid8, order=2, texture_size=8)
    k6 = bf.sh_k(bluepaint, grid8, order=6, texture_size=8)
    check_report(k6, grid8, "sh-k", nonnegative=False)
    # A higher band limit approximates the product function better.
    assert k6.metrics["cos_rmse"] < k2.metrics["cos_rmse"]
    r = bf.sh_r(bluepaint, grid8, order=8, view_order=2, max_order=8, max_view_order=2)
    check_report(r, grid8, "sh-r", nonnegative=False)
    with pytest.raises(ValueError, match=r"^sh-r: order: fixed orders need both order and view_order"):
        bf.sh_r(bluepaint, order=4)


def test_model_fit_recovers_planted_parameters():
    b = bf.brdf("ward", kd=(0.05, 0.1, 0.2), ks=(0.1, 0.1, 0.1), ax=0.2, ay=0.2)
    s = bf.sample_grid(b, 8)
    f = bf.model_fit(s, model="ward", starts=2, threads=1)
    check_report(f, s, "model-fit")
    p = f.info["model_fit"]["parameters"]
    assert p["a"] == pytest.approx(0.2, rel=1e-3)
    assert p["kd.b"] == pytest.approx(0.2, rel=1e-3)
    assert f.metrics["rel_mse"] < 1e-8


def test_refinement_lowers_its_objective(grid8):
    start = bf.mccool(grid8, texture_size=8)
    r = bf.refine(start, grid8, objective="linear", max_iterations=10, threads=1)
    assert r.method == "mccool+refine-linear"
    assert r.metrics["lin_rmse"] < start.metrics["lin_rmse"]
    assert r.info["refinement"]["final_cost"] < r.info["refinement"]["initial_cost"]
    # The stage of a method call is the same refinement.
    staged = bf.mccool(grid8, texture_size=8, refine="linear", refine_iterations=10)
    assert staged.metrics["lin_rmse"] == pytest.approx(r.metrics["lin_rmse"], rel=1e-9)
    with pytest.raises(ValueError, match=r"^refine: expected a factorization of mccool, fit or search"):
        bf.refine(bf.svd(bf.brdf("lambert"), terms=1, texture_size=8), grid8)


def test_unknown_and_mistyped_options_are_named(grid8):
    # The config reader's words: Python values are read as the TOML values they are.
    with pytest.raises(ValueError, match=r"^search: restart: unknown key for kind = \"search\" \(accepted: .*restarts.*\) \(did you mean 'restarts'\?\)$"):
        bf.search(grid8, restart=2)
    with pytest.raises(ValueError, match=r"^mccool: texture_size: expected an integer in 2..1024 or \"auto\", found 1 \(an integer\)$"):
        bf.mccool(grid8, texture_size=1)
    with pytest.raises(ValueError, match=r"^search: restarts: expected an integer in 0..100000, found \"2\" \(a string\)$"):
        bf.search(grid8, restarts="2")
    with pytest.raises(ValueError, match=r"^search: terms: expected an integer in 1..64, found 4294967296$"):
        bf.search(grid8, terms=2**32)
    with pytest.raises(ValueError, match=r"^svd: log: expected true or false, found 1 \(an integer\)$"):
        bf.svd(bf.brdf("lambert"), log=1)
    with pytest.raises(ValueError, match=r"^mccool: metric_eps: expected a number in \(0, 1\], found 2$"):
        bf.mccool(grid8, metric_eps=2.0)
    with pytest.raises(ValueError, match=r"^search: label: names or sweeps a config's \[\[method\]\] table"):
        bf.search(grid8, label="x")
    with pytest.raises(ValueError, match=r"^mccool: refine: expected a value a config holds .*found <object"):
        bf.mccool(grid8, refine=object())
    # Every problem of a call is reported, each on its own line, as the CLI lists them.
    with pytest.raises(ValueError) as e:
        bf.mccool(grid8, smoothing=-1.0, solve_last=0)
    assert str(e.value).splitlines() == ["mccool: smoothing: expected a number in [0, 1000000], found -1",
                                         "mccool: solve_last: expected an integer in 1..64, found 0"]
    # Ranges as the config reader words them, and rules of the options' validate().
    with pytest.raises(ValueError, match=r"^mccool: smoothing: expected a number in \[0, 1000000\], found -1$"):
        bf.mccool(grid8, smoothing=-1.0)
    with pytest.raises(ValueError, match=r"^search: beam: expected 1..\(restarts \+ guesses\) = 1..2, found 9$"):
        bf.search(grid8, restarts=2, beam=9)
    with pytest.raises(ValueError, match=r"^search: restarts: restarts = 0 and no guesses leave nothing to search from"):
        bf.search(grid8, strategy="greedy", restarts=0)
    with pytest.raises(ValueError, match=r"^svd: eps: eps applies only to the log-space SVD"):
        bf.svd(bf.brdf("lambert"), eps=1e-3)
    with pytest.raises(ValueError, match=r"^mccool: tolerance.metric: expected one of"):
        bf.mccool(grid8, texture_size="auto", tolerance=("rel_mze", 0.1))
    with pytest.raises(ValueError, match=r"^model-fit: "):
        bf.model_fit(grid8, model="no-such-model")


def test_export_reload_is_bit_identical(tmp_path, grid8):
    f = bf.mccool(grid8, texture_size=8)
    files = f.export(str(tmp_path), "paint")
    assert os.path.exists(files["sidecar"]) and len(files["textures"]) == 2
    assert os.path.exists(files["glsl"])
    g = bf.load(files["sidecar"])
    wi, wo = random_pairs(2000)
    np.testing.assert_array_equal(f.eval(wi, wo), g.eval(wi, wo))
    assert g.metrics is None and g.score(grid8) == f.metrics
    # A sidecar is also a BRDF spec, as on the command line.
    np.testing.assert_array_equal(bf.brdf(files["sidecar"]).eval(wi, wo), f.eval(wi, wo))
    merl = str(tmp_path / "paint.binary")
    f.export_merl(merl)
    assert os.path.getsize(merl) == 34992012


def test_factor_dispatches_by_kind(grid8, bluepaint):
    a = bf.factor("mccool", samples=grid8, texture_size=8)
    assert a.metrics == bf.mccool(grid8, texture_size=8).metrics
    b = bf.factor("svd", brdf=bluepaint, samples=grid8, terms=2, texture_size=8)
    assert b.method == "svd" and b.metrics is not None
    with pytest.raises(ValueError, match=r"^kind: expected one of"):
        bf.factor("pca", samples=grid8)
