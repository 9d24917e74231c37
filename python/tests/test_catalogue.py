"""Catalogue from Python: listings, spec strings with keyword overrides,
evaluation on arrays (shapes, broadcasting, closed forms), CLI-equal errors."""
import math
import subprocess

import numpy as np
import pytest

import brdf_factor as bf
from conftest import random_pairs


def test_models_and_presets_are_listed():
    models = {m["name"]: m for m in bf.models()}
    assert {"lambert", "cook-torrance", "ward", "lafortune", "blinn-phong"} <= set(models)
    ct = {p["name"] for p in models["cook-torrance"]["params"]}
    assert {"m", "kd", "ks"} <= ct
    presets = {p["name"]: p for p in bf.presets()}
    assert presets["bluepaint"]["model"] == "lafortune"
    assert len(presets) > 500
    assert ".astm" in bf.file_formats() and ".json" in bf.file_formats()


def test_lambert_closed_form_and_shapes():
    b = bf.brdf("lambert", kd=(0.2, 0.4, 0.6))
    wi, wo = random_pairs(1000)
    v = b.eval(wi, wo)
    assert v.shape == (1000, 3) and v.dtype == np.float64
    np.testing.assert_allclose(v, np.tile([0.2 / math.pi, 0.4 / math.pi, 0.6 / math.pi], (1000, 1)), rtol=1e-15)
    # (3,) with (3,) gives (3,); a single direction broadcasts against (N, 3).
    assert b.eval(wi[0], wo[0]).shape == (3,)
    np.testing.assert_array_equal(b.eval(wi[0], wo), b.eval(np.tile(wi[0], (1000, 1)), wo))
    # Unnormalized input is normalized as the CLI's eval does; below the horizon is 0.
    np.testing.assert_array_equal(b(3.0 * wi, 0.5 * wo), v)
    below = wo * np.array([1, 1, -1])
    assert np.all(b.eval(wi, below) == 0)


def test_overrides_equal_the_spec_string():
    wi, wo = random_pairs(200, seed=2)
    a = bf.brdf("cook-torrance", m=0.2, kd=(0.1, 0.2, 0.3))
    b = bf.brdf("cook-torrance:m=0.2,kd=0.1/0.2/0.3")
    np.testing.assert_array_equal(a.eval(wi, wo), b.eval(wi, wo))
    assert a.to_string() == b.to_string()
    # numpy values work as overrides too.
    e = bf.brdf("cook-torrance", m=np.float64(0.2), kd=np.array([0.1, 0.2, 0.3]))
    np.testing.assert_array_equal(e.eval(wi, wo), b.eval(wi, wo))
    # Overrides of a preset and of a spec with assignments.
    c = bf.brdf("cole-cook-torrance", m=0.25)
    d = bf.brdf("cole-cook-torrance:m=0.25")
    np.testing.assert_array_equal(c.eval(wi, wo), d.eval(wi, wo))


def test_eval_rejects_bad_shapes_with_the_argument_named():
    b = bf.brdf("lambert")
    with pytest.raises(ValueError, match=r"^wi: expected shape \(N, 3\) or \(3,\), found \(4, 2\)$"):
        b.eval(np.zeros((4, 2)), np.zeros((4, 3)))
    with pytest.raises(ValueError, match=r"wi has 4 directions and wo 5"):
        b.eval(np.ones((4, 3)), np.ones((5, 3)))
    wi = np.ones((4, 3))
    wi[2] = 0
    with pytest.raises(ValueError, match=r"^wi\[2\]: direction must be non-zero and finite$"):
        b.eval(wi, np.ones((4, 3)))


def cli_error(cli, *args):
    r = subprocess.run([cli, *args], capture_output=True, text=True)
    assert r.returncode == 2
    assert r.stderr.startswith("brdf-factor: ")
    return r.stderr[len("brdf-factor: "):].rstrip("\n")


@pytest.mark.parametrize("spec", ["no-such-model", "cook-torrance:m=-1", "cook-torrance:mm=0.2",
                                  "/nonexistent/file.astm"])
def test_errors_carry_the_cli_message(cli, spec):
    with pytest.raises(ValueError) as e:
        bf.brdf(spec)
    expected = cli_error(cli, "eval", "--brdf", spec, "--wi", "0,0,1", "--wo", "0,0,1")
    # The CLI names the option (--brdf), the module the argument (brdf).
    assert str(e.value) == expected.replace("--brdf", "brdf")
