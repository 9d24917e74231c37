"""Symmetries as data in Python: a SampleSet declares them, a BRDF claims them;
the interpolant of a CSV claims nothing its data do not declare."""
import pytest

import brdf_factor as bf


def test_sampleset_declares_symmetries(bluepaint, tmp_path):
    # A set of a BRDF's values declares what the BRDF claims; a CSV declares none.
    s = bf.sample_stratified(bluepaint, 100, seed=1)
    assert s.symmetries == "isotropic+reciprocal+bilateral"
    assert bf.sample_grid(bf.brdf("ward", ax=0.1, ay=0.1), 4).symmetries == "isotropic+reciprocal+bilateral"
    assert bf.sample_grid(bf.brdf("ward", ax=0.1, ay=0.3), 4).symmetries == "reciprocal+bilateral"
    path = str(tmp_path / "s.csv")
    s.write_csv(path)
    read = bf.read_samples(path)
    assert read.symmetries == "none"
    assert bf.evaluate(bluepaint, read).symmetries == "isotropic+reciprocal+bilateral"
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


def test_search_final_reciprocity_auto_reads_the_grids_declaration(bluepaint, tmp_path):
    # "auto" in Python reads the samples' declaration: a grid of a reciprocal
    # BRDF turns it on (as a config's grid of that BRDF does), the same pairs
    # read back from a CSV (which declares nothing) leave it off.
    g = bf.sample_grid(bluepaint, 6)
    on = bf.search(g, terms=1, texture_size=6, restarts=1, threads=1, seed=1)
    assert on.info["final_reciprocity"]["on"] is True
    path = str(tmp_path / "g.csv")
    g.write_csv(path)
    off = bf.search(bf.read_samples(path), terms=1, texture_size=6, restarts=1, threads=1, seed=1)
    assert off.info["final_reciprocity"]["on"] is False
