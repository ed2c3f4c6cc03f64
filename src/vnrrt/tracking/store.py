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
  runs named ``<network> <scale>``, ``predict <scale>``, ``ideas <scale>`` and ``evaluation
  <scale>``, followed by an ablation's overrides (``evaluation quick tau=0.7``:
  :func:`run_name`), tagged with kind, scale, git commit, DVC stage and experiment, and the
  overrides in full (``overrides``: ``planner.tau=0.7``, or ``none``); params spelled
  as in YAML (:func:`param_text`). What each run holds: ``vnrrt.training.runs``,
  ``vnrrt.predict.runs``, ``vnrrt.evaluation.*.runs``; lineage between them:
  :mod:`vnrrt.tracking.lineage`.
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
  (:func:`mark_stale_runs`, called by :func:`open_experiment`).

Browse with ``mlflow ui --backend-store-uri sqlite:///mlflow.db``.
"""

from __future__ import annotations

import dataclasses
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
    DVC stage / experiment (when run by DVC), the host and process making it and ``extra``."""
    env = os.environ
    return {
        "host": socket.gethostname(),
        "pid": str(os.getpid()),
        "kind": kind,
        "network": kind,  # kept for older queries; the network name for training runs
        "scale": scale,
        "git_commit": git_commit(),
        "dvc_stage": env.get("DVC_STAGE", "none"),
        "dvc_experiment": env.get("DVC_EXP_NAME", "none"),
        "dvc_baseline": env.get("DVC_EXP_BASELINE_REV", "none"),
        "overrides": " ".join(f"{k}={v}" for k, v in overrides().items()) or "none",
        **extra,
    }


def overrides(params: str | Path = "params.yaml") -> dict[str, str]:
    """The settings of the run's ``params`` file that differ from ``conf/``'s default
    composition at the same scale (what ``dvc exp run -S ...`` changed), as ``{"a.b":
    text}`` in key order; ``{}`` where the file is missing or unreadable (a library call)."""
    path = Path(params).resolve()
    stat = path.stat() if path.is_file() else None
    return dict(_overrides(str(path), stat and (stat.st_mtime_ns, stat.st_size)))


@functools.cache
def _overrides(params: str, version) -> tuple[tuple[str, str], ...]:
    """:func:`overrides` of one version (mtime, size) of the file, composed once."""
    from vnrrt.config import ConfigError, compose, load_params

    try:
        ran = flat_params(load_params(params))
        default = flat_params(compose([f"scale={ran.get('scale.name', 'quick')}"]))
    except (ConfigError, OSError):
        return ()
    return tuple((k, v) for k, v in ran.items() if default.get(k) != v)


def override_text(changed: dict[str, str]) -> str:
    """``changed`` (:func:`overrides`) as a run name's suffix: ``tau=0.7 eps=0.02``, each
    setting by its last key unless two share it (then in full); ``""`` for none."""
    last = [k.rsplit(".", 1)[-1] for k in changed]
    names = [k if last.count(k.rsplit(".", 1)[-1]) > 1 else k.rsplit(".", 1)[-1] for k in changed]
    return " ".join(f"{n}={v}" for n, v in zip(names, changed.values(), strict=True))


def run_name(base: str, params: str | Path = "params.yaml") -> str:
    """``base`` (e.g. ``evaluation quick``) followed by the run's overrides, if any: an
    ablation's runs read ``evaluation quick tau=0.7`` beside the default's."""
    suffix = override_text(overrides(params))
    return f"{base} {suffix}" if suffix else base


def param_text(value) -> str:
    """A scalar as an MLflow param: booleans and ``None`` spelled as in YAML (``true``,
    ``false``, ``null``), everything else as ``str``."""
    if isinstance(value, bool):
        return "true" if value else "false"
    return "null" if value is None else str(value)


def flat_params(cfg, prefix: str = "") -> dict[str, str]:
    """A (nested) config flattened to ``{"a.b.c": text}`` for MLflow params: scalars as
    :func:`param_text`, lists as comma-separated text."""
    from omegaconf import DictConfig, OmegaConf

    node = OmegaConf.to_container(cfg, resolve=True) if isinstance(cfg, DictConfig) else cfg
    out: dict[str, str] = {}
    for key, value in node.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(flat_params(value, name + "."))
        elif isinstance(value, list | tuple):
            out[name] = ",".join(param_text(v) for v in value)
        else:
            out[name] = param_text(value)
    return out


def _gone(tags: dict[str, str]) -> bool:
    """Whether the process that made a run with ``tags`` no longer runs: a run of another host
    is never known gone; one without host and pid tags (older runs) always is."""
    if "host" not in tags or "pid" not in tags:
        return True
    if tags["host"] != socket.gethostname() or not tags["pid"].isdigit():
        return False
    pid = int(tags["pid"])
    if pid == os.getpid():  # this process is starting the stage again: its old run is over
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except PermissionError:  # alive, another user's
        return False
    return False


def mark_stale_runs(uri: str, exp_id: str, tags: dict[str, str]) -> list[str]:
    """Mark RUNNING runs of experiment ``exp_id`` whose ``kind``, ``dvc_stage`` and ``scale``
    tags equal ``tags``' and whose process is gone (:func:`_gone`) KILLED: a killed process
    cannot end its own runs, nested runs included. Returns their ids."""
    client = open_store(uri)
    query = (
        f"attributes.status = 'RUNNING' and tags.kind = '{tags['kind']}' "
        f"and tags.dvc_stage = '{tags['dvc_stage']}' and tags.scale = '{tags['scale']}'"
    )
    stale = [r for r in client.search_runs([exp_id], filter_string=query) if _gone(r.data.tags)]
    for run in stale:
        client.set_terminated(run.info.run_id, status="KILLED")
    return [r.info.run_id for r in stale]


def open_experiment(logger, kind: str, scale: str, **extra: str) -> tuple[str, str, dict]:
    """What a stage needs to log its MLflow runs, given its ``logger`` config (``uri``,
    ``experiment``, ``artifact_location``): ``(store uri, experiment id, run tags)``, after
    checking the store and marking the stale runs of this kind, stage and scale KILLED."""
    uri = tracking_uri(logger.uri)
    exp = experiment_id(logger.experiment, uri, logger.artifact_location)
    tags = run_tags(kind, scale, **extra)
    mark_stale_runs(uri, exp, tags)
    return uri, exp, tags


@dataclasses.dataclass
class LoggerConfig:
    """The ``logger`` section (``conf/logger/mlflow.yaml``): whether and where runs go."""

    enabled: bool
    uri: str | None
    experiment: str
    artifact_location: str | None
    log_model: bool
    registry_prefix: str | None
    system_metrics_seconds: float | None
    lightning: dict

    def validate(self) -> None:
        from vnrrt.config import ConfigError

        if not self.experiment:
            raise ConfigError("invalid config value logger.experiment: an empty name")
        seconds = self.system_metrics_seconds
        if seconds is not None and not seconds > 0:
            raise ConfigError(
                f"invalid config value logger.system_metrics_seconds={seconds!r}: a positive "
                "number of seconds, or null for no system metrics"
            )


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
