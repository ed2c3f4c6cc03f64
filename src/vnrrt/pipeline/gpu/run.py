"""``scripts/gpu/paper_network.sh --device cuda --budget 300 --out $OUT``: the whole chain of
issue 27 on one machine, inside a time budget (shares: :mod:`vnrrt.pipeline.gpu.plan`).

1. data: label one map (numba compiles once, forked workers share it), one round of shards
   (one per core), probes, then more rounds until the shards cover one pass of the images
   the training can see, or the data share is spent;
2. probes: the largest batch that fits, the loader's rate, ``torch.compile`` if it pays;
3. each network (``vertexnet``, ``nrrtnet``: the bundle's architecture, bf16, channels_last):
   trained for its share, tested on the shards' test split, its heatmaps of the bundle's
   instances predicted, inference throughput and heatmap metrics measured;
4. the returned files (:mod:`vnrrt.data.returned`) written to ``--out`` within the limits.

Nothing here imports Hydra, OmegaConf, MLflow or DVC.
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import platform
import sys
import time
from pathlib import Path

import lightning as L
import torch

from vnrrt.data.returned import (
    LOG_BYTES,
    NETWORKS,
    Instances,
    check_limits,
    heatmap_parts,
    write_returned_heatmaps,
)
from vnrrt.infra.io import write_json, write_text
from vnrrt.infra.parallel import n_workers
from vnrrt.pipeline.gpu import data as gdata
from vnrrt.pipeline.gpu.plan import Clock, RunPlan, load_config, parse_args
from vnrrt.pipeline.gpu.predict import evaluate
from vnrrt.pipeline.gpu.probe import (
    compile_pays,
    effective_rate,
    loader_rate,
    probe_batch,
    probe_compiled,
)
from vnrrt.pipeline.gpu.train import curves_csv, make_datamodule, make_module, train_network

log = logging.getLogger("vnrrt.pipeline.gpu")
LOADER_SECONDS = 3.0  # the loader probe, at most


def machine(device: torch.device) -> dict:
    """What ran the run: accelerator, cores, versions."""
    info = {"device": device.type, "cpu_cores": n_workers(0), "host": platform.node(),
            "python": platform.python_version(), "torch": torch.__version__,
            "lightning": L.__version__}  # fmt: skip
    if device.type == "cuda":
        p = torch.cuda.get_device_properties(device)
        info.update(name=p.name, memory_gib=p.total_memory / 2**30, sms=p.multi_processor_count)
    else:
        info["name"] = platform.processor() or platform.machine()
    return info


def batch_sizes(lo: int, hi: int) -> list[int]:
    """``lo, 2 lo, 4 lo, ...`` below ``hi``, then ``hi``."""
    sizes = [lo]
    while sizes[-1] * 2 < hi:
        sizes.append(sizes[-1] * 2)
    return sizes + ([hi] if hi > lo else [])


def first_data(plan: RunPlan, cfg: dict, clock: Clock) -> dict:
    """Numba warm-up and one round of shards (one per core) with their manifest."""
    tick = time.perf_counter()
    warm = gdata.warm_up(cfg)
    n = min(n_workers(plan.cores), plan.max_shards)
    counts = gdata.build_round(plan.work / "shards", list(range(n)), cfg, plan.cores)
    round_s = time.perf_counter() - tick - warm
    gdata.manifest(plan.work / "shards", n, plan.work / "manifest.json")
    clock.add("data", time.perf_counter() - tick)
    per_shard = gdata.train_per_shard(cfg, counts)
    return {"shards": n, "warm_up_s": warm, "round_s": round_s, "train_per_shard": per_shard}


def rest_of_data(plan: RunPlan, cfg: dict, clock: Clock, got: dict, images: float) -> dict:
    """More rounds of shards for one pass of ``images`` training images (data share)."""
    tick = time.perf_counter()
    want = gdata.shards_wanted(images, got["train_per_shard"], plan.max_shards)
    left = plan.data_share * plan.budget_s - clock.phases["data"]
    n = gdata.more_rounds(plan.work / "shards", cfg, got["shards"], want, plan.cores, left,
                          got["round_s"])  # fmt: skip
    if n > got["shards"]:
        gdata.manifest(plan.work / "shards", n, plan.work / "manifest.json")
    clock.add("data", time.perf_counter() - tick)
    maps, seconds = n * cfg["maps_per_shard"], clock.phases["data"]
    return {**got, "shards": n, "shards_wanted": want, "maps": maps, "seconds": seconds}


def decide_compile(plan: RunPlan, make, dataset, device, precision: str, probe: dict,
                   loader: float, workers: int) -> dict:  # fmt: skip
    """Whether to train compiled (``--compile``): off; auto without CUDA or with too short
    a share skips the probe; else the compiled probe and :func:`compile_pays` decide."""
    train_s = plan.train_share * plan.budget_s
    if plan.compile == "off":
        return {"used": False, "reason": "--compile off"}
    if plan.compile == "auto" and device.type != "cuda":
        return {"used": False, "reason": "auto: compiles on CUDA only"}
    if plan.compile == "auto" and train_s < plan.compile_min_train_s:
        return {"used": False, "reason": f"auto: {train_s:.0f} s of training per network < "
                f"--compile-min-train-s {plan.compile_min_train_s:.0f}: no probe"}  # fmt: skip
    try:
        rate, compile_s = probe_compiled(make, dataset, device, precision, probe["batch"])
    except Exception as err:  # dynamo and inductor raise many kinds; train eager then
        log.warning("torch.compile failed, training eager: %s", err)
        return {"used": False, "reason": f"compile failed: {err}".splitlines()[0]}
    pays = compile_pays(probe["images_per_s"], rate, compile_s, loader, workers, train_s)
    return {"used": pays or plan.compile == "on", "pays": pays, "compile_s": compile_s,
            "images_per_s": rate, "reason": f"--compile {plan.compile}"}  # fmt: skip


def run_probes(plan: RunPlan, cfg: dict, clock: Clock, n_shards: int, device) -> dict:
    """Batch, loader and compile probes (probe share); ``planned_images_per_s``."""
    tick = time.perf_counter()
    torch_flags(cfg["trainer"])
    workers = _workers(plan, cfg)
    dm = make_datamodule(cfg, plan.work, n_shards, "vertexnet", plan.min_batch, workers,
                         device.type == "cuda")  # fmt: skip
    dataset, precision = dm.datasets["train"], cfg["trainer"]["precision"]
    make = functools.partial(make_module, cfg, "vertexnet")
    deadline = tick + plan.probe_share * plan.budget_s
    out = probe_batch(make, dataset, device, precision,
                      batch_sizes(plan.min_batch, plan.max_batch), deadline)  # fmt: skip
    seconds = min(LOADER_SECONDS, 0.25 * plan.probe_share * plan.budget_s)
    out["loader_images_per_s"] = loader = loader_rate(dataset, out["batch"], workers, seconds)
    out["compile"] = decide_compile(plan, make, dataset, device, precision, out, loader, workers)
    rate = out["compile"]["images_per_s"] if out["compile"]["used"] else out["images_per_s"]
    out["planned_images_per_s"] = effective_rate(rate, loader, workers)
    out["workers"] = workers
    clock.add("probe", time.perf_counter() - tick)
    return out


def torch_flags(trainer: dict) -> None:
    """cuDNN autotuning and deterministic algorithms as the Lightning trainer will set them
    (``benchmark``, ``deterministic``), so that the probes time the training's kernels."""
    torch.backends.cudnn.benchmark = bool(trainer["benchmark"])
    deterministic = trainer["deterministic"]
    if deterministic:
        torch.use_deterministic_algorithms(True, warn_only=deterministic == "warn")


