"""The package dependency rules of ``docs/architecture.md`` hold for every import in
``src/vnrrt`` (module level and inside functions: both run), there are no import cycles, and
each stage script is a thin call into ``vnrrt.pipeline``. The rules are read from the
document's ``layers`` block, so the document and the check cannot drift apart."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

from tests.stage_closure import REPO

SRC = REPO / "src"
DOC = REPO / "docs" / "architecture.md"


def layers(text: str) -> dict[str, int]:
    """``{package: layer}`` from the first fenced block tagged ``layers`` of ``text``: lines
    ``<layer> <package> [<package> ...]`` (higher layers may import lower ones only)."""
    block = re.search(r"```layers\n(.*?)```", text, re.S)
    assert block, "docs/architecture.md has no ```layers block"
    out = {}
    for line in block.group(1).splitlines():
        if line.strip():
            level, *names = line.split()
            for name in names:
                assert name not in out, f"{name} listed twice"
                out[name] = int(level)
    return out


def modules(src: Path) -> dict[str, Path]:
    """``{dotted name: file}`` of every module under ``src/vnrrt``."""
    out = {}
    for path in sorted((src / "vnrrt").rglob("*.py")):
        parts = list(path.relative_to(src).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


def imports(name: str, path: Path, known: set[str]) -> set[str]:
    """The vnrrt modules that module ``name`` imports anywhere in its file; ``from a import
    b`` counts as module ``a.b`` where that is a module, else as ``a``."""
    here = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                base = ".".join(here[: len(here) - node.level + 1] + ([base] if base else []))
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in known else base
                       for a in node.names]  # fmt: skip
        else:
            continue
        for target in targets:
            while target and target not in known:
                target = target.rpartition(".")[0]
            if target.startswith("vnrrt") and target != name:
                found.add(target)
    return found


def package(name: str) -> str:
    """The package a module belongs to: ``vnrrt.data.shards`` -> ``data``, the top-level
    module ``vnrrt.grid`` -> ``grid``, the root ``vnrrt`` -> ``__init__``."""
    parts = name.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def upward(graph: dict[str, set[str]], rank: dict[str, int]) -> list[str]:
    """Every import between packages that does not point to a strictly lower layer."""
    return sorted(f"{a} -> {b} ({package(a)}: {rank[package(a)]}, {package(b)}: {rank[package(b)]})"
                  for a, targets in graph.items() for b in targets
                  if package(a) != package(b) and rank[package(a)] <= rank[package(b)])  # fmt: skip


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan, iterative)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root), on.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = counter[0]
                    counter[0] += 1
                    stack.append(child), on.add(child)
                    work.append((child, iter(sorted(graph.get(child, ())))))
                elif child in on:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                comp = []
                while True:
                    top = stack.pop()
                    on.discard(top)
                    comp.append(top)
                    if top == node:
                        break
                if len(comp) > 1:
                    out.append(sorted(comp))
    return out


MODULES = modules(SRC)
GRAPH = {name: imports(name, path, set(MODULES)) for name, path in MODULES.items()}
RANK = layers(DOC.read_text())


def test_every_package_has_a_layer():
    missing = sorted({package(m) for m in MODULES} - set(RANK))
    assert not missing, f"packages without a layer in docs/architecture.md: {missing}"
    stale = sorted(set(RANK) - {package(m) for m in MODULES})
    assert not stale, f"docs/architecture.md names packages that do not exist: {stale}"


def test_no_import_points_up():
    assert upward(GRAPH, RANK) == []


@pytest.mark.parametrize("name", sorted({package(m) for m in MODULES}))
def test_no_import_cycle(name):
    """Within each package (across packages the layers rule cycles out)."""
    inside = {m: {t for t in ts if package(t) == name} for m, ts in GRAPH.items()
              if package(m) == name}  # fmt: skip
    assert cycles(inside) == []


def test_the_checks_catch_a_planted_upward_import_and_cycle():
    """The checker against a hand-made graph: one upward import, one cycle, one clean edge."""
    rank = {"grid": 0, "maps": 1, "viz": 2}
    graph = {
        "vnrrt.grid": {"vnrrt.maps.render"},
        "vnrrt.maps.render": {"vnrrt.maps.shapes"},
        "vnrrt.maps.shapes": {"vnrrt.maps.render"},
        "vnrrt.viz.maps": {"vnrrt.grid"},
    }
    assert upward(graph, rank) == ["vnrrt.grid -> vnrrt.maps.render (grid: 0, maps: 1)"]
    assert cycles(graph) == [["vnrrt.maps.render", "vnrrt.maps.shapes"]]
    assert cycles({"a": {"b"}, "b": {"c"}, "c": set()}) == []


def test_imports_resolve_relative_and_from_imports(tmp_path):
    """``from vnrrt.x import y`` is module ``x.y`` where that exists, else ``x``; relative
    imports resolve against the importing module's package."""
    pkg = tmp_path / "vnrrt" / "maps"
    pkg.mkdir(parents=True)
    for f in ("__init__.py", "shapes.py", "../__init__.py", "../grid.py"):
        (pkg / f).write_text("")
    (pkg / "render.py").write_text("from . import shapes\nfrom vnrrt.grid import disk\n"
                                   "def f():\n    from ..grid import x\n")  # fmt: skip
    known = set(modules(tmp_path))
    assert known == {"vnrrt", "vnrrt.grid", "vnrrt.maps", "vnrrt.maps.shapes", "vnrrt.maps.render"}
    assert imports("vnrrt.maps.render", pkg / "render.py", known) == {
        "vnrrt.maps.shapes", "vnrrt.grid"}  # fmt: skip


STAGES = [p for p in sorted((REPO / "stages").glob("*.py")) if not p.name.startswith("_")]


@pytest.mark.parametrize("script", STAGES, ids=lambda p: p.stem)
def test_a_stage_script_calls_one_pipeline_function(script):
    """``stages/<stage>.py`` imports one ``vnrrt.pipeline`` module and the stage runner."""
    tree = ast.parse(script.read_text())
    froms = [n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)]
    assert sorted(m for m in froms if m.startswith("vnrrt.pipeline.")) != []
    assert len([m for m in froms if m.startswith("vnrrt.pipeline.")]) == 1
    assert set(froms) - {"vnrrt.cli.stage"} <= {m for m in froms if m.startswith("vnrrt.pipeline.")}
    assert len(script.read_text().splitlines()) <= 10
    imports = [a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names]
    assert imports in ([], ["_interpreter"])  # stages/_interpreter.py: the venv's python
