"""Trial rows kept by everything that determines them, so that an ablation re-runs only the
configurations whose inputs changed and reuses the other configurations' rows, timings
included (a verdict whose configurations were all reused cannot move).

A *configuration* here is one (configuration key, regime cell) of a stage's jobs. Its
digest is the sha256 of, per job in order: the instance (every field of
:class:`~vnrrt.data.instances.EvalInstance`, with the one heatmap the key samples), the
job's key, stop rule, trial range and regime cell, the planner settings the job runs with
(:func:`run_settings`: the cell's settings with the key's informed flag and tau, less what
its run does not read), the heatmap
settings (:class:`~vnrrt.evaluation.trials.TrialSettings`), the global seed (the trials'
seeds derive from it and the instance index), and the source of the code that plans and
measures (:func:`code_digest`). A configuration with the same digest ran the same trials, so
its rows are read back from ``<store>/<digest>.csv`` instead of planned again; the rows' ``seq``
is renumbered to the current protocol's order.

The store is a cache beside the pipeline's outputs (``paths.reuse``), never an output:
deleting it only costs time. Files are written atomically (a run interrupted mid-stage keeps
the configurations it finished).
"""

from __future__ import annotations

import dataclasses
import hashlib
import importlib
import logging
from pathlib import Path

import numpy as np
import pandas as pd

from vnrrt.evaluation.protocol import TrialJob, timed_twice
from vnrrt.evaluation.table import TableError, read_table, write_table

log = logging.getLogger(__name__)

# What decides a trial's rows besides its inputs: the planners, the samplers and heatmap
# sources, the measurements and the row schema.
CODE_MODULES = (
    "vnrrt.planners",
    "vnrrt.evaluation.trials",
    "vnrrt.evaluation.sampling",
    "vnrrt.evaluation.sources",
    "vnrrt.evaluation.oracles",
    "vnrrt.evaluation.table",
    "vnrrt.search",
)


def _feed(h, obj) -> None:
    """Feed ``obj`` (arrays, dataclasses, mappings, sequences, scalars) into the hash ``h``
    unambiguously (type tags, shapes, dtypes, lengths)."""
    if isinstance(obj, np.ndarray):
        h.update(f"A{obj.dtype.str}{obj.shape}".encode())
        h.update(np.ascontiguousarray(obj).tobytes())
    elif dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        h.update(f"D{type(obj).__name__}".encode())
        _feed(h, {f.name: getattr(obj, f.name) for f in dataclasses.fields(obj)})
    elif isinstance(obj, dict):
        h.update(f"M{len(obj)}".encode())
        for k in sorted(obj, key=str):
            _feed(h, str(k))
            _feed(h, obj[k])
    elif isinstance(obj, list | tuple):
        h.update(f"L{len(obj)}".encode())
        for x in obj:
            _feed(h, x)
    else:  # scalars: repr round-trips floats exactly and tells 1 from 1.0 and True
        h.update(f"S{type(obj).__name__}:{obj!r};".encode())


def digest(*objs) -> str:
    """sha256 (hex) of ``objs`` fed by :func:`_feed`."""
    h = hashlib.sha256()
    for obj in objs:
        _feed(h, obj)
    return h.hexdigest()


def _module_files(name: str) -> list[Path]:
    module = importlib.import_module(name)
    path = Path(module.__file__)
    return sorted(path.parent.rglob("*.py")) if path.name == "__init__.py" else [path]


def code_digest(modules: tuple[str, ...] = CODE_MODULES) -> str:
    """sha256 of the source of ``modules`` (a package: every ``.py`` file under it)."""
    h = hashlib.sha256()
    for name in modules:
        for path in _module_files(name):
            h.update(path.name.encode())
            h.update(path.read_bytes())
    return h.hexdigest()


def job_config(job: TrialJob, configs: dict):
    """The planner settings job ``job`` runs with: its regime cell's (``configs[job.regime]``,
    a :class:`~vnrrt.planners.PlannerConfig`) with the key's informed flag and tau."""
    config = configs[job.regime]
    if job.key.informed:
        config = config.replace(informed=True)
    if job.key.tau is not None:
        config = config.replace(tau=job.key.tau)
    return config


def run_settings(job: TrialJob, configs: dict) -> dict:
    """The planner settings that decide job ``job``'s trials: :func:`job_config`'s fields
    without ``taus`` (the thresholds a study evaluates, read by no planner run) and, for a key
    without a threshold, without ``tau`` (read by M-VNRRT* only), so that a tau ablation
    leaves the other configurations' rows valid."""
    config = job_config(job, configs)
    out = {f.name: getattr(config, f.name) for f in dataclasses.fields(config)}
    out.pop("taus", None)
    if job.key.tau is None:
        out.pop("tau", None)
    return out


def group_digests(items: list, configs: dict, heat, seed: int, code: str,
                  repeat: bool = False) -> dict:  # fmt: skip
    """``{(key text, regime): (digest, [item index, ...])}`` of ``items`` (``(job, instance)``
    pairs, the instance holding only the heatmap the job samples), in first-seen order;
    ``repeat``: whether the stage times some jobs twice (it changes only their digests:
    :func:`~vnrrt.evaluation.protocol.timed_twice`)."""
    groups: dict[tuple[str, str], list[int]] = {}
    for i, (job, _) in enumerate(items):
        groups.setdefault((job.key.text, job.regime), []).append(i)
    out = {}
    for group, idx in groups.items():
        h = hashlib.sha256(f"{code}:{seed}:{digest(heat)}".encode())
        for i in idx:
            job, inst = items[i]
            fields = (job.instance, job.key.text, job.stop, job.first, job.count, job.regime,
                      repeat and timed_twice(job))  # fmt: skip
            h.update(digest(fields, run_settings(job, configs), inst).encode())
        out[group] = (h.hexdigest(), idx)
    return out


def stored(store: Path, key: str) -> Path:
    """The file of the configuration with digest ``key``."""
    return Path(store) / f"{key}.csv"


def load(store: Path, key: str, jobs: list[TrialJob]) -> pd.DataFrame | None:
    """The kept rows of a configuration (digest ``key``) renumbered for ``jobs``, its jobs in
    the current protocol; None where none are kept or the file does not fit them (then the
    configuration runs again)."""
    path = stored(store, key)
    if not path.is_file():
        return None
    try:
        table = read_table(path)
    except TableError as err:
        log.warning("kept trial rows %s unreadable, running again: %s", path, err)
        return None
    seqs = {
        (job.instance, job.stop, trial, job.regime): job.seq + trial - job.first
        for job in jobs
        for trial in range(job.first, job.first + job.count)
    }
    where = zip(table["instance"], table["stop"], table["trial"], table["regime"], strict=True)
    seq = [seqs.get(w) for w in where]
    if len(table) != len(seqs) or None in seq or len(set(seq)) != len(seq):
        log.warning("kept trial rows %s do not match their jobs, running again", path)
        return None
    return table.assign(seq=np.asarray(seq, dtype=np.int64))


def keep(store: Path, key: str, table: pd.DataFrame) -> None:
    """Keep a configuration's rows (digest ``key``), atomically."""
    Path(store).mkdir(parents=True, exist_ok=True)
    write_table(table, stored(store, key))


def summary(reused: int, total: int) -> str:
    """The log line of a stage's reuse."""
    return f"reused {reused} of {total} configurations (kept trial rows; {total - reused} run)"