def _workers(plan: RunPlan, cfg: dict) -> int:
    return int(cfg["datamodule"]["num_workers"] if plan.workers is None else plan.workers)


def train_all(plan: RunPlan, cfg: dict, clock: Clock, doc: dict, instances, device) -> dict:
    """Train, test and evaluate each network of :data:`NETWORKS`; returns their heatmaps.
    The first network's steps are planned at the probes' rate, the next at the steady rate
    the first one reached (same architecture and data: a closer estimate)."""
    probe, maps = doc["probe"], {}
    rate = probe["planned_images_per_s"]
    for name, trained in NETWORKS.items():
        tick = time.perf_counter()
        module, metrics = train_network(
            cfg, plan.work, doc["data"]["shards"], trained, probe["batch"], rate,
            plan.train_share * plan.budget_s, probe["workers"], device.type == "cuda",
            probe["compile"]["used"],
        )  # fmt: skip
        rate = metrics["train_images_per_s_steady"] or rate
        clock.add(f"train_{trained}", time.perf_counter() - tick)
        tick = time.perf_counter()
        maps[name], found = evaluate(module, instances, cfg, device, probe["batch"])
        clock.add(f"predict_{trained}", time.perf_counter() - tick)
        doc["networks"][name] = {"trained": trained, "target": module.record["target"],
                                 "params": module.net.describe(), "train": metrics,
                                 **found}  # fmt: skip
        del module
    return maps


