"""Each DVC stage depends on exactly the code it runs: the import closure of its script inside
src/vnrrt (tests/stage_closure.py states the rule), with Hydra ``_target_`` modules of its
parameters; a missing dep would leave stale results, an unrelated one re-runs work."""

import pytest
import yaml

from tests.stage_closure import REPO, closure, declared, declared_params, stage_scripts

STAGES = stage_scripts()


def deps(name: str) -> list[str]:
    entry = yaml.safe_load((REPO / "dvc.yaml").read_text())["stages"][name]
    return entry.get("do", entry)["deps"]


@pytest.mark.parametrize("name", sorted(STAGES))
def test_code_deps_equal_the_import_closure(name):
    script = STAGES[name]
    want = closure(script, declared_params(name))
    got = declared(deps(name))
    assert not want - got, f"{name}: dvc.yaml misses deps {sorted(map(str, want - got))}"
    assert not got - want, f"{name}: dvc.yaml lists unrelated deps {sorted(map(str, got - want))}"
    assert str(script.relative_to(REPO)) in deps(name)


def test_the_closure_sees_function_level_imports_and_hydra_targets():
    train = {str(p) for p in closure(STAGES["train"], declared_params("train"))}
    assert "src/vnrrt/data/datamodule.py" in train  # train.datamodule._target_
    assert "src/vnrrt/pipeline/callbacks.py" in train  # callbacks.*._target_
    assert "src/vnrrt/viz/training.py" in train  # imported inside a callback method
    assert "src/vnrrt/viz/evaluation.py" not in train
    trials = {str(p) for p in closure(STAGES["trials"], declared_params("trials"))}
    assert (
        "src/vnrrt/studies/paper_comparison/report.py" not in trials
    )  # a wording change re-runs no trial
    assert "src/vnrrt/evaluation/stats.py" not in trials
    oracle = {str(p) for p in closure(STAGES["oracle"], declared_params("oracle"))}
    assert "src/vnrrt/evaluation/sources.py" in oracle  # imported by a helper the entry calls
    assert "src/vnrrt/planners/rrt_star.py" in oracle
    shard = {str(p) for p in closure(STAGES["shard"], declared_params("shard"))}
    assert "src/vnrrt/maps/named.py" not in shard and "src/vnrrt/infra/parallel.py" in shard
