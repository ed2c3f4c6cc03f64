"""MLflow tracking: where runs go (this module) and what a stage's runs carry
(:mod:`vnrrt.tracking.experiments`: experiments, names, tags, params, stale runs).

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
  runs named ``<network> <scale>``, ``predict <scale>``, ``ideas <scale>`` and ``evaluation
  <scale>``, followed by an ablation's overrides (``evaluation quick tau=0.7``:
  :func:`~vnrrt.tracking.experiments.run_name`), tagged with kind, scale, git commit, DVC
  stage and experiment, and the overrides in full (``overrides``: ``planner.tau=0.7``, or
  ``none``); params spelled as in YAML (:func:`~vnrrt.tracking.experiments.param_text`).
  What each run holds: ``vnrrt.training.runs``, ``vnrrt.predict.runs``,
  ``vnrrt.studies.*.runs``; lineage between them: :mod:`vnrrt.tracking.lineage`.
* **Telemetry** is off (``MLFLOW_DISABLE_TELEMETRY=true`` unless set otherwise before vnrrt
  is imported): stages make no network calls. ``MLFLOW_DISABLE_TELEMETRY=false`` turns it on.
* **Services**: a tracking server (``http(s)://``) or database (``postgresql://`` ...) is
  checked once per process, within :data:`CHECK_SECONDS`, before a stage's first MLflow call
  (:func:`check_store`): an unreachable one is a one-line :class:`TrackingError`, not minutes
  of MLflow's retries. A SQLite store locked by another process is waited for: opening it is
  retried for :data:`LOCK_WAIT_SECONDS` (MLflow itself gives up after SQLite's 5 s there; its
  later calls wait up to 20 s each).
* **Stale runs**: runs carry the host and process id that made them; a stage that starts
  marks the RUNNING runs of its kind, stage and scale whose process is gone KILLED
  (:func:`vnrrt.tracking.experiments.mark_stale_runs`, called by its
  :func:`~vnrrt.tracking.experiments.open_experiment`).

Browse with ``mlflow ui --backend-store-uri sqlite:///mlflow.db``.
"""

from __future__ import annotations

import functools
import json
import os
import socket
import sqlite3
import time
import urllib.error
import urllib.request
from pathlib import Path
from urllib.parse import urlsplit

os.environ.setdefault("MLFLOW_DISABLE_TELEMETRY", "true")

DB_NAME = "mlflow.db"
ARTIFACTS = "mlartifacts"
CHECK_SECONDS = 5.0  # how long a tracking server or database may take to answer the check
LOCK_WAIT_SECONDS = 60.0  # how long opening a locked SQLite store is retried
DB_PORTS = {"postgresql": 5432, "mysql": 3306, "mssql": 1433}  # default ports of database URIs


class TrackingError(ValueError):
    """The tracking store (``logger.uri`` / ``MLFLOW_TRACKING_URI``) cannot be used; the
    message names it and what failed."""


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


@functools.lru_cache(maxsize=16)
def check_store(uri: str, timeout: float = CHECK_SECONDS) -> None:
    """Raise :class:`TrackingError` within about ``timeout`` seconds when the tracking server
    (``http(s)://``) does not answer or is not MLflow's (:func:`_check_server`), the
    database server (``postgresql://`` etc.: its port) of ``uri`` does not answer, or a local
    SQLite store is not an intact database (:func:`_check_sqlite`). A store that passed is
    not checked again in this process."""
    parts = urlsplit(uri)
    scheme = parts.scheme.split("+")[0]
    fix = "start it, or set logger.uri / MLFLOW_TRACKING_URI to a reachable store"
    if scheme in ("http", "https"):
        _check_server(uri, timeout, fix)
    elif scheme == "sqlite" and uri.startswith("sqlite:///"):
        _check_sqlite(Path(uri[len("sqlite:///") :]))
    elif scheme in DB_PORTS and parts.hostname:
        address = (parts.hostname, parts.port or DB_PORTS[scheme])
        try:
            socket.create_connection(address, timeout=timeout).close()
        except OSError as err:
            raise TrackingError(f"tracking database {parts.hostname}:{address[1]} of {scheme} "
                                f"store does not answer ({err}): {fix}") from None  # fmt: skip


# An MLflow REST call every tracking server answers with a JSON object (its experiments).
MLFLOW_PROBE = "/api/2.0/mlflow/experiments/search?max_results=1"


