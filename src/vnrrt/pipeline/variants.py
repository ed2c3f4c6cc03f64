"""A vertex target the network can learn, chosen fairly (issue 24): VertexNet trained at one
budget with each target variant that favours interior structure, and the default picked by
the interior-vertex AP on the validation split (``val/interior_ap``: pixel AP against the
A* label's interior vertices, start/goal disks left out; the same measure for every variant,
whatever its training target), never by a planner's result.

    python -m vnrrt.pipeline.variants --scale cpu --steps 2400 \\
        --out reports/cpu/target_variants.md [--val-instances 512] [overrides ...]

Variants (:data:`FACTORS`), each one change from the scale's configuration (the baseline):
the path ends the target keeps (``networks.vertexnet.endpoints``), the target dilation
(``train.datamodule.target_radius``, which the scale gives both networks), the focal loss's
positive weight (``model.loss.alpha``) and the output prior (``model.net.prior``); a variant
equal to the baseline is run once. Then the combination of every factor's best level, where
two or more factors beat the baseline. Each variant is a budget training
(:func:`vnrrt.pipeline.budget_training.run_budget_train`: a one-cycle schedule of its own
``--steps``)
in ``--work/<variant>/`` (default ``models/<scale>/variants``), MLflow off; a finished one
is read back, an interrupted one resumes. Needs the scale's shards (``dvc repro manifest``
at that scale). Writes the note ``--out`` (markdown) and its figures as JSON beside it.
"""

from __future__ import annotations

import argparse
import logging
import re
import sys
from dataclasses import dataclass
from pathlib import Path

log = logging.getLogger(__name__)

FACTORS = {  # factor -> (config key, levels tried)
    "endpoints": ("networks.vertexnet.endpoints", ["none", "goal"]),
    "target radius": ("train.datamodule.target_radius", [1.0, 2.0, 3.0]),
    "focal alpha": ("model.loss.alpha", [0.75, 0.9]),
    "prior": ("model.net.prior", [0.001, None]),
}
SELECT = "val/interior_ap"  # the selection metric (validation split)
SHOWN = (
    SELECT,
    "val/interior_recall",
    "val/mass_near_interior",
    "val/mass_near_interior_uniform",
    "val/mass_on_endpoints",
    "val/path_ap",
    "steps",
    "fit_seconds",
)


@dataclass(frozen=True)
class Variant:
    """One training: ``settings`` ``{config key: value}`` over the baseline's."""

    name: str
    settings: tuple[tuple[str, object], ...] = ()

    @property
    def slug(self) -> str:
        """A folder name."""
        return re.sub(r"[^a-z0-9.]+", "_", self.name.lower()).strip("_") or "baseline"

    def overrides(self) -> list[str]:
        """Hydra overrides of its settings."""
        return [f"{k}={'null' if v is None else v}" for k, v in self.settings]


def variants(baseline: dict) -> list[Variant]:
    """The baseline and every level of :data:`FACTORS` that differs from it (``baseline``:
    config key -> the baseline's value)."""
    out = [Variant("baseline")]
    for factor, (key, levels) in FACTORS.items():
        for level in levels:
            if level != baseline[key]:
                out.append(Variant(f"{factor} {level}", ((key, level),)))
    return out


def pick(results: dict[str, dict]) -> str:
    """The variant with the highest :data:`SELECT` (the first of equals, in run order)."""
    return max(results, key=lambda name: (results[name][SELECT], -list(results).index(name)))


def combined(results: dict[str, dict], runs: list[Variant]) -> Variant | None:
    """Every factor's best level where it beats the baseline, together; None unless two or
    more factors do."""
    base, best = results["baseline"][SELECT], {}
    for v in runs:
        if v.settings and results[v.name][SELECT] > base:
            key = v.settings[0][0]
            if key not in best or results[v.name][SELECT] > best[key][1]:
                best[key] = (v.settings[0][1], results[v.name][SELECT])
    if len(best) < 2:
        return None
    settings = tuple((k, value) for k, (value, _) in best.items())
    return Variant(
        "combined: " + ", ".join(f"{k.rsplit('.', 1)[-1]} {v}" for k, v in settings), settings
    )


