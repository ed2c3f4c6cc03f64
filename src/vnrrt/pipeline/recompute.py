"""Every number of both reports, recomputed from committed per-trial tables.

``python -m vnrrt.pipeline.recompute export --params params.yaml --out reports/cpu/results``
writes, from a finished run's files (its ``params.yaml``), the bundle of
:data:`BUNDLE` (schema in the bundle's ``README.md``): the merged trial tables of the paper
comparison, the oracle study and the regime sweep (gzip CSV, columns of
:mod:`vnrrt.evaluation.table`), the instances' optimal lengths and named maps, the networks'
``predict.json`` and training metrics, and the parameters.

``python -m vnrrt.pipeline.recompute run --bundle reports/cpu/results --out <folder>``
recomputes from the bundle alone (with the repository's ``data/paper/*.yaml``) the
statistics (``summary.json``, ``ideas.json``), ``paper_comparison.md``,
``sampling_ideas.md`` and ``headline.json``, through the functions the stages use: the same
numbers, byte for byte (tested at smoke scale). Figures are not redrawn.
"""

from __future__ import annotations

import argparse
import gzip
import shutil
import sys
from pathlib import Path

from omegaconf import OmegaConf

from vnrrt.config import ConfigError, compose, load_params, restrict, stage_params

BUNDLE = {  # file -> what it holds
    "params.yaml": "the run's parameters (the composed config)",
    "trials.csv.gz": "the paper comparison's trials, one row per planner run",
    "oracle.csv.gz": "the oracle study's trials",
    "regime.csv.gz": "the regime sweep's trials",
    "instances.json": "per map set the A*, exact and taut optimal lengths; the named maps; "
    "each instance's turning points (the strata) and free cells (the distinct regime cells)",
    "predict.json": "the networks' heatmap metrics, inference times and their settings",
    "train.json": "each network's training metrics (steps, images, time, architecture; with "
    "eval.gpu also the GPU-trained networks')",
}
LATER_SECTIONS = ("bench_maps",)  # sections a bundle may predate: no recomputed stage reads them
# settings a bundle may predate, at the value its run had in effect (RRT* timed once; fixed
# budgets; NRRT* sampling the path oracles, VNRRT* the others; the protocol cell's selection;
# runs stopped at the time budget)
LATER_SETTINGS = {"eval.timing_noise": False, "planner.iterations_per_free_cell": None,
                  "planner.seconds_per_free_cell": None, "eval.cap_factor": 1.0,
                  "oracle.planners": {"path": "nrrt_star"}, "oracle.per_cell": False}  # fmt: skip
_ABSENT = object()
MACHINE = "machine.json"  # optional: {"machine": the CPU whose timings the tables hold}


def _view(cfg, stage: str):
    from vnrrt.config import REPO_ROOT

    return restrict(cfg, stage_params(stage, REPO_ROOT / "dvc.yaml"))


def export(params: Path, out: Path) -> list[Path]:
    """Write the bundle (module doc) of the run that ``params`` describes; returns its files."""
    from vnrrt.data.instances import Instances
    from vnrrt.evaluation.table import write_table
    from vnrrt.infra.io import read_json, write_json
    from vnrrt.pipeline.sampling_ideas import ideas_settings, ideas_tables

    cfg = load_params(params)
    s = ideas_settings(_view(cfg, "ideas"))
    paths = s["paths"]
    out.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(params, out / "params.yaml")
    _gzip(Path(paths.trials_table), out / "trials.csv.gz")
    for which, table in ideas_tables(s).items():
        write_table(table, out / f"{which}.csv")
        _gzip(out / f"{which}.csv", out / f"{which}.csv.gz")
        (out / f"{which}.csv").unlink()
    inst = Instances(paths.instances)
    turns = {str(i): n for i, n in inst.turns().items()}
    free = {str(i): n for i, n in inst.free_cells().items()}
    write_json(out / "instances.json", {"optima": inst.optima(), "named": inst.named(),
                                        "turns": turns, "free_cells": free})  # fmt: skip
    predict = read_json(paths.predict_metrics)
    write_json(out / "predict.json", predict)
    trainings = {n: read_json(paths.train_metrics(n)) for n in predict["networks"]}
    if cfg.eval.get("gpu"):  # the report's GPU-trained rows, as stage report reads them
        from vnrrt.pipeline.paper_comparison import gpu_trainings

        trainings |= gpu_trainings(paths)
    write_json(out / "train.json", trainings)
    machine = read_json(paths.headline).get("machine")
    if machine:  # optional: the machine that made the timings (MACHINE)
        write_json(out / MACHINE, {"machine": machine})
    (out / "README.md").write_text(_schema())
    return [out / name for name in (*BUNDLE, *([MACHINE] if machine else []), "README.md")]


def _gzip(src: Path, dst: Path) -> None:
    """``src`` compressed to ``dst`` (no timestamp in the header: the same bytes each time)."""
    with (
        open(src, "rb") as f,
        open(dst, "wb") as raw,
        gzip.GzipFile(fileobj=raw, mode="wb", mtime=0, filename="") as g,
    ):
        shutil.copyfileobj(f, g)


def _schema() -> str:
    from vnrrt.evaluation.table import COLUMNS, TrialRow

    lines = ["# Per-trial results behind the committed reports", "", "| file | holds |",
             "| --- | --- |", *[f"| `{k}` | {v} |" for k, v in BUNDLE.items()],
             f"| `{MACHINE}` | the machine whose timings the tables hold (if recorded) |", "",
             "Trial table columns (`vnrrt.evaluation.table.TrialRow`):", ""]  # fmt: skip
    lines += [f"- `{c}`" for c in COLUMNS]
    lines += ["", TrialRow.__doc__.strip(), "",
              "Recompute every number of both reports: `python -m vnrrt.pipeline.recompute "
              "run --bundle <this folder> --out <folder>`.", ""]  # fmt: skip
    return "\n".join(lines)