def _check_server(uri: str, timeout: float, fix: str) -> None:
    """Raise :class:`TrackingError` unless the server at ``uri`` answers MLflow's REST API
    (:data:`MLFLOW_PROBE`) with JSON; one asking for credentials (HTTP 401, 403) passes: MLflow
    sends them (``MLFLOW_TRACKING_USERNAME``, a token)."""
    try:
        with urllib.request.urlopen(uri.rstrip("/") + MLFLOW_PROBE, timeout=timeout) as answer:
            body = answer.read(1 << 20)
    except urllib.error.HTTPError as err:  # it answered
        if err.code in (401, 403):
            return
        if err.code >= 500:
            raise TrackingError(f"tracking server {uri} answers HTTP {err.code}: {fix}") from None
        body = None
        status = f"HTTP {err.code}"
    except (OSError, ValueError) as err:  # URLError, timeouts, refused connections
        why = getattr(err, "reason", err)
        raise TrackingError(f"tracking server {uri} does not answer ({why}): {fix}") from None
    else:
        status = "no JSON object"
        try:
            body = json.loads(body)
        except ValueError:
            body = None
    if not isinstance(body, dict):
        raise TrackingError(f"{uri} answers but is not an MLflow tracking server (GET "
                            f"{MLFLOW_PROBE}: {status}): {fix}")  # fmt: skip


def _check_sqlite(db: Path) -> None:
    """Raise :class:`TrackingError` naming ``db`` when it exists but is not an intact SQLite
    database (another kind of file, truncated, damaged); a missing file is a new store."""
    if not db.exists():
        return
    fix = "move it aside (a new store is created) or set logger.uri / MLFLOW_TRACKING_URI"
    try:
        with open(db, "rb") as f:
            if db.stat().st_size and f.read(16) != b"SQLite format 3\x00":
                raise sqlite3.DatabaseError("file is not a database")
        con = sqlite3.connect(
            f"{db.resolve().as_uri()}?mode=ro", uri=True, timeout=LOCK_WAIT_SECONDS
        )
        try:
            problems = [r[0] for r in con.execute("PRAGMA quick_check")]
        finally:
            con.close()
    except (sqlite3.Error, OSError) as err:
        raise TrackingError(f"tracking store {db} is not a readable SQLite database ({err}): "
                            f"{fix}") from None  # fmt: skip
    if problems != ["ok"]:
        why = " ".join(str(problems[0]).split())[:200]
        raise TrackingError(f"tracking store {db} is damaged ({why}): {fix}")


def open_store(uri: str, wait: float = LOCK_WAIT_SECONDS):
    """An ``MlflowClient`` of store ``uri`` whose store is open (checked with
    :func:`check_store`); opening a SQLite store that another process holds locked is
    retried for up to ``wait`` seconds."""
    from mlflow import MlflowClient

    check_store(uri)
    deadline, pause = time.monotonic() + wait, 0.25
    while True:
        try:
            client = MlflowClient(uri)  # opens (and caches) the store
            client.search_experiments(max_results=1)
            return client
        except Exception as err:  # MlflowException or SQLAlchemy's OperationalError
            if "database is locked" not in str(err) or time.monotonic() + pause > deadline:
                raise
        time.sleep(pause)
        pause = min(2 * pause, 4.0)


def _relocate(uri: str, experiment_id: str, root: str) -> None:
    """Point experiment ``experiment_id`` of a local SQLite store at ``root/<id>``."""
    db = uri[len("sqlite:///") :]
    with sqlite3.connect(db, timeout=LOCK_WAIT_SECONDS) as con:
        con.execute(
            "UPDATE experiments SET artifact_location = ? WHERE experiment_id = ?",
            (f"{root}/{experiment_id}", int(experiment_id)),
        )


def experiment_id(name: str, uri: str, configured_root: str | None = None) -> str:
    """The id of experiment ``name`` in store ``uri``, created with this repository's
    artifact root if new, and re-pointed at it if a local store names another root."""
    client = open_store(uri)
    root = artifact_root(uri, configured_root)
    exp = client.get_experiment_by_name(name)
    if exp is None:
        return client.create_experiment(name, artifact_location=f"{root}/{name}")
    local = uri.startswith("sqlite:///") and not configured_root
    if local and not exp.artifact_location.startswith(root):
        _relocate(uri, exp.experiment_id, root)
    return exp.experiment_id
