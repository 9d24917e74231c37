#!/usr/bin/env python3
"""Issue #27's MERL criteria on many analytic models, not one: each model is
written as a MERL table by `export-merl`, the table is fitted on its cells
(`sampling.kind = "measured"`, default settings: measure weights, the orbit,
the fill, 10% held out, the "auto" whole-domain set) by McCool at texture 16
and, with --search, by the default 2-term search, and each fit is scored
against the analytic model on 20,000 pairs (`brdf-factor compare`), beside the
table's own score against the model (its binning floor):

    python3 scripts/merl-models.py [--bin build/experiments/brdf-factor]
                                   [--out results/merl-models] [--search]
                                   [--model NAME[:k=v,...] ...]

Prints the markdown table of docs/results.md §5a "MERL tables of analytic
models" and the two criteria: val_rel_mse <= 2x holdout_rel_mse, and the
error against the model <= 2x the table's own. A run already in OUT is reused
(the runner's cache)."""
import argparse
import csv
import json
import os
import subprocess
import sys

MODELS = [
    "cole-cook-torrance", "cook-torrance", "blinn-phong", "blinn-phong:n=200", "lafortune", "bluepaint",
    "clay", "ward", "ngan-ward/gold-paint", "ngan-ward/chrome-steel", "ngan-ward-duer/red-plastic",
    "ashikhmin-shirley", "ngan-ashikhmin-shirley/gray-plastic",
]


def table_name(model):
    return model.replace("/", "_").replace(":", "_").replace("=", "_") + ".binary"


def compare(binary, brdf, reference):
    out = subprocess.run([binary, "compare", "--brdf", brdf, "--reference", reference, "--pairs", "20000"],
                         check=True, capture_output=True, text=True).stdout
    return json.loads(out)["rel_mse"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--bin", default="build/experiments/brdf-factor")
    ap.add_argument("--out", default="results/merl-models")
    ap.add_argument("--search", action="store_true", help="also the default 2-term search (about 30 s a table)")
    ap.add_argument("--model", action="append", help="a catalogue name[:k=v,...] (repeat) instead of the 13 of results.md")
    a = ap.parse_args()
    models = a.model or MODELS
    binary = os.path.abspath(a.bin)
    out = os.path.abspath(a.out)
    tables = os.path.join(out, "tables")
    os.makedirs(tables, exist_ok=True)
    for m in models:
        path = os.path.join(tables, table_name(m))
        if not os.path.exists(path):
            subprocess.run([binary, "export-merl", "--brdf", m, "--out", path], check=True, capture_output=True)
    files = ", ".join('"%s"' % os.path.join(tables, table_name(m)) for m in models)
    methods = '[[method]]\nkind = "mccool"\ntexture_size = 16\n'
    if a.search:
        methods += '\n[[method]]\nkind = "search"\nterms = 2\n'
    config = os.path.join(out, "merl-models.toml")
    with open(config, "w") as f:
        f.write('[experiment]\nname = "merl-models"\nseed = 1\nplots = false\nrender = false\nexport = true\n'
                'description = "analytic models written by export-merl, fitted on their cells"\n\n'
                '[[brdf]]\nfile = [%s]\n\n[sampling]\nkind = "measured"\n\n%s' % (files, methods))
    # render = false: shade_rmse still comes from the default scene (shade is on by default).
    subprocess.run([binary, "run", config, "--out", out, "--no-plots"], check=True,
                   stdout=subprocess.DEVNULL)
    rows = list(csv.DictReader(open(os.path.join(out, "results.csv"))))
    by_file = {os.path.basename(r["brdf"]): [] for r in rows}
    for r in rows:
        by_file[os.path.basename(r["brdf"])].append(r)
    print("| model | table vs model | method | training | held-out | val (vs table) | val / held-out "
          "| vs model | vs model / table's | shade_rmse |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    ratios, floors, n = [], [], 0
    for m in models:
        t = os.path.join(tables, table_name(m))
        own = compare(binary, t, m)
        for r in sorted(by_file.get(table_name(m), []), key=lambda r: r["method"]):
            held, val = float(r["holdout_rel_mse"]), float(r["val_rel_mse"])
            fit = compare(binary, os.path.join(out, "runs", r["run_id"], "factors.json"), m)
            label = "mccool" if r["method"] == "mccool" else "search %s (%s)" % (
                r["terms"], " ".join(p[0] for p in r["term_parameterizations"].split("+")))
            ratios.append(val / held)
            floors.append(fit / own)
            n += 1
            print("| %s | %.3g | %s | %.4g | %.4g | %.4g | %.2f | %.4g | %.3f | %.3g |" % (
                m, own, label, float(r["rel_mse"]), held, val, val / held, fit, fit / own,
                float(r["shade_rmse"])))
    print()
    print("val <= 2x held-out: %d of %d (val / held-out %.2f-%.2f)" % (
        sum(x <= 2.0 for x in ratios), n, min(ratios), max(ratios)))
    print("vs model <= 2x the table's own: %d of %d (%.3f-%.3fx)" % (
        sum(x <= 2.0 for x in floors), n, min(floors), max(floors)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
