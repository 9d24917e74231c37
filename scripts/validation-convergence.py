#!/usr/bin/env python3
"""How precise val_rel_mse is: the same fits scored on validation sets of
several seeds and sizes (experiments/validation-convergence.toml).

    python3 scripts/validation-convergence.py [--binary B] [--seeds N] [--out DIR]

Runs the config once per experiment seed (1..N, default 8) and per
validation_pairs ("auto", 4096, 100000, 1000000); the fits do not depend on
the experiment seed (the config fixes the search's seed), only the validation
pairs do. Prints, per method and design, val_rel_mse relative to the mean of
the 1,000,000-pair estimates: the mean, the standard deviation and the largest
deviation over the seeds, the pairs scored and the median seconds of the
validation (run.json validation.seconds).
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys

DESIGNS = ["auto", "4096", "100000", "1000000"]


def run(binary, config, out, seed, pairs):
    p = subprocess.run([binary, "run", config, "--no-plots", "--out", out, "-D", "experiment.seed=%d" % seed,
                        "-D", "experiment.validation_pairs=%s" % ('"auto"' if pairs == "auto" else pairs)],
                       capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit("brdf-factor run failed (exit %d):\n%s" % (p.returncode, p.stderr))
    rows = {}
    with open(os.path.join(out, "results.csv"), newline="") as f:
        for r in csv.DictReader(f):
            if r["status"] != "ok":
                sys.exit("run %s failed: %s" % (r["run_id"], r.get("notes", "")))
            with open(os.path.join(out, "runs", r["run_id"], "run.json")) as g:
                v = json.load(g)["validation"]
            rows[r["method"]] = (float(r["val_rel_mse"]), v.get("pairs"), v.get("seconds"))
    return rows


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", default=os.path.join(here, "..", "build", "experiments", "brdf-factor"))
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--out", default="results/validation-convergence")
    a = ap.parse_args()
    config = os.path.join(here, "..", "experiments", "validation-convergence.toml")
    got = {}  # (method, design) -> list of (val, pairs, seconds)
    for seed in range(1, a.seeds + 1):
        for d in DESIGNS:  # interleaved: every design at every seed
            for m, v in run(a.binary, config, os.path.join(a.out, "s%d-%s" % (seed, d)), seed, d).items():
                got.setdefault((m, d), []).append(v)
    print("| method | validation_pairs | pairs scored | val_rel_mse / 1M-pair mean: mean | sd | max dev | median s |")
    print("|---|---|---|---|---|---|---|")
    for m in sorted({k[0] for k in got}):
        ref = statistics.mean(v[0] for v in got[(m, "1000000")])
        for d in DESIGNS:
            xs = [v[0] / ref for v in got[(m, d)]]
            pairs = sorted({v[1] for v in got[(m, d)]})
            shown = "%d-%d" % (pairs[0], pairs[-1]) if len(pairs) > 1 else "%d" % pairs[0]
            print("| %s | %s | %s | %.3f | %.3f | %.3f | %.3f |" % (
                m, d, shown, statistics.mean(xs), statistics.stdev(xs) if len(xs) > 1 else 0.0,
                max(abs(x - 1) for x in xs), statistics.median(v[2] for v in got[(m, d)])))
        print("| %s | 1M-pair mean | | %.5g | | | |" % (m, ref))


if __name__ == "__main__":
    main()
