"""Sample sets from the samplers and from numpy arrays: sizes, zero-copy
read-only views, masking of invalid samples, shape errors."""
import numpy as np
import pytest

import brdf_factor as bf
from conftest import random_pairs


def test_grid_sizes_and_views(bluepaint):
    s = bf.sample_grid(bluepaint, 16)
    assert len(s) == 43264 and s.valid_count == 43264
    wi, value = s.wi, s.value
    assert wi.shape == (43264, 3) and value.shape == (43264, 3) and s.valid.dtype == np.bool_
    # Views of the C++ vectors: the same memory on every access, not writable.
    assert np.shares_memory(wi, s.wi) and not wi.flags.writeable
    with pytest.raises(ValueError):
        wi[0, 0] = 1.0
    assert s.weight is None
    np.testing.assert_allclose(np.linalg.norm(wi, axis=1), 1.0, rtol=1e-14)
    # The values are the BRDF's at the pairs.
    np.testing.assert_array_equal(value[:100], bluepaint.eval(s.wi[:100], s.wo[:100]))


def test_stratified_is_deterministic(bluepaint):
    a = bf.sample_stratified(bluepaint, 5000, seed=3)
    b = bf.sample_stratified(bluepaint, 5000, seed=3)
    c = bf.sample_stratified(bluepaint, 5000, seed=4)
    assert len(a) == 5000
    np.testing.assert_array_equal(a.wi, b.wi)
    assert not np.array_equal(a.wi, c.wi)


def test_from_arrays_masks_invalid_samples(bluepaint):
    wi, wo = random_pairs(100)
    v = bluepaint.eval(wi, wo)
    v[3] = [-1.0, 0.1, 0.1]   # negative value
    v[5, 1] = np.nan          # NaN
    wo[7, 2] = -0.5           # below the horizon
    w = np.ones(100)
    w[9] = -2.0               # negative weight
    s = bf.SampleSet(wi, wo, v, weight=w, description="test")
    assert len(s) == 100 and s.valid_count == 96
    assert list(np.flatnonzero(~s.valid)) == [3, 5, 7, 9]
    np.testing.assert_array_equal(s.weight, w)
    assert s.description == "test"
    assert len(s.compacted()) == 96


def test_from_arrays_shape_errors():
    wi, wo = random_pairs(10)
    with pytest.raises(ValueError, match=r"same number of rows, found 10, 10, 9"):
        bf.SampleSet(wi, wo, np.ones((9, 3)))
    with pytest.raises(ValueError, match=r"^value: expected shape \(N, 3\) or \(3,\), found \(10, 4\)$"):
        bf.SampleSet(wi, wo, np.ones((10, 4)))
    with pytest.raises(ValueError, match=r"weight: expected shape \(10,\)"):
        bf.SampleSet(wi, wo, np.ones((10, 3)), weight=np.ones(3))


def test_csv_round_trip(tmp_path, bluepaint):
    s = bf.sample_stratified(bluepaint, 300, seed=1)
    p = str(tmp_path / "s.csv")
    s.write_csv(p)
    r = bf.read_samples(p)
    assert len(r) == 300
    np.testing.assert_allclose(r.value, s.value, rtol=1e-12)
    np.testing.assert_allclose(r.wi, s.wi, atol=1e-12)
