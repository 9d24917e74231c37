#!/usr/bin/env python3
"""The "one default search" criterion (docs/search.md, "Config default"):
per BRDF, the mean over seeds of the greedy and of the structured search's
rel_mse after each term (results.csv `errors_after_term`, runs labelled
"greedy" and "structured"), their ratio (bold where the structured mean is
higher) and the method seconds summed over the seeds.

    python3 scripts/search-criterion.py OUT   # OUT: the --out of experiments/search-criterion-measured.toml or -grid.toml

Only the standard library.
"""
import collections
import csv
import os
import statistics
import sys


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: search-criterion.py OUT (a run folder holding results.csv)")
    path = os.path.join(sys.argv[1], "results.csv")
    if not os.path.isfile(path):
        sys.exit(f"search-criterion: expected {path}, found no such file")
    by = collections.defaultdict(list)
    for r in csv.DictReader(open(path, newline="")):
        if r["status"] != "ok":
            sys.exit(f"search-criterion: {path}: run {r['run_id']} ({r['brdf']}, {r['label']}) has status {r['status']}")
        e = [float(x) for x in r["errors_after_term"].split(";")]
        by[(r["brdf"], r["label"])].append((e, float(r["seconds"])))
    worse, pairs = 0, 0
    print("| BRDF | greedy mean, terms 1-5 | structured mean, terms 1-5 | structured / greedy | method s greedy / structured |")
    print("|---|---|---|---|---|")
    for b in sorted({k[0] for k in by}):
        g, s = by[(b, "greedy")], by[(b, "structured")]
        terms = min(len(x[0]) for x in g + s)
        gm = [statistics.mean(x[0][k] for x in g) for k in range(terms)]
        sm = [statistics.mean(x[0][k] for x in s) for k in range(terms)]
        rt = [sm[k] / gm[k] for k in range(terms)]
        worse += sum(r > 1 for r in rt)
        pairs += terms
        print("| %s | %s | %s | %s | %.0f / %.0f |" % (
            b, ", ".join("%.4g" % x for x in gm), ", ".join("%.4g" % x for x in sm),
            ", ".join(("**%.4f**" if r > 1 else "%.3f") % r for r in rt),
            sum(x[1] for x in g), sum(x[1] for x in s)))
    print(f"\n(BRDF, term count) pairs where the structured mean is higher: {worse} of {pairs}")


if __name__ == "__main__":
    main()
