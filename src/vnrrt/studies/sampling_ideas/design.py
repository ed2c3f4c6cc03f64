"""What the sampling-ideas study runs (settings in :mod:`vnrrt.evaluation.config`: ``oracle``,
``regime``).

* **Instances.** The first ``oracle.random_maps`` random test instances, split by base map
  (:func:`split_instances`): ``oracle.selection_share`` of the maps select, the others
  evaluate; no base map is in both.
* **Selection** (stage ``oracle@<k>``): on the selection instances, RRT* and every member of
  every oracle family (:func:`family_members`): each target of ``oracle.families`` at each blur
  of ``oracle.sigmas`` and heatmap-draw probability of ``oracle.mixes``, and the path-vertex
  blend (:func:`vnrrt.evaluation.oracles.blend`) at each ``oracle.blend_weights`` x blur x
  mix, each sampled by its family's planner (``oracle.planners``: NRRT* the path oracles,
  M-VNRRT* at ``planner.tau`` the masked-vertex ones, a perfect M-VNRRT* heatmap; VNRRT* the
  others); every stop rule, ``oracle.trials`` trials each. Each
  family's best member per stop rule (the most RRT* iterations saved,
  :func:`vnrrt.studies.sampling_ideas.selection.select`) is its **envelope**. With
  ``oracle.per_cell`` the selection also runs in every other regime cell (the optimal stop
  rules; :func:`selection_cells`), and each cell's own envelopes run in that cell
  (:mod:`vnrrt.studies.sampling_ideas.per_cell`).
* **Evaluation** (stage ``regime@<k>``): on the evaluation instances, in the protocol's cell
  and in every other cell of ``regime.etas x`` radius rules ``x regime.goal_radii``
  (:func:`regime_cells`; one with the protocol's own settings is the protocol's): RRT*,
  ``regime.configurations`` (the trained networks), every envelope and the blend at every
  weight (at the blend envelope's blur and mix); the
  protocol's cell also runs the quality curve (each path and vertex envelope diluted to signal
  fraction ``oracle.qualities``, :func:`vnrrt.evaluation.oracles.dilute`) and every
  configuration under the other obstacle rule (``+free``).
"""

from __future__ import annotations

import math

import numpy as np

from vnrrt.evaluation.config import (
    BLEND_IDEA,
    Configurations,
    OracleConfig,
    RegimeConfig,
    RegimeGrid,
)
from vnrrt.evaluation.keys import ConfigKey
from vnrrt.evaluation.oracles import BLEND, OracleSource
from vnrrt.evaluation.protocol import STOPS
from vnrrt.studies.sampling_ideas.distinct import cell_key

PROTOCOL = "protocol"  # the regime cell of the protocol's own planner settings
QUALITY_IDEAS = ("path", "vertex")  # the families of the quality curve
MASKED_IDEA = "masked_vertex"  # the family a perfect M-VNRRT* heatmap is (oracle.planners)


def split_instances(
    instances: list[int], clusters: list[int], share: float, seed: int
) -> tuple[list[int], list[int]]:
    """``(selection, evaluation)`` instances: the base maps (``clusters[i]`` of instance
    ``instances[i]``) shuffled with ``seed``, the first ``share`` of them (at least one, at
    most all but one) select."""
    maps = sorted(set(clusters))
    if len(maps) < 2:
        raise ValueError(f"the oracle study needs instances of 2 base maps or more, got {maps}")
    order = np.random.default_rng([seed, 0x5E1EC7]).permutation(len(maps))
    n = min(max(1, round(share * len(maps))), len(maps) - 1)
    chosen = {maps[i] for i in order[:n]}
    sel = [i for i, c in zip(instances, clusters, strict=True) if c in chosen]
    ev = [i for i, c in zip(instances, clusters, strict=True) if c not in chosen]
    return sel, ev


def member(planner: str, source: OracleSource, mix: float, tau: float) -> ConfigKey:
    """The configuration in which ``planner`` samples oracle ``source`` with heatmap-draw
    probability ``mix``; M-VNRRT* masks it below ``tau`` (an oracle's maximum is 1, so tau
    reads as on a perfect network's probabilities, and as the ``max`` mask variant)."""
    key = ConfigKey(planner, tau=float(tau) if planner == "m_vnrrt_star" else None, mix=mix)
    return key.with_source(source.text)


