"""The DVC pipeline end to end at smoke scale, in a scratch git + DVC copy of the repository:
validation before any work, verified deterministic shards, resuming, temp files DVC does not
hash, the whole run with its report, metrics, plots and MLflow runs (logged through a real
tracking server and reviewed through its REST API; slow: in a browser), each stage writing
exactly its outputs, reproducible outputs, an ablation experiment that re-runs only the
evaluation and whose every report, figure and metrics file names the values it ran, and (slow)
the parts as multirun jobs.

Every stage script runs with ``tests/write_audit`` on ``PYTHONPATH``: it logs the files each
stage process created or changed (``writes.jsonl`` beside the work folder)."""

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from tests import mlflow_review as review
from tests.conftest import copy_dvc_files, copy_pipeline
from tests.mlflow_server import Rest, TrackingServer, metrics, params, tags
from vnrrt.config import compose, dump, section
from vnrrt.config.paths import Paths, stage_outputs
from vnrrt.data.build import build_shard
from vnrrt.data.config import LabelsConfig
from vnrrt.data.heatmaps import read_heatmaps
from vnrrt.data.manifest import verify_manifest
from vnrrt.data.shards import shard_file
from vnrrt.evaluation.noise import baseline_record
from vnrrt.evaluation.table import SEEDED_COLUMNS, merge_parts
from vnrrt.maps.config import DataConfig
from vnrrt.studies.paper_comparison.headline import VERDICT_KEYS

SHARDS = Path("data/smoke/shards")
# The session's pipeline runs at these values rather than conf/'s defaults, so that every test
# reading its outputs also checks that they name the values that ran (none of the defaults):
# the stop tolerance, the tau list and the CI level, ablated together (the claims' tau stays the
# paper's 0.5, so that every claim gets a verdict).
SESSION = ["planner.eps=0.05", "planner.taus=[0.3,0.7]", "stats.level=0.9"]
SMOKE = ["scale=smoke", *SESSION]
DEFAULT_TEXTS = ("within 1%", "1% of", "95%", "eps 0.01", "eps = 0.01", "τ=0.9", "τ=0.99")
# The training-budget curve's stages (conf/budget: none at smoke): run by the slow test at the
# end, at one budget of the pipeline training's own 3 steps (so they must reproduce it).
BUDGET_STAGES = {"budget_train", "budget_predict", "budget_trials", "budget_report"}
ONE_BUDGET = ["budget.steps=[3]", "budget.report=[training_budget]"]
AUDIT = Path(__file__).resolve().parents[1] / "write_audit"


def write_log(work: Path) -> Path:
    """The write audit's log of the work folder ``work`` (module doc)."""
    return work.parent / "writes.jsonl"


def _env(cwd: Path, **env_vars: str) -> dict[str, str]:
    """The environment of a DVC command in ``cwd``: this interpreter first on PATH, no MLflow
    URI from outside, the write audit on."""
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    env.pop("MLFLOW_TRACKING_URI", None)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(AUDIT), env.get("PYTHONPATH")) if p)
    env["VNRRT_WRITE_LOG"] = str(write_log(cwd))
    return env | env_vars


def seed_override(work: Path) -> str:
    """``seed=<n>``: the seed of the workspace's ``params.yaml`` (the session's, unless a test
    changed it), for a command that must compose the workspace's own values."""
    return f"seed={yaml.safe_load((work / 'params.yaml').read_text())['seed']}"


def run(cmd: list[str], cwd: Path, ok: bool = True, **env_vars: str) -> str:
    env = _env(cwd, **env_vars)
    proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, check=False)
    if ok:
        assert proc.returncode == 0, f"{' '.join(cmd)} failed:\n{proc.stdout}\n{proc.stderr}"
    else:
        assert proc.returncode != 0, f"{' '.join(cmd)} succeeded:\n{proc.stdout}"
    return proc.stdout + proc.stderr


@pytest.fixture(scope="module")
def workdir(tmp_path_factory, repo):
    work = copy_pipeline(repo, tmp_path_factory.mktemp("pipeline") / "repo")
    run(["git", "init", "-q"], work)
    run(["dvc", "init", "-q"], work)
    copy_dvc_files(repo, work)
    shutil.copy(repo / ".gitignore", work / ".gitignore")
    (work / "params.yaml").write_text(dump(compose(SMOKE)))
    return work


@pytest.fixture(scope="module")
def tracking_server(workdir):
    """A tracking server on the work folder's SQLite store, for the module; stopped after."""
    server = TrackingServer(workdir / "mlflow.db", workdir.parent / "mlflow-server.log")
    try:
        server.wait()
        yield server
    finally:
        server.stop()


DATA_STAGES = ["manifest", "named_maps"]


def test_a_bad_value_fails_before_the_first_shard(workdir):
    params = workdir / "params.yaml"
    good = params.read_text()
    doc = yaml.safe_load(good)
    doc["planner"]["eta"] = -1
    params.write_text(yaml.safe_dump(doc, sort_keys=False))
    try:
        out = run(["dvc", "repro", *DATA_STAGES], workdir, ok=False)
        assert "planner setting eta=-1" in out and not (workdir / SHARDS).exists()
        doc["planner"]["eta"], doc["planner"]["tau"] = 10.0, 1.5
        params.write_text(yaml.safe_dump(doc, sort_keys=False))
        out = run(["dvc", "repro", "shard@0"], workdir, ok=False)
        assert "planner.tau" in out and not (workdir / SHARDS).exists()
    finally:
        params.write_text(good)


