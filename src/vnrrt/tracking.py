"""MLflow tracking: where runs go, which tags they carry, experiments, models and the
evaluation runs.

* **Store**: ``sqlite:///<repo>/mlflow.db`` with artifacts in ``<repo>/mlartifacts``, where
  ``<repo>`` is the DVC root of the running stage (``DVC_ROOT``, set by ``dvc repro``), else
  the nearest folder above the working directory holding ``dvc.yaml``. ``MLFLOW_TRACKING_URI``
  or ``logger.uri`` override it. Lightning's ``MLFlowLogger`` reads ``MLFLOW_TRACKING_URI``
  when it is imported, so :func:`configure` runs first.
* **Artifact roots follow the repository**: MLflow stores an experiment's artifact root as
  an absolute path; when the default store of a repository names a root outside it (the
  repository was copied or moved), :func:`experiment_id` points the experiment at this
  repository's ``mlartifacts`` again, so a copy never writes into the original.
* **Experiments**: one per scale (``logger.experiment``, ``vnrrt-<scale>`` by default);
  runs named ``<network> <scale>`` and ``evaluation <scale>``, tagged with kind, scale, git
  commit, DVC stage and experiment.
* **Telemetry** is off (``MLFLOW_DISABLE_TELEMETRY=true`` unless set otherwise before vnrrt
  is imported): stages make no network calls. ``MLFLOW_DISABLE_TELEMETRY=false`` turns it on.

Browse with ``mlflow ui --backend-store-uri sqlite:///mlflow.db``.
"""

from __future__ import annotations

import dataclasses
import os
import sqlite3
from pathlib import Path
from typing import Any

os.environ.setdefault("MLFLOW_DISABLE_TELEMETRY", "true")

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


def artifact_root(uri: str, configured: str | None = None) -> str:
    """Artifact root for the experiments of store ``uri``: ``configured``, else the
    ``mlartifacts`` folder beside a local SQLite store, else ``<repo>/mlartifacts``."""
    if configured:
        return configured if "://" in configured else Path(configured).resolve().as_uri()
    if uri.startswith("sqlite:///"):
        return (Path(uri[len("sqlite:///") :]).resolve().parent / ARTIFACTS).as_uri()
    return (repo_root() / ARTIFACTS).as_uri()


def _relocate(uri: str, experiment_id: str, root: str) -> None:
    """Point experiment ``experiment_id`` of a local SQLite store at ``root/<id>``."""
    db = uri[len("sqlite:///") :]
    with sqlite3.connect(db) as con:
        con.execute(
            "UPDATE experiments SET artifact_location = ? WHERE experiment_id = ?",
            (f"{root}/{experiment_id}", int(experiment_id)),
        )


def experiment_id(name: str, uri: str, configured_root: str | None = None) -> str:
    """The id of experiment ``name`` in store ``uri``, created with this repository's
    artifact root if new, and re-pointed at it if a local store names another root."""
    from mlflow import MlflowClient

    client = MlflowClient(uri)
    root = artifact_root(uri, configured_root)
    exp = client.get_experiment_by_name(name)
    if exp is None:
        return client.create_experiment(name, artifact_location=f"{root}/{name}")
    local = uri.startswith("sqlite:///") and not configured_root
    if local and not exp.artifact_location.startswith(root):
        _relocate(uri, exp.experiment_id, root)
    return exp.experiment_id


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


def run_tags(kind: str, scale: str, **extra: str) -> dict[str, str]:
    """Tags of a run: kind (``vertexnet``, ``nrrtnet``, ``evaluation``), scale, git commit,
    DVC stage / experiment (when run by DVC) and ``extra``."""
    env = os.environ
    return {
        "kind": kind,
        "network": kind,  # kept for older queries; the network name for training runs
        "scale": scale,
        "git_commit": git_commit(),
        "dvc_stage": env.get("DVC_STAGE", "none"),
        "dvc_experiment": env.get("DVC_EXP_NAME", "none"),
        "dvc_baseline": env.get("DVC_EXP_BASELINE_REV", "none"),
        **extra,
    }


def flat_params(cfg, prefix: str = "") -> dict[str, Any]:
    """A (nested) config flattened to ``{"a.b.c": value}`` with scalar values: lists become
    comma-separated text, ``None`` the text ``null``; for MLflow params."""
    from omegaconf import DictConfig, OmegaConf

    node = OmegaConf.to_container(cfg, resolve=True) if isinstance(cfg, DictConfig) else cfg
    out: dict[str, Any] = {}
    for key, value in node.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(flat_params(value, name + "."))
        elif isinstance(value, list | tuple):
            out[name] = ",".join(str(v) for v in value)
        else:
            out[name] = "null" if value is None else value
    return out


def mark_stale_runs(uri: str, exp_id: str, tags: dict[str, str]) -> list[str]:
    """Mark RUNNING runs of experiment ``exp_id`` whose ``dvc_stage`` and ``kind`` tags equal
    ``tags``' as KILLED (a killed process cannot end its own run); returns their ids."""
    from mlflow import MlflowClient

    client = MlflowClient(uri)
    query = (
        f"attributes.status = 'RUNNING' and tags.kind = '{tags['kind']}' "
        f"and tags.dvc_stage = '{tags['dvc_stage']}' and tags.scale = '{tags['scale']}'"
    )
    stale = client.search_runs([exp_id], filter_string=query)
    for run in stale:
        client.set_terminated(run.info.run_id, status="KILLED")
    return [r.info.run_id for r in stale]


@dataclasses.dataclass
class LoggerConfig:
    """The ``logger`` section (``conf/logger/mlflow.yaml``): whether and where runs go."""

    enabled: bool
    uri: str | None
    experiment: str
    artifact_location: str | None
    log_model: bool
    registry_prefix: str | None
    lightning: dict

    def validate(self) -> None:
        if not self.experiment:
            from vnrrt.config import ConfigError

            raise ConfigError("invalid config value logger.experiment: an empty name")


def metric_name(*parts: str) -> str:
    """An MLflow metric name from parts joined by ``/``: ``@`` becomes ``_tau``, any other
    character MLflow does not allow in a name (``[]{}()+``...) ``_``."""
    import re

    return "/".join(re.sub(r"[^\w\-. :/]", "_", p.replace("@", "_tau")) for p in parts)


def flat_metrics(tree: dict, prefix: tuple = ()) -> dict[str, float]:
    """The finite numbers of a nested dict as ``{metric_name(*path): value}``."""
    import math

    out = {}
    for k, v in tree.items():
        if isinstance(v, dict):
            out.update(flat_metrics(v, (*prefix, str(k))))
        elif isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v):
            out[metric_name(*prefix, str(k))] = float(v)
    return out
