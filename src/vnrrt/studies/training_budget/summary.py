"""Statistics of one training seed's budget curve (the whole summary, over seeds:
:mod:`.pooled`), as plain JSON-able data (``paths.budget_summary``) for the report and the
figures.

* **Per budget**: the networks' heatmap metrics over the random instances in multiples of a
  uniform map's (the same metric of a constant map: an AP's is the positives' share, a
  mass's the area share); the paired, clustered speed-ups over RRT*
  (:func:`vnrrt.evaluation.stats.compare`: geometric mean over instances of median(RRT*) /
  median(planner), bootstrap CI) and, the same way, each of VNRRT* and M-VNRRT* against
  NRRT* (median(NRRT*) / median(planner): the ratio of their speed-ups over RRT*).
* **Trend** (:func:`trend`): the slope of a log speed-up (or ratio) against log2(images
  seen), as the factor per doubling of the images, with a bootstrap CI that resamples base
  maps, then instances, jointly for every budget (the budgets share instances and seeds).
  Per instance it takes the median over trials; trials are not resampled.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from vnrrt.evaluation.stats import bootstrap_means, compare

METRICS = ("time_to_stop", "iterations")
HEAT = ("interior_ap", "path_ap", "mass_near_interior", "mass_near_path", "mass_on_endpoints")
RAW = ("interior_recall", "vertex_recall")  # shown as they are (a constant map's is 0 or 1)
TRAIN = ("train_images", "epochs", "fit_seconds", "val/loss", "val/interior_ap", "val/path_ap",
         "checkpoint_sha256", "mlflow_run_id", "budget")  # fmt: skip
# the test split's metrics of each training (held-out base maps; docs/results.md's networks)
TEST = ("test/interior_ap", "test/interior_recall", "test/path_ap", "test/mass_near_interior",
        "test/mass_near_interior_uniform", "test/mass_near_path", "test/mass_near_path_uniform",
        "test/mass_on_endpoints")  # fmt: skip
BASELINE, CONTROL = "rrt_star", "nrrt_star"


def clean(obj):
    """``obj`` with every non-finite float as None (strict JSON)."""
    if isinstance(obj, dict):
        return {k: clean(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [clean(v) for v in obj]
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


def heat_keys(predict: dict) -> list[str]:
    """The metrics shown in multiples of a uniform map: :data:`HEAT` and the interior mass
    after each tau mask that was measured (``mass_near_interior_tau<t>``)."""
    masked = sorted(k[len("test/") :] for k in predict["uniform"]
                    if k.startswith("test/mass_near_interior_tau"))  # fmt: skip
    return [*HEAT, *masked]


def heat_ratios(predict: dict) -> dict[str, dict]:
    """``{network: {metric: {value, uniform, ratio}}}`` over the random instances, and the
    recalls of :data:`RAW` (``value`` only)."""
    uniform, out = predict["uniform"], {}
    for name, metrics in predict["networks"].items():
        cells = {}
        for key in heat_keys(predict):
            value, base = metrics[f"test/{key}"], uniform[f"test/{key}"]
            cells[key] = {"value": value, "uniform": base,
                          "ratio": value / base if base > 0 else math.nan}  # fmt: skip
        cells |= {key: {"value": metrics[f"test/{key}"]} for key in RAW}
        out[name] = cells
    return out


def _random(table: pd.DataFrame) -> pd.DataFrame:
    return table[table["map_set"] == "random"]


def _compare(base, plan, metric: str, settings: dict) -> dict:
    c = compare(base, plan, metric, n_boot=int(settings["bootstrap"]),
                level=float(settings["level"]))  # fmt: skip
    keep = ("speedup", "ci_low", "ci_high", "failed_baseline", "failed_planner", "trials")
    return {k: v for k, v in c.as_dict().items() if k in keep}


def budget_point(inp: dict, settings: dict) -> dict:
    """One budget's statistics (module doc) from its inputs (``steps``, ``trials``,
    ``predict``, ``trainings``: :func:`.stage.budget_inputs`)."""
    table, speedups, ratios, success = _random(inp["trials"]), {}, {}, {}
    for stop in settings["stops"]:
        sub = table[table["stop"] == stop]
        rows = {k: sub[sub["key"] == k] for k in settings["keys"]}
        success[stop] = {k: float(r["success"].mean()) for k, r in rows.items()}
        for metric in METRICS:
            speedups.setdefault(stop, {})[metric] = {
                k: _compare(rows[BASELINE], r, metric, settings)
                for k, r in rows.items() if k != BASELINE}  # fmt: skip
            ratios.setdefault(stop, {})[metric] = {
                k: _compare(rows[CONTROL], rows[k], metric, settings)
                for k in settings["ratio_keys"]}  # fmt: skip
    heat = heat_ratios(inp["predict"])
    networks = {n: {"train": {k: t[k] for k in (*TRAIN, *TEST) if k in t}, "heatmap": heat[n]}
                for n, t in inp["trainings"].items()}  # fmt: skip
    images = {int(t["train_images"]) for t in inp["trainings"].values()}
    if len(images) != 1:
        raise ValueError(f"budget {inp['steps']}: the networks saw {sorted(images)} images")
    return {"steps": int(inp["steps"]), "images": images.pop(), "networks": networks,
            "speedups": speedups, "ratios": ratios, "success": success}  # fmt: skip


def instance_log_ratios(table: pd.DataFrame, base: str, plan: str, stop: str,
                        metric: str) -> pd.Series:  # fmt: skip
    """``log(median(base) / median(plan))`` per random instance (index: instance, cluster)
    of one stop rule; iterations counted +1 as :func:`vnrrt.evaluation.stats.compare` does."""
    sub = _random(table)
    sub = sub[(sub["stop"] == stop) & sub["key"].isin([base, plan])]
    shift = 1.0 if metric == "iterations" else 0.0
    med = sub.groupby(["instance", "cluster", "key"])[metric].median().unstack("key") + shift
    return np.log(med[base]) - np.log(med[plan])


def trend(tables: list[pd.DataFrame], images: list[int], base: str, plan: str, stop: str,
          metric: str, settings: dict) -> dict:  # fmt: skip
    """The factor per doubling of the images seen of the geometric-mean speed-up of ``plan``
    over ``base`` (module doc), with its bootstrap CI and a verdict: ``grows`` (CI above 1),
    ``shrinks`` (below 1), ``no clear trend``; NaN with one budget."""
    out = {"base": base, "planner": plan, "stop": stop, "metric": metric}
    if len(tables) < 2:
        return out | {"per_doubling": math.nan, "ci_low": math.nan, "ci_high": math.nan,
                      "verdict": "one budget: no trend"}  # fmt: skip
    logs = pd.concat([instance_log_ratios(t, base, plan, stop, metric) for t in tables], axis=1)
    if logs.isna().any().any():
        raise ValueError(f"{plan} against {base} ({stop}): the budgets' instances differ")
    x = np.log2(np.asarray(images, np.float64))
    weights = (x - x.mean()) / np.sum((x - x.mean()) ** 2)  # OLS slope = weights @ y
    per_instance = logs.to_numpy() @ weights  # (I,): each instance's share of the slope
    clusters = logs.index.get_level_values("cluster").to_numpy()
    rng = np.random.default_rng(0)
    boots = bootstrap_means(per_instance, clusters, int(settings["bootstrap"]), rng)
    level = float(settings["level"])
    lo, hi = np.quantile(boots, [(1 - level) / 2, (1 + level) / 2])
    verdict = "grows" if lo > 0 else "shrinks" if hi < 0 else "no clear trend"
    return out | {"per_doubling": float(np.exp(per_instance.mean())),
                  "ci_low": float(np.exp(lo)), "ci_high": float(np.exp(hi)),
                  "verdict": verdict}  # fmt: skip


def trends(inputs: list[dict], images: list[int], settings: dict) -> list[dict]:
    """:func:`trend` of every speed-up over RRT* and every ratio against NRRT*, per stop rule
    and metric."""
    tables = [inp["trials"] for inp in inputs]
    pairs = [(BASELINE, k) for k in settings["keys"] if k != BASELINE]
    pairs += [(CONTROL, k) for k in settings["ratio_keys"]]
    return [trend(tables, images, base, plan, stop, metric, settings)
            for stop in settings["stops"] for metric in METRICS
            for base, plan in pairs]  # fmt: skip
