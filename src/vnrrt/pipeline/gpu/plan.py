"""The settings of a GPU run: the command line, the time budget and its shares, the bundle's
config (plain JSON from :mod:`vnrrt.pipeline.gpu.bundle`) and the objects built from it
without Hydra.

Shares are fractions of the budget (seconds of wall-clock time from the start of the run):
``data`` for generating and labelling shards, ``probe`` for the batch, loader and compile
probes, ``train`` for each network's training (both networks get the same share); the rest
is left for testing, prediction, writing and a margin for the machine's start and transfers.
"""

from __future__ import annotations

import argparse
import functools
import importlib
import json
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

DEVICES = ("cuda", "cpu")
COMPILE_MODES = ("auto", "on", "off")


@dataclass
class RunPlan:
    """One run's arguments (the command line of :mod:`vnrrt.pipeline.gpu.run`)."""

    device: str
    budget_s: float
    bundle: Path
    out: Path
    work: Path
    data_share: float = 0.10
    probe_share: float = 0.08
    train_share: float = 0.30  # per network
    max_shards: int = 100  # 100 x maps_per_shard maps at most (the paper: 10,000 maps)
    min_batch: int = 16
    max_batch: int = 512
    compile: str = "auto"
    compile_min_train_s: float = 600.0  # auto: below this a compile cannot pay back
    workers: int | None = None  # loader workers; None: the config's
    cores: int = 0  # processes for the shards; 0: all cores

    def validate(self) -> None:
        """Raise ``ValueError`` naming the first bad argument."""
        if self.device not in DEVICES:
            raise ValueError(f"--device must be one of {DEVICES}, got {self.device!r}")
        if self.budget_s <= 0:
            raise ValueError(f"--budget must be positive seconds, got {self.budget_s}")
        shares = self.data_share + self.probe_share + 2 * self.train_share
        if min(self.data_share, self.probe_share, self.train_share) <= 0 or shares >= 1:
            raise ValueError(f"shares must be positive with data + probe + 2 train < 1, "
                             f"got {shares:.2f}")  # fmt: skip
        if not 1 <= self.min_batch <= self.max_batch:
            raise ValueError(f"need 1 <= --min-batch <= --max-batch: {self.min_batch}, "
                             f"{self.max_batch}")  # fmt: skip
        if self.compile not in COMPILE_MODES:
            raise ValueError(f"--compile must be one of {COMPILE_MODES}, got {self.compile!r}")
        if self.max_shards < 1 or self.cores < 0 or (self.workers or 0) < 0:
            raise ValueError("--max-shards must be >= 1, --cores and --workers >= 0")
        for name in ("run_config.json", "instances.npz"):
            if not (self.bundle / name).is_file():
                raise ValueError(f"bundle {self.bundle} has no {name} (make it with "
                                 "`python -m vnrrt.pipeline.gpu.bundle`)")  # fmt: skip
        if self.out.resolve() in (self.work.resolve(), *self.work.resolve().parents):
            raise ValueError(f"--work {self.work} must not be inside --out {self.out}")


@dataclass
class Clock:
    """Wall-clock time of the run against its budget, and the seconds of each phase."""

    budget_s: float
    start: float = field(default_factory=time.perf_counter)
    phases: dict[str, float] = field(default_factory=dict)

    def elapsed(self) -> float:
        return time.perf_counter() - self.start

    def left(self) -> float:
        return self.budget_s - self.elapsed()

    def add(self, phase: str, seconds: float) -> None:
        self.phases[phase] = self.phases.get(phase, 0.0) + seconds


def parse_args(argv: list[str] | None = None) -> RunPlan:
    """A validated :class:`RunPlan` from the command line."""
    p = argparse.ArgumentParser(prog="scripts/gpu/paper_network.sh", description=__doc__)
    p.add_argument("--device", required=True, help="cuda | cpu")
    p.add_argument("--budget", type=float, required=True, help="seconds for the whole run")
    p.add_argument("--bundle", type=Path, default=Path("data/gpu/bundle"))
    p.add_argument("--out", type=Path, required=True, help="folder of the returned files")
    p.add_argument("--work", type=Path, default=None, help="scratch folder (default: a temp)")
    for name, default in (("data-share", 0.10), ("probe-share", 0.08), ("train-share", 0.30),
                          ("compile-min-train-s", 600.0)):  # fmt: skip
        p.add_argument(f"--{name}", type=float, default=default)
    for name, default in (("max-shards", 100), ("min-batch", 16), ("max-batch", 512),
                          ("cores", 0)):  # fmt: skip
        p.add_argument(f"--{name}", type=int, default=default)
    p.add_argument("--workers", type=int, default=None, help="loader workers (config's)")
    p.add_argument("--compile", default="auto", help="auto | on | off")
    a = p.parse_args(argv)
    work = a.work or Path(os.environ.get("TMPDIR", "/tmp")) / f"vnrrt-gpu-{os.getpid()}"
    plan = RunPlan(a.device, a.budget, a.bundle, a.out, work, a.data_share, a.probe_share,
                   a.train_share, a.max_shards, a.min_batch, a.max_batch, a.compile,
                   a.compile_min_train_s, a.workers, a.cores)  # fmt: skip
    plan.validate()
    return plan


def load_config(bundle: Path) -> dict:
    """The bundle's ``run_config.json`` (written by
    :func:`vnrrt.pipeline.gpu.bundle.run_config`)."""
    path = bundle / "run_config.json"
    try:
        return json.loads(path.read_text())
    except json.JSONDecodeError as err:
        raise ValueError(f"{path} is not valid JSON: {err}") from None


def build(node):
    """The object of a config node with ``_target_`` (a ``functools.partial`` with
    ``_partial_: true``), keyword arguments built first; other values as they are."""
    if not isinstance(node, dict) or "_target_" not in node:
        return node
    kwargs = {k: build(v) for k, v in node.items() if k not in ("_target_", "_partial_")}
    module, _, name = str(node["_target_"]).rpartition(".")
    try:
        target = getattr(importlib.import_module(module), name)
    except (ImportError, AttributeError, ValueError) as err:
        raise ValueError(f"config _target_ {node['_target_']!r} is not importable: {err}") from None
    return functools.partial(target, **kwargs) if node.get("_partial_") else target(**kwargs)
