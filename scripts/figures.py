#!/usr/bin/env python3
"""The quick figures: measured by commands, written into the docs, checked in CI.

A figure in README.md or docs/*.md that this script can measure in about a
minute is written between markers, invisible in rendered markdown:

    <!--fig:w1_mccool_rel_mse-->0.0686<!--/fig-->

(figure names are lower case; an upper-case placeholder such as NAME in an
example is not a marker). Every marker names a figure of the table FIGURES below, which says the command
that measures it (a `brdf-factor` command line or a config run), how the value
is read from its output, how it is printed and the relative tolerance of the
check. Errors are deterministic for a build (seeded searches, fixed grids);
the tolerance absorbs the last digits that another CPU's kernels round
differently (docs/testing.md, "Quick figures").

    scripts/figures.py --cli build/experiments/brdf-factor --check   # exit 1 when a doc disagrees
    scripts/figures.py --cli build/experiments/brdf-factor --write   # measure and rewrite the markers
    scripts/figures.py --list                                        # the figures and their commands

--write also regenerates docs/quick-figures.md, the table of every figure with
its value, command and tolerance. Times are never quick figures: they depend on
the machine's load (docs/speed.md states their commands and conditions).
"""
import argparse
import csv
import glob
import json
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MARKER = re.compile(r"<!--fig:([a-z0-9_]+)-->(.*?)<!--/fig-->")

# Jobs: one command each; several figures read one job's output.
# A job is ("bench", [args]) -> the JSON lines it prints, or
# ("run", config path relative to ROOT, [extra -D args]) -> results.csv rows.
JOBS = {
    "w1_mccool": ("run", "experiments/figures-w1-mccool.toml", []),
    "w1_search5": ("bench", ["bench", "search", "--brdf", "bluepaint", "--terms", "5", "--restarts", "6",
                             "--strategy", "both"]),
    "w1_search2": ("bench", ["bench", "search", "--brdf", "bluepaint", "--terms", "2", "--restarts", "6",
                             "--strategy", "structured"]),
    "quickstart": ("run", "experiments/quickstart.toml", []),
}


def job_command(name):
    kind, *rest = JOBS[name]
    if kind == "bench":
        return "brdf-factor " + " ".join(rest[0])
    config, extra = rest
    return "brdf-factor run " + config + "".join(" -D " + d for d in extra)


def bench_line(strategy, field, index):
    def read(out):
        for line in out:
            if line.get("strategy") == strategy:
                return line[field][index]
        raise KeyError("no JSON line with strategy " + strategy)
    return read


def row(method_label, column):
    def read(rows):
        hits = [r for r in rows if r.get("label", r.get("method")) == method_label or r.get("method") == method_label]
        if len(hits) != 1:
            raise KeyError("expected one row for %r, found %d" % (method_label, len(hits)))
        value = hits[0][column]
        if value in ("", None):
            raise KeyError("row %r has no %s" % (method_label, column))
        return float(value)
    return read


def ratio(num, den):
    return ("ratio", num, den)


# key: (job, reader, format, relative tolerance, what it is)
FIGURES = {
    "w1_mccool_rel_mse": ("w1_mccool", row("mccool", "rel_mse"), "%.3g", 0.005,
                          "W1: McCool's rel_mse (texture 16, default fit options)"),
}
for strategy, short, what in (("greedy", "greedy", "Cole's greedy search"),
                              ("structured", "struct", "the structured search's answer")):
    for k in range(1, 6):
        FIGURES["w1_%s%d_rel_mse" % (short, k)] = (
            "w1_search5", bench_line(strategy, "rel_mse_after_term", k - 1), "%.3g", 0.03,
            "W1: %s, %d texture%s" % (what, k, "s" if k > 1 else ""))
FIGURES.update({
    "w1_struct2_ratio": (None, ratio("w1_struct2_rel_mse", "w1_mccool_rel_mse"), "%.3g", 0.03,
                         "W1: structured 2 textures / McCool (like for like: both with today's defaults)"),
    "w1_struct5_ratio": (None, ratio("w1_struct5_rel_mse", "w1_mccool_rel_mse"), "%.3g", 0.03,
                         "W1: structured 5 textures / McCool"),
    "w1_greedy2_ratio": (None, ratio("w1_greedy2_rel_mse", "w1_mccool_rel_mse"), "%.3g", 0.03,
                         "W1: greedy 2 textures / McCool"),
    "w1_greedy5_ratio": (None, ratio("w1_greedy5_rel_mse", "w1_mccool_rel_mse"), "%.3g", 0.03,
                         "W1: greedy 5 textures / McCool"),
    "w1_only2_rel_mse": ("w1_search2", bench_line("structured", "rel_mse_after_term", 1), "%.3g", 0.03,
                         "W1: a structured search of 2 terms (re-seeded), 2 textures"),
})
FIGURES["w1_only2_ratio"] = (None, ratio("w1_only2_rel_mse", "w1_mccool_rel_mse"), "%.3g", 0.03,
                             "W1: 2-term structured search / McCool")
for method, label in (("mccool", "McCool"), ("search", "search, 2 textures"), ("svd", "linear SVD, rank 2")):
    for column, fmt in (("rel_mse", "%.3g"), ("lin_rmse", "%.3g"), ("cos_rmse", "%.3g"),
                        ("shade_rmse", "%.3g"), ("storage_floats", "%d")):
        tol = 0.0 if column == "storage_floats" else (0.03 if method == "search" else 0.005)
        FIGURES["qs_%s_%s" % (method, column)] = ("quickstart", row(method, column), fmt, tol,
                                                  "quickstart: %s, %s" % (label, column))


