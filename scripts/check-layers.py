#!/usr/bin/env python3
"""Checks that includes flow one way: between the top-level libraries
(solvers < brdfs < factor < search < experiments < python) and between the
role folders of experiments/ (common < plan < report < methods < config < run
< cli). A file may include its own folder and lower ones, never a higher one.
Prints every violation as file:line and exits 1 if there is one."""
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TOP = ['solvers', 'brdfs', 'factor', 'search', 'experiments', 'python']
GROUPS = ['common', 'plan', 'report', 'methods', 'config', 'run', 'cli']
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def rank(path):
    """(top rank, group rank or -1) of a repository path, or None outside the layers."""
    parts = path.split('/')
    if parts[0] not in TOP:
        return None
    top = TOP.index(parts[0])
    group = -1
    if parts[0] == 'experiments':
        if len(parts) < 3 or parts[1] not in GROUPS:
            return (top, None)  # a loose file in experiments/: reported separately
        group = GROUPS.index(parts[1])
    return (top, group)


def main():
    bad = []
    for top in TOP:
        for dirpath, _, files in os.walk(os.path.join(ROOT, top)):
            for name in files:
                if not name.endswith(('.h', '.cpp', '.inc')):
                    continue
                rel = os.path.relpath(os.path.join(dirpath, name), ROOT)
                me = rank(rel)
                if me[1] is None:
                    bad.append(f'{rel}: a source file in experiments/ outside a role folder ({", ".join(GROUPS)})')
                    continue
                with open(os.path.join(ROOT, rel), encoding='utf-8') as f:
                    for n, line in enumerate(f, 1):
                        m = INCLUDE.match(line)
                        if not m:
                            continue
                        other = rank(m.group(1))
                        if other is None or other[1] is None:
                            continue
                        if other[0] > me[0] or (other[0] == me[0] and other[1] > me[1]):
                            bad.append(f'{rel}:{n}: includes "{m.group(1)}", which stands above it')
    for b in bad:
        print(b)
    if bad:
        print(f'check-layers: {len(bad)} include(s) against the layer order', file=sys.stderr)
        return 1
    print('check-layers: ok')
    return 0


if __name__ == '__main__':
    sys.exit(main())