def family_members(oc: OracleConfig, tau: float) -> dict[str, list[ConfigKey]]:
    """``{idea: members}``: every family of ``oracle.families`` and the ``blend`` (module
    doc), in a fixed order, each sampled by its planner (``oracle.planners``; ``tau``:
    ``planner.tau``, M-VNRRT*'s threshold)."""
    out = {}
    for idea, kinds in oc.families.items():
        p, grid = oc.planner_of(idea), [(s, m) for s in oc.sigmas for m in oc.mixes]
        out[idea] = [member(p, OracleSource(k, s), m, tau) for k in kinds for s, m in grid]
    p = oc.planner_of(BLEND_IDEA)
    out[BLEND_IDEA] = [
        member(p, OracleSource(BLEND, s, w=w), m, tau)
        for w in oc.blend_weights
        for s in oc.sigmas
        for m in oc.mixes
    ]
    return out


def selection_keys(oc: OracleConfig, tau: float) -> list[ConfigKey]:
    """RRT* and every family member (module doc; ``tau``: ``planner.tau``), each once."""
    keys = [ConfigKey("rrt_star")]
    for members in family_members(oc, tau).values():
        keys += members
    return list(dict.fromkeys(keys))


def idea_of(key: ConfigKey, oc: OracleConfig) -> str | None:
    """The family a configuration's oracle belongs to: the one holding its oracle kind and
    sampled by its planner (``blend`` for the blend; None for networks and RRT*)."""
    if not key.named_source or not key.source.startswith("oracle_"):
        return None
    kind = OracleSource.parse(key.source).kind
    if kind == BLEND:
        return BLEND_IDEA
    found = (i for i, kinds in oc.families.items() if kind in kinds)
    return next((i for i in found if oc.planner_of(i) == key.planner), None)


def blend_at(key: ConfigKey, w: float) -> ConfigKey:
    """The blend configuration ``key`` at weight ``w`` (same blur and mix)."""
    o = OracleSource.parse(key.source)
    return key.with_source(OracleSource(BLEND, o.sigma, o.q, w).text)


def diluted(key: ConfigKey, q: float) -> ConfigKey:
    """An oracle configuration ``key`` at signal fraction ``q`` (the quality curve)."""
    o = OracleSource.parse(key.source)
    return key.with_source(OracleSource(o.kind, o.sigma, q, o.w).text)


def evaluation_keys(envelopes: dict, oc: OracleConfig, rc: RegimeConfig, ev: Configurations,
                    protocol: dict, own: dict | None = None) -> dict[str, list]:  # fmt: skip
    """``{cell: keys}`` of the evaluation (module doc); ``envelopes``: ``{stop: {idea: key
    text}}`` (:func:`vnrrt.studies.sampling_ideas.selection.select`); ``protocol``: the
    protocol cell's settings (:func:`protocol_settings`); ``own``: ``{cell: envelopes}``, the
    envelopes selected in each other cell (``oracle.per_cell``), run in that cell too."""
    chosen = list(
        dict.fromkeys(ConfigKey.parse(t) for per in envelopes.values() for t in per.values())
    )
    blends = [k for k in chosen if idea_of(k, oc) == BLEND_IDEA]
    blends = [blend_at(k, w) for k in blends for w in oc.blend_weights]
    base = [ConfigKey("rrt_star"), *(ConfigKey.parse(t, ev.sources) for t in rc.configurations)]
    every = list(dict.fromkeys([*base, *chosen, *blends]))
    quality = [
        diluted(k, q)
        for k in chosen
        if idea_of(k, oc) in QUALITY_IDEAS
        for q in oc.qualities
        if q != 1.0
    ]
    flipped = [k.with_free(not ev.zero_obstacles) for k in [*base, *chosen]]
    cells = {PROTOCOL: list(dict.fromkeys([*every, *quality, *flipped]))}
    for label in regime_cells(rc, protocol):
        mine = [
            ConfigKey.parse(t) for per in (own or {}).get(label, {}).values() for t in per.values()
        ]
        cells[label] = list(dict.fromkeys([*every, *mine]))
    return cells


SELECTED_HERE = ""  # the selection table's label of the protocol's cell (its first selection)


def selection_cells(oc: OracleConfig, grid: RegimeGrid | None, protocol: dict) -> dict:
    """``{label: planner overrides}`` of the cells the selection runs in: the protocol's
    (:data:`SELECTED_HERE`, no override) and, with ``oracle.per_cell``, every other regime cell
    of ``grid`` (:func:`regime_cells`, distinct settings only)."""
    cells: dict[str, dict] = {SELECTED_HERE: {}}
    if oc.per_cell:
        if grid is None:
            raise ValueError("oracle.per_cell needs the regime cells (regime.etas, ...)")
        cells |= regime_cells(grid, protocol)
    return cells


