"""The target-variant comparison (issue 24): the variants are one change each from the
scale's configuration (none equal to it), the pick is the highest validation interior AP,
the combination joins the factors that beat the baseline, and a tiny run on the 64x64 data
writes a note whose figures are the trainings' own and reads finished trainings back."""

import json

import pytest

from tests.train_helpers import SMALL, paths
from vnrrt.config import compose
from vnrrt.pipeline.variants import SELECT, Variant, combined, main, pick, variants


def test_the_variants_change_one_setting_each_and_skip_the_baseline():
    cfg = compose(["scale=cpu"])
    baseline = {
        "networks.vertexnet.endpoints": "both",
        "train.datamodule.target_radius": 1.0,
        "model.loss.alpha": None,
        "model.net.prior": 0.01,
    }
    assert {k: v for k, v in baseline.items()} == {
        "networks.vertexnet.endpoints": cfg.networks.vertexnet.endpoints,
        "train.datamodule.target_radius": cfg.train.datamodule.target_radius,
        "model.loss.alpha": cfg.model.loss.alpha,
        "model.net.prior": cfg.model.net.prior,
    }
    runs = variants(baseline)
    assert runs[0] == Variant("baseline") and len({v.slug for v in runs}) == len(runs)
    changed = [dict(v.settings) for v in runs[1:]]
    assert all(len(c) == 1 and baseline[k] != v for c in changed for k, v in c.items())
    radii = sorted(
        c["train.datamodule.target_radius"]
        for c in changed
        if "train.datamodule.target_radius" in c
    )
    assert radii == [2.0, 3.0] and {"endpoints none", "prior None"} <= {v.name for v in runs}
    assert Variant("prior None", (("model.net.prior", None),)).overrides() == [
        "model.net.prior=null"
    ]


def test_the_pick_is_the_best_validation_ap_and_the_combination_its_factors():
    runs = [
        Variant("baseline"),
        Variant("a", (("x.a", 1),)),
        Variant("b", (("x.b", 2),)),
        Variant("b'", (("x.b", 3),)),
        Variant("c", (("x.c", 4),)),
    ]
    results = {v.name: {SELECT: ap} for v, ap in zip(runs, [0.2, 0.3, 0.25, 0.35, 0.1])}
    assert pick(results) == "b'"
    both = combined(results, runs)
    assert both is not None and dict(both.settings) == {"x.a": 1, "x.b": 3}
    assert pick({"baseline": {SELECT: 0.3}, "a": {SELECT: 0.3}}) == "baseline"  # first of equals
    assert combined({**results, "a": {SELECT: 0.1}}, runs) is None  # one factor beats it


def test_a_tiny_comparison_writes_the_trainings_figures_and_reads_them_back(small_data, tmp_path):
    out, work = tmp_path / "note.md", tmp_path / "work"
    args = [
        "--scale",
        "smoke",
        "--steps",
        "2",
        "--out",
        str(out),
        "--work",
        str(work),
        "--only",
        "baseline,endpoints none",
        *SMALL[1:],
        *paths(small_data, tmp_path),
        "trainer.limit_val_batches=1",
        "train.threads=1",
    ]
    assert main(args) == 0
    found = json.loads(out.with_suffix(".json").read_text())
    assert list(found["results"]) == ["baseline", "endpoints none"]
    for name, slug in (("baseline", "baseline"), ("endpoints none", "endpoints_none")):
        trained = json.loads((work / slug / "budget/2-0/train_vertexnet.json").read_text())
        assert found["results"][name][SELECT] == trained[SELECT] and trained["steps"] == 2
        target = trained["target"]["endpoints"]
        assert target == ("none" if name == "endpoints none" else "both")
    best = max(found["results"], key=lambda n: found["results"][n][SELECT])
    text = out.read_text()
    assert found["picked"] == best and f"**{best}**" in text
    assert "`networks.vertexnet.endpoints=none`" in text and "val interior AP" in text
    before = {p: p.stat().st_mtime for p in work.rglob("*.ckpt")}
    assert main(args) == 0  # finished trainings are read back, not run again
    assert {p: p.stat().st_mtime for p in work.rglob("*.ckpt")} == before
    assert json.loads(out.with_suffix(".json").read_text()) == found


def test_a_bad_argument_is_one_line(tmp_path, capsys):
    args = [
        "--scale",
        "smoke",
        "--steps",
        "3",
        "--out",
        str(tmp_path / "n.md"),
        "trainer.max_epochs=2",
    ]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "budget.steps=3: each budget must be a multiple" in err and err.count("\n") == 1


@pytest.fixture(autouse=True)
def _threads():
    import torch

    before = torch.get_num_threads()
    yield
    torch.set_num_threads(before)