def test_dvc_repro_smoke_builds_verified_deterministic_shards(workdir):
    run(["dvc", "repro", *DATA_STAGES], workdir)
    manifest = workdir / "data/smoke/manifest.json"
    assert len(verify_manifest(manifest)) == 2
    metrics = json.loads((workdir / "reports/metrics/data.json").read_text())
    assert metrics["instances"] == 2 * 4 * 144 and metrics["bytes_per_instance"] < 700
    assert (workdir / "reports/figures/named_maps.png").stat().st_size > 10_000
    direct = workdir / "direct.npz"
    build_shard(direct, 1, 0, 4, DataConfig(), LabelsConfig(), workers=1)
    assert direct.read_bytes() == shard_file(workdir / SHARDS, 1).read_bytes()
    assert "didn't change" in run(["dvc", "repro", *DATA_STAGES], workdir)


def test_a_stray_temp_file_beside_the_shards_changes_nothing(workdir):
    """A killed write leaves ``<name>.tmp-<pid>``: DVC does not hash it (.dvcignore) and the
    next write of that file removes it."""
    stray = workdir / SHARDS / "shard_0.npz.tmp-999999"
    stray.write_bytes(b"half a shard")
    assert "up to date" in run(["dvc", "status", *DATA_STAGES], workdir)
    run(["dvc", "repro", "-f", "-s", "shard@0"], workdir)
    assert not stray.exists()


def test_an_interrupted_run_resumes_after_the_last_finished_shard(workdir):
    """DVC records each finished stage in dvc.lock; a run stopped after shard@0 resumes
    with shard@1 and does not redo shard@0."""
    (workdir / "params.yaml").write_text(dump(compose([*SMOKE, "seed=1"])))
    run(["dvc", "repro", "shard@0"], workdir)  # the run that got this far, then stopped
    out = run(["dvc", "repro", *DATA_STAGES], workdir)
    assert "Running stage 'shard@1'" in out and "Running stage 'shard@0'" not in out
    assert not list((workdir / "data").rglob("*.tmp-*"))


def test_smoke_dvc_repro_end_to_end(workdir, tracking_server):
    """Every stage at smoke scale: report, headline metrics, plots and MLflow runs (the
    stages log through the tracking server)."""
    from mlflow import MlflowClient

    run(["dvc", "repro"], workdir, MLFLOW_TRACKING_URI=tracking_server.url)
    report = (workdir / "reports/paper_comparison.md").read_text()
    for text in (
        "| VNRRT* | ours | ",
        "| M-VNRRT* τ=0.3 | ours | ",
        "## Optimal path lengths",
        "exact continuous optimum",
        "## Planning time and network inference",
        "Bonferroni",
        "## Settings: this run beside the paper",
        "| heatmap draw probability | 0.5 (`planner.mix`)",
        "### What the masked claims test",
        "## Time to within 5% of the exact continuous optimum",
    ):
        assert text in report, text
    ideas = (workdir / "reports/sampling_ideas.md").read_text()
    for text in (
        "## Conclusion",
        "## Envelopes, within 5% of A*",
        "The blend at each w against w = 0",
        "## The heatmap-quality curve",
        "## The obstacle rule",
        "## The planner regime",
        "[oracle_vertex@s",
    ):
        assert text in ideas, text
    assert (workdir / "reports/figures/ideas/quality_curve.png").stat().st_size > 10_000
    headline = json.loads((workdir / "reports/metrics/headline.json").read_text())
    # one verdict per testable claim; an untestable claim gets none in the counts
    counted = sum(headline[k] for k in VERDICT_KEYS.values())
    assert counted + headline["untestable"] == 8 and headline["testable"] == counted
    client = MlflowClient(f"sqlite:///{workdir / 'mlflow.db'}")
    exp = client.get_experiment_by_name("vnrrt-smoke")
    runs = client.search_runs([exp.experiment_id])
    stages = sorted(r.data.tags.get("dvc_stage", "") for r in runs)
    assert stages.count("train@vertexnet") == 1 and stages.count("train@nrrtnet") == 1
    parents = [
        r
        for r in runs
        if r.data.tags.get("kind") == "evaluation" and "mlflow.parentRunId" not in r.data.tags
    ]
    children = [r for r in runs if r.data.tags.get("mlflow.parentRunId") == parents[0].info.run_id]
    # 6 configurations, each also informed, and the mask variants and control at the claims' tau
    assert len(parents) == 1 and len(children) == 12 + 3
    train_ids = {r.info.run_id for r in runs if r.data.tags.get("kind") == "vertexnet"}
    assert parents[0].data.tags["training_run.vertexnet"] in train_ids
    rate = "random_maps/within_5pct_of_astar/success_rate"
    assert all(0 <= c.data.metrics[rate] <= 1 for c in children)


