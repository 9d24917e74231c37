#!/usr/bin/env python3
"""Plots of an experiment's results.csv (brdf-factor run calls this after the runs).

Writes into --out (default: plots/ beside the CSV), one file per figure:
  error_vs_terms    error against the number of textures, one panel per BRDF, one
                    line per method label / parameterization / reciprocity (like
                    Figure 4.2 of Cole's thesis); runs with errors_after_term give
                    a whole curve, others one point at their `terms`
  error_vs_seconds  error against run time, all runs, with the Pareto front
  error_vs_storage  error against storage_floats (floats a renderer holds)
  by_brdf_<metric>  one row of panels per BRDF: error against storage_floats
                    (left) and against seconds (right), one marker and colour per
                    method label, log axes; for --metric and for cos_rmse (the
                    fair metric when SH methods, which represent f cos, take part)
Prints "wrote PATH" per file on stdout; exits 0 with nothing written when no row
has the error column. Needs matplotlib (Debian: python3-matplotlib).

usage: plot_results.py results.csv [--out DIR] [--metric rel_mse] [--format png|svg|both]
"""
import argparse
import csv
import math
import os
import sys
from collections import OrderedDict


def number(cell):
    try:
        v = float(cell)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def load(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return [r for r in rows if r.get("status", "ok") in ("", "ok")]


def series_key(r):
    label = r.get("label") or r.get("method", "")
    parts = [label]
    # The sweep values of the run, except the x axis (terms).
    parts += [kv for kv in (r.get("sweep") or "").split() if not kv.startswith("terms=")]
    if r.get("parameterization"):
        parts.append(r["parameterization"])
    if r.get("reciprocity") == "true":
        parts.append("recip")
    if r.get("sampling"):
        parts.append(r["sampling"])
    return " ".join(parts)


def save(fig, out_dir, stem, formats):
    written = []
    for ext in formats:
        final = os.path.join(out_dir, stem + "." + ext)
        tmp = os.path.join(out_dir, "." + stem + ".tmp." + ext)
        fig.savefig(tmp, dpi=110, bbox_inches="tight")
        os.replace(tmp, final)
        written.append(final)
    return written


def pareto(points):
    """Lower-left front of (x, y) points: sorted by x, keeping strictly decreasing y."""
    front, best = [], float("inf")
    for x, y in sorted(points):
        if y < best:
            front.append((x, y))
            best = y
    return front


MARKERS = ["o", "s", "^", "D", "v", "P", "X", "<", ">", "*", "h", "p"]


def plot_by_brdf(plt, all_rows, metric, out_dir, formats):
    rows = [r for r in all_rows if number(r.get(metric)) is not None and number(r[metric]) > 0]
    if not rows:
        return []
    brdfs = list(OrderedDict.fromkeys(r["brdf"] for r in rows))
    labels = list(OrderedDict.fromkeys(r.get("label") or r["method"] for r in rows))
    style = {lab: (MARKERS[i % len(MARKERS)], "C%d" % (i % 10)) for i, lab in enumerate(labels)}
    columns = (("storage_floats", "storage (floats)"), ("seconds", "seconds (method wall time)"))
    fig, axes = plt.subplots(len(brdfs), 2, figsize=(11.5, 3.6 * len(brdfs)), squeeze=False)
    for i, brdf in enumerate(brdfs):
        for j, (column, xlabel) in enumerate(columns):
            ax = axes[i][j]
            for lab in labels:
                pts = sorted((number(r.get(column)), number(r[metric])) for r in rows
                             if r["brdf"] == brdf and (r.get("label") or r["method"]) == lab
                             and number(r.get(column)) is not None and number(r.get(column)) > 0)
                if not pts:
                    continue
                marker, colour = style[lab]
                # Storage grows with the size knob, so a line there follows one
                # method's sizes; times are noisy, so that panel has markers only.
                ax.plot([p[0] for p in pts], [p[1] for p in pts], marker=marker, color=colour,
                        linestyle="-" if column == "storage_floats" else "none", linewidth=0.8,
                        markersize=5, label=lab)
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel(xlabel)
            ax.set_ylabel(metric)
            ax.set_title(brdf, fontsize=10)
            ax.grid(True, which="both", alpha=0.25)
    handles, names = [], []
    for row in axes:
        for ax in row:
            for h, n in zip(*ax.get_legend_handles_labels()):
                if n not in names:
                    handles.append(h)
                    names.append(n)
    fig.tight_layout()
    legend_rows = (len(names) + 3) // 4
    fig.subplots_adjust(top=1.0 - (0.45 + 0.22 * legend_rows) / (3.6 * len(brdfs)))
    fig.legend(handles, names, loc="upper center", ncol=min(4, max(1, len(names))), fontsize=8,
               bbox_to_anchor=(0.5, 1.0 - 0.25 / (3.6 * len(brdfs))), frameon=False)
    fig.suptitle(metric + " against storage and time, per BRDF (log axes)", y=1.0)
    out = save(fig, out_dir, "by_brdf_" + metric, formats)
    plt.close(fig)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv")
    ap.add_argument("--out", default=None)
    ap.add_argument("--metric", default="rel_mse")
    ap.add_argument("--format", default="png", choices=["png", "svg", "both"])
    a = ap.parse_args()
    out_dir = a.out or os.path.join(os.path.dirname(os.path.abspath(a.csv)), "plots")
    formats = ["png", "svg"] if a.format == "both" else [a.format]

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import MaxNLocator

    all_rows = load(a.csv)
    rows = [r for r in all_rows if number(r.get(a.metric)) is not None]
    if not rows:
        return 0
    os.makedirs(out_dir, exist_ok=True)
    written = []
    log_y = all(number(r[a.metric]) > 0 for r in rows)

    # 1. error against number of textures, per BRDF.
    brdfs = list(OrderedDict.fromkeys(r["brdf"] for r in rows))
    n = len(brdfs)
    cols = min(3, n)
    nrows = (n + cols - 1) // cols
    fig, axes = plt.subplots(nrows, cols, figsize=(5.2 * cols, 3.8 * nrows), squeeze=False)
    any_curve = False
    for i, brdf in enumerate(brdfs):
        ax = axes[i // cols][i % cols]
        series = OrderedDict()
        for r in rows:
            if r["brdf"] != brdf:
                continue
            key = series_key(r)
            pts = series.setdefault(key, {})
            curve = [number(x) for x in r.get("errors_after_term", "").split(";") if x]
            if a.metric == "rel_mse" and curve and all(v is not None for v in curve):
                for k, v in enumerate(curve, start=1):
                    pts.setdefault(k, v)
                    pts[k] = min(pts[k], v)
            terms = number(r.get("terms"))
            if terms is not None:
                v = number(r[a.metric])
                pts[int(terms)] = min(pts.get(int(terms), v), v)
        for key, pts in series.items():
            if not pts:
                continue
            xs = sorted(pts)
            ax.plot(xs, [pts[x] for x in xs], marker="o", label=key)
            any_curve = True
        ax.set_title(brdf, fontsize=10)
        ax.set_xlabel("textures (terms)")
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        ax.set_ylabel(a.metric)
        if log_y:
            ax.set_yscale("log")
        ax.grid(True, alpha=0.3)
        if series:
            # Below the panel, so no curve is hidden (savefig's tight box keeps it).
            ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.2), frameon=False)
    for j in range(n, nrows * cols):
        axes[j // cols][j % cols].axis("off")
    if any_curve:
        fig.suptitle(a.metric + " against number of textures")
        written += save(fig, out_dir, "error_vs_terms", formats)
    plt.close(fig)

    # 2. and 3. error against time and storage, all runs.
    for column, stem, xlabel in (("seconds", "error_vs_seconds", "seconds (method wall time)"),
                                 ("storage_floats", "error_vs_storage", "storage (floats)")):
        pts = [(number(r.get(column)), number(r[a.metric]), r) for r in rows]
        pts = [p for p in pts if p[0] is not None and p[0] > 0]
        if not pts:
            continue
        fig, ax = plt.subplots(figsize=(6.5, 4.5))
        groups = OrderedDict()
        for x, y, r in pts:
            sweep = (r.get("sweep") or "").split()
            key = (r.get("label") or r["method"]) + (" " + sweep[0] if sweep else "") + " / " + r["brdf"]
            groups.setdefault(key, []).append((x, y))
        for key, g in groups.items():
            ax.scatter([p[0] for p in g], [p[1] for p in g], label=key, s=22)
        front = pareto([(x, y) for x, y, _ in pts])
        if len(front) > 1:
            ax.step([p[0] for p in front], [p[1] for p in front], where="post", color="k", alpha=0.5,
                    linewidth=1, label="Pareto front")
        ax.set_xscale("log")
        if log_y:
            ax.set_yscale("log")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(a.metric)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), frameon=False,
                  ncol=2 if len(groups) > 8 else 1)
        ax.set_title(a.metric + " against " + column)
        written += save(fig, out_dir, stem, formats)
        plt.close(fig)

    # 4. per BRDF: error against storage and against time, one marker per method.
    for metric in OrderedDict.fromkeys([a.metric, "cos_rmse"]):
        written += plot_by_brdf(plt, all_rows, metric, out_dir, formats)

    for w in written:
        print("wrote " + w)
    return 0


if __name__ == "__main__":
    sys.exit(main())
