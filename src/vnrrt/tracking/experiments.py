"""The runs a stage logs to MLflow: its experiment opened (:func:`open_experiment`), its name
and tags (kind, scale, git commit, DVC stage and experiment, an ablation's overrides, host and
process), its params spelled as in YAML and its metrics flattened, and the stale runs of a
killed process marked KILLED. Where the runs go: :mod:`vnrrt.tracking.store`; the ``logger``
section: :class:`LoggerConfig`.
"""

from __future__ import annotations

import dataclasses
import functools
import os
import socket
from pathlib import Path

from vnrrt.tracking.store import experiment_id, open_store, repo_root, tracking_uri


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
