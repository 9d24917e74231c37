#!/usr/bin/env python3
"""Generated tables of the docs: written by a command, never pasted by hand.

A block of README.md or docs/*.md (not docs/notebook/) between

    <!-- BEGIN generated: brdf-factor ARGS -->

    ...
    <!-- END generated -->

holds exactly what `brdf-factor ARGS` prints (after the blank line that
follows the BEGIN marker). The command is read from the marker itself, so a
new generated table is a new pair of markers. Today: the method key tables of
docs/experiments.md (`brdf-factor list methods`, from the key specs of
experiments/methods/).

    scripts/gen-docs.py --cli build/experiments/brdf-factor --check   # exit 1 naming each block that differs
    scripts/gen-docs.py --cli build/experiments/brdf-factor --write   # rewrite every block from its command
    scripts/gen-docs.py --list                                        # the blocks and their commands

--check is the CTest entry "docs: generated tables are the commands' output"
(label docs, docs/testing.md).
"""
import argparse
import glob
import os
import re
import shlex
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BEGIN = re.compile(r"<!-- BEGIN generated: brdf-factor ([^>]*?) -->\n\n")
END = "<!-- END generated -->"


def doc_files():
    files = [os.path.join(ROOT, "README.md")]
    for f in sorted(glob.glob(os.path.join(ROOT, "docs", "**", "*.md"), recursive=True)):
        if os.sep + "notebook" + os.sep not in f:
            files.append(f)
    return files


def blocks(text, path):
    """(args, start of content, end of content, line) of every generated block."""
    out = []
    for m in BEGIN.finditer(text):
        end = text.find(END, m.end())
        line = text.count("\n", 0, m.start()) + 1
        if end < 0:
            raise ValueError("%s:%d: expected '%s' after the BEGIN marker, found none" %
                             (os.path.relpath(path, ROOT), line, END))
        nxt = BEGIN.search(text, m.end())
        if nxt and nxt.start() < end:
            raise ValueError("%s:%d: expected '%s' before the next BEGIN marker (line %d), found none" %
                             (os.path.relpath(path, ROOT), line, END, text.count("\n", 0, nxt.start()) + 1))
        out.append((m.group(1), m.end(), end, line))
    return out


def run(cli, args, cache):
    if args not in cache:
        r = subprocess.run([cli] + shlex.split(args), capture_output=True, text=True)
        if r.returncode != 0:
            raise RuntimeError("brdf-factor %s: exit %d: %s" % (args, r.returncode, r.stderr.strip()))
        cache[args] = r.stdout
    return cache[args]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cli", default=os.path.join(ROOT, "build", "experiments", "brdf-factor"))
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--check", action="store_true")
    g.add_argument("--write", action="store_true")
    g.add_argument("--list", action="store_true")
    a = ap.parse_args()
    try:
        found = []
        for path in doc_files():
            with open(path, encoding="utf-8") as f:
                text = f.read()
            found += [(path, text, b) for b in blocks(text, path)]
        if a.list:
            for path, _, (args, _, _, line) in found:
                print("%s:%d  brdf-factor %s" % (os.path.relpath(path, ROOT), line, args))
            return 0
        if not found:
            print("gen-docs: expected at least one generated block in README.md or docs/, found none",
                  file=sys.stderr)
            return 1
        if not os.access(a.cli, os.X_OK):
            print("gen-docs: %s: not an executable (build first, or pass --cli)" % a.cli, file=sys.stderr)
            return 2
        cache, stale, new_text = {}, [], {}
        for path in doc_files():
            mine = [(text, b) for p, text, b in found if p == path]
            if not mine:
                continue
            text, pieces, pos = mine[0][0], [], 0
            for _, (args, start, end, line) in mine:
                want = run(a.cli, args, cache)
                if text[start:end] != want:
                    stale.append("%s:%d: the block of `brdf-factor %s` differs from the command's output" %
                                 (os.path.relpath(path, ROOT), line, args))
                pieces += [text[pos:start], want]
                pos = end
            pieces.append(text[pos:])
            if "".join(pieces) != text:
                new_text[path] = "".join(pieces)
        if a.write:
            for path, text in new_text.items():
                with open(path, "w", encoding="utf-8") as f:
                    f.write(text)
            print("gen-docs: %d generated blocks, %d stale ones rewritten" % (len(found), len(stale)))
            return 0
        for s in stale:
            print(s)
        if stale:
            print("gen-docs: %d of %d generated blocks are stale; run scripts/gen-docs.py --write" %
                  (len(stale), len(found)))
            return 1
        print("gen-docs: %d generated blocks agree with their commands" % len(found))
        return 0
    except (ValueError, RuntimeError, OSError) as e:
        print("gen-docs: %s" % e, file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
