"""conf/ is the single source of truth: params.yaml is its composition; bad keys and values
fail early and clearly; a stage sees only the parameters it declares."""

import pytest
from omegaconf import OmegaConf

from vnrrt.config import (
    ConfigError,
    compose,
    dump,
    load_params,
    restrict,
    section,
    stage_params,
)
from vnrrt.data.config import LabelsConfig, ScaleConfig
from vnrrt.evaluation.config import OracleConfig
from vnrrt.maps.config import DataConfig
from vnrrt.pipeline.params import main as params_main
from vnrrt.pipeline.validate import validate_config


def test_committed_params_yaml_equals_the_default_composition(repo):
    committed = (repo / "params.yaml").read_text()
    assert committed == dump(compose()), "params.yaml is stale: run `make params`"


def test_params_yaml_leads_with_the_scale_and_the_ablation_keys():
    assert list(compose())[:5] == ["scale", "seed", "workers", "planner", "eval"]


@pytest.mark.parametrize(
    ("scale", "shards", "maps"),
    [("smoke", 2, 8), ("quick", 4, 200), ("cpu", 8, 800), ("paper", 100, 10_000)],
)
def test_scales_compose_validate_and_paper_scale_matches_the_paper(scale, shards, maps):
    cfg = compose([f"scale={scale}"])
    typed = validate_config(cfg)
    sc, data = typed["scale"], typed["data"]
    assert sc.name == scale and len(sc.shards) == shards and sc.n_maps == maps
    assert sc.shards == list(range(shards))
    assert cfg.paths.shards == f"data/{scale}/shards" and cfg.paths.models == f"models/{scale}"
    if scale == "paper":
        assert sc.n_maps * data.n_starts * data.n_goals == 1_440_000
        assert data.train_fraction == 0.7 and data.size == 200


def test_unknown_key_is_named():
    cfg = OmegaConf.create({"data": {"size": 200, "n_obstacle": [1, 2]}})
    with pytest.raises(ConfigError, match="data.n_obstacle"):
        section(cfg, "data", DataConfig)
    with pytest.raises(Exception, match="n_obstacle"):
        compose(["data.n_obstacle=[1,2]"])  # Hydra refuses it too (struct mode)


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ("data.size=big", "data.size"),
        ("data.n_obstacles=[5,2]", "data.n_obstacles"),
        ("data.shapes=[hexagon]", "data.shapes"),
        ("data.train_fraction=1.0", "data.train_fraction"),
        ("planner.eta=-1", "planner setting eta"),
        ("planner.tau=1.5", "planner.tau"),
        ("planner.taus=[0.5,2]", "planner.taus"),
        ("planner.eps=-0.1", "eps"),
        ("planner.max_iterations=0", "max_iterations"),
        ("eval.parts=[]", "eval.parts"),
        ("eval.parts=[1,2]", "eval.parts"),
        ("predict.parts=[0,0]", "predict.parts"),
        ("eval.random_maps=100000", "eval.random_maps"),
        ("eval.sources.vnrrt_star=nonet", "eval.sources.vnrrt_star"),
        ("networks.vertexnet.target=corner", "networks.vertexnet.target"),
        ("stats.level=1.5", "stats.level"),
        ("seed=-3", "seed"),
        # issue #28: combinations that cannot succeed or would be cut later, before any work
        ("planner.eps=0", "planner.eps=0.*exact continuous optimum"),
        ("eval.random_maps=0", "eval.random_maps=0.*random instances"),
        ("oracle.random_maps=100000", "oracle.random_maps.*<= eval.random_maps"),
        ("train.threads=0", "train.threads"),
    ],
)
def test_bad_values_fail_validation_naming_the_key(override, message):
    with pytest.raises(ConfigError, match=message):
        validate_config(compose([override]))


def test_eps_zero_is_allowed_without_an_exact_stop():
    validate_config(compose(["planner.eps=0", "eval.any_angle=false"]))


def test_a_section_must_give_every_key():
    with pytest.raises(ConfigError, match="lacks"):
        section(OmegaConf.create({"labels": {}}), "labels", LabelsConfig)
    with pytest.raises(ConfigError, match="'labels' is missing"):
        section(OmegaConf.create({}), "labels", LabelsConfig)


