"""Inputs from Python are checked as the CLI checks them: an omitted option is
never garbage (SampleSet weights), every entry that reads a user's file refuses
FIFOs, folders and missing files at once with a message naming the path, and
numeric options have the config's ranges."""
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import brdf_factor as bf
from conftest import random_pairs


# ---------------------------------------------------------------- weights


def _arrays(bluepaint, n=2704, seed=5):
    wi, wo = random_pairs(n, seed)
    return wi, wo, bluepaint.eval(wi, wo)


def test_omitted_weight_is_unit_weight(bluepaint):
    wi, wo, v = _arrays(bluepaint)
    a = bf.SampleSet(wi, wo, v)
    b = bf.SampleSet(wi, wo, v, weight=np.ones(len(wi)))
    # Every sample of a clean set is valid, with or without weights.
    assert a.valid_count == len(wi) == b.valid_count
    assert a.weight is None
    # The fit is the same to the last bit.
    fa, fb = bf.mccool(a, texture_size=8), bf.mccool(b, texture_size=8)
    assert fa.metrics == fb.metrics
    assert fa.metrics["rel_mse"] > 1e-3  # a real error, not a fit to a handful of samples
    for ta, tb in zip(fa.textures(), fb.textures()):
        np.testing.assert_array_equal(ta, tb)
    assert fa.A == fb.A
    # What the samples score is independent of how the weights were spelled.
    assert bf.score(fa, a) == bf.score(fa, b)


def test_repeated_construction_gives_identical_sets(bluepaint):
    wi, wo, v = _arrays(bluepaint, 500)
    sets = [bf.SampleSet(wi, wo, v) for _ in range(20)]
    for s in sets:
        assert s.weight is None and s.valid_count == 500
        np.testing.assert_array_equal(s.valid, sets[0].valid)
    # Interleaved with other allocations (an uninitialized read would see them).
    junk = [np.full(500, 1e287) for _ in range(10)]
    s = bf.SampleSet(wi, wo, v)
    del junk
    assert s.weight is None and s.valid_count == 500


def test_weight_rejects_wrong_shapes_and_types(bluepaint):
    wi, wo, v = _arrays(bluepaint, 10)
    for bad in (np.ones(3), np.ones((10, 1)), np.float64(1.0), "heavy", [[1.0] * 10]):
        with pytest.raises(ValueError, match=r"^SampleSet: weight: expected shape \(10,\)"):
            bf.SampleSet(wi, wo, v, weight=bad)
    # A list and an integer array are numbers like any other.
    s = bf.SampleSet(wi, wo, v, weight=list(range(1, 11)))
    np.testing.assert_array_equal(s.weight, np.arange(1, 11, dtype=float))


