"""The library's defaults of every typed config section are the group's file in ``conf/``
(one source of settings): read here independently with OmegaConf, compared key by key."""

import dataclasses
import math

import pytest
from omegaconf import OmegaConf

from vnrrt.config import CONF_DIR, ConfigError, conf_defaults, conf_file
from vnrrt.data.config import LabelsConfig, ScaleConfig
from vnrrt.evaluation.config import (
    Configurations,
    EvalConfig,
    OracleConfig,
    RegimeConfig,
    Rules,
    StatsConfig,
)
from vnrrt.maps.config import DataConfig
from vnrrt.pipeline.sampling_ideas import StudyRules
from vnrrt.studies.training_budget.budget import BudgetConfig

SECTIONS = [
    (Configurations, "eval/default.yaml", None),
    (EvalConfig, "eval/default.yaml", None),
    (Rules, "planner/default.yaml", None),
    (StudyRules, "planner/default.yaml", None),
    (StatsConfig, "stats/default.yaml", None),
    (OracleConfig, "oracle/default.yaml", None),
    (RegimeConfig, "regime/default.yaml", None),
    (LabelsConfig, "labels/default.yaml", None),
    (ScaleConfig, "scale/quick.yaml", "scale"),
    (DataConfig, "data/default.yaml", None),
    (BudgetConfig, "budget/default.yaml", None),
]


@pytest.mark.parametrize(
    ("schema", "file", "node"), SECTIONS, ids=lambda x: getattr(x, "__name__", x)
)
def test_every_default_is_the_conf_files_value(schema, file, node):
    doc = OmegaConf.to_container(OmegaConf.load(CONF_DIR / file))
    doc = doc[node] if node else doc
    made = schema()
    for f in dataclasses.fields(schema):
        assert f.name in doc, f"{schema.__name__}.{f.name} has no value in conf/{file}"
        assert getattr(made, f.name) == doc[f.name], (schema.__name__, f.name)


def test_the_defaults_are_fresh_copies():
    a, b = OracleConfig(), OracleConfig()
    a.families["path"].append("x")
    a.sigmas.append(99.0)
    assert "x" not in b.families["path"] and 99.0 not in b.sigmas
    assert RegimeConfig().etas[-1] == math.inf and RegimeConfig().goal_radii[0] is None


def test_a_field_missing_from_the_file_is_named(tmp_path, monkeypatch):
    (tmp_path / "g").mkdir()
    (tmp_path / "g" / "default.yaml").write_text("a: 1\n")
    monkeypatch.setattr("vnrrt.config.CONF_DIR", tmp_path)

    with pytest.raises(ConfigError, match=r"conf/g/default.yaml lacks \['b'\]"):

        @dataclasses.dataclass
        @conf_defaults("g")
        class Section:
            a: int
            b: int


def test_an_unreadable_file_is_named(tmp_path, monkeypatch):
    (tmp_path / "g").mkdir()
    (tmp_path / "g" / "default.yaml").write_text("a: [1\n")
    monkeypatch.setattr("vnrrt.config.CONF_DIR", tmp_path)
    with pytest.raises(ConfigError, match="default.yaml is not valid YAML"):
        conf_file("g")
    with pytest.raises(ConfigError, match="missing.yaml does not exist"):
        conf_file("g", "missing")
    with pytest.raises(ConfigError, match="no mapping under 'x'"):
        (tmp_path / "g" / "ok.yaml").write_text("a: 1\n")
        conf_file("g", "ok", node="x")
