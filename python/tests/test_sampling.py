"""Importance sampling from Python: Brdf.sample(wo, u) and Brdf.pdf(wi, wo)
on BRDFs and factorizations, numpy in and out, errors naming the argument."""
import numpy as np
import pytest

import brdf_factor as bf


def _wo(n, seed=1):
    rng = np.random.default_rng(seed)
    ct = rng.uniform(0.05, 1.0, n)
    ph = rng.uniform(0, 2 * np.pi, n)
    st = np.sqrt(1 - ct * ct)
    return np.stack([st * np.cos(ph), st * np.sin(ph), ct], axis=1)


@pytest.mark.parametrize("spec", ["bluepaint", "cook-torrance:kd=0.1,ks=0.9,m=0.2,f0=0.1"])
def test_sample_returns_unit_wi_and_its_own_pdf(spec):
    b = bf.brdf(spec)
    wo = _wo(200)
    u = np.random.default_rng(2).uniform(0, 1, (200, 2))
    wi, pdf = b.sample(wo, u, view_bins=4, theta_bins=8, phi_bins=16)
    assert wi.shape == (200, 3) and pdf.shape == (200,) and wi.dtype == np.float64
    ok = pdf > 0
    assert ok.sum() > 150
    np.testing.assert_allclose(np.linalg.norm(wi[ok], axis=1), 1.0, atol=1e-12)
    assert (wi[ok, 2] > 0).all()
    np.testing.assert_allclose(b.pdf(wi[ok], wo[ok], view_bins=4, theta_bins=8, phi_bins=16), pdf[ok], rtol=1e-12)
    # One wo broadcasts over every u.
    wi1, pdf1 = b.sample(np.array([0.0, 0.0, 1.0]), u, view_bins=4, theta_bins=8, phi_bins=16)
    assert wi1.shape == (200, 3)


def test_factorization_samples_and_integrates_to_one():
    s = bf.sample_grid(bf.brdf("bluepaint"), 6)
    f = bf.mccool(s, texture_size=8)
    wo = np.array([0.6, 0.0, 0.8])
    # The tabulated pdf integrates to 1 over the hemisphere (midpoint rule).
    n = 200
    ct = (np.arange(n) + 0.5) / n
    ph = 2 * np.pi * (np.arange(2 * n) + 0.5) / (2 * n)
    C, P = np.meshgrid(ct, ph, indexing="ij")
    S = np.sqrt(1 - C * C)
    wi = np.stack([S * np.cos(P), S * np.sin(P), C], axis=-1).reshape(-1, 3)
    p = f.pdf(wi, wo, method="tabulated", view_bins=4, theta_bins=8, phi_bins=16)
    assert (p > 0).all()
    assert abs(p.mean() * 2 * np.pi - 1.0) < 2e-3
    wi_s, pdf_s = f.sample(wo, np.array([[0.3, 0.7]]), method="tabulated", view_bins=4, theta_bins=8, phi_bins=16)
    assert pdf_s[0] > 0


def test_bad_inputs_name_the_argument():
    b = bf.brdf("bluepaint")
    with pytest.raises(ValueError, match=r"u\[0\]\[1\]"):
        b.sample(np.array([0, 0, 1.0]), np.array([[0.5, 1.0]]))
    with pytest.raises(ValueError, match="wo"):
        b.sample(np.zeros((2, 3)), np.full((2, 2), 0.5))
    with pytest.raises(ValueError, match="theta_bins"):
        b.sample(np.array([0, 0, 1.0]), np.array([0.5, 0.5]), theta_bins=1)
    with pytest.raises(ValueError, match="method"):
        b.pdf(np.array([0, 0, 1.0]), np.array([0, 0, 1.0]), method="bogus")
    # Below the horizon: no sample, pdf 0.
    wi, pdf = b.sample(np.array([0.6, 0, -0.8]), np.array([0.5, 0.5]))
    assert pdf[0] == 0
