#!/usr/bin/env python3
"""cycles.py LIBRARY [ALLOWED ...]: the call graph between a static
library's object files from `nm -A` (A -> B when A uses a symbol B
defines), its cycles (strongly connected components of more than one
file) printed; exit 1 when one is not among ALLOWED (each a
comma-separated set of file names without .c.o, e.g. async_compile,pipelines)."""
import re
import subprocess
import sys

lib, allowed = sys.argv[1], {frozenset(a.split(',')) for a in sys.argv[2:]}
out = subprocess.run(['nm', '-A', lib], capture_output=True, text=True, check=True).stdout
defs, uses = {}, {}
for line in out.splitlines():
    m = re.match(r'^.*?:([^:/]+)\.o:\s*(.*)$', line)   # LIB:OBJECT.o: [VALUE] TYPE NAME
    if not m:
        continue
    obj = m.group(1).rsplit('.c', 1)[0]
    f = m.group(2).split()
    uses.setdefault(obj, set())
    if len(f) == 2 and f[0] == 'U':
        uses[obj].add(f[1])
    elif len(f) == 3 and f[1] in 'TDBR':
        defs[f[2]] = obj
edges = {o: sorted({defs[s] for s in u if s in defs and defs[s] != o}) for o, u in uses.items()}

# Tarjan's strongly connected components, iteratively
index, low, stack, on, sccs = {}, {}, [], set(), []
for root in sorted(edges):
    if root in index:
        continue
    work = [(root, 0)]
    while work:
        v, i = work.pop()
        if i == 0:
            index[v] = low[v] = len(index)
            stack.append(v)
            on.add(v)
        if i < len(edges[v]):
            work.append((v, i + 1))
            w = edges[v][i]
            if w not in index:
                work.append((w, 0))
            elif w in on:
                low[v] = min(low[v], index[w])
            continue
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                sccs.append(sorted(comp))
        if work:
            parent = work[-1][0]
            low[parent] = min(low[parent], low[v])

bad = 0
for c in sccs:
    ok = frozenset(c) in allowed
    bad += not ok
    print('cycle%s: %s' % (' (allowed)' if ok else '', ' <-> '.join(c)))
print('%d objects, %d cycles, %d not allowed' % (len(edges), len(sccs), bad))
sys.exit(1 if bad else 0)
