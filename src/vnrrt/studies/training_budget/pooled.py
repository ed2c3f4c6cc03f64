"""The budget curve over several training seeds (``budget.seeds``): each budget's speed-ups
pooled over the seeds' networks, and trend labels that hold across seeds.

* **Pooled speed-ups** (:func:`pooled_point`): the geometric mean over (seed, instance) of
  ``median(base) / median(plan)`` with a bootstrap CI that resamples training seeds, then
  base maps, instances and trials (:func:`vnrrt.evaluation.seeds.seed_compare`), so the
  interval includes the training variance. With one seed the point is that seed's own
  (:func:`.summary.budget_point`, clustered over base maps, instances and trials).
* **Trends** (:func:`seed_trends`): the slope per doubling of the images (:func:`.summary.trend`)
  within each seed; the label is ``grows`` or ``shrinks`` only where every seed's CI says so,
  ``no clear trend`` where none does, and ``differs between seeds`` otherwise.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from vnrrt.evaluation.seeds import seed_compare
from vnrrt.evaluation.table import solved
from vnrrt.studies.training_budget.summary import (
    BASELINE,
    CONTROL,
    METRICS,
    budget_point,
    clean,
    trend,
)

BY = ["instance", "trial"]


def paired_rows(inputs: list[dict], base: str, plan: str, stop: str, metric: str, *,
                map_set: str = "random") -> pd.DataFrame:  # fmt: skip
    """One row per (training seed, instance of ``map_set``, trial) of ``base`` and ``plan``
    at one stop rule: columns ``network_seed``, ``cluster``, ``instance``, ``trial``,
    ``base`` and ``plan`` (the metric), ``base_ok`` and ``plan_ok`` (success); ``inputs``:
    one budget's runs (``seed``, ``trials``)."""
    frames = []
    for inp in inputs:
        t = inp["trials"]
        t = t[(t["map_set"] == map_set) & (t["stop"] == stop)]
        t = t.assign(success=solved(t, metric))  # as the metric's reading counts a success
        cols = [*BY, "cluster", metric, "success"]
        b = t[t["key"] == base][cols].rename(columns={metric: "base", "success": "base_ok"})
        p = t[t["key"] == plan][[*BY, metric, "success"]]
        p = p.rename(columns={metric: "plan", "success": "plan_ok"})
        frames.append(b.merge(p, on=BY, validate="one_to_one").assign(network_seed=inp["seed"]))
    return pd.concat(frames, ignore_index=True)


def _pooled(inputs: list[dict], base: str, plan: str, stop: str, metric: str,
            settings: dict) -> dict:  # fmt: skip
    """One pooled cell: ``speedup``, ``ci_low``, ``ci_high``, ``per_seed``, the failed trials
    of either side and the trials (module doc)."""
    rows = paired_rows(inputs, base, plan, stop, metric)
    c = seed_compare(rows, metric, n_boot=int(settings["bootstrap"]),
                     level=float(settings["level"]))  # fmt: skip
    return {"speedup": c["speedup"], "ci_low": c["ci_low"], "ci_high": c["ci_high"],
            "per_seed": c["per_seed"], "failed_baseline": int((~rows["base_ok"]).sum()),
            "failed_planner": int((~rows["plan_ok"]).sum()), "trials": len(rows)}  # fmt: skip


def _mean_heat(points: list[dict]) -> dict:
    """``{network: {"train": {seed: record}, "heatmap": {metric: {ratio, value, low, high}}}}``:
    each heatmap metric's mean over the seeds' networks, and its smallest and largest."""
    out = {}
    for name in points[0]["networks"]:
        heat = {}
        for key, cell in points[0]["networks"][name]["heatmap"].items():
            field = "ratio" if "ratio" in cell else "value"
            vals = [p["networks"][name]["heatmap"][key][field] for p in points]
            vals = [v for v in vals if v is not None and math.isfinite(v)]
            mean = float(np.mean(vals)) if vals else math.nan
            heat[key] = {field: mean, "low": min(vals, default=math.nan),
                         "high": max(vals, default=math.nan)}  # fmt: skip
        train = {str(p["seed"]): p["networks"][name]["train"] for p in points}
        out[name] = {"train": train, "heatmap": heat}
    return out


