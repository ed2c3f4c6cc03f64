"""The paper's published numbers (``paths.paper_tables``, ``data/paper/tables.yaml``: its
Tables 1-3 and the improvements its text quotes), read once for both studies."""

from __future__ import annotations

from pathlib import Path

from vnrrt.config import ConfigError
from vnrrt.infra.io import read_yaml


def load_paper_tables(path: str | Path) -> dict:
    """The paper's tables and quoted claims; :class:`ConfigError` naming the file."""
    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"the paper's tables {path} do not exist")
    paper = read_yaml(path, "the paper's tables", ConfigError)
    if not isinstance(paper, dict) or not {"columns", "tables", "claims"} <= set(paper):
        raise ConfigError(f"the paper's tables {path} lack columns, tables or claims")
    return paper


def claim_pairs(paper: dict, stop: str = "optimal") -> list[tuple[str, str]]:
    """The (planner, baseline) key pairs of the claims on tables of stop rule ``stop``, each
    once, in the paper's order."""
    pairs = [
        (c["planner"], c["baseline"])
        for c in paper["claims"]
        if paper["tables"][c["table"]]["stop"] == stop
    ]
    return list(dict.fromkeys(pairs))
