#!/usr/bin/python3
"""Noise against samples per pixel of the Monte Carlo sphere: one line per
(integrand, sampler) of `brdf-factor mc-variance --noise-csv`.

Usage: experiments/report/plot_noise.py NOISE.csv OUT.png
x = samples per pixel, y = RMSE of the Monte Carlo image against the
deterministic render, both log scale, with a 1/sqrt(N) guide through the
first point of each line (an unbiased render follows it). The table of the
same points is printed. Labels come from the file and are drawn as plain text.
"""
import csv
import math
import sys

from plot_results import plain  # the same script folder: labels drawn as plain text


def read(path):
    lines = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            try:
                spp, rmse = int(row["spp"]), float(row["rmse"])
            except (KeyError, ValueError) as e:
                raise SystemExit(f"{path}: expected columns integrand,sampler,spp,rmse with numbers, found {row}: {e}")
            if spp <= 0 or not math.isfinite(rmse) or rmse < 0:
                raise SystemExit(f"{path}: expected spp > 0 and a finite rmse >= 0, found {row}")
            lines.setdefault((row["integrand"], row["sampler"]), []).append((spp, rmse))
    if not lines:
        raise SystemExit(f"{path}: no rows")
    return {k: sorted(v) for k, v in lines.items()}


def main(argv):
    if len(argv) != 3:
        raise SystemExit(__doc__)
    lines = read(argv[1])
    print("| integrand | sampler | spp | rmse |")
    print("|---|---|---|---|")
    for (integrand, sampler), pts in lines.items():
        for spp, rmse in pts:
            print(f"| {integrand} | {sampler} | {spp} | {rmse:.4g} |")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4.2))
    for (integrand, sampler), pts in lines.items():
        x = [p[0] for p in pts]
        y = [max(p[1], 1e-300) for p in pts]
        (h,) = ax.plot(x, y, marker="o", label=f"{integrand} / {sampler}")
        ax.plot(x, [y[0] * math.sqrt(x[0] / v) for v in x], ls=":", color=h.get_color(), lw=0.8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("samples per pixel")
    ax.set_ylabel("image RMSE vs deterministic render")
    ax.set_title("Monte Carlo noise (dotted: 1/sqrt(N))")
    for t in ax.legend(fontsize=8).get_texts():
        plain(t)
    fig.tight_layout()
    fig.savefig(argv[2], dpi=120)
    print(f"wrote {argv[2]}")


if __name__ == "__main__":
    main(sys.argv)
