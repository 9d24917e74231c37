"""Symmetries as data in Python: a SampleSet declares them, a BRDF claims them;
the interpolant of a CSV claims nothing its data do not declare."""
import pytest

import brdf_factor as bf


def test_sampleset_declares_symmetries(bluepaint):
    s = bf.sample_stratified(bluepaint, 100, seed=1)
    assert s.symmetries == "none"
    d = bf.SampleSet(s.wi, s.wo, s.value, symmetries="isotropic+reciprocal")
    assert d.symmetries == "isotropic+reciprocal"
    with pytest.raises(ValueError, match="symmetries"):
        bf.SampleSet(s.wi, s.wo, s.value, symmetries="isotropic+round")


def test_csv_interpolant_is_not_isotropic(tmp_path, bluepaint):
    s = bf.sample_stratified(bluepaint, 200, seed=2)
    path = str(tmp_path / "s.csv")
    s.write_csv(path)
    b = bf.brdf(path)
    assert not b.isotropic and not b.reciprocal and not b.bilateral and not b.whole_domain
    k = bf.brdf("krylon-blue")
    assert k.isotropic and k.reciprocal and k.bilateral and k.whole_domain
    assert bf.brdf("ward", ax=0.1, ay=0.3).bilateral