def pooled_point(inputs: list[dict], settings: dict) -> dict:
    """One budget's statistics over its seeds' runs ``inputs`` (each ``steps``, ``seed``,
    ``trials``, ``predict``, ``trainings``): ``steps``, ``images``, ``seeds``, ``per_seed``
    (each seed's :func:`.summary.budget_point`), and the pooled ``speedups``, ``ratios``,
    ``success`` and ``networks`` (module doc)."""
    per_seed = [budget_point(inp, settings) | {"seed": int(inp["seed"])} for inp in inputs]
    images = {p["images"] for p in per_seed}
    if len(images) != 1:
        raise ValueError(f"budget {inputs[0]['steps']}: the seeds' networks saw {images} images")
    out = {"steps": per_seed[0]["steps"], "images": per_seed[0]["images"],
           "seeds": [p["seed"] for p in per_seed], "per_seed": per_seed}  # fmt: skip
    if len(per_seed) == 1:
        one = per_seed[0]
        return out | {k: one[k] for k in ("speedups", "ratios", "success", "networks")}
    speedups, ratios, success = {}, {}, {}
    for stop in settings["stops"]:
        success[stop] = {k: float(np.mean([p["success"][stop][k] for p in per_seed]))
                         for k in settings["keys"]}  # fmt: skip
        for metric in METRICS:
            speedups.setdefault(stop, {})[metric] = {
                k: _pooled(inputs, BASELINE, k, stop, metric, settings)
                for k in settings["keys"] if k != BASELINE}  # fmt: skip
            ratios.setdefault(stop, {})[metric] = {
                k: _pooled(inputs, CONTROL, k, stop, metric, settings)
                for k in settings["ratio_keys"]}  # fmt: skip
    return out | {"speedups": speedups, "ratios": ratios, "success": success,
                  "networks": _mean_heat(per_seed)}  # fmt: skip


def label_across(verdicts: list[str]) -> str:
    """One trend label from the seeds' own (module doc)."""
    return verdicts[0] if len(set(verdicts)) == 1 else "differs between seeds"


def seed_trends(inputs: list[dict], settings: dict) -> list[dict]:
    """Every trend of :func:`.summary.trends` per seed with at least two budgets, and the
    label across them (module doc): ``per_doubling`` the geometric mean of the seeds'
    factors; ``ci_low``/``ci_high`` that seed's CI with one seed, else None (each seed's is
    in ``per_seed``)."""
    by_seed: dict[int, list[dict]] = {}
    for inp in inputs:
        by_seed.setdefault(int(inp["seed"]), []).append(inp)
    pairs = [(BASELINE, k) for k in settings["keys"] if k != BASELINE]
    pairs += [(CONTROL, k) for k in settings["ratio_keys"]]
    out = []
    for stop in settings["stops"]:
        for metric in METRICS:
            for base, plan in pairs:
                per = {str(s): trend([i["trials"] for i in runs], [_images(i) for i in runs],
                                     base, plan, stop, metric, settings)
                       for s, runs in sorted(by_seed.items())}  # fmt: skip
                out.append(_across(per, base, plan, stop, metric))
    return out


def _images(inp: dict) -> int:
    """The training images a run's networks saw (they agree: :func:`.summary.budget_point`)."""
    return int(next(iter(inp["trainings"].values()))["train_images"])


def _across(per: dict, base: str, plan: str, stop: str, metric: str) -> dict:
    """The trend across seeds of the per-seed trends ``per`` (:func:`seed_trends`)."""
    head = {"base": base, "planner": plan, "stop": stop, "metric": metric}
    slopes = [t["per_doubling"] for t in per.values()]
    if any(not math.isfinite(v) for v in slopes):
        return head | {"per_doubling": math.nan, "ci_low": math.nan, "ci_high": math.nan,
                       "verdict": "one budget: no trend", "per_seed": per}  # fmt: skip
    one = next(iter(per.values())) if len(per) == 1 else None
    return head | {
        "per_doubling": float(np.exp(np.mean(np.log(slopes)))),
        "ci_low": None if one is None else one["ci_low"],
        "ci_high": None if one is None else one["ci_high"],
        "verdict": label_across([t["verdict"] for t in per.values()]),
        "per_seed": per,
    }


def analyze_budgets(inputs: list[dict], settings: dict) -> dict:
    """The whole summary of the budget curve of every run's inputs (``steps``, ``seed``,
    ``trials``, ``predict``, ``trainings``; every budget at the same seeds): per budget
    :func:`pooled_point`, the trends across seeds (:func:`seed_trends`), the instances and
    base maps. ``settings`` (kept in the summary for its readers, with the heatmap metrics'
    own) holds at least ``stops``, ``keys``, ``ratio_keys``, ``bootstrap`` and ``level``."""
    if not inputs:
        raise ValueError("the budget curve needs at least one budget (budget.steps)")
    by_steps: dict[int, list[dict]] = {}
    for inp in inputs:
        by_steps.setdefault(int(inp["steps"]), []).append(inp)
    seeds = {tuple(sorted(int(i["seed"]) for i in runs)) for runs in by_steps.values()}
    if len(seeds) != 1:
        raise ValueError(f"every budget must run at the same training seeds, not {seeds}")
    points = [pooled_point(by_steps[s], settings) for s in sorted(by_steps)]
    first = inputs[0]["trials"]
    first = first[first["map_set"] == "random"]
    summary = {
        "settings": {**settings, "heatmap": dict(inputs[0]["predict"]["settings"])},
        "metrics": list(METRICS),
        "seeds": list(seeds.pop()),
        "budgets": points,
        "trends": seed_trends(inputs, settings),
        "instances": int(first["instance"].nunique()),
        "clusters": int(first["cluster"].nunique()),
    }
    return clean(summary)
