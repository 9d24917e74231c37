#!/usr/bin/env python3
"""Plots of an experiment's results.csv (brdf-factor run calls this after the runs).

Writes into --out (default: plots/ beside the CSV), one file per figure:
  error_vs_terms    error against the number of textures, one panel per BRDF;
                    runs with errors_after_term give a whole curve, others one
                    point at their `terms`
  error_vs_storage  error against storage_floats (floats a renderer holds), one
                    panel per BRDF, with that BRDF's Pareto front
  error_vs_seconds  error against run time, one panel per BRDF, Pareto front
  error_vs_<key>    error against each swept numeric option other than terms
                    (texture_size, order, ...), one panel per BRDF
  by_brdf_<metric>  one row of panels per BRDF: error against storage_floats
                    (left) and against seconds (right), Pareto fronts; for
                    --metric and for cos_rmse (the fair metric when SH methods,
                    which represent f cos, take part)
  noise_vs_spp      runs with `sampler = true`: Monte Carlo image RMSE against
                    samples per pixel, cosine and the run's own sampler (the
                    "noise" rows of "sampling" in runs/<run_id>/run.json)

What the figures promise:
  - one series = one method label with one requested parameterization
    (the swept value or the `parameterization` column, never the terms'
    `term_parameterizations`), reciprocity (the swept value when swept:
    a search asked without it whose answers were refit reciprocal is
    "recip answers", never merged with one asked with it),
    sampling and value of every non-numeric swept option; each series has its
    own colour AND marker (the pair is distinct for up to 60 series);
  - a line joins points only along one swept numeric option, the others held
    fixed (never merely because two runs share a label);
  - the Pareto front (no other run of that BRDF has both less x and less error)
    is a dashed black step line, computed per BRDF only;
  - log axes get labelled ticks at 1-2-5 steps (or decades) chosen so that
    there are 3 to 8 of them and they do not overlap;
  - text from the results (BRDF names, labels, swept values, the metric) is
    drawn as plain text: no mathtext, no TeX, whatever `$`, a backslash, `_`, `^`,
    `%` or `{` it holds, and a leading `_` does not hide a legend entry.

Plots are redrawn only when their inputs changed: a SHA-256 of the CSV, this
script and the arguments is kept in OUT/.plot-inputs.json with the files it
produced; when it matches and every file exists, nothing is drawn and the
files are reported again.

Prints "wrote PATH" per file on stdout; exits 0 with nothing written when no row
has the error column. Needs matplotlib (Debian: python3-matplotlib).

usage: plot_results.py results.csv [--out DIR] [--metric rel_mse] [--format png|svg|both] [--force]
"""
import argparse
import csv
import hashlib
import json
import math
import os
import sys
from collections import OrderedDict

STAMP = ".plot-inputs.json"
# True when every run used the same sampling: legends then leave it out.
SINGLE_SAMPLING = False


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


def sweep_of(r):
    """The run's swept options as an ordered dict key -> text value."""
    out = OrderedDict()
    for kv in (r.get("sweep") or "").split():
        if "=" in kv:
            k, v = kv.split("=", 1)
            out[k] = v
    return out


def label_of(r):
    return r.get("label") or r.get("method", "")


def series_name(r, axis_keys):
    """Legend name of a run's series: everything that tells it apart except the
    numeric swept options (axis_keys), which are positions along its lines."""
    parts = [label_of(r)]
    # What the run asked for: a swept value, else the column (which, for a
    # search, is the asked parameterization or "either"; the terms' own are in
    # term_parameterizations and never split a series).
    p = sweep_of(r).get("parameterization") or r.get("parameterization")
    if p and p not in parts[0]:
        parts.append(p)
    # Reciprocity as asked: a swept value splits series by the option, and the
    # column (the result's form) only tells apart a search asked without it
    # whose answers were refit with reciprocal terms (final_reciprocity). Not
    # swept, the column says whether the textures are read reciprocally.
    asked = sweep_of(r).get("reciprocity")
    if asked == "true" or (asked is None and r.get("reciprocity") == "true"):
        parts.append("recip")
    elif asked == "false" and r.get("reciprocity") in ("true", "mixed"):
        parts.append("recip answers")
    for k, v in sweep_of(r).items():
        if k in axis_keys or k in ("parameterization", "reciprocity"):
            continue
        parts.append("%s=%s" % (k, v))
    if r.get("sampling") and not SINGLE_SAMPLING:
        parts.append(r["sampling"])
    return " ".join(parts)


