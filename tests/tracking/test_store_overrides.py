"""An ablation's MLflow runs are named and tagged after its overrides: the settings of the
run's params.yaml that differ from conf/'s default composition at its scale."""

from vnrrt.config import compose, dump
from vnrrt.tracking.experiments import override_text, overrides, run_name, run_tags


def params(tmp_path, over: list[str]):
    path = tmp_path / "params.yaml"
    path.write_text(dump(compose(over)))
    return path


def test_the_default_composition_has_no_overrides_at_any_scale(tmp_path):
    assert overrides(params(tmp_path, [])) == {}
    (tmp_path / "smoke").mkdir()
    assert overrides(params(tmp_path / "smoke", ["scale=smoke"])) == {}
    assert run_name("evaluation quick", tmp_path / "params.yaml") == "evaluation quick"


def test_an_ablation_is_named_and_tagged_after_what_it_changed(tmp_path, monkeypatch):
    path = params(tmp_path, ["scale=smoke", "planner.tau=0.7", "stats.level=0.9"])
    assert overrides(path) == {"planner.tau": "0.7", "stats.level": "0.9"}
    assert run_name("evaluation smoke", path) == "evaluation smoke tau=0.7 level=0.9"
    monkeypatch.chdir(tmp_path)
    assert run_tags("evaluation", "smoke")["overrides"] == "planner.tau=0.7 stats.level=0.9"


def test_settings_sharing_a_last_key_are_named_in_full():
    changed = {"eval.random_maps": "8", "oracle.random_maps": "4", "planner.eta": "5.0"}
    assert override_text(changed) == "eval.random_maps=8 oracle.random_maps=4 eta=5.0"
    assert override_text({}) == ""


def test_no_params_file_means_no_overrides(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert overrides() == {} and run_tags("evaluation", "quick")["overrides"] == "none"
    (tmp_path / "params.yaml").write_text("not: [valid")
    assert overrides(tmp_path / "params.yaml") == {}
