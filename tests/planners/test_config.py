"""Planner settings (planners/config.py): PlannerConfig's defaults are conf/planner/default.yaml
and FASTEST is conf/planner/fastest.yaml, read as Hydra composes them; invalid values and
files that do not match the dataclass are refused with the setting named."""

import dataclasses
import math

import pytest
import yaml

from vnrrt.config import CONF_DIR, compose, conf_defaults, conf_file, section
from vnrrt.planners import FASTEST, PlannerConfig, PlannerConfigError


def test_the_defaults_are_the_default_yaml():
    """Every field's default is the value of default.yaml (read here with PyYAML), and the
    file names no other key."""
    with open(CONF_DIR / "planner" / "default.yaml") as f:
        written = yaml.safe_load(f)
    got = dataclasses.asdict(PlannerConfig())
    assert got == written and got.keys() == written.keys()
    assert PlannerConfig().taus is not PlannerConfig().taus  # a list per config


def test_fastest_is_the_hydra_option_planner_fastest():
    """The pipeline's ``planner=fastest`` composes the settings of FASTEST (the scale group
    sets the time budget in both compositions), and FASTEST differs from the defaults only
    where fastest.yaml says."""
    default = section(compose([]), "planner", PlannerConfig)
    fastest = section(compose(["planner=fastest"]), "planner", PlannerConfig)
    with open(CONF_DIR / "planner" / "fastest.yaml") as f:
        written = yaml.safe_load(f)
    changed = set(written) - {"defaults"}
    for f in dataclasses.fields(PlannerConfig):
        mine, theirs = getattr(FASTEST, f.name), getattr(fastest, f.name)
        if f.name in changed:
            assert mine == theirs == written[f.name], f.name
        elif f.name == "max_seconds":  # the scale's budget in both compositions
            assert theirs == default.max_seconds and mine == PlannerConfig().max_seconds
        else:
            assert mine == theirs == getattr(PlannerConfig(), f.name), f.name
    assert FASTEST.goal_radius == math.inf and FASTEST.straight_first


def test_a_yaml_file_that_does_not_match_the_dataclass_is_refused(tmp_path, monkeypatch):
    (tmp_path / "planner").mkdir()
    (tmp_path / "planner" / "base.yaml").write_text("eta: 3.0\nmix: 0.5\n")
    (tmp_path / "planner" / "over.yaml").write_text("defaults:\n  - base\n  - _self_\neta: 4.0\n")
    (tmp_path / "planner" / "first.yaml").write_text("defaults:\n  - _self_\n  - base\neta: 4.0\n")
    monkeypatch.setattr("vnrrt.config.CONF_DIR", tmp_path)
    assert conf_file("planner", "over") == {"eta": 4.0, "mix": 0.5}
    assert conf_file("planner", "first") == {"eta": 3.0, "mix": 0.5}  # _self_ first
    only_eta = type("C", (), {"__annotations__": {"eta": "float"}})
    with pytest.raises(PlannerConfigError, match="differ"):
        conf_defaults("planner", "base", exact=True, error=PlannerConfigError)(only_eta)


def test_an_invalid_setting_is_named():
    with pytest.raises(PlannerConfigError, match="eta"):
        PlannerConfig(eta=-1.0).validate()
    with pytest.raises(PlannerConfigError, match="unknown planner setting"):
        PlannerConfig().replace(speed=2.0)
