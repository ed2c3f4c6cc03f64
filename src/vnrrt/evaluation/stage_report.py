"""The ``report`` stage: ``paper_comparison.md``, the evaluation figures, the headline
metrics (``dvc metrics show``) and the MLflow evaluation runs, all from the statistics the
``evaluate`` stage computed once (``paths.summary``)."""

from __future__ import annotations

import logging
from pathlib import Path

import numpy as np
from omegaconf import DictConfig

from vnrrt.config import section
from vnrrt.evaluation.analysis import load_paper_tables
from vnrrt.evaluation.config import EvalConfig
from vnrrt.evaluation.instances import Instances
from vnrrt.evaluation.protocol import planner_specs
from vnrrt.evaluation.report import build_report
from vnrrt.io import read_json, write_json, write_text

log = logging.getLogger(__name__)
VERDICT_GROUPS = ("reproduced", "same direction", "not reproduced", "reversed")


def optima(path: str | Path) -> dict:
    """``{map_set: {"astar", "exact", "taut"}}``: each named map's optimal lengths and the
    means over the random instances (the paper's random column is a mean too)."""
    inst = Instances(path)
    a = inst.arrays
    out: dict = {}
    for map_set in dict.fromkeys(a["map_set"]):
        sel = a["map_set"] == map_set
        out[str(map_set)] = {
            k: float(np.mean(a[f"{k}_length"][sel])) for k in ("astar", "exact", "taut")
        }
    return out


def key_networks(ev: EvalConfig, taus: list[float]) -> dict[str, str]:
    """Configuration key -> the network whose heatmap it samples."""
    return {s.key: s.source for s in planner_specs(ev, taus) if s.source}


def short_key(key: str) -> str:
    """A short configuration name for metric columns: ``m_vnrrt_star@0.5`` -> ``m0.5``."""
    base, _, tau = key.partition("@")
    short = {"rrt_star": "rrt", "nrrt_star": "nrrt", "vnrrt_star": "vnrrt", "m_vnrrt_star": "m"}
    return short.get(base, base) + tau


def headline(summary: dict, predict: dict) -> dict:
    """A dozen numbers for ``dvc metrics show``: each network's mass near what it is for
    (VertexNet: the interior vertices; the path network: the path) as a multiple of a
    uniform map's, VertexNet's interior-vertex AP, the median planning time (ms) to the
    A*-relative optimum on random maps per configuration, and the counts of verdicts on the
    paper's claims."""
    out: dict = {"mass_x_uniform": {}, "opt_ms": {}, "verdicts": {}}
    out["interior_ap"] = {}
    for net, m in predict.items():
        target = "interior" if net == "vertexnet" else "path"  # what each network is for
        share, uniform = (
            m.get(f"test/mass_near_{target}"),
            m.get(f"test/mass_near_{target}_uniform"),
        )
        if share is not None and uniform:
            out["mass_x_uniform"][net] = round(share / uniform, 3)
        if "test/interior_ap" in m and net == "vertexnet":
            out["interior_ap"][net] = round(m["test/interior_ap"], 4)
    for key, sets in summary["cells"].get("optimal", {}).items():
        s = sets.get("random", {}).get("time_to_stop")
        if s is not None and not key.endswith("+informed"):
            out["opt_ms"][short_key(key)] = round(1e3 * s["median"], 3)
    rows = summary["claims"]["rows"]
    verdicts = [r[m]["verdict"] for r in rows for m in ("time_to_stop", "iterations") if r[m]]
    for group in VERDICT_GROUPS:
        out["verdicts"][group.replace("same direction", "same_dir").replace(" ", "_")] = sum(
            v.startswith(group) for v in verdicts
        )
    return out


def report(cfg: DictConfig) -> Path:
    """Write the report, figures and headline metrics; log the MLflow runs when enabled."""
    ev = section(cfg, "eval", EvalConfig)
    taus = [float(t) for t in (*cfg.planner.taus, cfg.planner.tau)]
    summary = read_json(cfg.paths.summary)
    paper = load_paper_tables(cfg.paths.paper_tables)
    predict_file = Path(cfg.paths.metrics) / "predict.json"
    predict = read_json(predict_file) if predict_file.is_file() else {}
    inference = {n: float(m.get("ms_per_map", 0.0)) for n, m in predict.items()}
    text = build_report(
        summary,
        paper,
        optima(cfg.paths.instances),
        inference,
        key_networks(ev, taus),
        str(cfg.scale.name),
        predict,
    )
    out = Path(cfg.paths.report)
    write_text(out, text)
    figures = save_figures(cfg, summary)
    metrics = headline(summary, predict)
    write_json(Path(cfg.paths.metrics) / "headline.json", metrics)
    if cfg.logger.enabled:
        from vnrrt.evaluation.mlflow_runs import log_evaluation

        log_evaluation(cfg, summary, metrics, [out, *figures, Path(cfg.paths.trials_table)])
    return out


def save_figures(cfg: DictConfig, summary: dict) -> list[Path]:
    """Fig. 5 (paired improvement over RRT*) per stop rule that was run, and the
    convergence figure; returns the files written."""
    import pandas as pd

    from vnrrt.viz.evaluation import save_convergence, save_improvements

    figs = Path(cfg.paths.figures) / "evaluation"
    written = []
    for stop in summary["stops"]:
        if stop in summary["over_rrt_star"]["time_to_stop"]:
            path = figs / f"improvement_{stop}.png"
            save_improvements(path, summary["over_rrt_star"]["time_to_stop"][stop], stop)
            written.append(path)
    curves = pd.read_csv(f"{cfg.paths.plots}/convergence.csv")
    if len(curves):
        inst = Instances(cfg.paths.instances)
        names = {
            str(m): str(n)
            for m, n in zip(inst.arrays["map_set"], inst.arrays["name"])
            if m != "random"
        }
        save_convergence(figs / "convergence.png", curves, names)
        written.append(figs / "convergence.png")
    return written
