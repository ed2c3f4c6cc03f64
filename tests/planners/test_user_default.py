"""The default outside the study (issue 52): plan(), Planner and ``vnrrt plan`` use
conf/planner/user.yaml (our fastest settings, budgets scaled with the map's free cells); the
budget rule is what the file states; the pipeline keeps the paper's protocol (default.yaml)."""

import dataclasses
import math

import numpy as np
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from vnrrt.cli.main import main
from vnrrt.config import CONF_DIR, compose, load_params, section
from vnrrt.pipeline.evaluation import trials_settings
from vnrrt.planners import FASTEST, USER, Planner, PlannerConfig, plan
from vnrrt.planners.config import PlannerConfig as ConfigClass


def read_option(option: str) -> dict:
    """conf/planner/<option>.yaml composed by hand (its defaults first, then its own keys),
    read with PyYAML: independent of vnrrt.config's reader."""
    with open(CONF_DIR / "planner" / f"{option}.yaml") as f:
        doc = yaml.safe_load(f)
    merged: dict = {}
    for base in doc.pop("defaults", []):
        merged.update(doc if base == "_self_" else read_option(base))
    return merged | doc


def expected_budget(option: str, free: int) -> tuple[int, float]:
    """The budgets of the rule written in the file's comments, from its values."""
    v = read_option(option)
    it, sec = v["max_iterations"], v["max_seconds"]
    if v["iterations_per_free_cell"] is not None:
        it = max(it, math.ceil(v["iterations_per_free_cell"] * free))
    if v["seconds_per_free_cell"] is not None:
        sec = max(sec, v["seconds_per_free_cell"] * free)
    return it, sec


def test_the_library_default_is_user_yaml():
    written = read_option("user")
    assert dataclasses.asdict(USER) == written
    assert PlannerConfig.named("user") == USER and PlannerConfig.named("fastest") == FASTEST
    assert Planner(np.zeros((8, 8), np.uint8)).config is USER
    fastest = read_option("fastest")
    differ = {k for k in written if written[k] != fastest[k]}
    assert differ == {"iterations_per_free_cell", "seconds_per_free_cell"}  # FASTEST, scaled


def test_plan_without_a_config_is_plan_with_user():
    g = np.zeros((120, 120), np.uint8)
    g[20:100, 60] = 1
    s, e = (30.5, 60.5), (90.5, 60.5)
    a = plan(g, s, e, stop="optimal", seed=4)
    b = plan(g, s, e, stop="optimal", seed=4, config=USER)
    np.testing.assert_array_equal(a.path, b.path)
    assert a.cost == b.cost and a.iterations == b.iterations and a.budget == b.budget
    assert a.budget == expected_budget("user", int((g == 0).sum()))
    paper = plan(g, s, e, stop="optimal", seed=4, config=PlannerConfig.paper())
    assert paper.budget == expected_budget("default", 0) != a.budget


@st.composite
def made_maps(draw):
    """A map of up to 640 x 640 cells with random rectangles of obstacles, its corner 3 x 3
    free (the query's cell)."""
    h, w = draw(st.integers(4, 640)), draw(st.integers(4, 640))
    g = np.zeros((h, w), np.uint8)
    for _ in range(draw(st.integers(0, 6))):
        y, x = draw(st.integers(0, h - 1)), draw(st.integers(0, w - 1))
        g[y : y + draw(st.integers(1, h)), x : x + draw(st.integers(1, w))] = 1
    g[:3, :3] = 0
    return g


@settings(max_examples=40, deadline=None)
@given(grid=made_maps())
def test_the_budget_rule_scales_with_free_cells_as_documented(grid):
    free = int(np.count_nonzero(grid == 0))
    r = plan(grid, (1.5, 1.5), (1.5, 1.5))
    assert r.budget == expected_budget("user", free) == USER.budgets(free)
    bigger = np.pad(grid, ((0, 64), (0, 0)))  # 64 more free rows: never a smaller budget
    more = plan(bigger, (1.5, 1.5), (1.5, 1.5)).budget
    assert more[0] >= r.budget[0] and more[1] >= r.budget[1]
    assert plan(grid, (1.5, 1.5), (1.5, 1.5), config=PlannerConfig.paper()).budget == (
        PlannerConfig().max_iterations, PlannerConfig().max_seconds)  # fmt: skip


def test_the_budget_rule_grows_linearly_above_its_floors():
    k_it, k_s = USER.iterations_per_free_cell, USER.seconds_per_free_cell
    big = 10 * math.ceil(max(USER.max_iterations / k_it, USER.max_seconds / k_s))
    assert USER.budgets(big) == (math.ceil(k_it * big), pytest.approx(k_s * big))
    assert USER.budgets(2 * big)[0] == 2 * USER.budgets(big)[0]
    assert USER.budgets(0) == (USER.max_iterations, USER.max_seconds)


def test_the_docstrings_state_the_files_rule():
    rule = (
        f"``max({USER.max_iterations}, ceil({USER.iterations_per_free_cell:g} F))`` "
        f"iterations, ``max({USER.max_seconds:g}, {USER.seconds_per_free_cell:g} F)``"
    )
    assert rule in " ".join(Planner.__doc__.split())


def test_the_pipeline_keeps_the_papers_protocol():
    """The study composes planner=default: its typed planner section (what the stages build
    their PlannerConfig from) is the paper's protocol with fixed budgets, in the composition
    and in the committed params.yaml, and not the library default."""
    composed = section(compose([]), "planner", ConfigClass)
    committed = section(load_params(), "planner", ConfigClass)
    assert composed == committed
    assert composed.iterations_per_free_cell is None and composed.seconds_per_free_cell is None
    paper = PlannerConfig.paper()
    for f in dataclasses.fields(ConfigClass):
        if f.name != "max_seconds":  # the scale group sets the time budget
            assert getattr(composed, f.name) == getattr(paper, f.name), f.name
    assert composed.straight_first is False and composed.informed is False
    assert trials_settings(load_params())["planner"] == composed  # the trials stages' settings
    user = section(compose(["planner=user"]), "planner", ConfigClass)  # selectable too
    assert user.iterations_per_free_cell == USER.iterations_per_free_cell


def test_the_cli_names_its_configuration_and_budget(tmp_path, capsys):
    g = np.zeros((100, 100), np.uint8)
    g[10:90, 50] = 1
    np.save(tmp_path / "m.npy", g)
    args = ["plan", "--map", str(tmp_path / "m.npy"), "--start", "20.5,50.5",
            "--goal", "80.5,50.5"]  # fmt: skip
    assert main(args) == 0
    out = capsys.readouterr().out
    it, sec = expected_budget("user", int((g == 0).sum()))
    assert f"budget={it} it/{sec:g} s" in out and "config: user (conf/planner/user.yaml)" in out
    assert main([*args, "--config", "default", "--set", "eta=5"]) == 0
    out = capsys.readouterr().out
    assert "config: default (conf/planner/default.yaml) --set eta=5" in out
    assert main([*args, "--set", "max_iterations=7"]) in (0, 1)  # a budget set is the budget
    assert "budget=7 it/" in capsys.readouterr().out
