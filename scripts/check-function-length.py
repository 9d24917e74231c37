#!/usr/bin/env python3
"""Lists C++ functions whose body is longer than --max lines.

Scans .cpp, .h and .inc files under the given folders with a brace matcher
(comments, string and character literals are skipped). A function is a '{'
block whose header (the text since the previous ';', '{' or '}') ends in a
parameter list ')' optionally followed by qualifiers, an initializer list or a
trailing return type; class, struct, namespace, enum, lambda-free control
blocks (if/for/while/switch/catch/do/else) are not functions. Lambdas inside a
function count towards the enclosing function. Length is the number of lines
from the header's first line to the closing brace.

A function preceded by a line containing `// data table` is exempt.

Prints `file:line name length` for each function over the limit and exits 1
if any was found, else 0.

Usage: scripts/check-function-length.py [--max 120] folder [folder...]
"""
import argparse
import os
import re
import sys

EXTS = (".cpp", ".h", ".inc")
CONTROL = {"if", "for", "while", "switch", "catch", "do", "else", "try",
           "return", "sizeof", "alignof", "decltype", "noexcept", "requires"}
NOT_FUNC = re.compile(r"\b(class|struct|union|namespace|enum)\b")


def strip_code(text):
    """Returns text with comments and literals blanked (newlines kept)."""
    out = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        nxt = text[i + 1] if i + 1 < n else ""
        if c == "/" and nxt == "/":
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif c == "/" and nxt == "*":
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "R" and nxt == '"' and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            if m:
                end = text.find(")" + m.group(1) + '"', i)
                end = n if end < 0 else end + len(m.group(1)) + 2
                out.append(re.sub(r"[^\n]", " ", text[i:end]))
                i = end
            else:
                out.append(c)
                i += 1
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum() and nxt.isalnum():
                out.append(" ")  # digit separator 1'000
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(c + " " * (j - i - 2) + c if j - i >= 2 else " " * (j - i))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def blank_preprocessor(code):
    lines = code.split("\n")
    res = []
    cont = False
    for line in lines:
        if cont or line.lstrip().startswith("#"):
            cont = line.rstrip().endswith("\\")
            res.append(" " * len(line))
        else:
            res.append(line)
    return "\n".join(res)


def function_name(header):
    """Returns the function name if header looks like a function header, else None."""
    h = " ".join(header.split())
    if not h or NOT_FUNC.search(h.split("(")[0]):
        return None
    if h.endswith("=") or h.endswith(",") or h.endswith("("):
        return None
    # Drop a constructor initializer list: the ':' after the parameter list.
    depth = 0
    close = -1
    for k, ch in enumerate(h):
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth -= 1
            if depth == 0:
                close = k
                break
    if close < 0:
        return None
    before = h[:h.index("(")].rstrip()
    m = re.search(r"((?:[A-Za-z_~][\w]*\s*::\s*)*(?:operator\s*[^\s(]+|operator\s*\(\)|~?[A-Za-z_]\w*))\s*$", before)
    if not m:
        return None
    name = re.sub(r"\s+", "", m.group(1))
    last = name.split("::")[-1]
    if last in CONTROL or before.endswith("]"):
        return None
    if "=" in before and not before.rstrip().startswith("operator"):
        # `auto f = [..](..)` or `x = g(...)`: not a definition.
        if re.search(r"(?<![=!<>])=(?!=)", before.replace("operator=", "")):
            return None
    return name


def scan(path, limit):
    with open(path, encoding="utf-8", errors="replace") as f:
        raw = f.read()
    raw_lines = raw.split("\n")
    code = blank_preprocessor(strip_code(raw))
    hits = []
    stack = []  # (kind, name, start_line, exempt)
    header_start = 0
    line_of = [0] * (len(code) + 1)
    ln = 1
    for k, ch in enumerate(code):
        line_of[k] = ln
        if ch == "\n":
            ln += 1
    line_of[len(code)] = ln
    in_func = 0
    for k, ch in enumerate(code):
        if ch in ";{}":
            if ch == "{":
                header = code[header_start:k]
                name = None
                if in_func == 0:
                    name = function_name(header)
                if name:
                    # First non-blank character of the header.
                    off = len(header) - len(header.lstrip())
                    start = line_of[header_start + off]
                    # Template line(s) just before are part of the header too.
                    prev = raw_lines[start - 2] if start >= 2 else ""
                    exempt = "// data table" in prev
                    stack.append(("f", name, start, exempt))
                    in_func += 1
                else:
                    stack.append(("b", None, 0, False))
            elif ch == "}":
                if stack:
                    kind, name, start, exempt = stack.pop()
                    if kind == "f":
                        in_func -= 1
                        length = line_of[k] - start + 1
                        if length > limit and not exempt:
                            hits.append((start, name, length))
            header_start = k + 1
    return hits


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--max", type=int, default=120)
    ap.add_argument("folders", nargs="+")
    args = ap.parse_args()
    found = 0
    for folder in args.folders:
        paths = []
        if os.path.isfile(folder):
            paths = [folder]
        else:
            for root, _, files in os.walk(folder):
                paths += [os.path.join(root, f) for f in files if f.endswith(EXTS)]
        for p in sorted(paths):
            for line, name, length in scan(p, args.max):
                print(f"{p}:{line} {name} {length}")
                found += 1
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