def train_variant(base: list[str], variant: Variant, steps: int, work: Path) -> dict:
    """The variant's training metrics: read back when it finished before, else trained."""
    from vnrrt.config import compose, section
    from vnrrt.config.paths import Paths
    from vnrrt.infra.io import read_json
    from vnrrt.pipeline.budget_training import run_budget_train

    folder = work / variant.slug
    places = [
        f"paths.models={folder / 'models'}",
        f"paths.budget={folder / 'budget'}",
        f"paths.metrics={folder / 'metrics'}",
        f"paths.figures={folder / 'figures'}",
    ]
    cfg = compose([*base, *variant.overrides(), *places, "logger.enabled=false"])
    seed = int(cfg.train.seed)
    files = section(cfg, "paths", Paths).budget_training("vertexnet", steps, seed)
    if files.metrics.is_file() and files.checkpoint.is_file():
        log.info("%s: read back from %s", variant.name, files.metrics)
        return read_json(files.metrics)
    log.info("%s: training %d steps (%s)", variant.name, steps, variant.overrides())
    return run_budget_train(cfg, "vertexnet", steps, seed)


def compare(base: list[str], steps: int, work: Path, only: list[str] | None = None) -> dict:
    """Train every variant (``only``: these names), then the combination; returns ``{"steps",
    "results": {name: figures}, "settings": {name: overrides}, "picked"}``."""
    from vnrrt.config import compose

    cfg = compose(base)
    baseline = {key: _select(cfg, key) for key, _ in FACTORS.values()}
    runs = [v for v in variants(baseline) if only is None or v.name in only]
    results = {v.name: _shown(train_variant(base, v, steps, work)) for v in runs}
    extra = combined(results, runs) if "baseline" in results else None
    if extra is not None:
        results[extra.name] = _shown(train_variant(base, extra, steps, work))
        runs.append(extra)
    return {
        "steps": steps,
        "baseline": baseline,
        "results": results,
        "settings": {v.name: v.overrides() for v in runs},
        "picked": pick(results),
    }


def _select(cfg, key: str):
    from omegaconf import OmegaConf

    return OmegaConf.select(cfg, key)


def _shown(metrics: dict) -> dict:
    return {k: metrics[k] for k in SHOWN if k in metrics}


def note(found: dict, scale: str) -> str:
    """The markdown note of :func:`compare`'s result."""
    head = [
        "variant",
        "overrides",
        "val interior AP",
        "val interior recall",
        "val interior mass x uniform",
        "val mass on start/goal",
        "val path AP",
        "fit s",
    ]
    lines = [
        f"# VertexNet target variants at {found['steps']:,} steps (scale {scale})",
        "",
        f"Picked by the validation split's interior-vertex AP (`{SELECT}`), never by a "
        f"planner: **{found['picked']}**. Baseline: "
        + ", ".join(f"`{k}={v}`" for k, v in found["baseline"].items())
        + ".",
        "",
        "| " + " | ".join(head) + " |",
        "|" + " --- |" * len(head),
    ]
    order = sorted(found["results"], key=lambda n: -found["results"][n][SELECT])
    for name in order:
        r = found["results"][name]
        mass = r["val/mass_near_interior"] / max(r["val/mass_near_interior_uniform"], 1e-12)
        cells = [
            name,
            " ".join(f"`{o}`" for o in found["settings"][name]) or "(none)",
            f"{r[SELECT]:.4f}",
            f"{r['val/interior_recall']:.3f}",
            f"{mass:.2f}",
            f"{r['val/mass_on_endpoints']:.3f}",
            f"{r['val/path_ap']:.4f}",
            f"{r['fit_seconds']:.0f}",
        ]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join([*lines, ""])


def main(argv: list[str] | None = None) -> int:
    """The command line (module doc); returns the exit status."""
    from vnrrt.cli.stage import run_reporting
    from vnrrt.infra.io import write_json, write_text

    p = argparse.ArgumentParser(
        prog="python -m vnrrt.pipeline.variants",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--scale", required=True, help="the scale whose shards and settings to use")
    p.add_argument("--steps", type=int, required=True, help="the budget (optimizer steps)")
    p.add_argument("--out", type=Path, required=True, help="the note (markdown; JSON beside)")
    p.add_argument("--work", type=Path, help="trainings' folder (default: models/<scale>/variants)")
    p.add_argument("--val-instances", type=int, help="validation instances (default: scale's)")
    p.add_argument("--only", help="comma-separated variant names (default: all)")
    p.add_argument("overrides", nargs="*", help="Hydra overrides of the baseline")
    args = p.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    base = [f"scale={args.scale}", *args.overrides]
    if args.val_instances:
        base.append(f"train.datamodule.val_instances={args.val_instances}")
    work = args.work or Path("models") / args.scale / "variants"

    def run() -> int:
        only = args.only.split(",") if args.only else None
        found = compare(base, args.steps, work, only)
        write_json(args.out.with_suffix(".json"), found)
        write_text(args.out, note(found, args.scale))
        return 0

    return run_reporting("vnrrt.pipeline.variants", run)


if __name__ == "__main__":
    sys.exit(main())
