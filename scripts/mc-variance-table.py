#!/usr/bin/env python3
"""The Monte Carlo variance table of docs/results.md ("Scene-weighted fits and
Monte Carlo variance"): `brdf-factor mc-variance` on every factorization of a
run of experiments/sampling-variance.toml, against the sky environment, 64 spp,
32x32 pixels, with MIS, one view azimuth bin.

    brdf-factor run experiments/sampling-variance.toml --no-plots --out OUT
    python3 scripts/mc-variance-table.py OUT [--exe build/experiments/brdf-factor]

Prints one row per original model (the integrand "the model itself", taken
from the first run of that model) and per search (its factorization), in the
order of the config's BRDFs, then wiwo before halfdiff. Only the standard
library.
"""
import argparse
import csv
import os
import subprocess
import sys

# The config's BRDF names and the catalogue strings mc-variance reads them by.
BRDFS = [
    ("cook-torrance-m0.2", "cook-torrance:m=0.2", "CT m = 0.2"),
    ("cook-torrance-m0.2-glossy", "cook-torrance:m=0.2,kd=0.05,ks=0.95,f0=1", "glossy CT"),
]
SAMPLERS = ["cosine", "tabulated", "model", "cosine+light", "tabulated+light", "model+light"]


def mc_variance(exe, brdf, factors, env):
    cmd = [exe, "mc-variance", "--brdf", brdf, "--approx", factors, "--environment", env,
           "--spp", "64", "--size", "32", "--mis", "--view-phi-bins", "1"]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"mc-variance-table: `{' '.join(cmd)}` exited {done.returncode}: {done.stderr.strip()}")
    out = done.stdout
    rows = {}
    for line in out.splitlines():
        f = line.split()
        if len(f) == 6 and f[0] in ("original", "approx") and f[1] in SAMPLERS:
            rows[(f[0], f[1])] = (float(f[3]), float(f[4]))
    for who in ("original", "approx"):
        for s in SAMPLERS:
            if (who, s) not in rows:
                sys.exit(f"mc-variance-table: `{' '.join(cmd)}` printed no row for {who} {s}")
    return rows


def cells(rows, who):
    out = []
    for s in SAMPLERS:
        v, r = rows[(who, s)]
        out.append(f"{v:.3g}" if s in ("cosine", "cosine+light") else f"{v:.3g} ({r:.2f})")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", help="the --out of a run of experiments/sampling-variance.toml")
    ap.add_argument("--exe", default="build/experiments/brdf-factor")
    ap.add_argument("--environment", default="data/env/sky.exr")
    a = ap.parse_args()
    if not os.path.isfile(a.exe):
        sys.exit(f"mc-variance-table: expected the brdf-factor executable at {a.exe} (--exe), found no such file")
    path = os.path.join(a.out, "results.csv")
    if not os.path.isfile(path):
        sys.exit(f"mc-variance-table: expected {path}, found no such file")
    runs = list(csv.DictReader(open(path, newline="")))
    print("| integrand | rel_mse | cosine | tabulated (vs cos) | model (vs cos) | cosine+light | "
          "tabulated+light (vs cos) | model+light (vs cos) | run_id |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, brdf, label in BRDFS:
        mine = [r for r in runs if r["brdf"] == name]
        if sorted(r["parameterization"] for r in mine) != ["halfdiff", "wiwo"]:
            sys.exit(f"mc-variance-table: {path}: expected 2 runs of {name} (wiwo, halfdiff), found "
                     f"{[r['parameterization'] for r in mine]}")
        mine.sort(key=lambda r: ["wiwo", "halfdiff"].index(r["parameterization"]))
        for i, r in enumerate(mine):
            if r["status"] != "ok":
                sys.exit(f"mc-variance-table: {path}: run {r['run_id']} has status {r['status']}")
            rows = mc_variance(a.exe, brdf, os.path.join(a.out, "runs", r["run_id"], "factors.json"), a.environment)
            if i == 0:
                print(f"| {label}, the model itself | 0 | " + " | ".join(cells(rows, "original")) + " | |")
            rel = float(r["rel_mse"])
            recip = " (reciprocal answer)" if r["reciprocity"] == "true" else ""
            print(f"| its search, {r['parameterization']}{recip} | {rel:.3g} | " + " | ".join(cells(rows, "approx")) +
                  f" | {r['run_id']} |")


if __name__ == "__main__":
    main()