def numeric_sweep_keys(rows):
    """Swept options whose every value is a number (texture_size, terms, order, ...)."""
    keys = OrderedDict()
    for r in rows:
        for k, v in sweep_of(r).items():
            keys.setdefault(k, True)
            if number(v) is None:
                keys[k] = False
    return [k for k, ok in keys.items() if ok]


def plain(text):
    """Draws a matplotlib Text as the characters it holds: no mathtext (a `$`
    in a label would start it, and a lone one raises), no TeX."""
    text.set_usetex(False)
    if hasattr(text, "set_parse_math"):  # matplotlib >= 3.5
        text.set_parse_math(False)
    else:
        text.set_text(text.get_text().replace("$", r"\$"))
    return text


def legend_label(name):
    """A series name as a legend label: matplotlib leaves out labels that start
    with '_', so such a name gets a leading space."""
    return " " + name if name.startswith("_") else name


MARKERS = ["o", "s", "^", "D", "v", "P", "X", "<", ">", "*", "h", "p"]


class Styles:
    """Colour and marker per series name: colour i mod 10, marker i mod 12, so
    the pair is distinct for the first 60 series."""

    def __init__(self):
        self.names = []

    def __call__(self, name):
        if name not in self.names:
            self.names.append(name)
        i = self.names.index(name)
        return MARKERS[i % len(MARKERS)], "C%d" % (i % 10)


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


def compact(v):
    """Short tick text: 0.002, 0.5, 40, 1500, 2e4, 1.5e-5."""
    if v == 0:
        return "0"
    e = math.floor(math.log10(abs(v)) + 1e-9)
    if -3 <= e <= 3:
        return "%g" % float("%.3g" % v)
    m = float("%.2g" % (v / 10.0 ** e))
    if m >= 10:
        m, e = m / 10, e + 1
    return "1e%d" % e if m == 1 else "%ge%d" % (m, e)


# Tick sets tried in order: (mantissas per decade, every k-th decade).
TICK_SETS = [((1, 1.5, 2, 3, 5, 7), 1), ((1, 2, 5), 1), ((1, 3), 1), ((1,), 1), ((1,), 2),
             ((1,), 3), ((1,), 5), ((1,), 10)]


def log_ticks(lo, hi):
    """3..8 ticks inside [lo, hi] (0 < lo < hi): the densest of the 1-1.5-2-3-5-7,
    1-2-5, 1-3, decade, and every k-th decade sets that has at most 8; inside
    less than about a third of a decade, linear steps."""
    if not (lo > 0 and hi > lo):
        return []
    e0, e1 = math.floor(math.log10(lo)) - 1, math.ceil(math.log10(hi)) + 1
    best = []
    for mantissas, step in TICK_SETS:
        ticks = [m * 10.0 ** e for e in range(e0, e1 + 1) if e % step == 0 for m in mantissas]
        ticks = [t for t in ticks if lo * (1 - 1e-9) <= t <= hi * (1 + 1e-9)]
        if len(ticks) <= 8:
            best = ticks
            break
    if len(best) >= 3:
        return best
    span = hi - lo
    unit = 10 ** math.floor(math.log10(span / 3))
    for mult in (1, 2, 2.5, 5, 10):
        s = unit * mult
        t = [k * s for k in range(math.ceil(lo / s - 1e-9), math.floor(hi / s + 1e-9) + 1)]
        t = [x for x in t if x > 0]
        if 3 <= len(t) <= 7:
            return t
    return best


def finish_log_axis(ax, which):
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullFormatter
    lim = ax.get_xlim() if which == "x" else ax.get_ylim()
    ticks = log_ticks(min(lim), max(lim))
    axis = ax.xaxis if which == "x" else ax.yaxis
    if ticks:
        axis.set_major_locator(FixedLocator(ticks))
        axis.set_major_formatter(FuncFormatter(lambda v, _p: compact(v)))
        axis.set_minor_formatter(NullFormatter())