def test_the_study_reads_in_mlflow_through_the_rest_api(workdir, tracking_server):
    """What a reviewer sees, read as the UI reads it (the server's REST API and artifact
    route), against the pipeline's files: the evaluation run's description links, per-claim
    metrics and verdict tags, model and dataset inputs (dvc.lock's hashes); the predict run's
    figures and inference metric; the ideas children's params; the aliases (and a heatmap by
    alias); the training runs' datasets and system metrics; every figure a logged report
    shows among its run's artifacts."""
    from vnrrt.data.instances import Instances
    from vnrrt.predict import heatmap
    from vnrrt.studies.benchmark_maps.report import description

    rest = Rest(tracking_server.url)
    exp = rest.get("experiments/get-by-name", experiment_name="vnrrt-smoke")["experiment"]
    top, children = review.runs_by_kind(rest, exp["experiment_id"])
    evaluation, ideas = top["evaluation"], top["ideas"]
    review.check_description_links(rest, exp["experiment_id"], evaluation, workdir)
    review.check_claims(evaluation, review.read(workdir, "data/smoke/summary.json"))
    trainings = {n: review.read(workdir, f"reports/metrics/train_{n}.json") for n in
                 ("vertexnet", "nrrtnet")}  # fmt: skip
    models = {m["model_id"] for m in evaluation["inputs"]["model_inputs"]}
    assert models == {t["mlflow_model_id"] for t in trainings.values()}
    for model in models:
        assert rest.get(f"logged-models/{model}")["model"]["info"]["name"] in trainings
    heat = {f"heatmaps part_{k}": f"data/smoke/heatmaps/part_{k}.npz" for k in (0, 1)}
    files = {"instances": "data/smoke/instances.npz", "trials": "data/smoke/trials.csv", **heat}
    review.check_inputs(evaluation, workdir, "evaluation", files)
    assert tags(evaluation)["ideas_run"] == ideas["info"]["run_id"]
    assert review.check_reports(rest, evaluation) == ["paper_comparison.md"]
    assert review.check_reports(rest, ideas) == ["sampling_ideas.md"]
    bench = top["bench_maps"]  # the benchmark-maps study: its report as description and files
    assert review.check_reports(rest, bench) == ["benchmark_maps.md"]
    studied = review.read(workdir, "reports/metrics/benchmark_maps.json")
    assert tags(bench)["mlflow.note.content"] == description(studied, "smoke")
    cells = studied["cells"]
    (vnrrt,) = [c for c in cells if (c["map"], c["configuration"]) == ("pooled", "vnrrt_star")]
    name = "pooled/within_5pct_of_exact_optimum/vnrrt/speedup_over_rrt_star/time_to_stop/speedup"
    assert metrics(bench)[name] == vnrrt["time_to_stop"]["speedup"]
    predict = review.read(workdir, "reports/metrics/predict.json")
    run = top["predict"]
    assert "figures/heatmaps.png" in rest.artifact_paths(run["info"]["run_id"])
    for net, m in predict["networks"].items():
        assert metrics(run)[f"inference/ms_per_map/{net}"] == m["ms_per_map"]
        assert metrics(run)[f"named_maps/interior_ap/{net}"] == m["named/interior_ap"]
    review.check_ideas_children(children[ideas["info"]["run_id"]], review.read(
        workdir, "data/smoke/ideas.json"))  # fmt: skip
    names = {c["info"]["run_name"] for c in children[evaluation["info"]["run_id"]]}
    assert all(n.endswith(" · evaluation smoke") for n in names) and len(names) == 15
    for net, t in trainings.items():
        alias = rest.get("registered-models/alias", name=f"vnrrt-{net}", alias="smoke")
        assert alias["model_version"]["run_id"] == t["mlflow_run_id"]
        train = rest.get("runs/get", run_id=t["mlflow_run_id"])["run"]
        assert params(train)["network.target"] == t["target"]["kind"]
        assert any(k.startswith("system/") for k in metrics(train))
        split = {f"shards smoke ({s} split)": "data/smoke/manifest.json" for s in ("train",)}
        review.check_inputs(train, workdir, "training", split)
    inst = Instances(workdir / "data/smoke/instances.npz")[0]
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("MLFLOW_TRACKING_URI", tracking_server.url)
        by_alias = heatmap(
            "models:/vnrrt-vertexnet@smoke", inst.grid, inst.start_cell, inst.goal_cell
        )
    by_file = heatmap(
        workdir / "models/smoke/vertexnet.ckpt", inst.grid, inst.start_cell, inst.goal_cell
    )
    np.testing.assert_allclose(by_alias, by_file, atol=1e-6)


@pytest.mark.slow
def test_the_evaluation_run_page_shows_the_verdict_table_and_fig5_in_a_browser(
    workdir, tracking_server
):
    """The evaluation run's page in headless Chromium: the verdict table (every claim and
    its verdict) and Fig. 5 rendered (loaded, non-empty) in the description, the run's name
    and overrides tag (the session's settings are an ablation of conf/'s); the report's
    HTML in the artifact viewer's frame. Needs Debian's chromium (``apt-get install
    chromium`` as root)."""
    from tests.browser import Browser, chromium, open_run_page

    if chromium() is None:
        pytest.skip("no chromium on PATH: `apt-get install chromium` (Debian, as root)")
    run(["dvc", "repro"], workdir, MLFLOW_TRACKING_URI=tracking_server.url)  # up to date
    rest = Rest(tracking_server.url)
    exp = rest.get("experiments/get-by-name", experiment_name="vnrrt-smoke")["experiment"]
    exp_id = exp["experiment_id"]
    top, _ = review.runs_by_kind(rest, exp_id)
    run_id = top["evaluation"]["info"]["run_id"]
    rows = review.read(workdir, "data/smoke/summary.json")["claims"]["rows"]
    with Browser() as page:
        open_run_page(page, tracking_server.url, exp_id, run_id)
        tables = page.wait_for(
            "[...document.querySelectorAll('table')].map(t => t.innerText)"
            ".filter(t => t.includes('verdict') && t.includes('the paper'))"
        )
        assert tables, "no verdict table on the run page"
        lines = tables[0].splitlines()
        for row in rows:
            (line,) = [ln for ln in lines if ln.startswith(row["text"])]
            assert row["verdict"] in line, (row["text"], line)
        shown = page.wait_for(
            "[...document.images].filter(i => i.src.includes('get-artifact') && i.complete"
            " && i.naturalWidth > 0).map(i => [i.src, i.naturalWidth, i.naturalHeight])"
        )
        assert shown and "improvement_optimal.png" in shown[0][0] and shown[0][1] > 300
        # the session's settings differ from conf/'s: the page names the run after them and
        # shows them as its overrides tag
        name, said = top["evaluation"]["info"]["run_name"], review.tags(top["evaluation"])
        assert "eps=0.05" in name and "planner.eps=0.05" in said["overrides"], (name, said)
        body = page.wait_for(
            f"document.body.innerText.includes({json.dumps(name)}) && "
            f"document.body.innerText.includes('overrides') && document.body.innerText"
        )
        assert body, f"the run page does not show its name {name!r} and overrides tag"
        page.goto(f"{tracking_server.url}/#/experiments/{exp_id}/runs/{run_id}/artifacts/"
                  "paper_comparison.html")  # fmt: skip
        frame = page.wait_for(
            "[...document.querySelectorAll('iframe')].map(f => f.src).filter(s => "
            "s.startsWith('blob:'))"
        )
        assert frame, "the HTML report is not shown in the artifact viewer"


