#!/usr/bin/env python3
"""The Cornell table of docs/results.md §5a and the README, from two runs of
experiments/cornell-validation.toml: on the raw samples (the default) and on
the interpolant's 12^4 grid. Prints the markdown table and the issue #27
criteria counted over McCool and the default 2- and 3-term search (each term's
parameterization chosen; `parameterization` "either" in results.csv), over
McCool and the 2- and 3-term search held to wiwo (the count before the default
search had its own rows), and over all rows:

    brdf-factor run experiments/cornell-validation.toml --no-plots --out RAW
    brdf-factor run experiments/cornell-validation.toml --no-plots --out GRID \\
        -D sampling.kind=grid -D sampling.resolution=12
    python3 scripts/cornell-table.py RAW GRID [--readme]

    brdf-factor run experiments/cornell-baselines.toml --no-plots --out BASE
    python3 scripts/cornell-table.py RAW GRID --baselines BASE

--readme prints the README's shorter table (McCool and the default 3-term
search). The "before" columns come from docs/notebook/data/cornell-before.csv
(the held-out error when issue #27 was filed, the whole-domain error before
the fill); the default search has no row there, so its held-out bar is the
lower of the wiwo and halfdiff searches' "before" values (the stricter). --baselines prints the baselines of experiments/cornell-baselines.toml
beside McCool's raw fit instead."""
import argparse
import csv
import os
import sys

PAINTS = ["krylon-blue", "garnet-red", "cayman", "acryl-blue", "mystique"]


def fmt(x):
    return f"{x:.3g}"


def key(r):
    return (r["brdf"], r["method"], r["parameterization"], r["terms"])


def run_rows(folder):
    """The rows of folder/results.csv; exits naming the file when a run failed."""
    path = os.path.join(folder, "results.csv")
    with open(path, newline="") as f:
        rows = [r for r in csv.DictReader(f)]
    bad = [r["run_id"] for r in rows if r["status"] != "ok"]
    if bad:
        sys.exit(f"{path}: runs not ok: {', '.join(bad)}")
    return rows


def rows_of(folder):
    return {key(r): r for r in run_rows(folder)}


def before_rows():
    path = os.path.join(os.path.dirname(__file__), "..", "docs", "notebook", "data", "cornell-before.csv")
    with open(path, newline="") as f:
        lines = [l for l in f if not l.startswith("#")]
    return {key(r): r for r in csv.DictReader(lines)}


def label(k):
    if k[1] == "mccool":
        return "McCool"
    return "search (default)" if k[2] == "either" else f"search ({k[2]})"


def row_label(k, r):
    """label(k), with the default search's mix (w: wiwo, h: halfdiff term)."""
    if k[1] == "search" and k[2] == "either":
        mix = " ".join(p[0] for p in r["term_parameterizations"].split("+"))
        return f"search (default: {mix})"
    return label(k)


def order(k):
    return (PAINTS.index(k[0]), k[1] != "mccool", ["either", "wiwo", "halfdiff"].index(k[2])
            if k[1] != "mccool" else 0, int(k[3]))


def holdout_before(before, k):
    """The held-out error at the issue's filing: the row's own, or for the
    default search (no row then) the lower of the wiwo and halfdiff searches'."""
    if k in before:
        return float(before[k]["holdout_before"])
    if k[1] == "search" and k[2] == "either":
        vals = [float(before[b]["holdout_before"]) for b in ((k[0], k[1], p, k[3]) for p in ("wiwo", "halfdiff"))
                if b in before]
        return min(vals) if vals else None
    return None


