#!/usr/bin/env python3
"""The factor-and-evaluate round trip from Python against the same round trip
in C++ (bench-eval-cpp): a McCool fit on a GRID^4 sample grid, then the
factorization evaluated at N direction pairs. Both sides time only the fit and
the evaluation (direction generation and file I/O excluded); the variants run
interleaved, REPS times each, and the medians and their ratio are printed
with the load. The two sides' values are checked to be identical.

    PYTHONPATH=build/python /usr/bin/python3 python/bench/bench_eval.py \\
        [--cpp build/python/bench-eval-cpp] [--n 1000000] [--reps 7]
"""
import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import brdf_factor as bf


def main():
    here = pathlib.Path(bf.__file__).resolve().parent.parent  # <build>/python
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cpp", default=str(here / "bench-eval-cpp"), help="the C++ side (built with the module)")
    ap.add_argument("--brdf", default="bluepaint")
    ap.add_argument("--grid", type=int, default=16)
    ap.add_argument("--texture", type=int, default=16)
    ap.add_argument("--n", type=int, default=1_000_000)
    ap.add_argument("--reps", type=int, default=7)
    a = ap.parse_args()

    rng = np.random.default_rng(1)
    def hemi(k):
        v = rng.normal(size=(k, 3))
        v[:, 2] = np.abs(v[:, 2])
        return v / np.linalg.norm(v, axis=1, keepdims=True)
    wi, wo = hemi(a.n), hemi(a.n)
    with tempfile.TemporaryDirectory() as tmp:
        dirs = os.path.join(tmp, "dirs.bin")
        out = os.path.join(tmp, "out.bin")
        np.hstack([wi, wo]).tofile(dirs)
        b = bf.brdf(a.brdf)
        py_t, py_fit, cpp_t, cpp_fit = [], [], [], []
        for rep in range(a.reps):
            # Python: the whole round trip, as a user would write it.
            t0 = time.perf_counter()
            s = bf.sample_grid(b, a.grid)
            f = bf.mccool(s, texture_size=a.texture)
            t1 = time.perf_counter()
            v = f.eval(wi, wo)
            t2 = time.perf_counter()
            py_t.append(t2 - t0)
            py_fit.append(t1 - t0)
            r = subprocess.run([a.cpp, a.brdf, str(a.grid), str(a.texture), dirs, out],
                               capture_output=True, text=True, check=True)
            c = json.loads(r.stdout)
            cpp_t.append(c["seconds"])
            cpp_fit.append(c["fit_seconds"])
            if rep == 0:
                cv = np.fromfile(out).reshape(-1, 3)
                if not np.array_equal(cv, v):
                    sys.exit("bench_eval: Python and C++ values differ (max |diff| %g)" % np.max(np.abs(cv - v)))
    # Python's sample_grid + mccool also scores the fit (metrics): part of its round trip.
    med = statistics.median
    print(json.dumps({
        "n": a.n, "brdf": a.brdf, "grid": a.grid, "texture": a.texture, "reps": a.reps,
        "python_seconds": round(med(py_t), 4), "cpp_seconds": round(med(cpp_t), 4),
        "python_fit_seconds": round(med(py_fit), 4), "cpp_fit_seconds": round(med(cpp_fit), 4),
        "python_eval_seconds": round(med(py_t) - med(py_fit), 4),
        "cpp_eval_seconds": round(med(cpp_t) - med(cpp_fit), 4),
        "ratio": round(med(py_t) / med(cpp_t), 3),
        "ratios_per_rep": [round(p / c, 3) for p, c in zip(py_t, cpp_t)],
        "load": os.getloadavg(),
    }))


if __name__ == "__main__":
    main()