def test_metrics_and_plots_read_well(workdir):
    """`dvc metrics show` shows the headline only, in lines a terminal shows (the stages'
    records are cached outputs, so that DVC's run cache keeps the trainings); each
    convergence plot
    has one series per planner and renders to PNG offline."""
    import vl_convert

    every = run(["dvc", "metrics", "show"], workdir)
    assert "reports/metrics/headline.json" in every and len(every.strip().splitlines()) == 2
    assert max(map(len, every.splitlines())) <= 300, every  # a terminal shows it
    spec_json = run(["dvc", "plots", "show", "--json"], workdir)
    plots = json.loads(spec_json[spec_json.index("{") :])
    random = next(v for k, v in plots["data"].items() if "Random maps" in k)[0]
    spec = random["content"]
    assert spec["encoding"]["color"]["field"] == "planner"
    planners = {row["planner"] for row in spec["data"]["values"]}
    assert len(planners) == 6 + 3 and "M-VNRRT* τ=0.3" in planners
    png = vl_convert.vegalite_to_png(spec)
    assert png[:4] == b"\x89PNG" and len(png) > 5000


@pytest.mark.slow
def test_the_plots_page_renders_offline_in_a_browser(workdir, tmp_path):
    """`make plots`'s page (DVC's plots with the offline template, vnrrt.viz.plots_page)
    loads nothing from the network and draws every plot in headless Chromium with the
    network switched off."""
    from tests.browser import Browser, chromium
    from vnrrt.viz.plots_page import write_offline_page

    if chromium() is None:
        pytest.skip("chromium is not installed")
    template = write_offline_page(tmp_path / "template.html")
    out = tmp_path / "plots"
    run(["dvc", "plots", "show", "--html-template", str(template), "-o", str(out)], workdir)
    page = (out / "index.html").read_text()
    assert "cdn.jsdelivr" not in page and "<script src=" not in page
    n_plots = page.count("vegaEmbed('#")
    with Browser() as b:
        b.send("Network.enable", session=True)
        b.send("Network.emulateNetworkConditions", session=True, offline=True, latency=0,
               downloadThroughput=-1, uploadThroughput=-1)  # fmt: skip
        b.goto((out / "index.html").as_uri())
        drawn = "document.querySelectorAll('.vega-embed canvas, .vega-embed svg.marks').length"
        b.wait_for(f"{drawn} >= {n_plots}")
        assert n_plots >= 6 and b.js(drawn) >= n_plots


NOT_OUTPUTS = ("mlflow.db", "mlartifacts/")  # the MLflow store: runs, not pipeline outputs


def _stage_of(argv: list[str]) -> tuple[str, str | None]:
    """``(stage, item)`` of a stage script's command line: ``stages/trials.py --part 1``,
    ``stages/budget_train.py --network vertexnet --steps 3 --seed 1`` (item
    ``vertexnet-3-1``)."""
    name = Path(argv[0]).stem
    values = argv[2::2] if len(argv) > 2 and argv[1].startswith("--") else []
    return name, ("-".join(values) if values else None)


def stages_writing_their_outputs(workdir: Path) -> set[str]:
    """The stages whose processes the write audit recorded, each checked to have created or
    changed exactly the files of its outputs in ``dvc.yaml``
    (:func:`vnrrt.config.paths.stage_outputs`, files under an output folder included), besides
    the MLflow
    store."""
    cfg = yaml.safe_load((workdir / "params.yaml").read_text())
    paths = section(cfg, "paths", Paths)
    entries = [json.loads(line) for line in write_log(workdir).read_text().splitlines()]
    seen = set()
    for entry in entries:
        stage, item = _stage_of(entry["argv"])
        seen.add(stage)
        outs = [str(p) for p in stage_outputs(stage, paths, item)]
        for path in entry["written"]:
            if path.startswith((*NOT_OUTPUTS, paths.reuse + "/")):  # the kept rows: a cache
                continue
            assert any(path == o or path.startswith(o + "/") for o in outs), (stage, item, path)
        for out in outs:  # every declared output exists (an unchanged one is not rewritten)
            assert (workdir / out).exists(), (stage, out)
    return seen


def test_every_stage_writes_exactly_its_outputs(workdir, repo):
    """Each stage process writes exactly its outputs (:func:`stages_writing_their_outputs`),
    and every stage of ``dvc.yaml`` ran (the budget curve's: the slow test at the end)."""
    stages = yaml.safe_load((repo / "dvc.yaml").read_text())["stages"]
    assert stages_writing_their_outputs(workdir) == set(stages) - BUDGET_STAGES


def test_the_committed_tables_recompute_both_reports_byte_for_byte(workdir, tmp_path):
    """`recompute export` bundles the run's per-trial tables; `recompute run` makes from the
    bundle alone the same statistics, reports and headline metrics as the stages did."""
    bundle, out = tmp_path / "results", tmp_path / "again"
    env = {"VNRRT_WRITE_LOG": ""}  # not a stage
    cmd = [sys.executable, "-m", "vnrrt.pipeline.recompute"]
    run([*cmd, "export", "--params", "params.yaml", "--out", str(bundle)], workdir, **env)
    assert (bundle / "trials.csv.gz").stat().st_size > 1000 and (bundle / "README.md").is_file()
    run([*cmd, "run", "--bundle", str(bundle), "--out", str(out)], workdir, **env)
    for made, again in (
        ("reports/paper_comparison.md", "paper_comparison.md"),
        ("reports/sampling_ideas.md", "sampling_ideas.md"),
        ("reports/metrics/headline.json", "headline.json"),
        ("data/smoke/summary.json", "summary.json"),
        ("data/smoke/ideas.json", "ideas.json"),
    ):
        assert (workdir / made).read_bytes() == (out / again).read_bytes(), made


