"""Validate the whole composed configuration before any work (one entry point).

Used by the ``validate`` DVC stage (:func:`run_validate`), which every other stage depends
on (so ``dvc repro`` and ``dvc exp run -S ...`` stop on a bad value before the first shard
is written), by ``python -m vnrrt.pipeline.params`` (``make params``) and by the Hydra
multirun jobs.
Each section is checked against its typed dataclass; cross-section rules follow. Errors are
:class:`vnrrt.config.ConfigError` naming the key.
"""

from __future__ import annotations

from omegaconf import DictConfig

from vnrrt.config import ConfigError, check, check_parts, section
from vnrrt.config.paths import Paths
from vnrrt.data.config import LabelsConfig, ScaleConfig
from vnrrt.data.targets import ENDPOINTS
from vnrrt.data.targets import TARGETS as NETWORK_TARGETS
from vnrrt.evaluation.config import EvalConfig, OracleConfig, RegimeConfig, StatsConfig
from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.sources import is_oracle
from vnrrt.maps.config import DataConfig
from vnrrt.planners.config import PlannerConfig
from vnrrt.studies.benchmark_maps.config import BenchMapsConfig, map_files
from vnrrt.studies.training_budget.budget import BudgetConfig, batches_per_epoch
from vnrrt.tracking.experiments import LoggerConfig


def _taus(planner: PlannerConfig) -> None:
    for t in planner.taus:
        check(0.0 < t <= 1.0, "planner.taus", planner.taus, "every tau must be in (0, 1]")
    check(0.0 < planner.tau <= 1.0, "planner.tau", planner.tau, "must be in (0, 1]")


def _networks(cfg: DictConfig) -> set[str]:
    nets = cfg.get("networks") or {}
    for name, spec in nets.items():
        target = spec.get("target")
        check(
            target in NETWORK_TARGETS,
            f"networks.{name}.target",
            target,
            f"must be one of {NETWORK_TARGETS}",
        )
        ends = spec.get("endpoints", "both")
        check(ends in ENDPOINTS, f"networks.{name}.endpoints", ends, f"must be one of {ENDPOINTS}")
    train_seed = cfg.get("train", {}).get("seed", 0)
    ok = isinstance(train_seed, int) and train_seed >= 0
    check(ok, "train.seed", train_seed, "must be an integer >= 0")
    radius = cfg.get("train", {}).get("datamodule", {}).get("target_radius", 0.0)
    ok = isinstance(radius, int | float) and radius >= 0
    check(ok, "train.datamodule.target_radius", radius, "must be >= 0 pixels")
    return set(nets)


def _random_maps(ev: EvalConfig, data: DataConfig, scale: ScaleConfig) -> None:
    test_maps = round(scale.maps_per_shard * (1.0 - data.train_fraction)) * len(scale.shards)
    available = test_maps * data.n_starts * data.n_goals
    check(
        ev.random_maps <= available,
        "eval.random_maps",
        ev.random_maps,
        f"the test split of this scale holds {available} instances",
    )


def _unreachable(cfg: DictConfig, typed: dict) -> None:
    """Combinations that validate section by section but cannot succeed, or that a later
    stage would cut without a word (issue #28)."""
    planner, ev, oracle = typed["planner"], typed["eval"], typed["oracle"]
    exact = ev.any_angle or planner.reference == "any_angle"
    check(
        not (exact and planner.eps == 0),
        "planner.eps",
        planner.eps,
        "must be > 0 when a stop rule compares with the exact continuous optimum "
        "(eval.any_angle=true or planner.reference=any_angle): a sampled path never "
        "reaches it exactly, so every trial would run to its budget",
    )
    check(
        ev.random_maps >= 1,
        "eval.random_maps",
        ev.random_maps,
        "must be >= 1: the oracle, regime and ideas stages draw from the random instances",
    )
    check(
        oracle.random_maps <= ev.random_maps,
        "oracle.random_maps",
        oracle.random_maps,
        f"must be <= eval.random_maps ({ev.random_maps}): the oracle draws from those",
    )
    threads = cfg.get("train", {}).get("threads")
    ok = threads is None or (isinstance(threads, int) and not isinstance(threads, bool))
    check(ok and (threads is None or threads >= 1), "train.threads", threads, "null or >= 1")


def validate_config(cfg: DictConfig) -> dict:
    """Check every section of a composed config; returns the typed sections."""
    if not isinstance(cfg, DictConfig) or not cfg:
        raise ConfigError("the configuration is empty")
    typed = {
        "data": section(cfg, "data", DataConfig),
        "labels": section(cfg, "labels", LabelsConfig),
        "scale": section(cfg, "scale", ScaleConfig),
        "planner": section(cfg, "planner", PlannerConfig),
        "eval": section(cfg, "eval", EvalConfig),
        "stats": section(cfg, "stats", StatsConfig),
        "oracle": section(cfg, "oracle", OracleConfig),
        "regime": section(cfg, "regime", RegimeConfig),
        "paths": section(cfg, "paths", Paths),
        "logger": section(cfg, "logger", LoggerConfig),
        "budget": section(cfg, "budget", BudgetConfig),
        "bench_maps": section(cfg, "bench_maps", BenchMapsConfig),
    }
    for name in typed["bench_maps"].maps:  # a missing map file stops the run here
        map_files(typed["paths"].movingai, name)
    for steps in typed["budget"].steps:
        batches_per_epoch(steps, int(cfg.trainer.max_epochs))
    _taus(typed["planner"])
    networks = _networks(cfg)
    for planner, source in typed["eval"].sources.items():
        check(
            source in networks,
            f"eval.sources.{planner}",
            source,
            f"must name a network of `networks` ({sorted(networks)})",
        )
    _random_maps(typed["eval"], typed["data"], typed["scale"])
    _unreachable(cfg, typed)
    for key in typed["regime"].configurations:
        spec = ConfigKey.parse(key, typed["eval"].sources)
        ok = spec.source is None or is_oracle(spec.source) or spec.source in networks
        check(ok, "regime.configurations", key, f"its source must be a network {sorted(networks)}")
    check_parts(cfg.get("predict", {}).get("parts", [0]), "predict.parts")
    seed = cfg.get("seed")
    check(isinstance(seed, int) and seed >= 0, "seed", seed, "must be an integer >= 0")
    workers = cfg.get("workers", 0)
    check(isinstance(workers, int) and workers >= 0, "workers", workers, "must be >= 0")
    return typed


def run_validate(cfg: DictConfig) -> dict:
    """Stage ``validate``: check the composed parameters; write ``paths.validated`` with a
    constant text, so that a successful re-run changes no stage downstream."""
    from vnrrt.infra.io import write_text

    typed = validate_config(cfg)
    write_text(cfg.paths.validated, "params.yaml passed vnrrt.pipeline.validate\n")
    return typed
