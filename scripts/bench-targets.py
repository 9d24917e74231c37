#!/usr/bin/env python3
"""The speed targets of docs/speed.md, measured in one run.

    /usr/bin/python3 scripts/bench-targets.py [--cli build/experiments/brdf-factor]
                                               [--old OTHER_CLI] [--rounds 3] [--skip search,peer]

Each workload runs --rounds times; with --old, the two binaries alternate
(old, new, old, new, ...) so that both see the same machine state, and the
table reports the median of each. Timings are the benchmarks' own CPU
medians (`cpu_ms_median` of `bench fit`), wall and CPU seconds of
`bench search` (W1, 5 terms, 6 restarts: the greedy and the structured search
interleaved in each round, with their wall-time ratio round by round), and `/usr/bin/time` for `--help`. The load average is printed
at the start and the end: figures taken while anything else runs are not
comparable with idle ones (docs/speed.md).

Only the standard library; the scipy peer is scripts/bench-peer.py (its ratio
is measured against --cli in the same run).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys

FIT = ["bench", "fit", "--brdf", "bluepaint", "--grid", "16", "--terms", "2"]
WORKLOADS = [
    # (name, arguments, values taken from the JSON line)
    # (cpu_ms_median_prefix: the same fit with its first term held in a
    # JointPrefix, as every evaluation of the search after the first term)
    ("W1 fit, ms (target 1.5)", FIT + ["--texture", "16", "--repeats", "21"], ("cpu_ms_median", "cpu_ms_median_prefix")),
    ("1M samples, ms (target 30)", FIT + ["--samples", "1000000", "--texture", "16", "--repeats", "5"],
     ("cpu_ms_median",)),
    ("texture 32, ms (target 15)", FIT + ["--texture", "32", "--repeats", "7"], ("cpu_ms_median",)),
    ("texture 64, ms (target 300)", FIT + ["--texture", "64", "--repeats", "3"], ("cpu_ms_median",)),
]
SEARCH = ["bench", "search", "--brdf", "bluepaint", "--terms", "5", "--restarts", "6", "--strategy"]
# The W1 search of each strategy, interleaved in every round (greedy, structured,
# greedy, ...): `best`, the config default, runs the two one after the other.
STRATEGIES = ("greedy", "structured")


def run_json(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def help_cost(cli):
    r = subprocess.run(["/usr/bin/time", "-f", "%e %U %S %M", cli, "--help"], check=True,
                       capture_output=True, text=True)
    wall, user, sys_, rss = r.stderr.strip().splitlines()[-1].split()
    return float(wall), float(user) + float(sys_), int(rss) / 1024.0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default="build/experiments/brdf-factor")
    ap.add_argument("--old", help="another brdf-factor to alternate with (e.g. a build of the base commit)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--skip", default="", help="comma-separated: fit, search, peer, help")
    a = ap.parse_args()
    skip = set(filter(None, a.skip.split(",")))
    clis = [("new", a.cli)] + ([("old", a.old)] if a.old else [])
    for _, c in clis:
        if not os.access(c, os.X_OK):
            sys.exit(f"bench-targets: --cli/--old: expected an executable brdf-factor, found {c!r}")
    print(f"load average at start: {os.getloadavg()}", flush=True)
    if "fit" not in skip:
        for name, args, keys in WORKLOADS:
            vals = {(tag, key): [] for tag, _ in clis for key in keys}
            for _ in range(a.rounds):
                for tag, c in reversed(clis):  # old first when given
                    out = run_json([c] + args)
                    for key in keys:
                        vals[(tag, key)].append(out[key])
            for key in keys:
                print(f"{name} [{key}]: " + ", ".join(
                    f"{tag} {statistics.median(vals[(tag, key)]):.3f} {sorted(round(x, 3) for x in vals[(tag, key)])}"
                    for tag, _ in clis), flush=True)
    if "search" not in skip:
        res = {(tag, st): [] for tag, _ in clis for st in STRATEGIES}
        for _ in range(a.rounds):
            for st in STRATEGIES:
                for tag, c in reversed(clis):
                    res[(tag, st)].append(run_json([c] + SEARCH + [st]))
        for (tag, st), rs in res.items():
            walls = [r["seconds"] for r in rs]
            cpus = [r["cpu_seconds"] for r in rs]
            target = " (target 6 s wall)" if st == "greedy" else ""
            print(f"{st} W1 search{target} {tag}: wall {statistics.median(walls):.2f} s {sorted(round(w, 2) for w in walls)}, "
                  f"CPU {statistics.median(cpus):.2f} s, evaluations {sorted(set(r['evaluations'] for r in rs))}, "
                  f"rel_mse after each term {rs[0]['rel_mse_after_term']}", flush=True)
        for tag, _ in clis:
            ratios = [s["seconds"] / g["seconds"] for g, s in zip(res[(tag, "greedy")], res[(tag, "structured")])]
            print(f"structured / greedy wall, round by round {tag}: {[round(x, 2) for x in ratios]}, "
                  f"median {statistics.median(ratios):.2f}", flush=True)
        if a.old:
            for st in STRATEGIES:
                diff = max(abs(x - y) for x, y in zip(res[("new", st)][0]["rel_mse_after_term"],
                                                       res[("old", st)][0]["rel_mse_after_term"]))
                print(f"{st}: largest per-term rel_mse difference new - old: {diff:.3g}", flush=True)
    if "peer" not in skip:
        peer = run_json(["/usr/bin/python3", os.path.join(os.path.dirname(__file__), "bench-peer.py"),
                         "--rounds", str(max(5, a.rounds)), "--cli", a.cli])
        print(f"scipy peer (target 25x): peer {peer['peer_ms_median']:.2f} ms, C++ {peer['cpp_ms_median']:.3f} ms, "
              f"ratio {peer['ratio']:.1f}x (CPU ratio {peer['cpu_ratio']:.1f}x)", flush=True)
    if "help" not in skip:
        for tag, c in clis:
            hs = [help_cost(c) for _ in range(5)]
            print(f"--help (target 0.1 s, 60 MB) {tag}: wall {statistics.median(h[0] for h in hs):.3f} s, "
                  f"CPU {statistics.median(h[1] for h in hs):.3f} s, max RSS {statistics.median(h[2] for h in hs):.1f} MB",
                  flush=True)
    print(f"load average at end: {os.getloadavg()}")


if __name__ == "__main__":
    main()