def test_a_given_mapping_replaces_the_defaults_whole():
    """An older run's oracle families (one vertex family) gain none of today's defaults."""
    cfg = compose()
    OmegaConf.update(cfg, "oracle.families", {"path": ["oracle_path"],
                     "vertex": ["oracle_vertex", "oracle_taut_vertex"]}, merge=False)  # fmt: skip
    OmegaConf.update(cfg, "oracle.planners", {"path": "nrrt_star"}, merge=False)
    oc = section(cfg, "oracle", OracleConfig)
    assert oc.families == {"path": ["oracle_path"], "vertex": ["oracle_vertex",
                                                               "oracle_taut_vertex"]}  # fmt: skip
    assert oc.planners == {"path": "nrrt_star"}


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ("oracle.mixes=[0.5,1.01]", "oracle.mixes"),
        ("oracle.mixes=[0,0.5]", "oracle.mixes"),
        ("oracle.planners.path=rrt_star", "oracle.planners.path"),
        ("+oracle.planners.nofamily=nrrt_star", "oracle.planners.nofamily"),
        ("oracle.planners.masked_vertex=vnrrt_star", "is in vertex too"),
    ],
)
def test_bad_oracle_grids_and_planners_are_named(override, message):
    with pytest.raises(ConfigError, match=message):
        validate_config(compose([override]))


def test_missing_empty_or_broken_params_files(tmp_path):
    with pytest.raises(ConfigError, match="not found"):
        load_params(tmp_path / "params.yaml")
    (tmp_path / "empty.yaml").write_text("")
    with pytest.raises(ConfigError, match="empty"):
        load_params(tmp_path / "empty.yaml")
    (tmp_path / "broken.yaml").write_text("a: [1, 2\n")
    with pytest.raises(ConfigError, match="not valid YAML"):
        load_params(tmp_path / "broken.yaml")


def test_a_failed_composition_leaves_params_yaml_unchanged(tmp_path, capsys):
    out = tmp_path / "params.yaml"
    out.write_text("the old file\n")
    assert params_main(["--out", str(out), "scale=smok"]) == 2
    assert out.read_text() == "the old file\n"
    assert params_main(["--out", str(out), "planner.tau=1.5"]) == 2
    assert out.read_text() == "the old file\n"
    err = capsys.readouterr().err
    assert err.count("\n") == 2 and "planner.tau" in err  # one line each
    assert params_main(["--out", str(out), "scale=smoke"]) == 0
    assert load_params(out).scale.name == "smoke"


def test_a_stage_sees_only_what_it_declares(repo):
    cfg = compose()
    keys = stage_params("shard@0", repo / "dvc.yaml")
    assert "scale.shards" in keys and "planner" not in keys
    view = restrict(cfg, keys)
    assert view.scale.shards == cfg.scale.shards and view.paths.shards == cfg.paths.shards
    with pytest.raises(Exception, match="name"):
        _ = view.scale.name  # not declared by shard@<id>
    with pytest.raises(Exception, match="planner"):
        _ = view.planner
    train = stage_params("train@nrrtnet", repo / "dvc.yaml")
    assert "networks.nrrtnet" in train and "networks.vertexnet" not in train
    with pytest.raises(ConfigError, match="not in"):
        stage_params("no_such_stage", repo / "dvc.yaml")


def test_a_matrix_stage_names_each_axis_of_its_item(repo):
    """``budget_train@<network>-<steps>-<seed>``: ``${item.network}`` in its params is the
    network."""
    keys = stage_params("budget_train@nrrtnet-600-1", repo / "dvc.yaml")
    assert "networks.nrrtnet" in keys and not [k for k in keys if "${" in k or "vertexnet" in k]
    with pytest.raises(ConfigError, match="expected budget_train@<network>-<steps>-<seed>"):
        stage_params("budget_train@nrrtnet", repo / "dvc.yaml")


def test_every_section_of_the_default_params_validates(repo):
    typed = validate_config(load_params(repo / "params.yaml"))
    assert isinstance(typed["scale"], ScaleConfig) and isinstance(typed["data"], DataConfig)
