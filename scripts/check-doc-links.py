#!/usr/bin/env python3
"""Checks the relative links of README.md and docs/**/*.md.

Every link [text](target) whose target is not a URL must name a file or
folder that exists (relative to the linking file), and a #anchor must be a
heading of the target file (or an <a id="..."> in it), spelled as GitHub spells heading anchors (lower
case, punctuation dropped, spaces as '-', repeated headings suffixed -1, -2).
Exit 1 with one line per broken link (file:line: target: what is wrong).

    scripts/check-doc-links.py
"""
import glob
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LINK = re.compile(r"\]\(([^)\s]+)\)")
FENCE = re.compile(r"^\s*(```|~~~)")


def anchors(path):
    out, seen = set(), {}
    fenced = False
    with open(path, encoding="utf-8") as f:
        for line in f:
            if FENCE.match(line):
                fenced = not fenced
                continue
            if not fenced:
                out.update(re.findall(r'<a (?:id|name)="([^"]+)"', line))
            m = None if fenced else re.match(r"^(#{1,6})\s+(.*?)\s*#*\s*$", line)
            if not m:
                continue
            text = re.sub(r"<[^>]+>", "", m.group(2))
            text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
            slug = re.sub(r"[^\w\- ]", "", text.lower()).replace(" ", "-")
            n = seen.get(slug, 0)
            seen[slug] = n + 1
            out.add(slug if n == 0 else "%s-%d" % (slug, n))
    return out


def main():
    files = [os.path.join(ROOT, "README.md")]
    files += sorted(glob.glob(os.path.join(ROOT, "docs", "**", "*.md"), recursive=True))
    files += sorted(glob.glob(os.path.join(ROOT, "experiments", "**", "README.md"), recursive=True))
    cache, broken, checked = {}, [], 0
    for path in files:
        fenced = False
        with open(path, encoding="utf-8") as f:
            lines = f.readlines()
        for no, line in enumerate(lines, 1):
            if FENCE.match(line):
                fenced = not fenced
                continue
            if fenced:
                continue
            line = re.sub(r"`[^`]*`", "", line)
            for target in LINK.findall(line):
                if re.match(r"^[a-z]+:", target):
                    continue
                checked += 1
                file_part, _, anchor = target.partition("#")
                dest = os.path.normpath(os.path.join(os.path.dirname(path), file_part)) if file_part else path
                where = "%s:%d: %s" % (os.path.relpath(path, ROOT), no, target)
                if not os.path.exists(dest):
                    broken.append(where + ": expected an existing file, found none at " + os.path.relpath(dest, ROOT))
                    continue
                if anchor and dest.endswith(".md"):
                    if dest not in cache:
                        cache[dest] = anchors(dest)
                    if anchor not in cache[dest]:
                        broken.append(where + ": expected a heading with anchor #" + anchor + " in " +
                                      os.path.relpath(dest, ROOT) + ", found none")
    for b in broken:
        print(b)
    print("doc links: %d relative links checked, %d broken" % (checked, len(broken)))
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main())