def print_baselines(raw, folder):
    """Per paint: McCool's raw fit, then each baseline (storage, held-out,
    whole-domain and image errors)."""
    base = run_rows(folder)
    print("| paint | method | storage_floats | holdout_rel_mse | val_rel_mse | shade_rmse | shade_rmse / McCool's |")
    print("|---|---|---|---|---|---|---|")
    for paint in PAINTS:
        mc = [r for k, r in raw.items() if k[0] == paint and k[1] == "mccool"]
        if len(mc) != 1:
            sys.exit(f"{paint}: expected one McCool run on the raw samples, found {len(mc)}")
        rows = mc + [r for r in base if r["brdf"] == paint]
        ref = float(mc[0]["shade_rmse"])
        for r in rows:
            name = "McCool" if r is mc[0] else r["label"]
            print(f"| {paint} | {name} | {r['storage_floats']} | {fmt(float(r['holdout_rel_mse']))} | "
                  f"{fmt(float(r['val_rel_mse']))} | {fmt(float(r['shade_rmse']))} | "
                  f"{float(r['shade_rmse']) / ref:.2f} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("raw")
    ap.add_argument("grid")
    ap.add_argument("--readme", action="store_true")
    ap.add_argument("--baselines", metavar="DIR")
    a = ap.parse_args()
    raw, grid, before = rows_of(a.raw), rows_of(a.grid), before_rows()
    if a.baselines:
        print_baselines(raw, a.baselines)
        return
    keys = sorted(raw, key=order)
    for k in keys:
        if k not in grid:
            sys.exit(f"{a.grid}: no run for {k}")
    groups = {
        "McCool and the default 2- and 3-term search":
            [k for k in keys if k[1] == "mccool" or (k[2] == "either" and k[3] in ("2", "3"))],
        "McCool and the 2- and 3-term search held to wiwo":
            [k for k in keys if k[1] == "mccool" or (k[2] == "wiwo" and k[3] in ("2", "3"))],
    }

    def num(r, c):
        return float(r[c])

    checks = {
        "val_rel_mse <= 2 x holdout_rel_mse": lambda k: num(raw[k], "val_rel_mse") <= 2 * num(raw[k], "holdout_rel_mse"),
        "shade_rmse <= the grid fit's": lambda k: num(raw[k], "shade_rmse") <= num(grid[k], "shade_rmse"),
        "holdout_rel_mse <= 1.5 x before": lambda k: (hb := holdout_before(before, k)) is not None
        and num(raw[k], "holdout_rel_mse") <= 1.5 * hb,
    }
    if a.readme:
        print("| paint | method | holdout_rel_mse | val_rel_mse | shade_rmse | grid: val_rel_mse | grid: shade_rmse |")
        print("|---|---|---|---|---|---|---|")
        for k in keys:
            if not (k[1] == "mccool" or (k[2] == "either" and k[3] == "3")):
                continue
            r, g = raw[k], grid[k]
            what = "McCool, 2 textures" if k[1] == "mccool" else f"{row_label(k, r)}, {k[3]} textures"
            print(f"| {k[0]} | {what} | {fmt(num(r, 'holdout_rel_mse'))} | {fmt(num(r, 'val_rel_mse'))} | "
                  f"{fmt(num(r, 'shade_rmse'))} | {fmt(num(g, 'val_rel_mse'))} | {fmt(num(g, 'shade_rmse'))} |")
    else:
        print("| paint | method | terms | rel_mse | holdout_rel_mse (before) | val_rel_mse (no fill) | "
              "val / held-out | shade_rmse | grid: val_rel_mse | grid: shade_rmse | seconds |")
        print("|---|---|---|---|---|---|---|---|---|---|---|")
        for k in keys:
            r, g, b = raw[k], grid[k], before.get(k)
            ho, val = num(r, "holdout_rel_mse"), num(r, "val_rel_mse")
            hb0 = holdout_before(before, k)
            hb = f" ({fmt(hb0)})" if hb0 is not None else ""
            vb = f" ({b['val_no_fill']})" if b else ""
            print(f"| {k[0]} | {row_label(k, r)} | {k[3]} | {fmt(num(r, 'rel_mse'))} | {fmt(ho)}{hb} | {fmt(val)}{vb} | "
                  f"{val / ho:.2f} | {fmt(num(r, 'shade_rmse'))} | {fmt(num(g, 'val_rel_mse'))} | "
                  f"{fmt(num(g, 'shade_rmse'))} | {float(r['seconds']):.0f} |")
    for group, core in groups.items():
        print()
        print(f"{group}:")
        for name, ok in checks.items():
            miss = [f"{k[0]} {label(k)} {k[3]}" for k in core if not ok(k)]
            n_all = sum(1 for k in keys if ok(k))
            print(f"- {name}: {len(core) - len(miss)} of {len(core)} ({n_all} of {len(keys)} rows)"
                  + (f"; misses: {', '.join(miss)}" if miss else ""))


if __name__ == "__main__":
    main()