def draw_series(ax, rows, xcol, ycol, styles, axis_keys, legend):
    """Points of each series; lines along each numeric swept option (others
    fixed), in the order of that option's value."""
    groups = OrderedDict()
    for r in rows:
        x, y = number(r.get(xcol)), number(r.get(ycol))
        if x is None or y is None or x <= 0 or y <= 0:
            continue
        groups.setdefault(series_name(r, axis_keys), []).append((x, y, r))
    for name, pts in groups.items():
        marker, colour = styles(name)
        ax.plot([p[0] for p in pts], [p[1] for p in pts], linestyle="none", marker=marker,
                color=colour, markersize=5, label=legend_label(name) if name not in legend else None)
        legend.add(name)
        for key in axis_keys:
            lines = OrderedDict()
            for x, y, r in pts:
                sw = sweep_of(r)
                if key not in sw:
                    continue
                rest = tuple((k, v) for k, v in sw.items() if k != key)
                lines.setdefault(rest, []).append((number(sw[key]), x, y))
            for line in lines.values():
                if len(line) < 2 or len(set(p[0] for p in line)) < 2:
                    continue
                line.sort()
                ax.plot([p[1] for p in line], [p[2] for p in line], color=colour, linewidth=0.8,
                        alpha=0.8)
    return [(x, y) for pts in groups.values() for x, y, _ in pts]


def draw_pareto(ax, pts, legend):
    front = pareto(pts)
    if len(front) > 1:
        xs = [p[0] for p in front]
        ys = [p[1] for p in front]
        ax.step(xs, ys, where="post", color="k", linestyle="--", linewidth=1, alpha=0.7,
                label="Pareto front" if "Pareto front" not in legend else None)
        legend.add("Pareto front")


def figure_legend(fig, axes_list, nrows_height):
    handles, names = [], []
    for ax in axes_list:
        for h, n in zip(*ax.get_legend_handles_labels()):
            if n not in names:
                handles.append(h)
                names.append(n)
    if names:
        ncol = min(3, len(names))
        leg = fig.legend(handles, names, loc="upper center", ncol=ncol, fontsize=8, frameon=False,
                         bbox_to_anchor=(0.5, 0.0))
        for t in leg.get_texts():
            plain(t)