@pytest.mark.slow
def test_a_second_run_changes_only_timings(workdir):
    """Re-running prediction and trials on the same inputs gives byte-identical heatmaps
    and equal trial tables in every column but the timings; DVC sees nothing changed."""
    heat = workdir / "data/smoke/heatmaps/part_0.npz"
    before = heat.read_bytes()
    trials_before = pd.read_csv(workdir / "data/smoke/trials.csv")
    run(["dvc", "repro", "-f", "-s", "predict@0", "trials@0", "trials@1", "evaluate"], workdir)
    assert heat.read_bytes() == before
    trials_after = pd.read_csv(workdir / "data/smoke/trials.csv")
    timing = [
        c for c in trials_after if c.startswith("t_") or c.startswith("time_") or c == "setup_time"
    ]
    pd.testing.assert_frame_equal(
        trials_after.drop(columns=timing), trials_before.drop(columns=timing)
    )
    assert "predict@0" not in run(["dvc", "status"], workdir)


def _png_text(path: Path) -> str:
    from PIL import Image

    with Image.open(path) as img:
        return img.text.get("Description", "")


def check_names_its_values(work: Path, eps: float, taus: list[float], tau: float, level: float,
                           informed: bool, absent: tuple[str, ...]) -> None:  # fmt: skip
    """Every report, figure text, statistics file, headline metric and MLflow metric name of
    the run in ``work`` names the values it ran (stop tolerance ``eps``, tau list ``taus``,
    the claims' ``tau``, CI ``level``, ``informed`` runs or not) and none of ``absent``."""
    pct, ci = f"{100 * eps:g}%", f"{100 * level:g}%"
    run_taus = sorted({*taus, tau})
    table = pd.read_csv(work / "data/smoke/trials.csv")
    assert sorted(set(table["tau"].dropna())) == run_taus
    assert table["key"].str.endswith("+informed").any() == informed
    reports = {p: (work / p).read_text() for p in PAPER_REPORTS}
    for name, text in reports.items():
        text = "\n".join(ln for ln in text.splitlines() if "| paper |" not in ln)
        for default in absent:
            assert default not in text, (name, default)
        assert pct in text and ci in text, name
    bench = (work / "reports/benchmark_maps.md").read_text()  # the benchmark-maps study
    assert f"within {pct} of the exact optimum" in bench and f"{ci} paired bootstrap" in bench
    assert not any(d in bench for d in absent) and f"M-VNRRT* τ={tau:g} |" in bench
    paper = reports["reports/paper_comparison.md"]
    assert f"eps = {eps:g}" in paper and ("## Informed sampling" in paper) == informed
    ours = {ln.split("|")[1].strip() for ln in paper.splitlines() if "| ours |" in ln}
    masked = {n.split()[1] for n in ours if n.startswith("M-VNRRT*")}
    assert masked == {f"τ={t:g}" for t in run_taus}
    figures = sorted((work / "reports/figures").rglob("*.png"))
    said = {f.name: _png_text(f) for f in figures if "evaluation" in f.parts or "ideas" in f.parts}
    assert len(said) >= 5
    for name, text in said.items():
        assert not any(d in text for d in absent), (name, text)
    assert f"within {pct} of A*" in said["improvement_optimal.png"]
    assert f"{ci} CI" in said["improvement_optimal.png"] and f"{ci} CI" in said["quality_curve.png"]
    summary = json.loads((work / "data/smoke/summary.json").read_text())
    assert (summary["eps"], summary["level"]) == (eps, level)
    ideas = json.loads((work / "data/smoke/ideas.json").read_text())["settings"]
    assert (ideas["eps"], ideas["level"]) == (eps, level)
    predict = json.loads((work / "reports/metrics/predict.json").read_text())
    assert predict["settings"]["taus"] == run_taus
    masses = {k for k in predict["networks"]["vertexnet"] if "interior_tau" in k}
    assert {k.split("tau")[-1] for k in masses} == {f"{t:g}".replace(".", "_") for t in run_taus}
    headline = json.loads((work / "reports/metrics/headline.json").read_text())
    assert set(headline["opt_ms"]) == {"rrt", "nrrt", "vnrrt", "m"}  # M-VNRRT* at planner.tau
    from mlflow import MlflowClient  # the experiment's evaluation run names its values too

    client = MlflowClient(f"sqlite:///{work / 'mlflow.db'}")
    exp = client.get_experiment_by_name("vnrrt-smoke").experiment_id
    newest = ["attributes.start_time DESC"]
    query = "attributes.run_name LIKE 'evaluation smoke%'"  # an ablation's: with its overrides
    (last,) = client.search_runs([exp], query, order_by=newest, max_results=1)
    said = last.data.tags["overrides"]
    assert (f"planner.eps={eps:g}" in said) == (eps != 0.01), said
    assert last.info.run_name.startswith("evaluation smoke")
    names = "\n".join(last.data.metrics)
    slug = f"within_{pct.replace('%', 'pct')}_of_astar"
    assert f"{slug}/median_ms/m_vnrrt_star_tau{tau:g}" in names
    assert "within_1pct" not in names or eps == 0.01


def test_every_output_names_the_values_that_ran(workdir):
    """The session ran at ``SESSION``'s values, not conf/'s defaults: every output says so
    (:func:`check_names_its_values`)."""
    check_names_its_values(workdir, 0.05, [0.3, 0.7], 0.5, 0.9, True, DEFAULT_TEXTS)


EVALUATION_STAGES = ["bench_maps@benchmark_maps", "evaluate", "ideas", "oracle@0",
                     "predict_metrics", "regime@0", "report", "trials@0", "trials@1",
                     "validate"]  # fmt: skip


