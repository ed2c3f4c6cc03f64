"""The masked-vertex family (a perfect M-VNRRT* heatmap): on a hand-made instance its sampler
draws from exactly the disks that tau leaves of each blurred interior vertex (a Gaussian of
sigma px, maximum 1, is >= tau within sigma sqrt(2 ln(1/tau)) px of its centre), through the
same code as the trials; on a generated instance M-VNRRT* on it puts all its heatmap weight
near the turning points, where the unmasked VNRRT* member does not; the trained M-VNRRT* is
read against its envelope; and the report names its envelope and the taut-vertex envelope apart
from the vertex envelope."""

import itertools
import math

import numpy as np
import pandas as pd
import pytest

from tests.evaluation.test_oracles import make_instance
from vnrrt.data.instances import EvalInstance
from vnrrt.evaluation.config import OracleConfig
from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.sampling import build_sampler
from vnrrt.evaluation.sources import allowed_cells, mask_variant, source_heatmap
from vnrrt.evaluation.trials import run_trials
from vnrrt.planners import PlannerConfig
from vnrrt.studies.sampling_ideas.design import MASKED_IDEA, family_members
from vnrrt.studies.sampling_ideas.findings import conclusion
from vnrrt.studies.sampling_ideas.report import envelope_table
from vnrrt.studies.sampling_ideas.rows import network_rows

CORNERS = [(8, 40), (40, 40)]  # the hand-made path's interior vertices (x, y), 32 px apart