def oracle_counts(oc: OracleConfig, cell: str = SELECTED_HERE) -> dict[tuple[str, str], int]:
    """Trials per selection instance: every stop rule in the protocol's cell, the optimal ones
    in the others (as :func:`evaluation_counts`)."""
    stops = STOPS if cell == SELECTED_HERE else ("optimal", "optimal_any_angle")
    return {("random", stop): oc.trials for stop in stops}


def evaluation_counts(rc: RegimeConfig, cell: str) -> dict[tuple[str, str], int]:
    """Trials per evaluation instance: every stop rule in the protocol's cell, the two
    optimal ones in the others."""
    stops = STOPS if cell == PROTOCOL else ("optimal", "optimal_any_angle")
    return {("random", stop): rc.trials for stop in stops}


def radius_rules(rc: RegimeGrid) -> list[tuple[str, dict]]:
    """``(label, planner overrides)`` of each near-radius rule: ``shrinking`` at every
    ``regime.gamma_factors`` (``shrinking*0.1``), ``fixedK`` (K x eta)."""
    out = []
    for mode in rc.radius_modes:
        if mode == "shrinking":
            out += [
                (
                    "shrinking" if g == 1.0 else f"shrinking*{g:g}",
                    {"radius_mode": "shrinking", "gamma_factor": float(g)},
                )
                for g in rc.gamma_factors
            ]
        else:
            out.append((mode, {"radius_mode": "fixed", "fixed_factor": int(mode[len("fixed") :])}))
    return out


CELL_SETTINGS = ("eta", "radius_mode", "gamma_factor", "fixed_radius", "goal_radius")
"""The planner settings a regime cell overrides (``planner.<name>``)."""


def protocol_settings(planner) -> dict:
    """``{name: value}`` of :data:`CELL_SETTINGS` in ``planner`` (a
    :class:`~vnrrt.planners.config.PlannerConfig` or the config's ``planner`` section): the
    protocol's cell."""
    return {k: getattr(planner, k) for k in CELL_SETTINGS}


def regime_cells(rc: RegimeGrid, protocol: dict) -> dict[str, dict]:
    """``{label: planner overrides}`` of every cell besides the protocol's, e.g.
    ``eta=5 radius=shrinking*0.1 goal=inf``: ``{"eta": 5.0, "radius_mode": "shrinking",
    "gamma_factor": 0.1, "goal_radius": inf}``. Left out: an unlimited step with a fixed
    radius (every node near), and the cell whose overrides all equal ``protocol``'s settings
    (:func:`protocol_settings`), and a cell whose effective settings
    (:func:`~vnrrt.studies.sampling_ideas.distinct.cell_key`: the goal radius is moot at an
    unlimited step) equal the protocol's or an earlier cell's: it would repeat those runs
    exactly (the same seeds; the study's counts would count that setting twice)."""
    cells, seen = {}, {cell_key(protocol)}
    for eta in rc.etas:
        for name, rule in radius_rules(rc):
            over = dict(rule)
            if "fixed_factor" in over:
                if math.isinf(eta):
                    continue
                over["fixed_radius"] = float(eta) * over.pop("fixed_factor")
            for goal in rc.goal_radii:
                goal_label = "eta" if goal is None else f"{goal:g}"
                g = None if goal is None else float(goal)
                cell = {"eta": float(eta), "goal_radius": g, **over}
                if cell_key(cell) not in seen:
                    seen.add(cell_key(cell))
                    cells[f"eta={eta:g} radius={name} goal={goal_label}"] = cell
    return cells


def cell_of_label(label: str) -> dict:
    """The overrides of a regime cell from its label (:func:`regime_cells`' form, e.g.
    ``eta=5 radius=shrinking*0.5 goal=inf``); ``ValueError`` naming a label of another form."""
    try:
        parts = dict(item.split("=", 1) for item in label.split(" "))
        eta, name, goal = float(parts["eta"]), parts["radius"], parts["goal"]
    except (KeyError, ValueError):
        raise ValueError(f"{label!r} is not a regime cell label (eta= radius= goal=)") from None
    cell = {"eta": eta, "goal_radius": None if goal == "eta" else float(goal)}
    if name.startswith("fixed"):
        return cell | {"radius_mode": "fixed", "fixed_radius": eta * int(name[len("fixed") :])}
    factor = float(name.split("*")[1]) if "*" in name else 1.0
    return cell | {"radius_mode": "shrinking", "gamma_factor": factor}
