#!/usr/bin/env python3
"""Per-channel errors of an experiment's runs (run.json validation.channel_rel_mse).

    python3 scripts/channel-errors.py results/<experiment>

Prints a markdown table: brdf, method, the run's rel_mse, then val_rel_mse and
holdout_rel_mse overall and per channel (R / G / B).
"""
import csv
import json
import os
import sys


def fmt(x):
    return "" if x is None or x == "" else "%.3g" % float(x)


def main(folder):
    with open(os.path.join(folder, "results.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    print("| brdf | method | rel_mse | val_rel_mse | val R / G / B | holdout_rel_mse | holdout R / G / B |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        if r.get("status") != "ok":
            continue
        with open(os.path.join(folder, "runs", r["run_id"], "run.json")) as f:
            ch = json.load(f).get("validation", {}).get("channel_rel_mse", {})
        per = lambda k: " / ".join(fmt(v) for v in ch[k]) if k in ch else ""
        print("| %s | %s %s | %s | %s | %s | %s | %s |" % (
            r["brdf"], r["label"], r.get("sweep", ""), fmt(r["rel_mse"]), fmt(r["val_rel_mse"]), per("val"),
            fmt(r["holdout_rel_mse"]), per("holdout")))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
