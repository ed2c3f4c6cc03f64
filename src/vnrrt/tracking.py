"""MLflow tracking: where runs go, which tags they carry, the config as parameters.

The default store is ``sqlite:///<repo>/mlflow.db`` with artifacts in ``<repo>/mlartifacts``,
where ``<repo>`` is the DVC root of the running stage (``DVC_ROOT``, set by ``dvc repro``),
else the nearest folder above the working directory holding ``dvc.yaml``, else the working
directory. ``MLFLOW_TRACKING_URI`` in the environment or ``logger.uri`` in config override
it. Lightning's ``MLFlowLogger`` reads ``MLFLOW_TRACKING_URI`` when it is *imported*, so
:func:`configure` runs before ``lightning`` is imported (see ``stages/train.py``).

Browse with ``mlflow ui --backend-store-uri sqlite:///mlflow.db``.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from omegaconf import DictConfig, OmegaConf

DB_NAME = "mlflow.db"
ARTIFACTS = "mlartifacts"


def repo_root(start: str | Path | None = None) -> Path:
    """The repository a run belongs to (module doc): ``DVC_ROOT`` or the nearest folder
    above ``start`` (default: the working directory) holding ``dvc.yaml``."""
    if os.environ.get("DVC_ROOT"):
        return Path(os.environ["DVC_ROOT"]).resolve()
    here = Path(start or Path.cwd()).resolve()
    for folder in (here, *here.parents):
        if (folder / "dvc.yaml").is_file():
            return folder
    return here


def default_uri(root: Path | None = None) -> str:
    """``sqlite:///<repo>/mlflow.db``."""
    return f"sqlite:///{(root or repo_root()) / DB_NAME}"


def tracking_uri(configured: str | None = None) -> str:
    """The store to use: ``configured`` (``logger.uri``), else ``MLFLOW_TRACKING_URI``, else
    :func:`default_uri`."""
    return configured or os.environ.get("MLFLOW_TRACKING_URI") or default_uri()


def configure(configured: str | None = None) -> str:
    """Set ``MLFLOW_TRACKING_URI`` to :func:`tracking_uri` (before Lightning is imported)."""
    uri = tracking_uri(configured)
    os.environ["MLFLOW_TRACKING_URI"] = uri
    return uri


def artifact_location(configured: str | None = None) -> str:
    """Artifact root of a new experiment: ``configured`` or ``<repo>/mlartifacts`` (a URI)."""
    return configured or (repo_root() / ARTIFACTS).as_uri()


def git_commit(root: Path | None = None) -> str:
    """The checked-out commit, read from ``.git`` files (no git process); ``"unknown"``."""
    git = (root or repo_root()) / ".git"
    try:
        head = (git / "HEAD").read_text().strip()
        if not head.startswith("ref: "):
            return head
        ref = head[5:]
        if (git / ref).is_file():
            return (git / ref).read_text().strip()
        for line in (git / "packed-refs").read_text().splitlines():
            if line.endswith(" " + ref):
                return line.split()[0]
    except OSError:
        pass
    return "unknown"


def run_tags(network: str, scale: str) -> dict[str, str]:
    """Tags of a training run: git commit, DVC stage / experiment (when run by DVC), names."""
    env = os.environ
    return {
        "git_commit": git_commit(),
        "dvc_stage": env.get("DVC_STAGE", "none"),
        "dvc_experiment": env.get("DVC_EXP_NAME", "none"),
        "dvc_baseline": env.get("DVC_EXP_BASELINE_REV", "none"),
        "network": network,
        "scale": scale,
    }


def flat_params(cfg: DictConfig | dict, prefix: str = "") -> dict[str, Any]:
    """The config flattened to ``{"a.b.c": value}`` (lists kept whole), for MLflow params."""
    node = OmegaConf.to_container(cfg, resolve=True) if isinstance(cfg, DictConfig) else cfg
    out: dict[str, Any] = {}
    for key, value in node.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(flat_params(value, name + "."))
        else:
            out[name] = value
    return out