def network_meta(doc: dict) -> dict:
    """Per network the meta fields the heatmap files carry (:data:`NETWORK_META`)."""
    out = {}
    for name, n in doc["networks"].items():
        t = n["train"]
        rate = t["train_images_per_s_steady"] or t["train_images_per_s"]
        out[name] = {"target": n["target"], "checkpoint_sha256": t["checkpoint_sha256"],
                     "images_seen": t["train_images"], "train_images_per_s": rate,
                     "infer_images_per_s": n["infer_images_per_s"],
                     "batch_size": t["batch_size"], "steps": t["steps"]}  # fmt: skip
    return out


def write_outputs(plan: RunPlan, doc: dict, instances, maps: dict) -> None:
    """Heatmap parts, curves, metrics; then the log cut to size and the limits checked."""
    tick = time.perf_counter()
    write_returned_heatmaps(plan.out, instances.keys, maps, network_meta(doc),
                            machine=doc["machine"], budget_s=plan.budget_s)  # fmt: skip
    write_text(plan.out / "curves.csv", curves_csv(plan.work / "logs", NETWORKS))
    doc["phases"]["write"] = time.perf_counter() - tick
    log.info("done in %.0f s of a %.0f s budget", doc["elapsed_s"], plan.budget_s)
    for handler in [h for h in logging.root.handlers if isinstance(h, logging.FileHandler)]:
        logging.root.removeHandler(handler)
        handler.close()
    log_file = plan.out / "run.log"
    if log_file.is_file() and log_file.stat().st_size > LOG_BYTES:
        tail = log_file.read_bytes()[-LOG_BYTES:]
        write_text(log_file, tail.decode(errors="replace"))
    doc["files"] = check_limits(plan.out)
    write_json(plan.out / "metrics.json", doc)


def preflight(plan: RunPlan) -> tuple[dict, Instances, torch.device]:
    """The bundle's config and instances, and the device, checked before any work:
    ``ValueError`` naming the problem."""
    cfg = load_config(plan.bundle)
    instances = Instances(plan.bundle / "instances.npz")
    if instances.size != cfg["data"]["size"]:
        raise ValueError(f"instances of {instances.size}px, config data.size {cfg['data']['size']}")
    heatmap_parts(len(instances), instances.size, len(NETWORKS))  # fails now, not after training
    device = torch.device(plan.device)
    if device.type == "cuda" and not torch.cuda.is_available():
        raise ValueError("--device cuda but torch sees no CUDA device")
    return cfg, instances, device


def run(plan: RunPlan, cfg: dict, instances: Instances, device: torch.device) -> dict:
    """The whole run (module doc); returns the metrics document it writes."""
    clock = Clock(plan.budget_s)
    plain = {k: str(v) if isinstance(v, Path) else v for k, v in dataclasses.asdict(plan).items()}
    got = first_data(plan, cfg, clock)
    doc = {"machine": machine(device), "budget_s": plan.budget_s, "plan": plain,
           "source": cfg["source"], "phases": clock.phases, "networks": {}}  # fmt: skip
    doc["probe"] = run_probes(plan, cfg, clock, got["shards"], device)
    images = doc["probe"]["planned_images_per_s"] * plan.train_share * plan.budget_s
    doc["data"] = rest_of_data(plan, cfg, clock, got, images)
    files = [plan.work / "shards" / f"shard_{i}.npz" for i in range(doc["data"]["shards"])]
    doc["data"]["heldout"] = gdata.check_heldout(instances, files)
    write_json(plan.out / "metrics.json", doc)  # what is known so far, should training fail
    maps = train_all(plan, cfg, clock, doc, instances, device)
    doc["elapsed_s"] = clock.elapsed()
    write_outputs(plan, doc, instances, maps)
    return doc


def setup_logging(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    handlers = [logging.StreamHandler(sys.stderr), logging.FileHandler(out / "run.log")]
    logging.basicConfig(level=logging.INFO, handlers=handlers, force=True,
                        format="%(asctime)s %(name)s %(levelname)s %(message)s")  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    """The command line; exit 2 with one line for bad arguments, bundle or instances."""
    try:
        plan = parse_args(argv)
        cfg, instances, device = preflight(plan)
    except (ValueError, OSError) as err:
        print(f"paper_network: error: {err}".splitlines()[0], file=sys.stderr)
        return 2
    setup_logging(plan.out)
    plan.work.mkdir(parents=True, exist_ok=True)
    run(plan, cfg, instances, device)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
