"""``python -m vnrrt.pipeline.gpu.bundle --instances data/cpu/instances.npz [--out data/gpu/bundle]
[overrides...]``: the folder that travels to the GPU machine with the code.

It holds ``run_config.json`` (the settings of :mod:`vnrrt.pipeline.gpu.run`, composed here from
``conf/`` with Hydra, by default at ``scale=paper``: the paper's VertexNet, its loss and
training settings, the data and label settings; plain JSON, read there without Hydra) and
``instances.npz`` (a copy of the instances file whose heatmaps the run returns). ``data/`` is
ignored by git, so the folder travels only when the device call names it in ``carry``.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
from pathlib import Path

from vnrrt.config import REPO_ROOT, ConfigError, asdict, compose, section
from vnrrt.data.config import LabelsConfig
from vnrrt.data.returned import Instances
from vnrrt.infra.io import sha256, write_json
from vnrrt.maps.config import DataConfig

DEFAULT_OUT = Path("data/gpu/bundle")
DEFAULT_OVERRIDES = ("scale=paper",)
CONFIG_FILE, INSTANCES_FILE = "run_config.json", "instances.npz"
MAX_BUNDLE_BYTES = 32 << 20  # the whole working tree that travels is limited to 64 MiB
DATAMODULE_KEYS = ("target_radius", "marker_radius", "normalize", "val_fraction",
                   "val_instances", "test_instances", "num_workers", "pin_memory")  # fmt: skip
TRAINER_KEYS = ("precision", "deterministic", "benchmark", "gradient_clip_val",
                "log_every_n_steps")  # fmt: skip


def _plain(node) -> dict:
    from omegaconf import OmegaConf

    return OmegaConf.to_container(node, resolve=True)


def _commit() -> str:
    """The repository's HEAD commit (``unknown`` outside a git checkout)."""
    out = subprocess.run(["git", "-C", str(REPO_ROOT), "rev-parse", "HEAD"],
                         capture_output=True, text=True, check=False)  # fmt: skip
    return out.stdout.strip() or "unknown"


def run_config(overrides: list[str]) -> dict:
    """The settings of a GPU run (module doc) from ``conf/`` composed with ``overrides``."""
    cfg = compose(overrides)
    dm, trainer = cfg.train.datamodule, cfg.trainer
    return {
        "seed": int(cfg.seed),
        "maps_per_shard": int(cfg.scale.maps_per_shard),
        "data": asdict(section(cfg, "data", DataConfig)),
        "labels": asdict(section(cfg, "labels", LabelsConfig)),
        "net": _plain(cfg.model.net),
        "loss": _plain(cfg.model.loss),
        "networks": {
            n: {"target": str(s.target), "endpoints": str(s.endpoints)}
            for n, s in cfg.networks.items()
        },
        "module": _plain(cfg.train.module),
        "datamodule": {k: _plain(dm)[k] for k in DATAMODULE_KEYS},
        "train_seed": int(cfg.train.seed),
        "trainer": {k: _plain(trainer)[k] for k in TRAINER_KEYS},
        "progress_every": int(cfg.callbacks.progress.every_n_steps),
        "predict": {
            "metric_radius": float(cfg.predict.metric_radius),
            "metric_tau": float(cfg.predict.metric_tau),
            "metric_ap_radius": float(cfg.predict.metric_ap_radius),
            "metric_endpoint_radius": float(cfg.predict.metric_endpoint_radius),
            "batch_size": int(cfg.predict.batch_size),
        },
        "planner": {"taus": [float(t) for t in cfg.planner.taus], "tau": float(cfg.planner.tau)},
        "source": {"overrides": list(overrides), "commit": _commit()},
    }


def make_bundle(instances: str | Path, out: str | Path, overrides: list[str]) -> dict:
    """Write ``out/run_config.json`` and copy ``instances`` to ``out/instances.npz``;
    returns the config. :class:`ConfigError` if the instances do not fit the data size or
    the bundle is too large to travel."""
    inst = Instances(instances)
    config = run_config(overrides)
    if inst.size != config["data"]["size"]:
        raise ConfigError(f"instances file {instances} has {inst.size}px maps, the config "
                          f"data.size={config['data']['size']}")  # fmt: skip
    if Path(instances).stat().st_size > MAX_BUNDLE_BYTES:
        raise ConfigError(f"instances file {instances} is over {MAX_BUNDLE_BYTES >> 20} MiB")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    tmp = out / f"{INSTANCES_FILE}.tmp"
    shutil.copyfile(instances, tmp)
    tmp.replace(out / INSTANCES_FILE)
    config["source"]["instances"] = str(instances)
    config["source"]["instances_sha256"] = sha256(out / INSTANCES_FILE)
    write_json(out / CONFIG_FILE, config)
    return config


def main(argv: list[str] | None = None) -> int:
    """The command line (module doc); returns the exit status."""
    parser = argparse.ArgumentParser(
        prog="python -m vnrrt.pipeline.gpu.bundle", description=__doc__
    )
    parser.add_argument("--instances", type=Path, required=True, help="instances file")
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT, help="bundle folder")
    parser.add_argument("overrides", nargs="*", help=f"Hydra overrides (default: "
                        f"{' '.join(DEFAULT_OVERRIDES)})")  # fmt: skip
    args = parser.parse_args(argv)
    from hydra.errors import HydraException

    try:
        make_bundle(args.instances, args.out, args.overrides or list(DEFAULT_OVERRIDES))
    except (HydraException, ValueError) as err:
        print(f"vnrrt.pipeline.gpu.bundle: error: {err}".splitlines()[0], file=sys.stderr)
        return 2
    print(f"wrote {args.out}/{CONFIG_FILE} and {args.out}/{INSTANCES_FILE}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
