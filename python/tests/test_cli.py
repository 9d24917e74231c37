"""The module against the CLI: an experiment config run through bf.run and
through `brdf-factor run` gives the same results.csv, and the direct API with
the config's options gives the CLI's factorizations (rel_mse to 1e-12); config
errors carry the CLI's message."""
import os
import subprocess

import numpy as np
import pytest

import brdf_factor as bf

CONFIG = """
[experiment]
name = "pycheck"
seed = 1
jobs = 1
render = false
plots = false

[[brdf]]
preset = "bluepaint"

[sampling]
kind = "grid"
resolution = 8

[[method]]
kind = "mccool"
texture_size = 8

[[method]]
kind = "fit"
projections = [{ name = "wi" }, { name = "h" }]
texture_size = 8

[[method]]
kind = "search"
terms = 2
texture_size = 8
restarts = 2
threads = 1

[[method]]
kind = "svd"
terms = 2
texture_size = 8

[[method]]
kind = "sh-k"
order = 4
texture_size = 8

[[method]]
kind = "sh-r"
order = 8
view_order = 2
max_order = 8
max_view_order = 2

[[method]]
kind = "mccool"
label = "mccool+refine"
texture_size = 8
refine = "linear"
refine_iterations = 5

[[method]]
kind = "model-fit"
model = "blinn-phong"
starts = 2
threads = 1
"""

# The same methods through the direct API (config keys = keyword options).
DIRECT = {
    "mccool": lambda s, b: bf.mccool(s, texture_size=8),
    "fit": lambda s, b: bf.fit(s, projections=["wi", "h"], texture_size=8),
    # final_reciprocity "auto": the BRDF in the config, the grid's declaration
    # (the BRDF's symmetries) here; the same answer either way.
    "search": lambda s, b: bf.search(s, terms=2, texture_size=8, restarts=2, threads=1, seed=1),
    "svd": lambda s, b: bf.svd(b, s, terms=2, texture_size=8),
    "sh-k": lambda s, b: bf.sh_k(b, s, order=4, texture_size=8),
    "sh-r": lambda s, b: bf.sh_r(b, s, order=8, view_order=2, max_order=8, max_view_order=2),
    "mccool+refine": lambda s, b: bf.mccool(s, texture_size=8, refine="linear", refine_iterations=5),
    "model-fit": lambda s, b: bf.model_fit(s, model="blinn-phong", starts=2, threads=1, seed=1),
}
KINDS = ["mccool", "fit", "search", "svd", "sh-k", "sh-r", "mccool", "model-fit"]


