"""Exit statuses of the DVC stage scripts: bad configuration or input is status 2 with one
line on stderr, an internal error status 3 with its traceback; ``--help`` lists them."""

import os
import subprocess
import sys

import pytest
import yaml

from tests.conftest import copy_pipeline
from vnrrt.config import ConfigError, check_unchanged_since_validate, compose, dump


@pytest.fixture(scope="module")
def work(repo, tmp_path_factory):
    """A copy of the pipeline (dvc.yaml, stages, conf) with the default parameters."""
    dest = copy_pipeline(repo, tmp_path_factory.mktemp("stages"))
    (dest / "params.yaml").write_text(dump(compose([])))
    return dest


def run_stage(work, *args):
    return subprocess.run([sys.executable, *args], cwd=work, capture_output=True, text=True,
                          timeout=120)  # fmt: skip


@pytest.mark.parametrize(
    ("setup", "message"),
    [
        (["planner.eta=-1"], "eta=-1.0: must be > 0"),
        (None, "nothing.yaml"),
    ],
)
def test_bad_params_exit_2_with_one_line(work, tmp_path, setup, message):
    """An invalid value, or a parameters file that does not exist: one line naming it."""
    params = tmp_path / ("params.yaml" if setup else "nothing.yaml")
    if setup:
        params.write_text(dump(compose(setup)))
    out = run_stage(work, "stages/validate.py", "--params", str(params))
    assert out.returncode == 2, out.stderr
    assert message in out.stderr and out.stderr.count("\n") == 1, out.stderr
    assert "Traceback" not in out.stderr and out.stderr.startswith("stage validate: error: ")


def test_a_matrix_stage_takes_each_axis_and_fails_on_bad_input_in_one_line(work):
    """``budget_train --network nrrtnet --steps 7 --seed 1``: named
    ``budget_train@nrrtnet-7-1`` (its parameters found), then a budget that is no multiple of
    the epochs: status 2, one line."""
    args = ("--network", "nrrtnet", "--steps", "7", "--seed", "1")
    out = run_stage(work, "stages/budget_train.py", *args)
    assert out.returncode == 2 and out.stderr.count("\n") == 1, out.stderr
    assert out.stderr.startswith("stage budget_train@nrrtnet-7-1: error: invalid config value "
                                 "budget.steps=7: each budget must be a multiple")  # fmt: skip


def test_a_stage_that_succeeds_exits_0(work):
    out = run_stage(work, "stages/validate.py")
    assert out.returncode == 0, out.stderr


def test_an_internal_error_of_a_stage_exits_3_with_its_traceback(work):
    script = work / "stages" / "broken.py"
    script.write_text(
        "from vnrrt.cli.stage import stage_main\n\n"
        "def broken(cfg):\n    raise RuntimeError('boom')\n\n"
        "stage_main('validate', broken, 'a stage with a bug')\n"
    )
    out = run_stage(work, "stages/broken.py")
    assert out.returncode == 3, out.stderr
    last = out.stderr.strip().splitlines()[-1]
    assert "Traceback" in out.stderr and "raise RuntimeError('boom')" in out.stderr
    assert last.startswith("stage validate: internal error (RuntimeError: boom)")


def test_stage_help_lists_the_exit_statuses(work):
    out = run_stage(work, "stages/train.py", "--help")
    flat = " ".join(out.stdout.split())
    assert out.returncode == 0 and "2 bad configuration" in flat and "3 an internal error" in flat


def test_errors_are_classed_as_input_or_internal(capsys):
    import zipfile

    from mlflow.exceptions import MlflowException

    from vnrrt.cli.stage import EXIT_INPUT, is_input_error, run_reporting

    for err in (ValueError("x"), FileNotFoundError("x"), zipfile.BadZipFile("x"),
                MlflowException("store down")):  # fmt: skip
        assert is_input_error(err), err
    for err in (RuntimeError("x"), KeyError("x"), TypeError("x"), AssertionError()):
        assert not is_input_error(err), err

    def bad_input() -> int:
        raise ValueError("first line\nsecond line")

    assert run_reporting("prog", bad_input) == EXIT_INPUT
    assert capsys.readouterr().err == "prog: error: first line\n"


def _lock_with_validate(path, params_doc):
    """A dvc.lock whose validate entry recorded ``params_doc``'s seed, planner and eval."""
    recorded = {k: params_doc[k] for k in ("seed", "planner", "eval")}
    entry = {"cmd": "python stages/validate.py", "params": {"params.yaml": recorded}}
    path.write_text(yaml.safe_dump({"schema": "2.0", "stages": {"validate": entry}}))


def test_params_changed_since_validate_are_named(work, tmp_path):
    """Issue #28: a second `dvc exp run` rewrote params.yaml after this run validated it."""
    doc = yaml.safe_load((work / "params.yaml").read_text())
    _lock_with_validate(tmp_path / "dvc.lock", doc)
    params = tmp_path / "params.yaml"
    params.write_text(yaml.safe_dump(dict(doc, workers=7)))  # not a validate parameter
    check_unchanged_since_validate(params, tmp_path / "dvc.lock")
    changed = dict(doc, planner=dict(doc["planner"], eps=0.05), seed=doc["seed"] + 1)
    params.write_text(yaml.safe_dump(changed))
    with pytest.raises(ConfigError, match=r"planner\.eps: 0\.01 -> 0\.05; seed: 0 -> 1\)"):
        check_unchanged_since_validate(params, tmp_path / "dvc.lock")
    check_unchanged_since_validate(params, tmp_path / "no.lock")  # a first run: no entry yet


def test_a_stage_run_by_dvc_refuses_params_changed_since_validate(repo, work, tmp_path):
    """The stage script (DVC_STAGE set, as DVC sets it) stops with status 2 and one line;
    the same script run by hand (no DVC_STAGE) is not checked."""
    dest = copy_pipeline(repo, tmp_path / "w")
    doc = yaml.safe_load((work / "params.yaml").read_text())
    _lock_with_validate(dest / "dvc.lock", doc)
    doc["planner"]["eps"] = 0.05
    (dest / "params.yaml").write_text(yaml.safe_dump(doc, sort_keys=False))
    env = dict(os.environ, DVC_STAGE="named_maps")
    out = subprocess.run([sys.executable, "stages/named_maps.py"], cwd=dest, env=env,
                         capture_output=True, text=True, timeout=120)  # fmt: skip
    assert out.returncode == 2 and "planner.eps: 0.01 -> 0.05" in out.stderr, out.stderr
    assert "dvc exp run --queue" in out.stderr and out.stderr.count("\n") == 1
    # nothing written: data/ holds only the copied inputs data/movingai and data/paper
    assert sorted(p.name for p in (dest / "data").iterdir()) == ["movingai", "paper"]
