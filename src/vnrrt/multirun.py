"""Shard jobs as a Hydra app: one job builds one shard, the very file ``dvc repro`` writes.

The app composes the pipeline's own config (``conf/config.yaml``) plus a ``shard_id`` given
on the command line, and calls :func:`vnrrt.pipeline.run_shard`, as stage ``shard@<id>``
does. Hydra's launchers spread a sweep over shard ids (``docs/scaling.md``); run from the
repository root::

    python -m vnrrt.config scale=paper > params.yaml   # the same overrides as the jobs
    python -m vnrrt.multirun -m hydra/launcher=local +shard_id=0,1,2,3 workers=1
    python -m vnrrt.multirun -m hydra/launcher=slurm +shard_id='range(0,100)' scale=paper
    dvc commit -f shard                                 # `dvc repro` then skips shard@*

Relative ``paths`` resolve against the directory the command was started in (Hydra's
``runtime.cwd``), whatever directory a launcher runs a job in; Hydra's own outputs go to
``outputs/`` and ``multirun/``. A job whose config differs from ``params.yaml`` logs a
warning: ``dvc commit`` would record parameters the shards were not built with.
"""

from __future__ import annotations

import copy
import logging
from pathlib import Path

import hydra
from hydra.utils import to_absolute_path
from omegaconf import DictConfig, OmegaConf

from vnrrt.config import CONF_DIR, ConfigError, load_params
from vnrrt.pipeline import run_shard

log = logging.getLogger(__name__)

SHARD_KEY = "shard_id"  # the one key this app adds to the pipeline's config
NOT_IN_OUTPUTS = {SHARD_KEY, "workers"}  # keys that do not change a shard's bytes


def with_absolute_paths(cfg: DictConfig) -> DictConfig:
    """A copy of ``cfg`` whose ``paths`` entries are absolute (against Hydra's launch dir)."""
    out = copy.deepcopy(cfg)
    for key, value in cfg.paths.items():
        out.paths[key] = to_absolute_path(str(value))
    return out


def params_differences(cfg: DictConfig, params_file: str | Path) -> list[str]:
    """Top-level keys whose values differ between ``cfg`` and the file, less those that do
    not change a shard (``shard_id``, ``workers``).

    Returns ``[]`` when the file does not exist (nothing for ``dvc commit`` to disagree with).
    """
    if not Path(params_file).is_file():
        return []
    mine = OmegaConf.to_container(cfg, resolve=True)
    theirs = OmegaConf.to_container(load_params(params_file), resolve=True)
    keys = (mine.keys() | theirs.keys()) - NOT_IN_OUTPUTS
    return sorted(k for k in keys if mine.get(k) != theirs.get(k))


def shard_job(cfg: DictConfig) -> dict:
    """Build shard ``cfg.shard_id`` into ``paths.shards``; returns :func:`run_shard`'s counts."""
    shard_id = cfg.get(SHARD_KEY)
    if shard_id is None:
        raise ConfigError(f"no shard id: pass +{SHARD_KEY}=<id>, or sweep with -m +{SHARD_KEY}=0,1")
    differ = params_differences(cfg, to_absolute_path("params.yaml"))
    if differ:
        log.warning(
            "config differs from params.yaml in %s: write params.yaml with the same overrides "
            "(python -m vnrrt.config ... > params.yaml) before `dvc commit`",
            differ,
        )
    return run_shard(with_absolute_paths(cfg), int(shard_id))


@hydra.main(config_path=str(CONF_DIR), config_name="config", version_base="1.3")
def main(cfg: DictConfig) -> dict:
    """Hydra entry point (``python -m vnrrt.multirun [-m] +shard_id=... [overrides]``)."""
    return shard_job(cfg)


if __name__ == "__main__":
    main()