def test_extreme_but_finite_directions_are_directions(bluepaint):
    wi, wo, v = _arrays(bluepaint, 4)
    big = wi * 1e300   # |w|^2 overflows a double
    tiny = wo * 1e-300  # |w|^2 underflows to 0
    s = bf.SampleSet(big, tiny, v)
    assert s.valid_count == 4
    np.testing.assert_allclose(s.wi, wi, rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(s.wo, wo, rtol=1e-15, atol=1e-15)


# ---------------------------------------------------------------- files

# Each entry of the module that reads a file the user names, as a snippet of
# code with PATH in it.
FILE_ENTRIES = {
    "load": "bf.load(PATH)",
    "brdf .astm": "bf.brdf(PATH + '.astm')",
    "brdf .brdf": "bf.brdf(PATH + '.brdf')",
    "brdf .binary": "bf.brdf(PATH + '.binary')",
    "brdf .csv": "bf.brdf(PATH + '.csv')",
    "read_samples": "bf.read_samples(PATH)",
    "run": "bf.run(PATH, out=OUT)",
    "results": "bf.results(PATH)",
}


def _entry_paths(kind, tmp_path):
    """A path of `kind` (fifo, dir, missing) under tmp_path, named for every
    suffix the entries append."""
    base = str(tmp_path / ("input-" + kind))
    for suffix in ("", ".json", ".astm", ".brdf", ".binary", ".csv"):
        p = base + suffix
        if kind == "fifo":
            os.mkfifo(p)
        elif kind == "dir":
            os.mkdir(p)
    return base


def _run_entry(code, path, out, timeout=60):
    """Runs one entry in a child interpreter (a call that blocks must not hang
    the test session): returns (exit code, stderr)."""
    script = textwrap.dedent("""
        import sys
        import brdf_factor as bf
        PATH, OUT = sys.argv[1], sys.argv[2]
        try:
            %s
        except Exception as e:
            print(type(e).__name__ + ": " + str(e), file=sys.stderr)
            sys.exit(3)
        sys.exit(0)
    """) % code
    p = subprocess.run([sys.executable, "-c", script, path, out], capture_output=True, text=True,
                       timeout=timeout, env=dict(os.environ))
    return p.returncode, p.stderr


@pytest.mark.parametrize("entry", sorted(FILE_ENTRIES))
@pytest.mark.parametrize("kind", ["fifo", "dir", "missing"])
def test_file_entries_refuse_non_files_naming_the_path(tmp_path, entry, kind):
    base = _entry_paths(kind, tmp_path)
    code = FILE_ENTRIES[entry]
    suffix = code[code.find("PATH + '") + 8:code.find("')")] if "PATH + '" in code else ""
    path = base + suffix
    rc, err = _run_entry(code, base, str(tmp_path / "out"), timeout=60)
    assert rc == 3, err
    last = err.strip().splitlines()[-1]
    assert path in last, last
    expected = {"fifo": "expected a regular file, found a FIFO",
                "dir": "expected a regular file, found a directory",
                "missing": "file not found"}[kind]
    if entry == "results" and kind == "dir":  # an experiment folder: its results.csv is missing
        path, expected = os.path.join(path, "results.csv"), "file not found"
    assert expected in last, last
    assert "basic_filebuf" not in last


def test_load_on_a_fifo_returns_promptly_and_keeps_the_gil_free(tmp_path):
    """In-process: bf.load on a FIFO without a writer raises at once."""
    fifo = str(tmp_path / "pipe.json")
    os.mkfifo(fifo)
    code = textwrap.dedent("""
        import sys, threading, time
        import brdf_factor as bf
        ticks = []
        def tick():
            for _ in range(50):
                ticks.append(time.monotonic())
                time.sleep(0.01)
        t = threading.Thread(target=tick, daemon=True)
        t.start()
        try:
            bf.load(sys.argv[1])
        except ValueError as e:
            print(str(e))
        t.join(5)
        print(len(ticks))
    """)
    p = subprocess.run([sys.executable, "-c", code, fifo], capture_output=True, text=True, timeout=60)
    assert p.returncode == 0, p.stderr
    lines = p.stdout.strip().splitlines()
    assert lines[0] == fifo + ": factorization sidecar: expected a regular file, found a FIFO"
    assert lines[1] == "50"


def test_load_errors_name_the_file(tmp_path):
    not_json = tmp_path / "x.json"
    not_json.write_text("{not json")
    with pytest.raises(ValueError, match="^" + str(not_json) + ": "):
        bf.load(str(not_json))
    # An export sidecar whose data file is a FIFO or missing names the data file.
    f = bf.svd(bf.brdf("lambert"), terms=1, texture_size=6)
    files = f.export(str(tmp_path / "svd"), "s")
    os.remove(files["data"])
    with pytest.raises(ValueError, match=r"s\.f64: cannot open data file: file not found"):
        bf.load(files["sidecar"])
    os.mkfifo(files["data"])
    with pytest.raises(ValueError, match=r"s\.f64: data file: expected a regular file, found a FIFO"):
        bf.load(files["sidecar"])


def test_config_naming_a_fifo_sample_file_is_refused(tmp_path):
    fifo = tmp_path / "samples.csv"
    os.mkfifo(fifo)
    cfg = tmp_path / "c.toml"
    cfg.write_text(textwrap.dedent("""
        [experiment]
        name = "fifo"
        [[brdf]]
        model = "lambert"
        [[sampling]]
        kind = "file"
        path = "%s"
        [[method]]
        kind = "mccool"
        texture_size = 4
    """) % fifo)
    rc, err = _run_entry("bf.run(PATH, out=OUT)", str(cfg), str(tmp_path / "out"))
    assert rc != 0 and str(fifo) in err and "FIFO" in err, err


# ---------------------------------------------------------------- numeric options


@pytest.mark.parametrize("key", ["smoothing", "extrapolation_prior", "refine_smoothing", "refine_blend"])
def test_huge_fit_weights_are_refused_naming_the_key(grid8, key):
    opts = {key: 1e300}
    if key.startswith("refine_"):
        opts["refine"] = "blend"
    with pytest.raises(ValueError, match=r"^mccool: %s: expected a number in \[0, 1000000\], found 1e\+300$" % key):
        bf.mccool(grid8, texture_size=6, **opts)


def test_refine_weights_are_bounded(grid8):
    f = bf.mccool(grid8, texture_size=6)
    for key in ("smoothing", "blend_weight"):
        with pytest.raises(ValueError, match=r"^refine: %s: expected a number in \[0, 1000000\], found 1e\+300$" % key):
            bf.refine(f, grid8, **{key: 1e300})


@pytest.mark.parametrize("eps", [0.0, -1.0, 2.0, float("nan")])
def test_score_metric_eps_has_the_config_range(grid8, eps):
    f = bf.mccool(grid8, texture_size=6)
    with pytest.raises(ValueError, match=r"metric_eps: expected a number in \(0, 1\]"):
        bf.score(f, grid8, metric_eps=eps)
    with pytest.raises(ValueError, match=r"metric_eps: expected a number in \(0, 1\]"):
        f.score(grid8, metric_eps=eps)
