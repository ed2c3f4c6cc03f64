"""The rules every trial table's rows keep (vnrrt.evaluation.invariants), on the committed
results bundle: it keeps them all, and each planted violation is refused, naming the file,
the row and the rule, by the checks themselves, by merging parts (the stages) and by the
bundle's recompute command (exit 2)."""

import dataclasses
import gzip
import math
import shutil
import subprocess
import sys

import numpy as np
import pytest

from tests.conftest import REPO
from vnrrt.config.paths import table_part_file
from vnrrt.evaluation.invariants import Design, bundle_design
from vnrrt.evaluation.protocol import trial_seed
from vnrrt.evaluation.table import TableError, merge_parts, read_table, write_table
from vnrrt.infra.io import read_json

BUNDLE = REPO / "reports/cpu/results"
EPS, BUDGET, SEED = 0.01, 200000, 0  # the bundle's params.yaml
ROW = 100  # instance 0 (map_1 'open'), rrt_star, stop optimal, trial 0: a success


@pytest.fixture(scope="module")
def trials():
    return read_table(BUNDLE / "trials.csv.gz")


@pytest.fixture(scope="module")
def design(trials):
    optima = read_json(BUNDLE / "instances.json")["optima"]
    d = bundle_design({"trials": trials}, optima, EPS, BUDGET, SEED)
    return dataclasses.replace(d, keys=frozenset(trials["key"]), names={0: ("open", "map_1")})


def test_the_bundle_parameters_are_the_ones_assumed_here():
    params = (BUNDLE / "params.yaml").read_text()
    assert f"eps: {EPS}" in params and f"max_iterations: {BUDGET}" in params
    assert "\nseed: 0\n" in params


def test_the_committed_table_keeps_every_rule_and_row_is_what_it_says(trials, design):
    design.check(trials[trials["instance"] == 0], "trials")  # names known for instance 0
    unnamed = dataclasses.replace(design, names={})  # map names unchecked
    unnamed.check(trials[trials["instance"] > 0], "trials")
    r = trials.iloc[ROW]
    assert (r.instance, r.key, r.stop, r.trial, bool(r.success)) == (
        0,
        "rrt_star",
        "optimal",
        0,
        True,
    )
    assert r.seed == trial_seed(SEED, 0, "optimal", 0)  # an independent reading of the seed
    # the A* length is the reference; the exact optimum (any-angle rows) lies below it
    assert design.exact[0] < r.reference_length == design.astar[0] < r.cost


def _planted(table, **values):
    t = table.iloc[ROW - 5 : ROW + 5].copy()  # a slice around the row, still seq-ordered
    for col, v in values.items():
        t.loc[t.index[5], col] = v(t.iloc[5]) if callable(v) else v
    return t


CASES = {  # rule fragment -> the planted values of row ROW
    "cost >= the exact optimum": {"cost": lambda r: 0.01 * r.reference_length},
    "stop is a stop rule": {"stop": "fastest"},
    "stop_reason is solved": {"stop_reason": "gave_up"},
    "key is a configuration key": {"key": "rrt_star@@x"},
    "key's planner is the row's planner": {"key": "vnrrt_star"},
    "key is one of the design's": {"key": "vnrrt_star[elsewhere]", "planner": "vnrrt_star"},
    "trial >= 0": {"trial": -1},
    "paired seed": {"seed": lambda r: r.seed + 1},
    "reference_length is the instance's optimum": {
        "reference_length": lambda r: r.reference_length * 1.5
    },
    "instance is one of the instances file's": {"instance": 10_000},
    "map and map_set are the instance's": {"map": "u_trap"},
    "run_stop_reason is solved": {"run_stop_reason": "gave_up"},
    "run_stop_reason equals stop_reason unless": {"run_stop_reason": "max_iterations"},
    "success exactly when stop_reason is solved": {
        "stop_reason": "max_iterations",
        "run_stop_reason": "max_iterations",
    },
    "a success has a path": {"cost": math.inf, "time_to_first": math.nan},
    "cost <= (1 + eps) x reference_length": {"cost": lambda r: 1.5 * r.reference_length},
    "cost is a length": {"cost": math.nan},
    "iterations in 0..200000": {"iterations": BUDGET + 1},
    "tree_size in 1..iterations + 2": {"tree_size": lambda r: r.iterations + 3},
    "collision_checks >= 0": {"collision_checks": -1},
    "time_to_stop is finite": {"time_to_stop": -0.5},
    "setup_time is finite": {"setup_time": math.inf},
    "time_to_first is in 0..time_to_stop": {"time_to_first": lambda r: r.time_to_stop + 1.0},
    "time_to_first is NaN when no path": {
        "cost": math.inf,
        "success": False,
        "stop_reason": "max_iterations",
        "run_stop_reason": "max_iterations",
    },
    "t_1.05x is NaN or in 0..time_to_stop": {"t_1.05x": -1.0},
}