def recompute(bundle: Path, out: Path) -> list[Path]:
    """Recompute the statistics and reports from the bundle alone (module doc) into
    ``out``; returns the files written."""
    from vnrrt.infra.io import read_json, write_json, write_text
    from vnrrt.pipeline.paper_comparison import (
        evaluate_settings,
        evaluate_summary,
        report_settings,
        report_text,
    )
    from vnrrt.pipeline.sampling_ideas import ideas_settings, ideas_summary, ideas_text
    from vnrrt.studies.paper_comparison.headline import headline

    missing = [n for n in BUNDLE if not (bundle / n).is_file()]
    if missing:
        raise ConfigError(f"results bundle {bundle} lacks {missing} (see its README.md)")
    cfg = load_params(bundle / "params.yaml", optional=LATER_SECTIONS)
    # every input comes from the bundle but the paper's numbers and settings, read where this
    # repository keeps them: the paths of this code, not of the run that made the bundle
    cfg.paths = compose([f"scale={cfg.scale.name}"]).paths
    for key, value in LATER_SETTINGS.items():  # settings newer than the bundle
        if OmegaConf.select(cfg, key, default=_ABSENT) is _ABSENT:
            OmegaConf.update(cfg, key, value)
    predict, trainings = read_json(bundle / "predict.json"), read_json(bundle / "train.json")
    es = evaluate_settings(_view(cfg, "evaluate"))
    tables = checked_tables(bundle, es, read_json(bundle / "instances.json")["optima"])
    out.mkdir(parents=True, exist_ok=True)
    summary = evaluate_summary(tables["trials"], es, predict, bundle_field(bundle, "turns"))
    write_json(out / "summary.json", summary)
    summary = read_json(out / "summary.json")  # as the report stage reads it
    rs = report_settings(_view(cfg, "report"))
    optima = read_json(bundle / "instances.json")["optima"]
    write_text(out / "paper_comparison.md", report_text(rs, summary, predict, trainings, optima))
    machine = read_json(bundle / MACHINE)["machine"] if (bundle / MACHINE).is_file() else None
    tau = float(cfg.planner.tau)
    write_json(out / "headline.json", headline(summary, predict["networks"], tau, machine))
    ids = ideas_settings(_view(cfg, "ideas"))
    study = {w: tables[w] for w in ("oracle", "regime")}
    write_json(out / "ideas.json", ideas_summary(study, ids, bundle_field(bundle, "free_cells")))
    write_text(out / "sampling_ideas.md", ideas_text(read_json(out / "ideas.json"), ids))
    names = ("summary.json", "paper_comparison.md", "headline.json", "ideas.json")
    return [out / n for n in (*names, "sampling_ideas.md")]


def bundle_field(bundle: Path, name: str) -> dict[int, int] | None:
    """Per instance ``name`` (``turns``: turning points; ``free_cells``) from the bundle's
    ``instances.json``; None where the bundle predates it (``python -m
    vnrrt.pipeline.bundle_turns`` adds both)."""
    from vnrrt.infra.io import read_json

    values = read_json(bundle / "instances.json").get(name)
    return None if values is None else {int(i): int(n) for i, n in values.items()}


def checked_tables(bundle: Path, es: dict, optima: dict) -> dict:
    """The bundle's three trial tables (``{"trials", "oracle", "regime"}``), each checked
    against what physics and the protocol guarantee (:mod:`vnrrt.evaluation.invariants`,
    with stage ``evaluate``'s settings ``es`` and the instances' mean ``optima``); the paper
    comparison's keys must be its configurations."""
    import dataclasses

    from vnrrt.evaluation.invariants import bundle_design
    from vnrrt.evaluation.protocol import configurations
    from vnrrt.evaluation.table import read_table

    files = {w: bundle / f"{w}.csv.gz" for w in ("trials", "oracle", "regime")}
    tables = {w: read_table(f) for w, f in files.items()}
    rules = es["planner"]
    design = bundle_design({str(f): tables[w] for w, f in files.items()}, optima, rules.eps,
                           rules.max_iterations, es["seed"])  # fmt: skip
    keys = frozenset(k.text for k in configurations(es["eval"], rules.mask_taus, rules.tau))
    for w, f in files.items():
        (dataclasses.replace(design, keys=keys) if w == "trials" else design).check(
            tables[w], str(f)
        )
    return tables


def main(argv: list[str] | None = None) -> int:
    """The command line (module doc); returns the exit status."""
    parser = argparse.ArgumentParser(prog="python -m vnrrt.pipeline.recompute",
                                     description=__doc__.split("\n\n")[0])  # fmt: skip
    sub = parser.add_subparsers(dest="command", required=True)
    ex = sub.add_parser("export", help="write the results bundle of a finished run")
    ex.add_argument("--params", type=Path, default=Path("params.yaml"))
    ex.add_argument("--out", type=Path, required=True)
    rc = sub.add_parser("run", help="recompute both reports from a results bundle")
    rc.add_argument("--bundle", type=Path, required=True)
    rc.add_argument("--out", type=Path, required=True)
    args = parser.parse_args(argv)
    try:
        files = (
            export(args.params, args.out)
            if args.command == "export"
            else recompute(args.bundle, args.out)
        )
    except (ConfigError, OSError, ValueError) as err:
        print(f"vnrrt.pipeline.recompute: error: {err}".splitlines()[0], file=sys.stderr)
        return 2
    for f in files:
        print(f)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
