#!/usr/bin/env python3
"""Worked example of docs/python.md: factor a Cornell paint (krylon-blue,
measured) with several methods, compare their errors and storage, and plot a
slice of each approximation against the measurement with matplotlib.

    PYTHONPATH=build/python /usr/bin/python3 python/examples/compare_methods.py [OUT.png]
"""
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import brdf_factor as bf

paint = bf.brdf("krylon-blue")              # Cornell measurement, interpolated
measured = bf.measured_samples(paint)       # the raw measured samples
grid = bf.sample_grid(paint, 12)            # a 12^4 grid of the interpolant
print(paint.to_string())
print("measured:", measured.summary(), "| grid:", grid.summary())

methods = {
    "mccool 16": lambda: bf.mccool(grid, texture_size=16),
    "search 2 terms": lambda: bf.search(grid, terms=2, texture_size=16, search_texture_size=8, restarts=2),
    "svd rank 2": lambda: bf.svd(paint, grid, terms=2, texture_size=16),
    "sh-k order 6": lambda: bf.sh_k(paint, grid, order=6, texture_size=16),
    "ward fit": lambda: bf.model_fit(grid, model="ward", starts=2),
}
results = {}
print("%-16s %10s %10s %10s %8s %7s" % ("method", "rel_mse", "lin_rmse", "cos_rmse", "floats", "s"))
for name, run in methods.items():
    f = run()
    # Scored on the raw measurements too (the fit used the 12^4 grid).
    m = f.score(measured)
    results[name] = f
    print("%-16s %10.4g %10.4g %10.4g %8d %7.2f" % (name, m["rel_mse"], m["lin_rmse"], m["cos_rmse"],
                                                   f.storage_floats, f.seconds))

# Incidence plane slice: light at 45 degrees, view swept from -89 to 89 degrees.
t = np.radians(np.linspace(-89, 89, 357))
wo = np.stack([np.sin(t), np.zeros_like(t), np.cos(t)], axis=1)
wi = np.array([-np.sin(np.radians(45)), 0.0, np.cos(np.radians(45))])
fig, ax = plt.subplots(figsize=(7, 4))
ax.semilogy(np.degrees(t), paint.eval(wi, wo)[:, 2], "k", lw=2, label="krylon-blue (blue channel)")
for name, f in results.items():
    ax.semilogy(np.degrees(t), np.maximum(f.eval(wi, wo)[:, 2], 1e-4), label=name)
ax.set_xlabel("view angle in the incidence plane (degrees), light at -45")
ax.set_ylabel("f (1/sr)")
ax.legend(fontsize=8)
fig.tight_layout()
out = sys.argv[1] if len(sys.argv) > 1 else "compare_methods.png"
fig.savefig(out, dpi=100)
print("wrote", out)
