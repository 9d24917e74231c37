#!/usr/bin/python3
"""Error against time of the projection search: one marker per JSON line of
`brdf-factor bench search` (optimizer / restarts / beam / backfit setting).

Usage: experiments/report/plot_time_error.py BENCH.jsonl OUT.png [--cpu]
x = wall seconds (or process CPU seconds with --cpu, when the lines have it),
y = rel_mse after the last texture; a table of the same points is printed.
Lines that are not JSON (e.g. "# command" comments) are skipped. Settings
are text from the file: the table escapes them for markdown, the plot draws
them as plain text (no mathtext or TeX).
"""
import json
import sys

from plot_results import plain  # the same script folder: labels drawn as plain text


def label(j):
    s = f"{j['optimizer']} r{j['restarts']}"
    if j.get("beam", 1) != 1:
        s += f" beam{j['beam']}"
    if j.get("backfit_sweeps", 0):
        s += f" backfit{j['backfit_sweeps']}"
    if j.get("texture", 16) != j.get("search_texture", j.get("texture", 16)):
        s += f" tex{j['texture']}"
    return s


def md_cell(s):
    """Markdown table cell text: one line, no cell split, no markup or HTML."""
    s = " ".join(str(s).splitlines())
    out = []
    for c in s:
        if c in "\\`*_[]#|~$":
            out.append("\\" + c)
        else:
            out.append({"&": "&amp;", "<": "&lt;", ">": "&gt;"}.get(c, c))
    return "".join(out)


def main(argv):
    if len(argv) < 3:
        sys.exit("usage: plot_time_error.py BENCH.jsonl OUT.png [--cpu]")
    use_cpu = "--cpu" in argv
    pts = []
    with open(argv[1]) as f:
        for n, line in enumerate(f, 1):
            line = line.strip()
            if not line.startswith("{"):
                continue
            try:
                j = json.loads(line)
            except json.JSONDecodeError as e:
                sys.exit(f"{argv[1]}:{n}: not a JSON line ({e})")
            if j.get("bench") != "search":
                continue
            x = j.get("cpu_seconds") if use_cpu else j["seconds"]
            if x is None:
                sys.exit(f"{argv[1]}:{n}: --cpu needs cpu_seconds, found none")
            pts.append((label(j), x, j["rel_mse_after_term"][-1], j["evaluations"], j["terms"]))
    if not pts:
        sys.exit(f"{argv[1]}: no bench search lines")
    print("| setting | textures | fits | %s | rel_mse |" % ("cpu s" if use_cpu else "wall s"))
    print("|---|---|---|---|---|")
    for p in pts:
        print(f"| {md_cell(p[0])} | {p[4]} | {p[3]} | {p[1]:.1f} | {p[2]:.4f} |")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 4.5))
    markers = "osD^v<>ph*X"
    for i, p in enumerate(pts):
        ax.scatter(p[1], p[2], marker=markers[i % len(markers)], s=50, label=(" " if p[0].startswith("_") else "") + f"{p[0]} ({p[4]} tex)")
    ax.set_xlabel("process CPU seconds" if use_cpu else "wall seconds")
    ax.set_ylabel("rel_mse after the last texture")
    ax.set_title("projection search: error against time")
    ax.grid(True, alpha=0.3)
    for t in ax.legend(fontsize=7).get_texts():
        plain(t)
    fig.tight_layout()
    fig.savefig(argv[2], dpi=120)
    print(f"wrote {argv[2]}")


if __name__ == "__main__":
    main(sys.argv)
