"""The code a DVC stage runs: the import closure of its script inside ``src/vnrrt``.

Rule: start from ``stages/<stage>.py``. The module that defines the stage's entry function
(a module of ``vnrrt.pipeline``) counts with its module-level imports and the imports inside
that function and the module's functions it calls (its other entry functions belong to other
stages); every other module
counts with all its imports (module level and inside functions: they run when called). Each
imported module brings the ``__init__.py`` of its packages. ``python -m tests.stage_closure``
prints every stage's closure as ``dvc.yaml`` deps.
"""

from __future__ import annotations

import ast
import functools
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
SRC = REPO / "src"


def module_file(name: str) -> Path | None:
    """The file of module ``vnrrt.x.y`` (package ``__init__.py`` or module), or None."""
    if not name.startswith("vnrrt"):
        return None
    base = SRC / Path(*name.split("."))
    for cand in (base / "__init__.py", base.with_suffix(".py")):
        if cand.is_file():
            return cand
    return None


def _names(node: ast.AST, here: str) -> list[str]:
    """Absolute module names imported by ``node`` (``from a import b`` may be module a.b)."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names]
    if isinstance(node, ast.ImportFrom):
        base = node.module or ""
        if node.level:
            parts = here.split(".")[: -node.level]
            base = ".".join([*parts, base]) if base else ".".join(parts)
        return [base, *(f"{base}.{a.name}" for a in node.names)]
    return []


def reachable(tree: ast.Module, start: str) -> set[str]:
    """Names of the module-level functions and classes that ``start`` calls or names,
    transitively (``start`` included)."""
    defs = {s.name: s for s in tree.body
            if isinstance(s, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef)}  # fmt: skip
    seen, todo = set(), [start]
    while todo:
        fn = todo.pop()
        if fn in seen or fn not in defs:
            continue
        seen.add(fn)
        todo += [n.id for n in ast.walk(defs[fn]) if isinstance(n, ast.Name) and n.id in defs]
    return seen


def imports(path: Path, name: str, only_function: str | None = None) -> set[str]:
    """vnrrt modules imported in ``path``: everywhere, or at module level plus inside
    ``only_function`` and the module's functions it calls."""
    tree = ast.parse(path.read_text())
    here = name
    nodes: list[ast.AST] = []
    if only_function is None:
        nodes = list(ast.walk(tree))
    else:
        used = reachable(tree, only_function)
        for stmt in tree.body:
            if isinstance(stmt, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                if stmt.name in used:
                    nodes += list(ast.walk(stmt))
            else:
                nodes += list(ast.walk(stmt))
    pkg = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    found = set()
    for node in nodes:
        for mod in _names(node, pkg + ".x" if isinstance(node, ast.ImportFrom) else here):
            if module_file(mod) is not None:
                found.add(mod)
    return found


def _packages(name: str) -> list[str]:
    parts = name.split(".")
    return [".".join(parts[:i]) for i in range(1, len(parts))]


def targets(node) -> set[str]:
    """vnrrt modules named by ``_target_`` entries (Hydra) anywhere in a config ``node``."""
    found = set()
    if isinstance(node, dict):
        for key, value in node.items():
            if key == "_target_" and isinstance(value, str):
                name = value
                while name and module_file(name) is None and "." in name:
                    name = name.rsplit(".", 1)[0]
                if module_file(name) is not None:
                    found.add(name)
            else:
                found |= targets(value)
    elif isinstance(node, list):
        for value in node:
            found |= targets(value)
    return found


def closure(script: Path, params: dict | None = None) -> set[Path]:
    """Files under ``src/vnrrt`` a stage script runs (module doc); ``params`` (the stage's
    declared parameters) adds the modules their Hydra ``_target_`` entries instantiate."""
    tree = ast.parse(script.read_text())
    entry: tuple[str, str] | None = None  # (module, function) of the stage's entry point
    start: set[str] = set()
    for node in tree.body:
        if (
            isinstance(node, ast.ImportFrom)
            and node.module
            and node.module.startswith("vnrrt.pipeline.")
        ):
            entry = (node.module, node.names[0].name)
        start |= {m for m in _names(node, "stages") if module_file(m) is not None}
    seen: set[str] = set()
    todo = sorted(start | targets(params or {}))
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen.add(name)
        path = module_file(name)
        only = entry[1] if entry and name == entry[0] else None
        todo += [m for m in imports(path, name, only) | set(_packages(name)) if m not in seen]
    return {module_file(m).relative_to(REPO) for m in seen}


def declared(deps: list[str]) -> set[Path]:
    """The ``src/vnrrt`` python files a stage's ``deps`` list names (folders expanded)."""
    out = set()
    for dep in deps:
        path = REPO / dep
        if not str(dep).startswith("src/vnrrt"):
            continue
        files = sorted(path.rglob("*.py")) if path.is_dir() else [path]
        out |= {f.relative_to(REPO) for f in files if "__pycache__" not in f.parts}
    return out


@functools.cache
def _dvc_stages() -> dict:
    """``dvc.yaml``'s stages, parsed once per test process."""
    import yaml

    return yaml.safe_load((REPO / "dvc.yaml").read_text())["stages"]


@functools.cache
def _default_config():
    """The default composition, composed once per test process (read only here)."""
    from vnrrt.config import compose

    return compose()


def declared_params(stage: str) -> dict:
    """The parameters ``stage``'s ``dvc.yaml`` entry declares, from the default composition."""
    from omegaconf import OmegaConf

    from vnrrt.config import restrict, stage_params

    cfg = _default_config()
    entry = _dvc_stages()[stage]
    if "foreach" in entry:  # ${scale.shards} -> the first id (a stand-in for an empty list)
        stage = f"{stage}@{_first(cfg, entry['foreach'])}"
    if "matrix" in entry:  # the first value of each axis: stage@<a>-<b>
        stage = f"{stage}@{'-'.join(_first(cfg, axis) for axis in entry['matrix'].values())}"
    view = restrict(cfg, stage_params(stage, REPO / "dvc.yaml"), always=())
    return OmegaConf.to_container(view, resolve=True)


def _first(cfg, items: str) -> str:
    """The first item of a ``foreach``/``matrix`` list ``${key}`` of ``cfg``; ``0`` where the
    default composition leaves it empty (the budget stages: their keys name no item)."""
    from omegaconf import OmegaConf

    values = OmegaConf.select(cfg, items.strip("${}"))
    return str(values[0]) if values else "0"


def stage_scripts() -> dict[str, Path]:
    """``{stage name: script}`` of every ``dvc.yaml`` stage (from its ``cmd``)."""
    out = {}
    for name, entry in _dvc_stages().items():
        cmd = entry.get("do", entry)["cmd"]
        out[name] = REPO / next(w for w in cmd.split() if w.startswith("stages/"))
    return out


if __name__ == "__main__":
    for name, script in stage_scripts().items():
        print(f"# {name}")
        for f in sorted(closure(script, declared_params(name))):
            print(f"        - {f}")
    sys.exit(0)
