"""Every key of the evaluation's config sections (``eval``, ``stats``, ``oracle``, ``regime``,
``budget``) reaches the stages that declare it: the config is composed with every key changed (Hydra
overrides, as ``dvc exp run -S`` passes them), each stage whose ``dvc.yaml`` entry declares a
key (or its section) sees exactly its declared parameters (:func:`vnrrt.config.restrict`), and
its typed settings hold the new value. A key a stage declares but ignores, or a dataclass
default standing in for it, fails here."""

import dataclasses
import functools
import json

import pytest
import yaml

from tests.stage_closure import REPO
from vnrrt.config import compose, restrict, stage_params
from vnrrt.pipeline import training_budget as budget
from vnrrt.pipeline.benchmark_maps import bench_settings
from vnrrt.pipeline.evaluation import instances_settings, trials_settings
from vnrrt.pipeline.paper_comparison import evaluate_settings, report_settings
from vnrrt.pipeline.sampling_ideas import ideas_settings, part_settings
from vnrrt.pipeline.validate import validate_config

SETTINGS = {
    "instances": instances_settings,
    "trials": trials_settings,
    "evaluate": evaluate_settings,
    "report": report_settings,
    "oracle": lambda cfg: part_settings(cfg, "oracle"),
    "regime": lambda cfg: part_settings(cfg, "regime"),
    "ideas": ideas_settings,
    "budget_trials": budget.trials_settings,
    "budget_report": budget.report_settings,
    "bench_maps": bench_settings,
    "validate": validate_config,
}
DICT_VALUES = ("sources", "families", "planners")  # keys whose values are dicts
CHANGED = {  # key -> a valid value other than the default's
    "eval.planners": ["rrt_star", "vnrrt_star"],
    "eval.sources": {"nrrt_star": "vertexnet", "vnrrt_star": "nrrtnet", "m_vnrrt_star": "nrrtnet"},
    "eval.named_initial": 7,
    "eval.named_optimal": 3,
    "eval.random_maps": 11,
    "eval.random_initial": 2,
    "eval.random_optimal": 2,
    "eval.any_angle": False,
    "eval.informed": False,
    "eval.parts": [0, 1, 2],
    "eval.timing_noise": False,
    "eval.mask_variants": ["max"],
    "eval.masked_controls": False,
    "eval.endpoint_radius": 2.0,
    "eval.zero_obstacles": True,
    "eval.cap_factor": 2.0,
    "eval.gpu": True,
    "stats.bootstrap": 300,
    "stats.level": 0.9,
    "stats.tail_draws": 20,
    "stats.untestable_endpoint_share": 0.7,
    "stats.untestable_fallback": 0.6,
    "stats.strata": [0, 2, 5],
    "stats.pairing": [0.3],
    "oracle.families": {  # Hydra merges a dict override into the default: every key given
        "path": ["oracle_path"],
        "vertex": ["oracle_vertex"],
        "taut_vertex": ["oracle_taut_path"],
        "masked_vertex": ["oracle_vertex_endpoints"],
        "control": ["oracle_endpoints"],
    },
    "oracle.planners": {"path": "vnrrt_star", "masked_vertex": "nrrt_star"},
    "oracle.sigmas": [2.5],
    "oracle.mixes": [0.3],
    "oracle.blend_weights": [0.0, 0.4],
    "oracle.selection_share": 0.4,
    "oracle.floor": 0.1,
    "oracle.radius": 2.0,
    "oracle.qualities": [1.0, 0.3],
    "oracle.random_maps": 9,
    "oracle.trials": 3,
    "oracle.per_cell": True,
    "oracle.parts": [0, 1],
    "regime.etas": [7.0],
    "regime.radius_modes": ["fixed2"],
    "regime.gamma_factors": [0.5],
    "regime.trials": 3,
    "regime.goal_radii": [3.0],
    "regime.configurations": ["rrt_star", "nrrt_star"],
    "regime.random_maps": 4,
    "regime.parts": [0, 1, 2],
    "budget.steps": [10, 20],  # multiples of the quick scale's trainer.max_epochs
    "budget.seeds": [1, 2],
    "budget.report": ["training_budget"],
}
SECTIONS = ("eval", "stats", "oracle", "regime", "budget")


def _override(key: str, value) -> str:
    """A Hydra override of ``key``: ``{a:b}`` dicts, JSON for the rest."""
    if isinstance(value, dict):
        return f"{key}={{{','.join(f'{k}:{v}' for k, v in value.items())}}}"
    return f"{key}={json.dumps(value)}"


def _flat(node, prefix: str = "") -> dict:
    """Dotted keys of a stage's settings (dataclasses and dicts nested)."""
    if dataclasses.is_dataclass(node):
        node = {f.name: getattr(node, f.name) for f in dataclasses.fields(node)}
    if not isinstance(node, dict) or (prefix and prefix.rsplit(".", 1)[-1] in DICT_VALUES):
        return {prefix: node}
    out = {}
    for k, v in node.items():
        out.update(_flat(v, f"{prefix}.{k}" if prefix else str(k)))
    return out


@functools.cache
def _stages() -> dict:
    return yaml.safe_load((REPO / "dvc.yaml").read_text())["stages"]


def _declares(stage: str, key: str) -> bool:
    entry = _stages()[stage]
    params = entry.get("do", entry).get("params", [])
    return any(key == p or key.startswith(p + ".") for p in params)


def _view(cfg, stage: str):
    entry = _stages()[stage]
    items = {"foreach": "0", "matrix": "-".join("0" * len(entry.get("matrix", {})))}
    name = next((f"{stage}@{v}" for k, v in items.items() if k in entry), stage)
    return restrict(cfg, stage_params(name, REPO / "dvc.yaml"))


def test_the_changed_values_differ_from_the_defaults_and_cover_every_key():
    default = compose()
    for section in SECTIONS:
        keys = {f"{section}.{k}" for k in default[section]}
        assert keys == {k for k in CHANGED if k.startswith(section + ".")}, section
    for key, value in CHANGED.items():
        section, name = key.split(".")
        assert default[section][name] != value, key


@pytest.fixture(scope="module")
def seen() -> dict[str, dict]:
    """Each stage's flattened settings from the config with every key of CHANGED changed."""
    cfg = compose([_override(k, v) for k, v in CHANGED.items()])
    views = {s: cfg if s == "validate" else _view(cfg, s) for s in SETTINGS}
    return {s: _flat(fn(views[s])) for s, fn in SETTINGS.items()}


@pytest.mark.parametrize("key", sorted(CHANGED))
def test_every_stage_that_declares_a_key_sees_its_new_value(key, seen):
    readers = [s for s in SETTINGS if s == "validate" or _declares(s, key)]
    assert len(readers) >= 2, f"{key}: no stage reads it"
    for stage in readers:
        flat = seen[stage]
        assert key in flat, f"{stage} declares {key} but its settings do not hold it"
        assert flat[key] == CHANGED[key], (stage, key, flat[key])
