"""bf.search's parameterization follows the config's rule: given, it is every
term's (whatever the strategy); not given, the structured search may choose per
term; term_param="either" together with it is refused, naming both keys."""
import json

import pytest

import brdf_factor as bf

# Small and fast; on McCool's form p(wi) q(h) p(wo) the free search mixes
# wiwo and halfdiff terms.
OPTS = dict(terms=2, texture_size=6, restarts=1, threads=1, seed=1)


@pytest.fixture(scope="module")
def grid6():
    return bf.sample_grid(bf.brdf("mccool-form"), 6)


def exported_params(f, tmp_path, stem):
    """Each term's parameterization as the exported sidecar says (the
    factorization itself, not the info record)."""
    with open(f.export(str(tmp_path), stem)["sidecar"]) as fh:
        return [t["parameterization"] for t in json.load(fh)["terms"]]


def test_an_explicit_parameterization_is_every_terms(grid6, tmp_path):
    free = bf.search(grid6, **OPTS)
    free_terms = exported_params(free, tmp_path, "free")
    # The control: without the key this case does mix, so the checks below
    # are not true by accident.
    assert set(free_terms) == {"wiwo", "halfdiff"}, free_terms
    for p in ("wiwo", "halfdiff"):
        for strategy in (None, "structured"):
            f = bf.search(grid6, parameterization=p, strategy=strategy, **OPTS)
            terms = exported_params(f, tmp_path, "%s-%s" % (p, strategy))
            assert terms == [p] * 2, (p, strategy, terms, f.info["search_strategy"])
            assert f.info["term_parameterizations"] == terms
            assert f.info["search_strategy"] in ("greedy", "structured")
    assert free.info["term_parameterizations"] == free_terms


def test_term_param_either_with_an_explicit_parameterization_is_refused(grid6):
    with pytest.raises(ValueError) as e:
        bf.search(grid6, parameterization="halfdiff", term_param="either", **OPTS)
    msg = str(e.value)
    assert msg.startswith("search: term_param:"), msg
    assert 'parameterization = "halfdiff"' in msg and 'term_param = "either"' in msg, msg
    # None is "not given": the search chooses, and term_param either is no contradiction.
    f = bf.search(grid6, parameterization=None, term_param="either", **OPTS)
    assert len(f.info["term_parameterizations"]) == 2
