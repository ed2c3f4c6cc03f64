"""Every file the pipeline writes or reads, once: the typed ``paths`` section
(``conf/paths/default.yaml``) and the single table of each stage's outputs
(:func:`stage_outputs`).

Stages get their file names from a :class:`Paths` (never by composing names of their own);
``dvc.yaml`` writes the same names again, as DVC needs them, and
``tests/test_stage_outputs.py`` checks that both agree and that each stage writes exactly its
outputs. Files of a part ``k``, a shard or a network are named here too (the format modules
re-export :func:`shard_file`, :func:`heatmaps_part_file` and :func:`table_part_file`). A leaf
module: it imports nothing of vnrrt but the config errors.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path

from vnrrt.config import ConfigError


@dataclass(frozen=True)
class Paths:
    """The ``paths`` section: folders and files relative to the repository root."""

    data: str
    validated: str
    shards: str
    manifest: str
    named_maps: str
    instances: str
    heatmaps: str
    timing: str
    trials: str
    trials_table: str
    reuse: str
    baseline: str  # the default run's claims (stage report; an ablation compares)
    summary: str
    oracle: str
    regime: str
    ideas_summary: str
    budget: str
    models: str
    budget_models: str
    figures: str
    metrics: str
    plots: str
    report: str
    ideas_report: str
    budget_report: str
    paper_tables: str
    paper_settings: str
    gpu_runs: str
    gpu_returned: str
    named_maps_figure: str
    heatmaps_figure: str
    data_metrics: str
    predict_metrics: str
    headline: str
    convergence: str
    convergence_plots: str
    evaluation_figures: str
    ideas_figures: str
    budget_summary: str
    budget_figures: str
    movingai: str
    bench_maps_trials: str
    bench_maps_summary: str
    bench_maps_report: str

    def validate(self) -> None:
        """Raise :class:`ConfigError` for an empty path."""
        for f in dataclasses.fields(self):
            if not str(getattr(self, f.name)).strip():
                raise ConfigError(f"invalid config value paths.{f.name}: an empty path")

    def shard(self, shard_id: int) -> Path:
        """Shard ``shard_id`` (stage ``shard@<id>``)."""
        return shard_file(self.shards, shard_id)

    def reuse_store(self, stage: str) -> Path:
        """The kept trial rows of stage ``stage``'s configurations (a cache, not an output:
        :mod:`vnrrt.evaluation.reuse`)."""
        return Path(self.reuse) / stage

    def checkpoint(self, network: str) -> Path:
        """The trained network's checkpoint (stage ``train@<network>``)."""
        return Path(self.models) / f"{network}.ckpt"

    def checksum(self, network: str) -> Path:
        """The sidecar sha256 of :meth:`checkpoint`."""
        return Path(self.models) / f"{network}.ckpt.sha256"

    def train_metrics(self, network: str) -> Path:
        """The training metrics of ``network`` (stage ``train@<network>``)."""
        return Path(self.metrics) / f"train_{network}.json"

    def run_folder(self, network: str) -> Path:
        """Lightning's last-epoch checkpoints of a training in progress (removed after)."""
        return Path(self.models) / "checkpoints" / network

    def training(self, network: str) -> TrainFiles:
        """The files of stage ``train@<network>``."""
        return TrainFiles(self.checkpoint(network), self.checksum(network),
                          self.train_metrics(network), self.run_folder(network))  # fmt: skip

    def budget_training(self, network: str, steps: int, seed: int) -> TrainFiles:
        """The files of stage ``budget_train@<network>-<steps>-<seed>``: the checkpoint under
        ``budget_models/<steps>-<seed>/``, the metrics in :meth:`budget_folder`."""
        models = Path(self.budget_models) / budget_run(steps, seed)
        return TrainFiles(models / f"{network}.ckpt", models / f"{network}.ckpt.sha256",
                          self.budget_folder(steps, seed) / f"train_{network}.json",
                          models / "checkpoints" / network)  # fmt: skip

    def budget_folder(self, steps: int, seed: int) -> Path:
        """What the stages of training budget ``steps`` at training seed ``seed`` write besides
        the checkpoints."""
        return Path(self.budget) / budget_run(steps, seed)

    def budget_heatmaps(self, steps: int, seed: int) -> Path:
        """The folder of the budget's heatmaps (``part_0.npz``, stage ``budget_predict``)."""
        return self.budget_folder(steps, seed) / "heatmaps"

    def budget_predict_metrics(self, steps: int, seed: int) -> Path:
        """The budget's heatmap metrics, as ``predict_metrics`` writes them (and a uniform
        map's)."""
        return self.budget_folder(steps, seed) / "predict.json"

    def budget_trials(self, steps: int, seed: int) -> Path:
        """The budget's trial table (stage ``budget_trials@<steps>-<seed>``)."""
        return self.budget_folder(steps, seed) / "trials.csv"

    def heatmaps_part(self, part: int) -> Path:
        """Heatmaps of prediction part ``part`` (stage ``predict@<part>``)."""
        return heatmaps_part_file(self.heatmaps, part)

    def timing_part(self, part: int) -> Path:
        """Inference times of prediction part ``part`` (stage ``predict@<part>``)."""
        return Path(self.timing) / f"predict_{part}.json"

    def trials_part(self, part: int) -> Path:
        """Trial table of part ``part`` (stage ``trials@<part>``)."""
        return table_part_file(self.trials, part)

    def oracle_part(self, part: int) -> Path:
        """Trial table of oracle-study part ``part`` (stage ``oracle@<part>``)."""
        return table_part_file(self.oracle, part)

    def regime_part(self, part: int) -> Path:
        """Trial table of regime-sweep part ``part`` (stage ``regime@<part>``)."""
        return table_part_file(self.regime, part)