def panels(plt, n, width=5.0, height=3.7, cols=3):
    cols = min(cols, n)
    nrows = (n + cols - 1) // cols
    fig, axes = plt.subplots(nrows, cols, figsize=(width * cols, height * nrows), squeeze=False)
    flat = [axes[i // cols][i % cols] for i in range(nrows * cols)]
    for ax in flat[n:]:
        ax.axis("off")
    return fig, flat[:n]


def plot_against(plt, rows, metric, xcol, xlabel, stem, title, out_dir, formats, axis_keys,
                 with_pareto, log_x=True):
    brdfs = list(OrderedDict.fromkeys(r["brdf"] for r in rows))
    usable = [r for r in rows if number(r.get(xcol)) is not None and number(r.get(xcol)) > 0
              and number(r.get(metric)) is not None and number(r.get(metric)) > 0]
    if not usable:
        return []
    fig, axes = panels(plt, len(brdfs))
    styles, legend = Styles(), set()
    for ax, brdf in zip(axes, brdfs):
        sub = [r for r in usable if r["brdf"] == brdf]
        pts = draw_series(ax, sub, xcol, metric, styles, axis_keys, legend)
        if with_pareto:
            draw_pareto(ax, pts, legend)
        if log_x:
            ax.set_xscale("log")
        ax.set_yscale("log")
        plain(ax.set_xlabel(xlabel))
        plain(ax.set_ylabel(metric))
        plain(ax.set_title(brdf, fontsize=10))
        ax.grid(True, which="major", alpha=0.3)
        ax.autoscale_view()
        if log_x:
            finish_log_axis(ax, "x")
        else:
            from matplotlib.ticker import MaxNLocator
            ax.xaxis.set_major_locator(MaxNLocator(integer=True, nbins=8))
        finish_log_axis(ax, "y")
    plain(fig.suptitle(title))
    fig.tight_layout()
    figure_legend(fig, axes, len(axes))
    out = save(fig, out_dir, stem, formats)
    plt.close(fig)
    return out


def plot_by_brdf(plt, all_rows, metric, out_dir, formats, axis_keys):
    rows = [r for r in all_rows if number(r.get(metric)) is not None and number(r[metric]) > 0]
    if not rows:
        return []
    brdfs = list(OrderedDict.fromkeys(r["brdf"] for r in rows))
    columns = (("storage_floats", "storage (floats)"), ("seconds", "seconds (method wall time)"))
    fig, axes = plt.subplots(len(brdfs), 2, figsize=(11.5, 3.8 * len(brdfs)), squeeze=False)
    styles, legend = Styles(), set()
    flat = []
    for i, brdf in enumerate(brdfs):
        for j, (column, xlabel) in enumerate(columns):
            ax = axes[i][j]
            flat.append(ax)
            sub = [r for r in rows if r["brdf"] == brdf and number(r.get(column)) is not None
                   and number(r.get(column)) > 0]
            pts = draw_series(ax, sub, column, metric, styles, axis_keys, legend)
            draw_pareto(ax, pts, legend)
            ax.set_xscale("log")
            ax.set_yscale("log")
            plain(ax.set_xlabel(xlabel))
            plain(ax.set_ylabel(metric))
            plain(ax.set_title(brdf, fontsize=10))
            ax.grid(True, which="major", alpha=0.3)
            ax.autoscale_view()
            finish_log_axis(ax, "x")
            finish_log_axis(ax, "y")
    plain(fig.suptitle(metric + " against storage and time, per BRDF (log axes; lines only along a sweep)"))
    fig.tight_layout()
    figure_legend(fig, flat, len(brdfs))
    out = save(fig, out_dir, "by_brdf_" + metric, formats)
    plt.close(fig)
    return out


def plot_terms(plt, rows, metric, out_dir, formats, axis_keys):
    brdfs = list(OrderedDict.fromkeys(r["brdf"] for r in rows))
    fig, axes = panels(plt, len(brdfs))
    styles, legend = Styles(), set()
    any_curve = False
    keys = [k for k in axis_keys if k != "terms"]
    for ax, brdf in zip(axes, brdfs):
        series = OrderedDict()
        for r in rows:
            if r["brdf"] != brdf:
                continue
            # One curve per run of the other swept options: terms is the axis.
            name = series_name(r, ["terms"])
            pts = series.setdefault(name, {})
            curve = [number(x) for x in r.get("errors_after_term", "").split(";") if x]
            if metric == "rel_mse" and curve and all(v is not None for v in curve):
                for k, v in enumerate(curve, start=1):
                    pts[k] = min(pts.get(k, v), v)
            terms = number(r.get("terms"))
            v = number(r.get(metric))
            if terms is not None and v is not None:
                pts[int(terms)] = min(pts.get(int(terms), v), v)
        for name, pts in series.items():
            pts = {k: v for k, v in pts.items() if v > 0}
            if not pts:
                continue
            xs = sorted(pts)
            marker, colour = styles(name)
            ax.plot(xs, [pts[x] for x in xs], marker=marker, color=colour, markersize=5,
                    linewidth=0.8, label=legend_label(name) if name not in legend else None)
            legend.add(name)
            any_curve = True
        plain(ax.set_title(brdf, fontsize=10))
        ax.set_xlabel("textures (terms)")
        from matplotlib.ticker import MaxNLocator
        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        plain(ax.set_ylabel(metric))
        ax.set_yscale("log")
        ax.grid(True, alpha=0.3)
        ax.autoscale_view()
        finish_log_axis(ax, "y")
    del keys
    out = []
    if any_curve:
        plain(fig.suptitle(metric + " against number of textures (a curve per run: error after each term)"))
        fig.tight_layout()
        figure_legend(fig, axes, len(axes))
        out = save(fig, out_dir, "error_vs_terms", formats)
    plt.close(fig)
    return out


def input_hash(csv_path, args):
    h = hashlib.sha256()
    with open(csv_path, "rb") as f:
        h.update(f.read())
    with open(os.path.abspath(__file__), "rb") as f:
        h.update(f.read())
    h.update(json.dumps(args, sort_keys=True).encode())
    return h.hexdigest()


def noise_lines(csv_path, rows):
    """(legend, [(spp, rmse)]) per run and sampler from the "noise" rows of the
    sampler entry in runs/<run_id>/run.json beside the CSV (`sampler = true`)."""
    base = os.path.dirname(os.path.abspath(csv_path))
    lines = OrderedDict()
    for r in rows:
        path = os.path.join(base, "runs", r.get("run_id", ""), "run.json")
        try:
            with open(path) as f:
                noise = json.load(f).get("sampler", {}).get("noise", [])
        except (OSError, ValueError, AttributeError):
            continue
        for n in noise if isinstance(noise, list) else []:
            try:
                spp, rmse = int(n["spp"]), float(n["rmse"])
            except (KeyError, TypeError, ValueError):
                continue
            if spp > 0 and math.isfinite(rmse) and rmse > 0:
                key = "%s %s / %s" % (r.get("brdf", ""), label_of(r), n.get("sampler", ""))
                lines.setdefault(key, []).append((spp, rmse))
    return [(k, sorted(v)) for k, v in lines.items()]


def plot_noise(plt, lines, out_dir, formats):
    """Monte Carlo noise against samples per pixel, one line per run and
    sampler, with a dotted 1/sqrt(N) guide through each line's first point."""
    if not lines:
        return []
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for name, pts in lines:
        x, y = [p[0] for p in pts], [p[1] for p in pts]
        (h,) = ax.plot(x, y, marker="o", label=name)
        ax.plot(x, [y[0] * math.sqrt(x[0] / v) for v in x], ls=":", color=h.get_color(), lw=0.8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("samples per pixel")
    ax.set_ylabel("image RMSE vs deterministic render")
    ax.set_title("Monte Carlo noise of the sampled runs (dotted: 1/sqrt(N))")
    for t in ax.legend(fontsize=7).get_texts():
        plain(t)
    written = save(fig, out_dir, "noise_vs_spp", formats)
    plt.close(fig)
    return written


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv")
    ap.add_argument("--out", default=None)
    ap.add_argument("--metric", default="rel_mse")
    ap.add_argument("--format", default="png", choices=["png", "svg", "both"])
    ap.add_argument("--force", action="store_true", help="redraw even when the inputs did not change")
    a = ap.parse_args()
    out_dir = a.out or os.path.join(os.path.dirname(os.path.abspath(a.csv)), "plots")
    formats = ["png", "svg"] if a.format == "both" else [a.format]

    digest = input_hash(a.csv, {"metric": a.metric, "format": a.format})
    stamp = os.path.join(out_dir, STAMP)
    if not a.force and os.path.exists(stamp):
        try:
            with open(stamp) as f:
                old = json.load(f)
            files = [os.path.join(out_dir, n) for n in old.get("files", [])]
            if old.get("sha256") == digest and all(os.path.exists(p) for p in files):
                print("plots unchanged (inputs hash %s): not redrawn" % digest[:12])
                for p in files:
                    print("wrote " + p)
                return 0
        except (OSError, ValueError):
            pass

    all_rows = load(a.csv)
    rows = [r for r in all_rows if number(r.get(a.metric)) is not None]
    if not rows:
        return 0

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    os.makedirs(out_dir, exist_ok=True)
    written = []
    axis_keys = numeric_sweep_keys(all_rows)
    global SINGLE_SAMPLING
    SINGLE_SAMPLING = len(set(r.get("sampling", "") for r in all_rows)) <= 1

    written += plot_terms(plt, rows, a.metric, out_dir, formats, axis_keys)
    written += plot_against(plt, rows, a.metric, "storage_floats", "storage (floats)", "error_vs_storage",
                            a.metric + " against storage_floats per BRDF, Pareto front dashed",
                            out_dir, formats, axis_keys, True)
    written += plot_against(plt, rows, a.metric, "seconds", "seconds (method wall time)", "error_vs_seconds",
                            a.metric + " against seconds per BRDF, Pareto front dashed",
                            out_dir, formats, axis_keys, True)
    for key in axis_keys:
        if key == "terms":
            continue
        sub = [dict(r, **{"_x": sweep_of(r).get(key)}) for r in rows if key in sweep_of(r)]
        written += plot_against(plt, sub, a.metric, "_x", key, "error_vs_" + key,
                                a.metric + " against the swept " + key, out_dir, formats,
                                [key], False, log_x=False)
    for metric in OrderedDict.fromkeys([a.metric, "cos_rmse"]):
        written += plot_by_brdf(plt, all_rows, metric, out_dir, formats, axis_keys)
    written += plot_noise(plt, noise_lines(a.csv, all_rows), out_dir, formats)

    tmp = stamp + ".tmp"
    with open(tmp, "w") as f:
        json.dump({"sha256": digest, "csv": os.path.abspath(a.csv),
                   "files": [os.path.basename(p) for p in written]}, f, indent=1)
    os.replace(tmp, stamp)
    for w in written:
        print("wrote " + w)
    return 0


if __name__ == "__main__":
    sys.exit(main())