@pytest.fixture(scope="module")
def runs(tmp_path_factory, cli):
    d = tmp_path_factory.mktemp("cli")
    cfg = d / "pycheck.toml"
    cfg.write_text(CONFIG)
    cli_out, py_out = d / "cli", d / "py"
    r = subprocess.run([cli, "run", str(cfg), "--out", str(cli_out), "--quiet", "--no-plots"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    summary = bf.run(cfg, out=py_out)
    return cli_out, py_out, summary


def test_run_summary(runs):
    cli_out, py_out, s = runs
    assert s["planned"] == 8 and s["executed"] == 8 and s["failed"] == 0
    assert s["out_dir"] == str(py_out)
    rows = s.results()
    assert [r["method"] for r in rows] == KINDS
    assert all(isinstance(r["rel_mse"], float) for r in rows)
    # Run again: every run comes from the cache.
    again = bf.run(cli_out.parent / "pycheck.toml", out=py_out)
    assert again["cached"] == 8 and again["executed"] == 0


def test_results_equal_the_cli(runs):
    cli_out, py_out, _ = runs
    a = bf.results(cli_out)
    b = bf.results(py_out)
    assert len(a) == len(b) == 8
    for ra, rb in zip(a, b):
        assert ra["run_id"] == rb["run_id"]
        for k in ("rel_mse", "rel_mae", "rel_max", "lin_rmse", "cos_rmse", "storage_floats", "samples"):
            assert ra[k] == rb[k], (ra["method"], k)


def test_direct_api_equals_the_cli(runs, bluepaint):
    cli_out, _, _ = runs
    s = bf.sample_grid(bluepaint, 8)
    for row in bf.results(cli_out):
        kind = row["label"]
        f = DIRECT[kind](s, bluepaint)
        # results.csv holds 9 significant digits.
        assert f.metrics["rel_mse"] == pytest.approx(row["rel_mse"], rel=1e-8, abs=0), kind
        assert f.storage_floats == row["storage_floats"], kind
        model = cli_out / "runs" / row["run_id"] / "model.json"
        if model.exists():
            # The CLI's model fit, rebuilt from its spec and scored at full precision.
            assert abs(bf.score(bf.load(str(model)), s)["rel_mse"] - f.metrics["rel_mse"]) <= 1e-12, kind
        sidecar = cli_out / "runs" / row["run_id"] / "factors.json"
        if sidecar.exists():
            # The CLI's exported factorization, scored here at full precision.
            g = bf.load(str(sidecar))
            assert abs(g.score(s)["rel_mse"] - f.metrics["rel_mse"]) <= 1e-12, kind
            wi, wo = s.wi[:500], s.wo[:500]
            np.testing.assert_array_equal(g.eval(wi, wo), f.eval(wi, wo))


def test_config_errors_carry_the_cli_message(tmp_path, cli):
    cfg = tmp_path / "bad.toml"
    cfg.write_text(CONFIG.replace("restarts = 2", "restarts = -2").replace('kind = "svd"', 'kind = "svd"\nrank = 3'))
    r = subprocess.run([cli, "run", str(cfg), "--quiet", "--dry-run"], capture_output=True, text=True)
    assert r.returncode == 2
    with pytest.raises(bf.ConfigError) as e:
        bf.run(cfg, dry_run=True)
    assert isinstance(e.value, ValueError)
    # main() prints what() after "brdf-factor: "; what() prefixes the later lines itself.
    assert r.stderr == "brdf-factor: " + str(e.value) + "\n"
    assert len(e.value.messages) == 2
    assert "restarts" in e.value.messages[0] and "rank" in e.value.messages[1]


def test_defines_and_frame(runs, tmp_path):
    cli_out, _, _ = runs
    s = bf.run(cli_out.parent / "pycheck.toml", out=tmp_path / "d", defines={"sampling.resolution": 6}, dry_run=True)
    assert s["planned"] == 8 and s["executed"] == 0
    try:
        import pandas  # noqa: F401
    except ImportError:
        with pytest.raises(ImportError):
            bf.results(cli_out, frame=True)
    else:
        assert len(bf.results(cli_out, frame=True)) == 8


# (kind, TOML lines of its [[method]] table, the same as keyword options)
BAD_OPTIONS = [
    ("mccool", "smoothing = -1.0", dict(smoothing=-1.0)),
    ("mccool", "solve_last = 0", dict(solve_last=0)),
    ("mccool", "refine_iterations = 0", dict(refine_iterations=0)),
    ("fit", 'projections = [{ name = "wi" }]\nterms = 2', dict(projections=["wi"], terms=2)),
    ("search", "restarts = -2", dict(restarts=-2)),
    ("search", "restarts = 2\nbeam = 9", dict(restarts=2, beam=9)),
    ("search", "ftol = 0.0", dict(ftol=0.0)),
    ("search", "search_texture_size = 1", dict(search_texture_size=1)),
    ("svd", "rim_inset = 0.7", dict(rim_inset=0.7)),
    ("sh-k", "order = 300", dict(order=300)),
    ("sh-r", "energy_eps = 2.0", dict(energy_eps=2.0)),
    ("model-fit", "lobes = 5", dict(lobes=5)),
    # Types, unknown keys, nested tables, pair rules: the same reader, the same words.
    ("search", 'restarts = "2"', dict(restarts="2")),
    ("search", "restart = 2", dict(restart=2)),
    ("svd", "log = 1", dict(log=1)),
    ("svd", "log = false\neps = 0.001", dict(log=False, eps=1e-3)),
    ("mccool", 'texture_size = "auto"\ntolerance = { metric = "rel_mze", value = 0.1 }',
     dict(texture_size="auto", tolerance=("rel_mze", 0.1))),
    ("fit", 'projections = [{ name = "x" }, { matrix = [[1, 0, 0, 0], [1, 0, 0, 0]] }]',
     dict(projections=["x", np.array([[1, 0, 0, 0], [1, 0, 0, 0]])])),
    ("fit", 'projections = [{ name = "wi", matrix = [[1, 0, 0, 0], [0, 1, 0, 0]] }]',
     dict(projections=[{"name": "wi", "matrix": np.eye(2, 4)}])),
    ("sh-r", "order = 4", dict(order=4)),
    ("sh-k", "reduce_isotropic = 1.5", dict(reduce_isotropic=1.5)),
    ("model-fit", "restarts = 2", dict(restarts=2)),
]


@pytest.mark.parametrize("kind,toml,options", BAD_OPTIONS, ids=[b[1].split("\n")[-1] for b in BAD_OPTIONS])
def test_option_errors_state_the_cli_rule(tmp_path, cli, grid8, bluepaint, kind, toml, options):
    cfg = tmp_path / "bad.toml"
    cfg.write_text('[[brdf]]\npreset = "bluepaint"\n[sampling]\nkind = "grid"\nresolution = 8\n'
                   '[[method]]\nkind = "%s"\n%s\n' % (kind, toml))
    r = subprocess.run([cli, "run", str(cfg), "--dry-run", "--quiet"], capture_output=True, text=True)
    assert r.returncode == 2
    # Each line "brdf-factor: FILE:LINE: method[0].KEY: RULE" or "...: method[0]: KEY: RULE" -> "KEY: RULE"
    cli_rules = [line.split("method[0]", 1)[1].lstrip(".: ") for line in r.stderr.strip().splitlines()]
    assert all(": " in rule for rule in cli_rules), r.stderr
    with pytest.raises(ValueError) as e:
        bf.factor(kind, brdf=bluepaint, samples=grid8, **options)
    assert str(e.value).splitlines() == [kind + ": " + rule for rule in cli_rules]


# ------------------------------------------------------------ every registered kind

def _toml(v):
    """A value of a kind's example options (_method_examples) as TOML."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return '"%s"' % v.replace("\\", "\\\\").replace('"', '\\"')
    if isinstance(v, dict):
        return "{ " + ", ".join("%s = %s" % (k, _toml(x)) for k, x in v.items()) + " }"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml(x) for x in v) + "]"
    return repr(v)


def test_every_registered_kind_runs_the_same_from_a_config_and_from_python(tmp_path, bluepaint):
    # The kinds come from the registry (_core._method_examples: every kind
    # with its small example options), not from a list here.
    from brdf_factor import _core
    examples = _core._method_examples()
    assert sorted(examples) == sorted(bf.METHODS)
    cfg = CONFIG.split("[[method]]")[0]
    for kind, options in examples.items():
        cfg += "[[method]]\nkind = \"%s\"\n" % kind + "".join("%s = %s\n" % (k, _toml(v)) for k, v in options.items())
    (tmp_path / "kinds.toml").write_text(cfg)
    rows = bf.run(tmp_path / "kinds.toml", out=tmp_path / "out").results()
    assert sorted(r["method"] for r in rows) == sorted(examples)
    s = bf.sample_grid(bluepaint, 8)
    for row in rows:
        kind = row["method"]
        f = bf.factor(kind, brdf=bluepaint, samples=s, **examples[kind])
        assert f.method == kind
        assert f.metrics["rel_mse"] == pytest.approx(row["rel_mse"], rel=1e-8, abs=0), kind
        assert f.storage_floats == row["storage_floats"], kind
        # The function bf.<kind> ('-' as '_') is the registry's, with its keys documented.
        fn, needs = bf.METHODS[kind]
        assert getattr(bf, kind.replace("-", "_")) is fn and needs in ("samples", "brdf")
        for key in examples[kind]:
            assert key in fn.__doc__, (kind, key)


def test_results_keep_text_columns_as_text(tmp_path):
    # A run id is 12 hex digits and can be decimal digits only, with a leading
    # zero; it must come back as the same string, not as an int.
    (tmp_path / "results.csv").write_text(
        "run_id,brdf,method,label,rel_mse,terms,reciprocity\n"
        "012345678901,7,search,42,0.5,2,true\n"
        "a1b2c3d4e5f6,bluepaint,mccool,,0.25,2,mixed\n")
    rows = bf.results(tmp_path)
    assert rows[0]["run_id"] == "012345678901"
    assert rows[0]["brdf"] == "7" and rows[0]["label"] == "42"
    assert rows[0]["rel_mse"] == 0.5 and rows[0]["terms"] == 2 and rows[0]["reciprocity"] is True
    assert rows[1]["run_id"] == "a1b2c3d4e5f6" and rows[1]["label"] is None and rows[1]["reciprocity"] == "mixed"
