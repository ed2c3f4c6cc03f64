"""The claims' verdict rules on synthetic inputs (every category, the testability rule; the
paper-compatibility rule is tested in test_readings.py), the resamples for the corrected
level, and the masked NRRT* control running through M-VNRRT*'s own sampler code."""

import math

import numpy as np
import pytest

from vnrrt.data.instances import EvalInstance
from vnrrt.evaluation import sampling as sampling_module
from vnrrt.evaluation.config import Configurations
from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.protocol import configurations
from vnrrt.evaluation.stats import verdict
from vnrrt.evaluation.trials import run_trials
from vnrrt.search import any_angle_path, astar, path_vertices
from vnrrt.studies.paper_comparison.claims import claim_boot
from vnrrt.studies.paper_comparison.claims import (
    testability as masked_rule,
)


@pytest.mark.parametrize(
    ("quoted", "low", "high", "want"),
    [
        (0.77, 0.5, 1.0, "reproduced"),
        (0.77, 0.1, 0.3, "same direction, smaller effect"),
        (0.77, 1.2, 2.0, "same direction, larger effect"),
        (0.77, -0.1, 0.4, "no clear effect"),
        (0.77, -0.6, -0.2, "reversed"),
        (-0.09, -0.3, -0.05, "reproduced"),  # a quoted slow-down
        (-0.09, 0.1, 0.3, "reversed"),
        (0.77, math.nan, math.nan, "no clear effect"),
    ],
)
def test_the_verdict_of_our_interval_on_a_quoted_value(quoted, low, high, want):
    assert verdict(quoted, low, high) == want


def test_the_untestable_rule():
    ok = {"mass_endpoints": 0.3, "mass_interior": 0.2, "mass_path": 0.1, "fallback_rate": 0.1}
    assert masked_rule(ok, 0.5, 0.5) == {"testable": True, "why": ""}
    ends = masked_rule({**ok, "mass_endpoints": 0.984}, 0.5, 0.5)
    assert not ends["testable"] and "98.4% of its sampler's mass is on the start" in ends["why"]
    falls = masked_rule({**ok, "fallback_rate": 1.0}, 0.5, 0.5)
    assert not falls["testable"] and "falls back to uniform sampling in 100%" in falls["why"]
    assert masked_rule(None, 0.5, 0.5)["testable"]  # not a masked claim


def test_enough_resamples_for_the_corrected_tails():
    strict = 1 - 0.05 / 8
    n = claim_boot(2000, 50, strict)
    assert round(n * (1 - strict) / 2, 6) >= 50 and n == 16_000
    assert claim_boot(2000, 1, 0.95) == 2000


def test_the_mask_variants_and_control_are_configured_at_the_claims_tau():
    ev = Configurations(mask_variants=["max", "noends"], masked_controls=True, informed=False)
    texts = [k.text for k in configurations(ev, [0.5, 0.9], 0.5)]
    assert texts[-3:] == ["m_vnrrt_star@0.5{max}", "m_vnrrt_star@0.5{noends}",
                          "m_vnrrt_star@0.5[nrrtnet]"]  # fmt: skip
    plain = Configurations(informed=False, mask_variants=[], masked_controls=False)
    assert not any("{" in k.text or "[" in k.text for k in configurations(plain, [0.5], 0.5))


def wall_instance(heatmaps: dict) -> EvalInstance:
    grid = np.zeros((40, 60), np.uint8)
    grid[5:35, 30] = 1
    s, g = (5, 20), (55, 20)
    path, length = astar(grid, s, g)
    exact, exact_len = any_angle_path(grid, (5.5, 20.5), (55.5, 20.5))
    return EvalInstance(0, (0, 0), "random", "wall", 0, grid, s, g, length, exact_len,
                        exact_len, path, path_vertices(path), exact, heatmaps)  # fmt: skip


def test_the_masked_control_runs_through_m_vnrrts_sampler(monkeypatch):
    """The control (M-VNRRT* on the path network's heatmap) builds the same masked sampler
    from its own heatmap; a path heatmap with nothing above tau falls back to uniform."""
    vertex = np.zeros((40, 60), np.float32)
    vertex[2:6, 28:33] = 0.9  # above the wall's end: what a vertex network marks
    path = np.full((40, 60), 0.2, np.float32)  # a faint path network: nothing above 0.5
    calls = []
    real = sampling_module.make_sampler

    def spy(planner, shape, heatmap, *, config):
        calls.append((planner, round(float(np.asarray(heatmap).max()), 6), config.tau))
        return real(planner, shape, heatmap, config=config)

    monkeypatch.setattr(sampling_module, "make_sampler", spy)
    inst = wall_instance({"vertexnet": vertex, "nrrtnet": path})
    keys = [ConfigKey("m_vnrrt_star", 0.5, "vertexnet"),
            ConfigKey("m_vnrrt_star", 0.5, "vertexnet").with_source("nrrtnet")]  # fmt: skip
    table = run_trials([inst], keys, {("random", "initial"): 2}, workers=1)
    assert sorted(calls) == [("m_vnrrt_star", 0.2, 0.5), ("m_vnrrt_star", 0.9, 0.5)]
    by_key = table.groupby("key")
    assert set(by_key.groups) == {"m_vnrrt_star@0.5", "m_vnrrt_star@0.5[nrrtnet]"}
    control = table[table["key"] == "m_vnrrt_star@0.5[nrrtnet]"]
    assert control["fallback_uniform"].all() and (control["planner"] == "m_vnrrt_star").all()
    assert not table.loc[table["key"] == "m_vnrrt_star@0.5", "fallback_uniform"].any()
    masked = table[table["key"] == "m_vnrrt_star@0.5"].iloc[0]
    assert masked["mass_interior"] + masked["mass_endpoints"] + masked["mass_path"] <= 1 + 1e-9


def test_the_mask_variants_change_what_the_mask_keeps():
    """max: a heatmap peaking at 0.4 keeps its peak above tau 0.5 once max-normalised;
    noends: the start/goal disks hold no weight."""
    from vnrrt.evaluation.sources import endpoint_disks, mask_variant

    heat = np.full((40, 60), 0.1)
    heat[20, 5] = heat[20, 55] = 0.4  # start and goal cells
    heat[4, 30] = 0.3
    inst = wall_instance({})
    assert (mask_variant(heat, "", inst, 3.0) >= 0.5).sum() == 0
    assert (mask_variant(heat, "max", inst, 3.0) >= 0.5).sum() == 3
    no_ends = mask_variant(heat, "noends", inst, 3.0)
    assert no_ends[endpoint_disks(inst, 3.0)].max() == 0 and no_ends[4, 30] == 0.3
