"""Shard jobs as a Hydra app: one job runs one part of a stage with parts, writing the very
file ``dvc repro`` writes.

The stages with parts (:data:`PART_STAGES`) are ``shard`` (``shard@<id>``,
ids ``scale.shards``: map generation and labelling), ``predict`` (``predict@<k>``, ids
``predict.parts``: heatmap prediction) and ``trials`` (``trials@<k>``, ids ``eval.parts``:
planner trials). The app composes the pipeline's own config (``conf/config.yaml``) plus
``+stage=<name> +part=<id>`` from the command line and calls the stage's entry point.
Hydra's launchers spread a sweep over ids (``docs/scaling.md``); run from the repository
root::

    python -m vnrrt.pipeline.params scale=paper --out params.yaml   # the same overrides as the jobs
    python -m vnrrt.pipeline.multirun -m hydra/launcher=local +stage=shard +part=0,1,2,3 \
        workers=1
    python -m vnrrt.pipeline.multirun -m hydra/launcher=slurm +stage=shard \
        +part='range(0,100)' scale=paper
    dvc commit -f shard                                 # `dvc repro` then skips shard@*

Relative ``paths`` resolve against the directory the command was started in (Hydra's
``runtime.cwd``), whatever directory a launcher runs a job in; Hydra's own outputs go to
``outputs/`` and ``multirun/``. A job whose config differs from ``params.yaml`` logs a
warning: ``dvc commit`` would record parameters the files were not built with.
"""

from __future__ import annotations

import copy
import logging
from pathlib import Path

import hydra
from hydra.utils import to_absolute_path
from omegaconf import DictConfig, OmegaConf

from vnrrt.config import CONF_DIR, ConfigError, load_params, restrict, stage_params

# Stages with parts: name -> (module, entry point taking (cfg, part id), key of the part ids).
PART_STAGES = {
    "shard": ("vnrrt.pipeline.data", "run_shard", "scale.shards"),
    "predict": ("vnrrt.pipeline.predict", "run_predict_part", "predict.parts"),
    "trials": ("vnrrt.pipeline.evaluation", "run_trials_part", "eval.parts"),
}

log = logging.getLogger(__name__)

STAGE_KEY, PART_KEY = "stage", "part"  # the keys this app adds to the pipeline's config
NOT_IN_OUTPUTS = {STAGE_KEY, PART_KEY, "workers"}  # keys that do not change a job's output


def with_absolute_paths(cfg: DictConfig) -> DictConfig:
    """A copy of ``cfg`` whose ``paths`` entries are absolute (against Hydra's launch dir)."""
    out = copy.deepcopy(cfg)
    for key, value in cfg.paths.items():
        out.paths[key] = to_absolute_path(str(value))
    return out


def params_differences(cfg: DictConfig, params_file: str | Path) -> list[str]:
    """Top-level keys whose values differ between ``cfg`` and the file, less those that do
    not change a job's output (``stage``, ``part``, ``workers``).

    Returns ``[]`` when the file does not exist (nothing for ``dvc commit`` to disagree with).
    """
    if not Path(params_file).is_file():
        return []
    mine = OmegaConf.to_container(cfg, resolve=True)
    theirs = OmegaConf.to_container(load_params(params_file), resolve=True)
    keys = (mine.keys() | theirs.keys()) - NOT_IN_OUTPUTS
    return sorted(k for k in keys if mine.get(k) != theirs.get(k))


def part_job(cfg: DictConfig) -> object:
    """Run part ``cfg.part`` of stage ``cfg.stage`` into the stage's files; returns what
    the stage's entry point returns."""
    stage, part = cfg.get(STAGE_KEY), cfg.get(PART_KEY)
    if stage not in PART_STAGES or part is None:
        raise ConfigError(f"pass +{STAGE_KEY}=<{'|'.join(PART_STAGES)}> and +{PART_KEY}=<id> "
                          f"(got {STAGE_KEY}={stage!r}, {PART_KEY}={part!r}); sweep with "
                          f"-m +{PART_KEY}=0,1")  # fmt: skip
    import importlib

    from vnrrt.pipeline.validate import validate_config

    module, entry, ids_key = PART_STAGES[stage]
    validate_config(cfg)
    ids = OmegaConf.select(cfg, ids_key)
    if int(part) not in list(ids):
        raise ConfigError(f"{PART_KEY}={part} is not in {ids_key}={list(ids)}")
    differ = params_differences(cfg, to_absolute_path("params.yaml"))
    if differ:
        log.warning(
            "config differs from params.yaml in %s: write params.yaml with the same overrides "
            "(python -m vnrrt.pipeline.params ... --out params.yaml) before `dvc commit`",
            differ,
        )
    run = getattr(importlib.import_module(module), entry)
    view = restrict(with_absolute_paths(cfg), stage_params(stage, to_absolute_path("dvc.yaml")))
    return run(view, int(part))


@hydra.main(config_path=str(CONF_DIR), config_name="config", version_base="1.3")
def main(cfg: DictConfig) -> object:
    """Hydra entry point (``python -m vnrrt.pipeline.multirun [-m] +stage=... +part=...
    [overrides]``)."""
    return part_job(cfg)


if __name__ == "__main__":
    main()
