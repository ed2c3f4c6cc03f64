"""The MLflow run of the heatmap metrics (stage ``predict_metrics``): ``predict <scale>`` in
the scale's experiment.

* params: the metrics' settings (``predict.metric_*``, the M-VNRRT* thresholds), each
  network's target and device;
* metrics named map set, statistic, network: ``random_maps/interior_ap/vertexnet``,
  ``named_maps/mass_near_interior/nrrtnet`` (``predict.json``'s ``test/`` and ``named/``),
  and ``inference/ms_per_map/vertexnet``;
* artifacts: Fig. 3 (``figures/heatmaps.png``, also in the description), ``predict.json``
  and the named maps as a table (``named_maps.json``: map set, name, start and goal cells,
  A* and exact optimal lengths);
* inputs: the networks' logged models and the instances file as a dataset with its DVC hash;
* the tag ``md5/predict.json``, by which the evaluation run finds this run
  (:mod:`vnrrt.tracking.lineage`).
"""

from __future__ import annotations

from pathlib import Path

from vnrrt.tracking import experiments, lineage
from vnrrt.tracking import store as tracking


def predict_metrics(out: dict) -> dict[str, float]:
    """``predict.json``'s numbers as metric names (module doc)."""
    tree: dict = {}
    places = {"test/": "random_maps", "named/": "named_maps"}
    for net, m in out["networks"].items():
        for key, value in m.items():
            prefix = next((p for p in places if key.startswith(p)), None)
            if prefix is not None:
                tree.setdefault(places[prefix], {}).setdefault(key[len(prefix) :], {})[net] = value
        tree.setdefault("inference", {}).setdefault("ms_per_map", {})[net] = m["ms_per_map"]
    return experiments.flat_metrics(tree)


def predict_params(out: dict) -> dict[str, str]:
    """The metrics' settings and each network's target and device (module doc)."""
    params = {f"predict.metric_{k}": v for k, v in out["settings"].items() if k != "taus"}
    params["planner.taus"] = out["settings"]["taus"]
    for net, m in out["networks"].items():
        params |= {f"{net}.target": m["target"], f"{net}.device": m["device"]}
    return experiments.flat_params(params)


def named_table(shown: list) -> dict[str, list]:
    """The named maps (``EvalInstance`` of each) as table columns."""
    return {
        "map_set": [i.map_set for i in shown],
        "name": [i.map for i in shown],
        "start_cell": [list(i.start_cell) for i in shown],
        "goal_cell": [list(i.goal_cell) for i in shown],
        "astar_length_px": [i.astar_length for i in shown],
        "exact_length_px": [i.exact_length for i in shown],
    }


def log_predict(logger: experiments.LoggerConfig, scale: str, out: dict, files: dict[str, Path],
                trainings: dict[str, Path], shown: list) -> str:  # fmt: skip
    """The run (module doc); ``out``: what ``predict.json`` holds; ``files``: its
    ``predict.json``, ``figure`` and ``instances`` files; ``trainings``: network -> training
    metrics file; ``shown``: the named instances. Returns the run's id."""
    import mlflow

    uri, exp, tags = experiments.open_experiment(logger, "predict", scale)
    client = tracking.open_store(uri)
    tags |= lineage.content_tag("predict.json", files["predict.json"])
    trained = [lineage.training_lineage(n, p) for n, p in sorted(trainings.items())]
    mlflow.set_tracking_uri(uri)
    name = experiments.run_name(f"predict {scale}")
    with mlflow.start_run(experiment_id=exp, run_name=name, tags=tags) as run:
        run_id = run.info.run_id
        mlflow.log_params(predict_params(out))
        mlflow.log_metrics(predict_metrics(out))
        client.log_artifact(run_id, str(files["figure"]), "figures")
        client.log_artifact(run_id, str(files["predict.json"]))
        mlflow.log_table(named_table(shown), "named_maps.json")
        models = [t.model_id for t in trained if t.model_id]
        lineage.log_datasets(client, run_id, {"instances": files["instances"]}, "prediction",
                             models)  # fmt: skip
        figure = f"figures/{Path(files['figure']).name}"
        names = ", ".join(f"{i.map_set} ({i.map.replace('_', ' ')})" for i in shown)
        mlflow.set_tag("mlflow.note.content", "\n".join([
            f"**Heatmap metrics at scale `{scale}`** of "
            + ", ".join(f"`{n}`" for n in out["networks"])
            + f": on the random test instances (`random_maps/...`) and the named maps "
            f"(`named_maps/...`: {names}); inference time per map (`inference/ms_per_map`).",
            "",
            "Networks:",
            "",
            *lineage.training_links(exp, trained),
            "",
            f"![Fig. 3: the named maps with each network's heatmap]"
            f"({lineage.artifact_url(run_id, figure)})",
        ]))  # fmt: skip
        return run_id