def test_an_ablation_would_rerun_only_the_evaluation(workdir):
    """Back at conf/'s defaults (stop tolerance, tau list, CI level), DVC would re-run
    validation (cheap, constant output), the heatmap metrics (their tau masks) and the
    evaluation stages, nothing else (``dvc repro --dry``: nothing runs)."""
    params = workdir / "params.yaml"
    session = params.read_text()
    params.write_text(dump(compose(["scale=smoke", seed_override(workdir)])))
    try:
        out = run(["dvc", "repro", "--dry"], workdir)
    finally:
        params.write_text(session)
    ran = sorted(line.split("'")[1] for line in out.splitlines() if "Running stage" in line)
    assert ran == EVALUATION_STAGES, out


def _rows_by_trial(workdir: Path) -> dict[tuple, str]:
    """Every trial row of the workspace's parts as its CSV text without ``seq``, keyed by
    (key, instance, stop, trial)."""
    rows = {}
    for part in sorted((workdir / "data/smoke/trials").glob("part_*.csv")):
        header, *lines = part.read_text().splitlines()
        cols = header.split(",")
        for line in lines:
            values = dict(zip(cols, line.split(","), strict=True))
            who = (values["key"], values["instance"], values["stop"], values["trial"])
            rows[who] = line.split(",", 1)[1]  # seq is the first column
    return rows


def _verdicts(workdir: Path) -> dict[str, str]:
    summary = json.loads((workdir / "data/smoke/summary.json").read_text())
    return {f"{r['planner']} vs {r['baseline']} {r['column']}": r["verdict"]
            for r in summary["claims"]["rows"]}  # fmt: skip


@pytest.mark.slow
def test_a_tau_ablation_reruns_only_m_vnrrt_and_moves_no_other_verdict(workdir):
    """`dvc exp run -S planner.tau=0.7` (the session's other values kept; its taus with 0.5,
    the session's planner.tau, so that the same M-VNRRT* thresholds run) re-runs only the
    M-VNRRT* configurations at planner.tau (its masked variants and control): every other
    row comes back byte for byte, timings included (the trial stages log what they reused),
    and no claim without M-VNRRT* changes its verdict."""
    run(["dvc", "repro"], workdir)
    run(["git", "add", "-A"], workdir)  # dvc exp run needs a commit to start from
    run(["git", "-c", "user.name=t", "-c", "user.email=t@t", "commit", "--allow-empty", "-qm",
         "before the tau ablation"], workdir)  # fmt: skip
    before, verdicts = _rows_by_trial(workdir), _verdicts(workdir)
    summary = json.loads((workdir / "data/smoke/summary.json").read_text())
    baseline = workdir / yaml.safe_load((workdir / "params.yaml").read_text())["paths"]["baseline"]
    # the session's run stands for the default run (which keeps its claims there itself)
    baseline.write_text(json.dumps(baseline_record(summary["claims"]["rows"])))
    ablation = ("planner.eps=0.05", "stats.level=0.9", "planner.taus=[0.3,0.5,0.7]",
                "planner.tau=0.7")  # fmt: skip
    sets = [x for o in ("scale=smoke", seed_override(workdir), *ablation) for x in ("-S", o)]
    out = run(["dvc", "exp", "run", *sets], workdir)
    assert "reused" in out
    after = _rows_by_trial(workdir)
    moved = {k for k in before.keys() & after.keys() if before[k] != after[k]}
    assert moved == set() and {k[0] for k in after.keys() - before.keys()} <= {
        k for k, *_ in after if k.startswith("m_vnrrt_star")
    }
    assert {k for k, *_ in after if not k.startswith("m_vnrrt_star")} == {
        k for k, *_ in before if not k.startswith("m_vnrrt_star")
    }
    now = _verdicts(workdir)
    for claim, verdict in verdicts.items():
        if "m_vnrrt_star" not in claim:
            assert now[claim] == verdict, claim
    # the report reads the machine's noise and sets each claim beside the default run's
    report = (workdir / "reports/paper_comparison.md").read_text()
    assert "## The machine's timing noise" in report and "### Against your default run" in report
    section = report.split("### Against your default run")[1].split("\n## ")[0]
    rows = [
        line
        for line in section.splitlines()
        if line.startswith("| ")
        and "---" not in line
        and "M-VNRRT*" not in line
        and "claim |" not in line
    ]
    assert rows and all("| +0.0% |" in r and "identical: re-timing only" in r for r in rows)
    shown = run(["dvc", "exp", "show", "--only-changed", "--drop", ".*/.*"], workdir)  # README's
    assert "planner.tau" in shown and max(map(len, shown.splitlines())) <= 300, shown
    _back_to_the_commit(workdir)  # the session's values again (dvc exp run applied tau=0.7)


ABLATION = {  # every reader-visible setting changed at once from the session's (one experiment)
    "planner.eps": 0.02,
    "planner.taus": "[0.4,0.8]",
    "planner.tau": 0.45,
    "stats.level": 0.8,
    "eval.informed": "false",
}
SESSION_TEXTS = ("within 5%", "5% of", "90%", "eps 0.05", "eps = 0.05", "τ=0.3", "τ=0.7")


@pytest.mark.slow
def test_an_ablation_reruns_only_the_evaluation_and_every_output_names_its_values(workdir):
    """After files of another scale appeared beside this one's (and a stray temp file),
    `dvc exp run -S ...` (at this workspace's smoke scale and seed: DVC composes conf/ with
    the -S overrides) changing the stop tolerance, the tau list, the CI level and the
    informed flag re-runs validation (cheap, constant output), the heatmap metrics (their
    tau masks) and the evaluation stages, nothing else; and every report, figure and metrics
    file names the values that ran, none of the defaults or the session's."""
    run(["dvc", "repro"], workdir)  # up to date first (a slow test before re-ran a prediction)
    run(["git", "add", "-A"], workdir)
    run(["git", "-c", "user.name=t", "-c", "user.email=t@t", "commit", "--allow-empty", "-qm",
         "smoke"], workdir)  # fmt: skip
    other = workdir / "data/quick/shards"
    other.mkdir(parents=True, exist_ok=True)
    (other / "shard_7.npz").write_bytes(b"another scale's shard")
    (workdir / SHARDS / "shard_1.npz.tmp-999999").write_bytes(b"stray")
    sets = [x for k, v in ABLATION.items() for x in ("-S", f"{k}={v}")]
    out = run(
        ["dvc", "exp", "run", "-S", "scale=smoke", "-S", seed_override(workdir), *sets], workdir
    )
    ran = sorted(line.split("'")[1] for line in out.splitlines() if "Running stage" in line)
    assert ran == EVALUATION_STAGES, out
    check_names_its_values(workdir, 0.02, [0.4, 0.8], 0.45, 0.8, False,
                           DEFAULT_TEXTS + SESSION_TEXTS)  # fmt: skip