@dataclass(frozen=True)
class TrainFiles:
    """What one training writes: the final ``checkpoint``, its sidecar ``checksum``, the
    ``metrics`` JSON, and the ``run_folder`` of Lightning's ``last.ckpt`` (while it runs)."""

    checkpoint: Path
    checksum: Path
    metrics: Path
    run_folder: Path

    def outputs(self) -> list[Path]:
        """The files the training's stage declares (the run folder is removed after)."""
        return [self.checkpoint, self.checksum, self.metrics]


def shard_file(shards_dir: str | Path, shard_id: int) -> Path:
    """Shard ``shard_id`` in ``shards_dir``: ``shard_<id>.npz``."""
    return Path(shards_dir) / f"shard_{shard_id}.npz"


def heatmaps_part_file(directory: str | Path, part: int) -> Path:
    """The heatmaps of prediction part ``part`` in ``directory``: ``part_<part>.npz``."""
    return Path(directory) / f"part_{part}.npz"


def table_part_file(directory: str | Path, part: int) -> Path:
    """The trial table of part ``part`` in ``directory``: ``part_<part>.csv``."""
    return Path(directory) / f"part_{part}.csv"


def stage_outputs(stage: str, paths: Paths, item=None) -> list[Path]:
    """The files (and output folders) stage ``stage`` (``item``: its part, shard id, network,
    budget steps or ``<network>-<steps>``) writes, as ``dvc.yaml`` declares them."""
    p = paths
    table = {
        "validate": lambda: [p.validated],
        "shard": lambda: [p.shard(int(item))],
        "named_maps": lambda: [p.named_maps, p.named_maps_figure],
        "manifest": lambda: [p.manifest, p.data_metrics],
        "instances": lambda: [p.instances],
        "train": lambda: p.training(item).outputs(),
        "budget_train": lambda: p.budget_training(*_network_run(item)).outputs(),
        "budget_predict": lambda: [
            heatmaps_part_file(p.budget_heatmaps(*parse_run(item)), 0),
            p.budget_predict_metrics(*parse_run(item)),
        ],
        "budget_trials": lambda: [p.budget_trials(*parse_run(item))],
        "budget_report": lambda: [p.budget_summary, p.budget_report, p.budget_figures],
        "bench_maps": lambda: [p.bench_maps_trials, p.bench_maps_summary, p.bench_maps_report],
        "predict": lambda: [p.heatmaps_part(int(item)), p.timing_part(int(item))],
        "predict_metrics": lambda: [p.predict_metrics, p.heatmaps_figure],
        "trials": lambda: [p.trials_part(int(item))],
        "oracle": lambda: [p.oracle_part(int(item))],
        "regime": lambda: [p.regime_part(int(item))],
        "ideas": lambda: [p.ideas_summary, p.ideas_report, p.ideas_figures],
        "evaluate": lambda: [p.trials_table, p.summary, p.convergence, p.convergence_plots],
        "report": lambda: [p.report, p.headline, p.evaluation_figures],
    }
    if stage not in table:
        raise ConfigError(f"no outputs known for stage {stage!r}; known: {sorted(table)}")
    return [Path(f) for f in table[stage]()]


def budget_run(steps: int, seed: int) -> str:
    """``600-1``: the name of a training budget's run (``steps`` optimizer steps at training
    seed ``seed``), as DVC names its stages' matrix items and its folders."""
    return f"{int(steps)}-{int(seed)}"


def parse_run(item: str) -> tuple[int, int]:
    """``(600, 1)`` of a budget run's name ``600-1`` (:func:`budget_run`)."""
    steps, _, seed = str(item).partition("-")
    if not (steps.isdigit() and seed.isdigit()):
        raise ConfigError(f"budget item {item!r} is not <steps>-<seed>")
    return int(steps), int(seed)


def _network_run(item: str) -> tuple[str, int, int]:
    """``("vertexnet", 600, 1)`` of a ``budget_train`` item ``vertexnet-600-1`` (DVC's
    matrix name)."""
    parts = str(item).rsplit("-", 2)
    if len(parts) != 3 or not parts[0]:
        raise ConfigError(f"budget_train item {item!r} is not <network>-<steps>-<seed>")
    return (parts[0], *parse_run(f"{parts[1]}-{parts[2]}"))
