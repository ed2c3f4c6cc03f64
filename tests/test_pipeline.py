"""The DVC pipeline end to end at smoke scale, in a scratch git + DVC copy of the repository:
validation before any work, verified deterministic shards, resuming, temp files DVC does not
hash, the whole run with its report, metrics, plots and MLflow runs, reproducible outputs, an
evaluation-only experiment that re-runs only the evaluation, and the parts as multirun jobs."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from tests.conftest import copy_dvc_files, copy_pipeline
from vnrrt.config import compose, dump
from vnrrt.data.build import build_shard
from vnrrt.data.config import LabelsConfig
from vnrrt.data.heatmaps import read_heatmaps
from vnrrt.data.manifest import verify_manifest
from vnrrt.data.shards import shard_file
from vnrrt.evaluation.table import SEEDED_COLUMNS, merge_parts
from vnrrt.maps.config import DataConfig

SHARDS = Path("data/smoke/shards")


def run(cmd: list[str], cwd: Path, ok: bool = True, **env_vars: str) -> str:
    env = dict(os.environ, PATH=f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}")
    env.pop("MLFLOW_TRACKING_URI", None)
    env.update(env_vars)
    proc = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, check=False)
    if ok:
        assert proc.returncode == 0, f"{' '.join(cmd)} failed:\n{proc.stdout}\n{proc.stderr}"
    else:
        assert proc.returncode != 0, f"{' '.join(cmd)} succeeded:\n{proc.stdout}"
    return proc.stdout + proc.stderr


@pytest.fixture(scope="module")
def workdir(tmp_path_factory, repo):
    work = copy_pipeline(repo, tmp_path_factory.mktemp("pipeline"))
    run(["git", "init", "-q"], work)
    run(["dvc", "init", "-q"], work)
    copy_dvc_files(repo, work)
    shutil.copy(repo / ".gitignore", work / ".gitignore")
    (work / "params.yaml").write_text(dump(compose(["scale=smoke"])))
    return work


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
    (workdir / "params.yaml").write_text(dump(compose(["scale=smoke", "seed=1"])))
    run(["dvc", "repro", "shard@0"], workdir)  # the run that got this far, then stopped
    out = run(["dvc", "repro", *DATA_STAGES], workdir)
    assert "Running stage 'shard@1'" in out and "Running stage 'shard@0'" not in out
    assert not list((workdir / "data").rglob("*.tmp-*"))


def test_smoke_dvc_repro_end_to_end(workdir):
    """Every stage at smoke scale: report, headline metrics, plots and MLflow runs."""
    from mlflow import MlflowClient

    run(["dvc", "repro"], workdir)
    report = (workdir / "reports/paper_comparison.md").read_text()
    for text in (
        "| VNRRT* | ours | ",
        "| M-VNRRT* τ=0.5 | ours | ",
        "## Optimal path lengths",
        "exact continuous optimum",
        "## Planning time and network inference",
        "Bonferroni",
        "## Time to within (1 + eps) of the exact continuous optimum",
    ):
        assert text in report, text
    ideas = (workdir / "reports/sampling_ideas.md").read_text()
    for text in (
        "## Conclusion",
        "## Oracles, within 1% of A*",
        "## The heatmap-quality curve",
        "## The planner regime",
        "VNRRT* [oracle_vertex]",
    ):
        assert text in ideas, text
    assert (workdir / "reports/figures/ideas/quality_curve.png").stat().st_size > 10_000
    headline = json.loads((workdir / "reports/metrics/headline.json").read_text())
    assert sum(headline["verdicts"].values()) == 16
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
    assert len(parents) == 1 and len(children) == 12  # 6 configurations, each also informed
    train_ids = {r.info.run_id for r in runs if r.data.tags.get("kind") == "vertexnet"}
    assert parents[0].data.tags["training_run.vertexnet"] in train_ids
    assert all(c.data.metrics["optimal/random/success_rate"] >= 0 for c in children)


def test_metrics_and_plots_read_well(workdir):
    """`dvc metrics show` stays short; each convergence plot has one series per planner and
    renders to PNG offline."""
    import vl_convert

    shown = run(["dvc", "metrics", "show"], workdir)
    assert max(len(line) for line in shown.splitlines()) < 300
    spec_json = run(["dvc", "plots", "show", "--json"], workdir)
    plots = json.loads(spec_json[spec_json.index("{") :])
    random = next(v for k, v in plots["data"].items() if "Random maps" in k)[0]
    spec = random["content"]
    assert spec["encoding"]["color"]["field"] == "planner"
    planners = {row["planner"] for row in spec["data"]["values"]}
    assert len(planners) == 6 and "M-VNRRT* τ=0.5" in planners
    png = vl_convert.vegalite_to_png(spec)
    assert png[:4] == b"\x89PNG" and len(png) > 5000


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


def test_an_evaluation_only_experiment_reruns_only_the_evaluation(workdir):
    """After files of another scale appeared beside this one's (and a stray temp file),
    `dvc exp run -S planner.tau=0.7` (at this workspace's smoke scale and seed: DVC composes
    conf/ with the -S overrides) re-runs validation (cheap, constant output) and the
    evaluation stages, nothing else."""
    run(["dvc", "repro"], workdir)  # up to date first (the test before re-ran a prediction)
    run(["git", "add", "-A"], workdir)
    run(["git", "-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "smoke"], workdir)
    other = workdir / "data/quick/shards"
    other.mkdir(parents=True)
    (other / "shard_7.npz").write_bytes(b"another scale's shard")
    (workdir / SHARDS / "shard_1.npz.tmp-999999").write_bytes(b"stray")
    out = run(
        ["dvc", "exp", "run", "-S", "scale=smoke", "-S", "seed=1", "-S", "planner.tau=0.7"], workdir
    )
    ran = sorted(line.split("'")[1] for line in out.splitlines() if "Running stage" in line)
    evaluation = ["evaluate", "ideas", "oracle@0", "regime@0", "report", "trials@0", "trials@1"]
    assert ran == [*evaluation, "validate"], out
    table = pd.read_csv(workdir / "data/smoke/trials.csv")
    assert "m_vnrrt_star@0.7" in set(table["key"])


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
        "vnrrt.multirun",
        "-m",
        "scale=smoke",
        "seed=1",
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
    cmd = f". {venv}/bin/activate && dvc repro -f -s named_maps && python -m vnrrt.params --help"
    proc = subprocess.run(
        ["bash", "-c", cmd], cwd=workdir, env=env, capture_output=True, text=True, check=False
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