PAPER_REPORTS = ("reports/paper_comparison.md", "reports/sampling_ideas.md")


@pytest.mark.slow
def test_predict_and_trial_parts_as_multirun_jobs_write_the_stage_files(workdir, request):
    """The predict@<k> and trials@<k> parts again, as Hydra multirun shard jobs (joblib;
    trials on the local SLURM cluster where it runs). They write the stages' files: heatmaps
    equal up to float16 rounding (threads differ), trials equal in every column but the
    timings given the same heatmaps; `dvc commit` makes `dvc repro` skip the stages."""
    run(["git", "checkout", "-q", "--", "."], workdir)  # back from the experiment (if it ran)
    run(["dvc", "checkout", "-f", "-q"], workdir)
    heat, trials = workdir / "data/smoke/heatmaps", workdir / "data/smoke/trials"
    stage_bytes = {p.name: p.read_bytes() for p in sorted(heat.glob("part_*.npz"))}
    stage_heat = {name: read_heatmaps(heat / name) for name in stage_bytes}
    n = len(pd.read_csv(workdir / "data/smoke/trials.csv"))
    stage_trials = merge_parts(trials, [0, 1], n)
    shutil.rmtree(heat)
    shutil.rmtree(trials)
    env = {"VNRRT_CONF_DIR": str(workdir / "conf")}
    job = [
        sys.executable,
        "-m",
        "vnrrt.pipeline.multirun",
        "-m",
        *SMOKE,  # the workspace's values (as committed: the session's, at its seed)
        seed_override(workdir),
        "workers=1",
        "+part=0,1",
    ]
    out = run([*job, "+stage=predict", "hydra/launcher=local"], workdir, **env)
    assert "differs from params.yaml" not in out
    for name, want in stage_heat.items():
        got = read_heatmaps(heat / name)
        np.testing.assert_array_equal(got["keys"], want["keys"])
        for net, maps in want["maps"].items():
            np.testing.assert_allclose(
                got["maps"][net].astype(np.float32),
                maps,
                rtol=4e-3,
                atol=1e-4,
                err_msg=f"{name} {net}",
            )
    for name, data in stage_bytes.items():  # the trials below run on the stage's heatmaps
        (heat / name).write_bytes(data)
    try:
        env["SLURM_CONF"] = request.getfixturevalue("slurm")
        launcher = [
            "hydra/launcher=slurm",
            "hydra.launcher.cpus_per_task=1",
            "hydra.launcher.mem_gb=2",
            "hydra.launcher.timeout_min=10",
        ]
    except pytest.skip.Exception:
        launcher = ["hydra/launcher=local"]
    run([*job, "+stage=trials", *launcher], workdir, **env)
    got = merge_parts(trials, [0, 1], n)
    pd.testing.assert_frame_equal(got[list(SEEDED_COLUMNS)], stage_trials[list(SEEDED_COLUMNS)])
    run(["dvc", "commit", "-f", "predict", "trials"], workdir)
    out = run(["dvc", "repro", "evaluate"], workdir)
    for stage in ("predict@0", "predict@1", "trials@0", "trials@1"):
        assert f"Stage '{stage}' didn't change" in out


