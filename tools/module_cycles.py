#!/usr/bin/env python3
"""Import cycles between the top-level modules of each weft crate.

A module `a` depends on `b` when a file of `a` names `crate::b` (in a `use`
or a path, not in a comment) or, inside a module folder, `super::b` from its `mod.rs` level.
Prints, per crate, the strongly connected components with more than one
module (each is an import cycle) and their count, and exits 1 if there is
any (`make lint` runs it). Usage, from the repository root:
`python3 tools/module_cycles.py [CRATE_DIR...]` (default: every crate under
engine/).
"""
import os
import re
import sys


def top_module(src, path):
    """The crate-level module a source file belongs to (`lib` for lib.rs/main.rs)."""
    rel = os.path.relpath(path, src)
    first = rel.split(os.sep)[0]
    if first in ("lib.rs", "main.rs"):
        return None
    return first[:-3] if first.endswith(".rs") else first


def dependencies(src):
    deps = {}
    for root, _, files in os.walk(src):
        for name in files:
            if not name.endswith(".rs"):
                continue
            path = os.path.join(root, name)
            module = top_module(src, path)
            if module is None:
                continue
            text = open(path, encoding="utf-8").read()
            # Leave out test modules: a cycle through tests is not one of the crate's.
            text = re.split(r"#\[cfg\(test\)\]\s*mod tests", text)[0]
            # Comments (doc links among them) name modules without importing them.
            text = re.sub(r"//[^\n]*", "", text)
            used = set(re.findall(r"\bcrate::([a-z_][a-z0-9_]*)", text))
            if os.path.dirname(path) == src:
                used |= set(re.findall(r"\bsuper::([a-z_][a-z0-9_]*)", text))
            deps.setdefault(module, set()).update(u for u in used if u != module)
    return deps


def cycles(deps):
    """Tarjan's strongly connected components of size > 1."""
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in deps.get(v, ()):
            if w not in deps:
                continue
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                out.append(sorted(component))

    sys.setrecursionlimit(10000)
    for v in sorted(deps):
        if v not in index:
            visit(v)
    return out


def main():
    crates = sys.argv[1:] or sorted(
        os.path.join("engine", c) for c in os.listdir("engine") if os.path.isdir(os.path.join("engine", c, "src"))
    )
    total = 0
    for crate in crates:
        found = cycles(dependencies(os.path.join(crate, "src")))
        total += len(found)
        print(f"{crate}: {len(found)} import cycle(s)")
        for component in found:
            print("  " + " <-> ".join(component))
    print(f"total: {total}")
    return 1 if total else 0


if __name__ == "__main__":
    sys.exit(main())