def _run(a: tuple[int, int], b: tuple[int, int]) -> list[tuple[int, int]]:
    """The cells of a straight horizontal or vertical run from ``a`` to ``b`` (both in)."""
    (x0, y0), (x1, y1) = a, b
    n = max(abs(x1 - x0), abs(y1 - y0))
    return [(x0 + (x1 - x0) * i // n, y0 + (y1 - y0) * i // n) for i in range(n + 1)]


def hand_made() -> EvalInstance:
    """A free 64 x 64 map labelled with a path of three straight legs (start (8, 8), up,
    across, down to the goal (40, 8)): its interior vertices are :data:`CORNERS`."""
    vertices = [(8, 8), *CORNERS, (40, 8)]
    cells = [vertices[0]]
    for a, b in itertools.pairwise(vertices):
        cells += _run(a, b)[1:]
    path, verts = np.array(cells, np.int64), np.array(vertices, np.int64)
    grid = np.zeros((64, 64), np.uint8)
    length = float(len(cells) - 1)
    return EvalInstance(0, (0, 0), "random", "hand", 0, grid, (8, 8), (40, 8), length,
                        length, length, path, verts, verts.astype(float) + 0.5)  # fmt: skip


def masked_member(sigma: float, tau: float, mix: float) -> ConfigKey:
    """The masked-vertex family's member on the interior-vertex oracle at ``sigma`` and
    ``mix``, as the study's design makes it (``tau``: ``planner.tau``)."""
    oc = OracleConfig(sigmas=[sigma], mixes=[mix])
    members = family_members(oc, tau)[MASKED_IDEA]
    return next(k for k in members if k.source == f"oracle_vertex@s{sigma:g}")


@pytest.mark.parametrize("sigma, tau", [(2.0, 0.5), (2.0, 0.9), (3.0, 0.5), (3.0, 0.75)])
def test_the_masked_sampler_draws_from_the_disks_tau_leaves(sigma, tau):
    inst, key = hand_made(), masked_member(sigma, tau, 0.5)
    assert key.planner == "m_vnrrt_star" and key.tau == tau and key.mix == 0.5
    allowed = allowed_cells(inst.grid, False)
    heat = source_heatmap(key.source, inst, None, 0.0, allowed)
    heat = mask_variant(heat, key.mask, inst, 3.0)
    planner = PlannerConfig().replace(tau=key.tau)  # as a trial job's settings (reuse.job_config)
    sampler, config, fallback = build_sampler(key, heat, allowed, planner, False)
    assert sampler.kind == "masked" and sampler.tau == tau and not fallback
    assert config.mix == 0.5 and sampler.mix == 0.5
    drawn = np.diff(sampler.cdf, prepend=0.0).reshape(inst.grid.shape) > 0  # [y, x]
    r2 = 2 * sigma**2 * math.log(1 / tau)  # squared radius of the disk tau leaves
    yy, xx = np.mgrid[:64, :64]
    want = np.zeros_like(drawn)
    for x, y in CORNERS:
        want |= (xx - x) ** 2 + (yy - y) ** 2 <= r2
    assert np.array_equal(drawn, want), (int(drawn.sum()), int(want.sum()))


def test_m_vnrrt_on_the_masked_oracle_weighs_only_the_turning_points():
    for map_id in range(40):  # an instance with interior vertices away from start and goal
        inst = make_instance(map_id)
        inner = inst.vertices[1:-1]
        ends = np.array([inst.start, inst.goal])
        if len(inner) and np.min(np.hypot(*(inner[:, None] - ends[None]).T)) > 8:
            break
    masked = masked_member(1.0, 0.5, 0.5)
    plain = ConfigKey("vnrrt_star", mix=0.5).with_source(masked.source)
    table = run_trials([inst], [masked, plain], {("random", "optimal"): 2}, workers=1)
    assert table["success"].all() and not table["fallback_uniform"].any()
    shares = table.groupby("key")[["mass_interior", "mass_endpoints"]].mean().sum(axis=1)
    assert shares[masked.text] == pytest.approx(1.0)  # the disks lie within 3 px of a vertex
    assert shares[plain.text] < 0.999  # the Gaussian's tail reaches past 3 px


def _ci(v: float) -> dict:
    return {"speedup": v, "ci_low": v * 0.8, "ci_high": v * 1.25}


def test_the_report_names_each_turning_point_family_apart():
    env = {"path": "nrrt_star~0.5[oracle_path@s1]",
           "vertex": "vnrrt_star~0.9[oracle_vertex_endpoints@s4]",
           "taut_vertex": "vnrrt_star~0.9[oracle_taut_vertex@s4]",
           "masked_vertex": "m_vnrrt_star@0.5~0.95[oracle_vertex@s2]",
           "blend": "vnrrt_star~0.75[oracle_blend@w0.5@s1]"}  # fmt: skip
    ratios = {"vertex": 0.5, "taut_vertex": 0.2, "masked_vertex": 3.0, "blend": 1.0}
    summary = {
        "settings": {"eps": 0.01},
        "selection": {"envelopes": {"optimal": env}, "edges": {"optimal": {}}},
        "cells": [{"regime": "protocol", "stop": "optimal", "configuration": t,
                   "iterations": _ci(2.0 + i)} for i, t in enumerate(env.values())],
        "envelopes": [{"regime": "protocol", "stop": "optimal", "idea": i, "against": "path",
                       "iterations": _ci(v)} for i, v in ratios.items()],
        "cell_names": ["protocol"], "w0": {}, "networks": [], "curves": [],
        "regime_claims": [],
    }  # fmt: skip
    said = "\n".join(conclusion(summary))
    head = next(ln for ln in said.splitlines() if ln.startswith("Envelopes"))
    for i, idea in enumerate(env):
        assert f"{idea} {2.0 + i:.2f}x" in head, idea
    assert "A* path's vertices (the vertex envelope" in said
    assert "true turning points (the taut-vertex envelope" in said
    masked = next(ln for ln in said.splitlines() if "masked-vertex envelope" in ln)
    assert "needs fewer iterations than" in masked and "3.00x" in masked
    assert "Path envelope against taut_vertex envelope" in said
    table = envelope_table(summary, "optimal").splitlines()
    assert table[0].split(" | ")[1:6] == ["path", "vertex", "taut_vertex", "masked_vertex", "blend"]
    assert "masked_vertex / path" in table[0] and "3.00x" in table[2]


def _trials(key: str, source: str, iterations: list[int]) -> pd.DataFrame:
    """Protocol-cell trials of ``key`` (one per instance, 4 base maps, 2 instances each)."""
    n = len(iterations)
    return pd.DataFrame({"regime": "protocol", "stop": "optimal", "key": key, "source": source,
                         "instance": range(n), "cluster": [i // 2 for i in range(n)],
                         "trial": 0, "success": True, "iterations": iterations,
                         "time_to_stop": [i / 1e4 for i in iterations]})  # fmt: skip


def test_the_trained_m_vnrrt_is_read_against_the_masked_envelope_at_its_tau():
    masked = "m_vnrrt_star@0.5~0.9[oracle_vertex@s2]"
    envelopes = {"optimal": {"vertex": "vnrrt_star~0.9[oracle_vertex@s2]", "masked_vertex": masked}}
    table = pd.concat([
        _trials(envelopes["optimal"]["vertex"], "oracle_vertex@s2", [100] * 8),
        _trials(masked, "oracle_vertex@s2", [50] * 8),
        _trials("vnrrt_star", "vertexnet", [400] * 8),
        _trials("m_vnrrt_star@0.5", "vertexnet", [200] * 8),  # read against the masked one
        _trials("m_vnrrt_star@0.9", "vertexnet", [200] * 8),  # another tau: not read
        _trials("m_vnrrt_star@0.5{max}", "vertexnet", [200] * 8),  # a mask variant: not read
    ])  # fmt: skip
    rows = network_rows(table, envelopes, {"vertexnet": "vertex"}, (200, 0.95))
    got = {r["configuration"]: (r["idea"], r["iterations"]["speedup"]) for r in rows}
    assert got == {
        "vnrrt_star": ("vertex", pytest.approx(101 / 401)),
        "m_vnrrt_star@0.5": ("masked_vertex", pytest.approx(51 / 201)),
    }