def test_a_stage_runs_as_the_readme_says(workdir, repo):
    """README convention: activate the project's venv, then plain `dvc ...` commands."""
    venv = Path(sys.executable).parent.parent
    if not (venv / "bin" / "activate").is_file():
        pytest.skip("not running inside a virtual environment")
    env = {k: v for k, v in os.environ.items() if k != "MLFLOW_TRACKING_URI"}
    env["PATH"] = "/usr/bin:/bin"  # a fresh shell: no project interpreter on PATH
    cmd = (
        f". {venv}/bin/activate && dvc repro -f -s named_maps"
        " && python -m vnrrt.pipeline.params --help"
    )
    proc = subprocess.run(
        ["bash", "-c", cmd], cwd=workdir, env=env, capture_output=True, text=True, check=False
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr


def _back_to_the_commit(workdir: Path) -> None:
    """The workspace as committed (after an experiment or a multirun test changed it)."""
    run(["git", "checkout", "-q", "--", "."], workdir)
    run(["dvc", "checkout", "-f", "-q"], workdir)


def _experiment(shown: list, name: str) -> dict:
    """The ``data`` of experiment ``name`` in ``dvc exp show --json``'s output."""
    stack = list(shown)
    while stack:
        node = stack.pop()
        if isinstance(node, dict):
            if node.get("name") == name and isinstance(node.get("data"), dict):
                return node["data"]
            stack.extend(node.values())
        elif isinstance(node, list):
            stack.extend(node)
    raise AssertionError(f"experiment {name} not in dvc exp show")


@pytest.mark.slow
def test_two_queued_experiments_finish_with_their_own_parameters(workdir):
    """Issue #28: parallel ablations as the README says (`dvc exp run --queue` twice, then
    `dvc queue start`): both finish, each with its own parameters in `dvc exp show` and in
    the statistics it wrote."""
    _back_to_the_commit(workdir)
    levels = {"level-90": 0.9, "level-80": 0.8}
    for name, level in levels.items():
        sets = ["-S", "scale=smoke", "-S", "seed=1", "-S", f"stats.level={level}"]
        run(["dvc", "exp", "run", "--queue", "-n", name, *sets], workdir)
    run(["dvc", "queue", "start", "-j", "1"], workdir)
    deadline = time.monotonic() + 1800
    while True:
        status = run(["dvc", "queue", "status"], workdir)
        if not any(word in status.split() for word in ("Queued", "Running")):
            break
        assert time.monotonic() < deadline, status
        time.sleep(5)
    assert status.count("Success") == 2, status
    proc = subprocess.run(["dvc", "exp", "show", "--json"], cwd=workdir, env=_env(workdir),
                          capture_output=True, text=True, check=True)  # fmt: skip
    shown = json.loads(proc.stdout)
    for name, level in levels.items():
        data = _experiment(shown, name)
        assert data["params"]["params.yaml"]["data"]["stats"]["level"] == level
        assert "headline.json" in json.dumps(data.get("metrics", {}))
        run(["dvc", "exp", "apply", name], workdir)
        summary = json.loads((workdir / "data/smoke/summary.json").read_text())
        assert summary["level"] == level, name
    _back_to_the_commit(workdir)


@pytest.mark.slow
def test_a_run_killed_after_its_trainings_does_not_train_again(workdir):
    """Issue #28: a `dvc exp run --temp` (as queued experiments run: in a temporary copy,
    lost when the run dies) that retrains (another training seed) is killed (SIGKILL, its
    whole process group) once its trainings have finished; the same command again restores
    them from DVC's run cache and runs no training. (In the workspace the finished stages'
    lock entries survive a kill; in a temporary copy only the run cache does.)"""
    _back_to_the_commit(workdir)
    sets = ["dvc", "exp", "run", "--temp", "-S", "scale=smoke", "-S", "seed=1",
            "-S", "train.seed=5"]  # fmt: skip
    log = workdir.parent / "killed_run.log"
    with log.open("w") as out:
        proc = subprocess.Popen(sets, cwd=workdir, env=_env(workdir), stdout=out,
                                stderr=subprocess.STDOUT, start_new_session=True)  # fmt: skip
    deadline = time.monotonic() + 1800
    try:
        while "Running stage 'predict@" not in log.read_text():
            assert proc.poll() is None and time.monotonic() < deadline, log.read_text()
            time.sleep(0.2)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    first = log.read_text()
    assert sorted(ln for ln in first.splitlines() if "Running stage 'train@" in ln) == [
        "Running stage 'train@nrrtnet':",
        "Running stage 'train@vertexnet':",
    ], first
    again = run(sets, workdir)
    assert "Running stage 'train@" not in again, again
    assert "Stage 'train@vertexnet' is cached - skipping run" in again
    assert "Running stage 'report'" in again
    _back_to_the_commit(workdir)


@pytest.mark.slow
def test_the_budget_stages_reproduce_the_training_of_their_steps(workdir):
    """The budget curve's stages by DVC at one budget of the smoke training's own 3 steps
    (~2.5 minutes: five more stage processes): each writes exactly its outputs; the budget
    has the pipeline training's settings, so the same checkpoint bytes; its heatmap metrics
    are predict_metrics' on them (up to the float16 heatmaps of another batching); its
    report; one MLflow run per budget training, with the budget as a param, and no model
    registered beside the pipeline's networks. Nothing else runs again."""
    from mlflow import MlflowClient

    _back_to_the_commit(workdir)
    client = MlflowClient(f"sqlite:///{workdir / 'mlflow.db'}")
    registered = len(client.search_model_versions("name='vnrrt-vertexnet'"))
    cfg = compose([*SMOKE, seed_override(workdir), *ONE_BUDGET])
    (workdir / "params.yaml").write_text(dump(cfg))
    item = f"3-{cfg.train.seed}"  # the one budget of 3 steps at the pipeline's training seed
    out = run(["dvc", "repro"], workdir)
    ran = {line.split("'")[1].split("@")[0] for line in out.splitlines() if "Running" in line}
    assert ran == {"validate", *BUDGET_STAGES}, out
    assert stages_writing_their_outputs(workdir) >= BUDGET_STAGES

    metrics, budget = workdir / "reports/metrics", workdir / f"data/smoke/budget/{item}"
    predict = json.loads((metrics / "predict.json").read_text())["networks"]
    again = json.loads((budget / "predict.json").read_text())["networks"]
    sha = {}
    for name in ("vertexnet", "nrrtnet"):
        main = json.loads((metrics / f"train_{name}.json").read_text())
        trained = json.loads((budget / f"train_{name}.json").read_text())
        assert trained["checkpoint_sha256"] == main["checkpoint_sha256"], name
        assert trained["budget"]["schedule_steps"] == trained["budget"]["schedule_total"] == 3
        sha[name] = trained["checkpoint_sha256"]
        numbers = [k for k, v in predict[name].items() if k != "ms_per_map" and v != str(v)]
        want = {k: predict[name][k] for k in numbers}
        assert {k: again[name][k] for k in numbers} == pytest.approx(want, rel=1e-3, abs=1e-5)
        assert again[name]["target"] == predict[name]["target"]
    report = (workdir / "reports/training_budget.md").read_text()
    assert "## What the curve says" in report and "one budget: no trend" in report
    exp = client.get_experiment_by_name("vnrrt-smoke").experiment_id
    runs = client.search_runs([exp], filter_string="tags.budget_steps = '3'")
    stages = sorted(r.data.tags["dvc_stage"] for r in runs)
    assert stages == [f"budget_train@nrrtnet-{item}", f"budget_train@vertexnet-{item}"]
    for r in runs:
        name = f"{r.data.tags['kind']} smoke budget 3"  # then the overrides of the defaults
        assert r.data.params["budget.steps"] == "3" and r.info.run_name.startswith(name)
        assert r.data.tags["checkpoint_sha256"] == sha[r.data.tags["kind"]]
    assert len(client.search_model_versions("name='vnrrt-vertexnet'")) == registered