@pytest.mark.parametrize("rule", list(CASES))
def test_each_planted_violation_names_the_file_row_and_rule(trials, design, rule):
    design.check(_planted(trials), "part.csv")  # the slice keeps every rule unplanted
    with pytest.raises(TableError) as err:
        design.check(_planted(trials, **CASES[rule]), "part.csv")
    text = str(err.value)
    assert "part.csv" in text and f"row seq={ROW} " in text and rule in text, text


def test_merging_parts_checks_each_part_and_names_it(trials, design, tmp_path):
    head = trials.iloc[: 2 * ROW]
    write_table(head.iloc[:ROW], table_part_file(tmp_path, 0))
    write_table(_planted(head, **CASES["cost >= the exact optimum"]).pipe(
        lambda bad: head.iloc[ROW:].assign(cost=np.where(head.iloc[ROW:]["seq"] == ROW,
                                           bad.iloc[5].cost, head.iloc[ROW:]["cost"]))),
        table_part_file(tmp_path, 1))  # fmt: skip
    with pytest.raises(TableError, match=r"part_1\.csv: row seq=100 .*exact optimum"):
        merge_parts(tmp_path, [0, 1], 2 * ROW, design)
    assert len(merge_parts(tmp_path, [0, 1], 2 * ROW)) == 2 * ROW  # unchecked: as before


def test_the_bundle_references_must_agree_and_average_to_the_instances(trials):
    optima = read_json(BUNDLE / "instances.json")["optima"]
    bad = trials.copy()
    bad.loc[bad.index[ROW], "reference_length"] *= 1.5
    with pytest.raises(TableError, match="instance 0 do not agree"):
        bundle_design({"trials": bad}, optima, EPS, BUDGET, SEED)
    moved = trials.copy()
    moved.loc[moved["instance"] == 0, "reference_length"] *= 1.5  # every row of one instance
    with pytest.raises(TableError, match="map set map_1 average"):
        bundle_design({"trials": moved}, optima, EPS, BUDGET, SEED)


def test_a_tampered_bundle_is_exit_2_naming_file_row_and_rule(trials, tmp_path):
    bundle = tmp_path / "results"
    shutil.copytree(BUNDLE, bundle)
    bad = trials.copy()
    bad.loc[bad.index[ROW], "cost"] = 0.01 * bad.iloc[ROW].reference_length  # the case
    write_table(bad, tmp_path / "trials.csv")
    with open(tmp_path / "trials.csv", "rb") as f, gzip.open(bundle / "trials.csv.gz", "wb") as g:
        shutil.copyfileobj(f, g)
    cmd = [sys.executable, "-m", "vnrrt.pipeline.recompute", "run", "--bundle", str(bundle),
           "--out", str(tmp_path / "out")]  # fmt: skip
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 2, proc.stderr
    line = proc.stderr.strip()
    assert "\n" not in line and "trials.csv.gz" in line and "row seq=100" in line, line
    assert "cost >= the exact optimum" in line and not (tmp_path / "out").exists()


def test_a_design_without_optima_leaves_the_cost_rule_unchecked(trials):
    bare = Design(EPS, BUDGET)
    bare.check(_planted(trials, cost=lambda r: 0.999 * r.reference_length, success=False,
                        stop_reason="max_iterations", run_stop_reason="max_iterations"),
               "t")  # fmt: skip
    assert Design(EPS, BUDGET).exact == {}
