"""brdf-factor from Python: the catalogue, sample sets, every factorization
method, and experiment configs, with numpy arrays in and out.

    import brdf_factor as bf
    b = bf.brdf("bluepaint")
    s = bf.sample_grid(b, 16)
    f = bf.search(s, terms=2, restarts=4)
    f.metrics["rel_mse"], f.eval(wi, wo)        # wi, wo: (N, 3) -> (N, 3)

Errors raise ValueError (bad input; ConfigError for configs) or RuntimeError
with the same text the CLI prints after "brdf-factor: ". See docs/python.md.
"""

import csv as _csv
import os as _os
import stat as _stat

from . import _core
from ._core import (  # noqa: F401  (the public API)
    Brdf,
    ConfigError,
    Factorization,
    SampleSet,
    __version__,
    brdf,
    data_dir,
    evaluate,
    file_formats,
    load,
    measured_samples,
    models,
    presets,
    read_samples,
    refine,
    run_experiment as _run_experiment,
    sample_grid,
    sample_stratified,
    score,
)

# Method kinds as the configs name them -> the function and what it factors
# ("samples": fitted to a sample set; "brdf": tabulates the BRDF itself), one
# per kind the catalogue registers (bf.mccool, bf.fit, bf.search, bf.svd,
# bf.sh_k, bf.sh_r, bf.model_fit, ...), bound by the module from the registry.
METHODS = {}
for _kind, _function, _input in _core._method_table():
    globals()[_function] = getattr(_core, _function)
    METHODS[_kind] = (getattr(_core, _function), _input)
del _kind, _function, _input

__all__ = sorted([
    "Brdf", "ConfigError", "Factorization", "SampleSet", "brdf", "data_dir", "evaluate",
    "factor", "file_formats", "load", "measured_samples",
    "models", "presets", "read_samples", "refine", "results", "run", "sample_grid",
    "sample_stratified", "score",
] + [fn.__name__ for fn, _ in METHODS.values()]) + ["METHODS"]


def factor(kind, brdf=None, samples=None, **options):
    """Runs method `kind` (a registered kind: the keys of METHODS, e.g.
    "mccool", "fit", "search", "svd", "sh-k", "sh-r", "model-fit") as a
    config's [[method]] with these options would.

    Sample-based kinds need `samples` (or a `brdf`, sampled on the 16^4 grid,
    the config's default sampling); tabulating kinds need `brdf` and report
    metrics when `samples` are given (or sampled from the brdf likewise)."""
    if kind not in METHODS:
        raise ValueError("kind: expected one of %s, found %r" % (", ".join(METHODS), kind))
    fn, needs = METHODS[kind]
    if samples is None and brdf is not None:
        samples = sample_grid(brdf, 16)
    if needs == "samples":
        if samples is None:
            raise ValueError("%s: needs samples (or a brdf to sample)" % kind)
        return fn(samples, **options)
    if brdf is None:
        raise ValueError("%s: needs a brdf (it tabulates the BRDF itself)" % kind)
    return fn(brdf, samples, **options)


def _defines(defines):
    if defines is None:
        return []
    if isinstance(defines, dict):
        out = []
        for k, v in defines.items():
            if isinstance(v, bool):
                v = "true" if v else "false"
            elif isinstance(v, str):
                v = '"%s"' % v if not v.startswith(("[", "{", '"')) else v
            out.append("%s=%s" % (k, v))
        return out
    return list(defines)


class Run(dict):
    """What run() returns: the run summary (out_dir, planned, executed, cached,
    failed, run_ids, files, output) as a dict, plus the results table."""

    def results(self, frame=False):
        return results(self["out_dir"], frame=frame)


def run(config, defines=None, out=None, dry_run=False, force=False, quiet=True,
        shard="1/1", jobs=-1, plots=False):
    """Runs an experiment config as `brdf-factor run CONFIG` does (same run
    cache, outputs and messages). defines: "key=value" strings (-D) or a dict
    (strings are quoted for TOML). plots=False skips plot_results.py (the
    CLI's --no-plots); quiet=True keeps progress off stderr. Returns a Run
    (a dict; .results() reads results.csv). Config errors raise ConfigError
    with the CLI's text; a failed run raises RuntimeError after the outputs
    are written."""
    s = _run_experiment(_os.fspath(config), _defines(defines), "" if out is None else _os.fspath(out),
                        dry_run, force, quiet, shard, jobs, plots)
    return Run(s)


def _value(text):
    if text == "":
        return None
    if text in ("true", "false"):
        return text == "true"
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        return text


_KINDS = ((_stat.S_ISFIFO, "a FIFO"), (_stat.S_ISCHR, "a character device"), (_stat.S_ISBLK, "a block device"),
          (_stat.S_ISDIR, "a directory"), (_stat.S_ISSOCK, "a socket"))


def _check_regular_file(path, what, max_bytes=2 << 30):
    """The checks of brdfs/file_check.h, with its messages: a regular file of
    at most max_bytes (a FIFO would block open(), a device never end)."""
    try:
        st = _os.stat(path)
    except FileNotFoundError:
        raise ValueError("%s: cannot open %s: file not found" % (path, what)) from None
    except OSError as e:
        raise ValueError("%s: cannot open %s: %s" % (path, what, e.strerror)) from None
    if not _stat.S_ISREG(st.st_mode):
        kind = next((k for test, k in _KINDS if test(st.st_mode)), "a non-regular file")
        raise ValueError("%s: %s: expected a regular file, found %s" % (path, what, kind))
    if st.st_size > max_bytes:
        raise ValueError("%s: %s: %d bytes, more than the limit of %d" % (path, what, st.st_size, max_bytes))


# Columns that are text whatever they look like: a run id is 12 hex digits
# and can be all decimal ("012345678901" must not become 12345678901), a
# label or BRDF name can be a number.
_TEXT_COLUMNS = frozenset(("run_id", "brdf", "method", "label", "sampling", "sweep", "notes", "flag",
                           "validation", "parameterization", "term_parameterizations", "search_strategy"))


def results(path, frame=False):
    """An experiment folder's results.csv (or the file itself) as a list of
    dicts, one per run, numbers as int/float, empty cells as None; with
    frame=True a pandas DataFrame (pandas must be installed). The text
    columns (run_id, brdf, method, label, sampling, sweep, notes, flag,
    validation, parameterization, term_parameterizations, search_strategy)
    stay strings: a run id of decimal digits only is still a run id."""
    path = _os.fspath(path)
    if _os.path.isdir(path):
        path = _os.path.join(path, "results.csv")
    _check_regular_file(path, "results table")
    with open(path, newline="") as f:
        rows = [{k: ((v or None) if k in _TEXT_COLUMNS else _value(v)) for k, v in row.items()}
                for row in _csv.DictReader(f)]
    if frame:
        import pandas  # noqa: raises ImportError naming pandas when it is missing
        return pandas.DataFrame(rows)
    return rows