def run_job(name, cli, cache):
    if name in cache:
        return cache[name]
    kind, *rest = JOBS[name]
    if kind == "bench":
        p = subprocess.run([cli] + rest[0], cwd=ROOT, capture_output=True, text=True)
        if p.returncode != 0:
            raise RuntimeError("%s failed (exit %d): %s" % (job_command(name), p.returncode, p.stderr.strip()))
        out = [json.loads(l) for l in p.stdout.splitlines() if l.startswith("{")]
    else:
        config, extra = rest
        with tempfile.TemporaryDirectory() as d:
            cmd = [cli, "run", os.path.join(ROOT, config), "--out", d]
            for e in extra:
                cmd += ["-D", e]
            p = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True)
            if p.returncode != 0:
                raise RuntimeError("%s failed (exit %d): %s" % (job_command(name), p.returncode, p.stderr.strip()))
            with open(os.path.join(d, "results.csv"), newline="") as f:
                out = list(csv.DictReader(f))
    cache[name] = out
    return out


def measure(key, cli, cache, values):
    if key in values:
        return values[key]
    job, reader, _, _, _ = FIGURES[key]
    if job is None:
        _, num, den = reader
        v = measure(num, cli, cache, values) / measure(den, cli, cache, values)
    else:
        v = float(reader(run_job(job, cli, cache)))
    values[key] = v
    return v


def command_of(key):
    job, reader, _, _, _ = FIGURES[key]
    if job is None:
        return "%s / %s" % (reader[1], reader[2])
    return job_command(job)


def parse_number(text):
    t = text.strip().replace(",", "").replace("**", "").rstrip("x×").strip()
    return float(t)


def doc_files():
    files = [os.path.join(ROOT, "README.md")]
    files += sorted(glob.glob(os.path.join(ROOT, "docs", "**", "*.md"), recursive=True))
    return files


def quick_table(values):
    lines = ["# Quick figures", "",
             "Generated by `scripts/figures.py --write` (do not edit by hand); `scripts/figures.py --check`",
             "(a CTest entry of the default suite, label `docs`) fails when a figure in README.md or docs/",
             "differs from a fresh measurement by more than its tolerance. Each figure is a deterministic error",
             "of the current build; what the commands mean is in [results.md](results.md).", "",
             "| figure | value | what | command | tolerance |", "|---|---|---|---|---|"]
    for key in FIGURES:
        _, _, fmt, tol, what = FIGURES[key]
        lines.append("| `%s` | <!--fig:%s-->%s<!--/fig--> | %s | `%s` | %g%% |" %
                     (key, key, fmt % values[key], what, command_of(key), 100 * tol))
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default=os.path.join(ROOT, "build", "experiments", "brdf-factor"))
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--check", action="store_true")
    g.add_argument("--write", action="store_true")
    g.add_argument("--list", action="store_true")
    a = ap.parse_args()
    if a.list:
        for key, (_, _, fmt, tol, what) in FIGURES.items():
            print("%-22s %-60s %s (tolerance %g%%)" % (key, what, command_of(key), 100 * tol))
        return 0
    if not os.access(a.cli, os.X_OK):
        print("figures: %s: not an executable (build first, or pass --cli)" % a.cli, file=sys.stderr)
        return 2
    cache, values = {}, {}
    for key in FIGURES:
        measure(key, a.cli, cache, values)
    if a.write:
        with open(os.path.join(ROOT, "docs", "quick-figures.md"), "w") as f:
            f.write(quick_table(values))
    bad = 0
    used = 0
    seen = set()
    for path in doc_files():
        with open(path, encoding="utf-8") as f:
            text = f.read()
        rel = os.path.relpath(path, ROOT)

        def fix(m):
            nonlocal bad, used
            key, shown = m.group(1), m.group(2)
            line = text.count("\n", 0, m.start()) + 1
            if key not in FIGURES:
                print("figures: %s:%d: unknown figure '%s' (known: scripts/figures.py --list)" % (rel, line, key))
                bad += 1
                return m.group(0)
            used += 1
            seen.add(key)
            fmt, tol = FIGURES[key][2], FIGURES[key][3]
            v = values[key]
            if a.write:
                return "<!--fig:%s-->%s<!--/fig-->" % (key, fmt % v)
            try:
                doc = parse_number(shown)
            except ValueError:
                print("figures: %s:%d: figure '%s': expected a number between the markers, found '%s'" %
                      (rel, line, key, shown))
                bad += 1
                return m.group(0)
            # The doc shows a rounded value: allow its rounding on top of the tolerance.
            rounding = abs(float(fmt % v) - v)
            if abs(doc - v) > tol * abs(v) + rounding + 1e-300:
                print("figures: %s:%d: figure '%s' reads %s, measured %s (tolerance %g%%; command: %s)" %
                      (rel, line, key, shown, fmt % v, 100 * tol, command_of(key)))
                bad += 1
            return m.group(0)

        new = MARKER.sub(fix, text)
        if a.write and new != text:
            with open(path, "w", encoding="utf-8") as f:
                f.write(new)
    if a.check:
        for key in FIGURES:
            if key not in seen:
                print("figures: figure '%s' appears in no doc (docs/quick-figures.md lists every figure: "
                      "run scripts/figures.py --write)" % key)
                bad += 1
        if bad:
            print("figures: %d figure(s) disagree with the docs: run scripts/figures.py --write and commit" % bad)
            return 1
        print("figures: %d markers in README.md and docs/ agree with %d measured figures" % (used, len(FIGURES)))
    else:
        print("figures: wrote %d markers and docs/quick-figures.md" % used)
    return 0


if __name__ == "__main__":
    sys.exit(main())
