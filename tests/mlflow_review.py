"""What a reviewer finds in MLflow after the smoke pipeline, read through a tracking server's
REST API (:mod:`tests.mlflow_server`) and checked against the pipeline's own files: the
statistics files, the training metrics and DVC's lock file (the independent record of every
file's hash). Used by ``tests/pipeline/test_pipeline.py``."""

from __future__ import annotations

import json
import re
from pathlib import Path

import yaml

from tests.mlflow_server import Rest, metrics, params, tags
from vnrrt.studies.paper_comparison.claims import verdict_text

IMAGE = re.compile(r"!\[[^\]]*\]\(([^)\s]+)\)")
LINK = re.compile(r"\]\((#/[^)\s]+)\)")


def dvc_hashes(work: Path) -> dict[str, str]:
    """``{path: md5}`` of every file DVC recorded in ``dvc.lock``."""
    lock = yaml.safe_load((work / "dvc.lock").read_text())
    out = {}
    for stage in lock["stages"].values():
        for entry in stage.get("outs", []) + stage.get("deps", []):
            if "md5" in entry and not entry["md5"].endswith(".dir"):
                out[entry["path"]] = entry["md5"]
    return out


def read(work: Path, path: str) -> dict:
    return json.loads((work / path).read_text())


def runs_by_kind(rest: Rest, exp: str) -> tuple[dict, dict]:
    """``({kind: top-level run}, {parent id: [children]})`` of experiment ``exp`` (the
    newest top-level run of each kind, as ``runs/get`` gives it: with its model inputs)."""
    top, children = {}, {}
    for run in sorted(rest.runs(exp), key=lambda r: int(r["info"]["start_time"])):
        t = tags(run)
        if "mlflow.parentRunId" in t:
            children.setdefault(t["mlflow.parentRunId"], []).append(run)
        else:
            top[t["kind"]] = run
    top = {k: rest.get("runs/get", run_id=r["info"]["run_id"])["run"] for k, r in top.items()}
    return top, children


def check_description_links(rest: Rest, exp: str, run: dict, work: Path) -> None:
    """The evaluation run's description links every training run, registry version, the
    predict run and the ideas run, and each link names what exists."""
    note = tags(run)["mlflow.note.content"]
    links = LINK.findall(note)
    for net in ("vertexnet", "nrrtnet"):
        train = read(work, f"reports/metrics/train_{net}.json")
        assert f"#/experiments/{exp}/runs/{train['mlflow_run_id']}" in links, net
        name, version = train["mlflow_model_version"].removeprefix("models:/").split("/")
        assert f"#/models/{name}/versions/{version}" in links, net
        got = rest.get("model-versions/get", name=name, version=version)["model_version"]
        assert got["run_id"] == train["mlflow_run_id"]
    for link in (x for x in links if "/runs/" in x):
        assert rest.get("runs/get", run_id=link.rsplit("/", 1)[1])["run"]
    assert "| **" in note and "verdict" in note  # the verdict table, verdicts in bold
    assert "get-artifact?path=figures%2Fevaluation%2Fimprovement_optimal.png" in note


def check_claims(run: dict, summary: dict) -> None:
    """Per claim and reading, the speed-up and CI bounds as metrics and the verdicts as tags,
    equal to the summary's."""
    m, t = metrics(run), tags(run)
    rows = summary["claims"]["rows"]
    verdicts = {k: v for k, v in t.items() if k.startswith("verdict/") and k.count("/") == 1}
    assert sorted(verdicts.values()) == sorted(verdict_text(r) for r in rows)  # the report's
    for row in rows:
        (key,) = [k for k, v in t.items() if k.startswith("claim/") and v == row["text"]]
        claim = key.removeprefix("claim/")
        assert t[f"verdict/{claim}"] == verdict_text(row)
        for reading, name in (("time_to_stop", "planning_time"), ("iterations", "iterations")):
            for stat in ("speedup", "ci_low", "ci_high"):
                assert m[f"claims/{claim}/{name}/{stat}"] == row[reading][stat], (claim, stat)
            assert t[f"verdict/{claim}/{name}"] == row[reading]["verdict"]


def check_inputs(run: dict, work: Path, context: str, files: dict[str, str]) -> None:
    """The run's dataset inputs (name -> pipeline file) in ``context``, each digest the
    file's hash in dvc.lock."""
    hashes = dvc_hashes(work)
    got = {
        d["dataset"]["name"]: (d["dataset"]["digest"], {x["key"]: x["value"] for x in d["tags"]})
        for d in run["inputs"].get("dataset_inputs", [])
    }
    for name, path in files.items():
        assert got[name] == (hashes[path], {"mlflow.data.context": context}), name


def check_reports(rest: Rest, run: dict) -> list[str]:
    """Every markdown report of a run: each image it shows is among the run's artifacts (and
    served); each UI link to an artifact names one that exists. Returns the reports."""
    run_id = run["info"]["run_id"]
    files = rest.artifact_paths(run_id)
    reports = sorted(p for p in files if p.endswith(".md"))
    for report in reports:
        text = rest.artifact(run_id, report).decode()
        images = IMAGE.findall(text)
        assert all(p in files for p in images), (report, images, files)
        for link in LINK.findall(text):
            if "/artifacts/" in link:
                other, path = link.split("/runs/")[1].split("/artifacts/")
                assert path in rest.artifact_paths(other), (report, link)
        assert report.replace(".md", ".html") in files
    return reports


def check_ideas_children(children: list[dict], ideas: dict) -> None:
    """One nested run per regime cell and configuration of ``ideas.json``, each with the
    params that say what it sampled (checked against its configuration's text)."""
    cells = {(c["regime"], c["configuration"]) for c in ideas["cells"]}
    got = {(params(c)["regime_cell"], tags(c)["planner"]): params(c) for c in children}
    assert set(got) == cells
    names = [c["info"]["run_name"] for c in children]
    assert len(set(names)) == len(names) and all(" · ideas " in n for n in names)
    for (_cell, text), p in got.items():
        named = re.search(r"\[([^\]]+)\]", text)
        source = named.group(1) if named else ""
        fields = dict(re.findall(r"@([wsq])([\d.]+)", source))
        if source.startswith("oracle_"):
            assert p["oracle"] == source.split("@")[0] and p["source"] == source
            assert float(p["q"]) == float(fields.get("q", 1))
            if "s" in fields:
                assert float(p["sigma"]) == float(fields["s"])
        mix = re.search(r"~([\d.]+)", text)
        assert (p["mix"] == "null") if mix is None else float(p["mix"]) == float(mix.group(1))
