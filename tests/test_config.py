"""conf/ is the single source of truth: params.yaml is its composition; bad keys fail clearly."""

import pytest
from omegaconf import OmegaConf

from vnrrt.config import (
    ConfigError,
    DataConfig,
    LabelsConfig,
    ScaleConfig,
    compose,
    dump,
    load_params,
    section,
)


def test_committed_params_yaml_equals_the_default_composition(repo):
    committed = (repo / "params.yaml").read_text()
    assert committed == dump(compose()), "params.yaml is stale: run `make params`"


@pytest.mark.parametrize(("scale", "shards", "maps"), [("smoke", 2, 8), ("quick", 4, 200),
                                                       ("paper", 100, 10_000)])  # fmt: skip
def test_scales_compose_and_paper_scale_matches_the_paper(scale, shards, maps):
    cfg = compose([f"scale={scale}"])
    sc = section(cfg, "scale", ScaleConfig)
    assert sc.name == scale and len(sc.shards) == shards and sc.n_maps == maps
    assert sc.shards == list(range(shards))
    data = section(cfg, "data", DataConfig)
    if scale == "paper":
        assert sc.n_maps * data.n_starts * data.n_goals == 1_440_000
        assert data.train_fraction == 0.7 and data.size == 200


def test_every_section_of_the_default_config_validates(repo):
    cfg = load_params(repo / "params.yaml")
    section(cfg, "data", DataConfig)
    section(cfg, "labels", LabelsConfig)
    section(cfg, "scale", ScaleConfig)


def test_unknown_key_is_named():
    cfg = OmegaConf.create({"data": {"size": 200, "n_obstacle": [1, 2]}})
    with pytest.raises(ConfigError, match="data.n_obstacle"):
        section(cfg, "data", DataConfig)
    with pytest.raises(Exception, match="n_obstacle"):
        compose(["data.n_obstacle=[1,2]"])  # Hydra refuses it too (struct mode)


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ({"size": "big"}, "data.size"),
        ({"n_obstacles": [5, 2]}, "data.n_obstacles"),
        ({"shapes": ["hexagon"]}, "data.shapes"),
        ({"train_fraction": 1.0}, "data.train_fraction"),
    ],
)
def test_bad_values_are_named(override, message):
    cfg = OmegaConf.create({"data": override})
    with pytest.raises(ConfigError, match=message):
        section(cfg, "data", DataConfig)


def test_missing_section_and_params_file(tmp_path):
    with pytest.raises(ConfigError, match="'labels' is missing"):
        section(OmegaConf.create({}), "labels", LabelsConfig)
    with pytest.raises(ConfigError, match="not found"):
        load_params(tmp_path / "params.yaml")
