"""Every figure function returns the figure its docstring documents: panels in the paper's
order, readable titles and labels, one colour scale with a colour bar, obstacles black,
start and goal marked, log time axes that always carry labels, one shared legend. Checked
on the matplotlib objects (not on pixels), with expected names written out by hand."""

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest
from matplotlib.image import AxesImage

from vnrrt.data.build_named import build_named_maps
from vnrrt.data.config import LabelsConfig
from vnrrt.data.reader import Shard
from vnrrt.planners import plan
from vnrrt.viz.budget import budget_figure
from vnrrt.viz.evaluation import convergence_figure, heatmaps_figure, improvements_figure
from vnrrt.viz.ideas import quality_figure, regime_figure
from vnrrt.viz.maps import named_maps_figure
from vnrrt.viz.planners import plot_plan
from vnrrt.viz.training import prediction_figure

BLACK = (0.0, 0.0, 0.0, 1.0)
SPEEDUP = ("speedup", "ci_low", "ci_high")


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _grid(n=24):
    g = np.zeros((n, n), np.uint8)
    g[4:20, 12] = 1
    return g


def _obstacle_image(ax):
    """The panel's obstacle layer: an image whose value 1 is opaque black."""
    layers = [im for im in ax.get_images() if tuple(im.cmap(1.0)) == BLACK and im.cmap(0.0)[3] == 0]
    assert len(layers) == 1, ax.get_title()
    return layers[0]


def _marker_labels(ax):
    return {line.get_label() for line in ax.get_lines()}


def _visible_tick_labels(axis):
    """The non-empty major tick labels inside the axis's view limits."""
    axis.axes.figure.canvas.draw()
    lo, hi = sorted(axis.get_view_interval())
    ticks = zip(axis.get_majorticklocs(), axis.get_majorticklabels(), strict=True)
    return [t.get_text() for loc, t in ticks if lo <= loc <= hi and t.get_text()]


def test_fig3_columns_in_the_papers_order_on_one_colour_scale():
    g = _grid()
    path = np.array([[2, 2], [11, 2], [13, 21], [21, 21]])
    heat_v, heat_p = np.full((2, 24, 24), 0.1), np.full((2, 24, 24), 0.8)
    heat_v[:, 2, 11] = 1.0
    fig = heatmaps_figure(
        [g, g],
        [path, path],
        [path[1:-1], path[1:-1]],
        [(2, 2), (2, 2)],
        [(21, 21), (21, 21)],
        {"vertexnet": heat_v, "nrrtnet": heat_p},  # not the paper's order
        titles=["Map 1: open", "Map 2: cluttered"],
    )
    panels = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
    bars = [ax for ax in fig.axes if ax.get_label() == "<colorbar>"]
    assert len(panels) == 8 and len(bars) == 1
    titles = [ax.get_title() for ax in panels]
    assert titles[:4] == [
        "Map 1: open\n(a) optimal path",
        "(b) vertices",
        "(c) NRRT* network",
        "(d) VertexNet",
    ]
    assert titles[4] == "Map 2: cluttered\n(a) optimal path"
    assert "probability" in bars[0].get_ylabel()
    heat_images = [im for ax in panels for im in ax.get_images() if im is not _obstacle_image(ax)]
    assert len(heat_images) == 4  # columns (c) and (d) of both rows
    assert {(im.norm.vmin, im.norm.vmax) for im in heat_images} == {(0.0, 1.0)}
    assert len({im.cmap.name for im in heat_images}) == 1
    np.testing.assert_array_equal(heat_images[0].get_array(), heat_p[0])  # (c) is NRRT*
    for ax in panels:
        np.testing.assert_array_equal(_obstacle_image(ax).get_array(), g != 0)
        assert {"start", "goal"} <= _marker_labels(ax)


def test_fig4_named_maps_panels(tmp_path):
    build_named_maps(tmp_path / "named.npz", 200, LabelsConfig())
    shard = Shard(tmp_path / "named.npz")
    fig = named_maps_figure(shard)
    assert len(fig.axes) == 5
    titles = [ax.get_title().split("\n") for ax in fig.axes]
    assert [t[0] for t in titles] == [
        "Map 1: open",
        "Map 2: cluttered",
        "Map 3: narrow passage",
        "Map 4: u trap",
        "Map 5: maze",
    ]
    for i, (ax, t) in enumerate(zip(fig.axes, titles, strict=True)):
        assert t[1] == f"A* length {shard.instance(i)['length']:.1f} px"
        np.testing.assert_array_equal(_obstacle_image(ax).get_array(), shard.grid(i) != 0)
        assert {"optimal path", "vertices", "start", "goal"} <= _marker_labels(ax)


def _speedups(value):
    return {"speedup": value, "ci_low": value - 0.1, "ci_high": value + 0.2}


def test_fig5_bars_in_the_papers_order_with_display_names_and_explained_whiskers():
    keys = [
        "m_vnrrt_star@0.9",
        "vnrrt_star",
        "vnrrt_star+informed",
        "nrrt_star",
        "m_vnrrt_star@0.5",
    ]
    per_key = {k: {"map_1": _speedups(1.5), "random": _speedups(0.8)} for k in keys}
    fig = improvements_figure(per_key, "optimal", eps=0.05, level=0.9)  # a run's, not defaults
    (ax,) = fig.axes
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert legend == [
        "NRRT*",
        "VNRRT*",
        "M-VNRRT* τ=0.5",
        "M-VNRRT* τ=0.9",
    ]  # informed: own section
    assert [t.get_text() for t in ax.get_xticklabels()] == ["Map 1", "Random maps"]
    heights = sorted({round(p.get_height(), 6) for p in ax.patches})
    assert heights == [-20.0, 50.0]  # (speed-up - 1) in %
    assert "(%)" in ax.get_ylabel() and "within 5% of A*" in ax.get_title()
    caption = " ".join(t.get_text() for t in fig.texts)
    assert "whiskers: 90% CI" in caption


def _curves():
    rows = []
    factors = [2.0, 1.5, 1.2, 1.1, 1.05, 1.02]
    for stop in ("optimal", "optimal_any_angle"):
        for planner, scale in (("nrrt_star", 1.0), ("rrt_star", 1.2)):
            for i, f in enumerate(factors):
                # map_3 spans 3-9.6 ms (no power of ten inside), random maps three decades
                rows.append((stop, planner, "map_3", f, scale * (3 + i) * 1e-3))
                rows.append((stop, planner, "random", f, scale * 10.0 ** (i / 2 - 4)))
    return pd.DataFrame(rows, columns=["stop", "planner", "map_set", "factor", "median_time"])


def test_convergence_grid_names_ms_log_axes_with_labels_and_one_legend():
    curves = _curves()
    fig = convergence_figure(curves, {"map_3": "narrow_passage"})
    assert len(fig.axes) == 4  # 2 stop rules x 2 map sets
    titles = [ax.get_title() for ax in fig.axes]
    assert titles == ["Map 3: narrow passage", "Random maps"] * 2
    assert [ax.get_ylabel() for ax in fig.axes[::2]] == [
        "best cost / A* length",
        "best cost / exact optimum",
    ]
    for ax in fig.axes:
        assert ax.get_xscale() == "log" and ax.get_xlabel() == "median time (ms)"
        assert len(_visible_tick_labels(ax.xaxis)) >= 2, ax.get_title()
        assert ax.get_legend() is None
        x = np.concatenate([line.get_xdata() for line in ax.get_lines()])
        assert x.min() >= 0.1 - 1e-9  # milliseconds, not seconds
    (legend,) = fig.legends
    assert [t.get_text() for t in legend.get_texts()] == ["RRT*", "NRRT*"]


def test_quality_curve_one_panel_per_stop_with_networks_as_stars():
    rows = []
    for stop in ("optimal", "optimal_any_angle"):
        members = (("path", "nrrt_star", True), ("vertex", "vnrrt_star", True),
                   ("path", "nrrt_star~0.5", False))  # the last: another stop rule's  # fmt: skip
        for idea, member, own in members:
            for q, x in ((1.0, 30.0), (0.1, 4.0), (0.0, 1.0)):  # mass x a uniform map's
                s = 1 + x / 3
                conf = f"{member}@q{q:g}"  # stands for the diluted envelope's key text
                rows.append((stop, idea, conf, member, own, q, x, "iterations", s, s * 0.9,
                             s * 1.1))  # fmt: skip
    columns = ["stop", "idea", "configuration", "member", "own", "q", "x_uniform", "metric"]
    curves = pd.DataFrame(rows, columns=[*columns, *SPEEDUP])
    nets = pd.DataFrame(
        [
            ("optimal", "vnrrt_star[vertexnet]", "iterations", 2.5, 1.3, 1.1, 1.5),
            ("optimal", "m_vnrrt_star@0.5[vertexnet]", "iterations", 2.5, 1.31, 1.1, 1.5),
            ("optimal", "vnrrt_star[vertexnet]+informed", "iterations", 2.5, 6.0, 5.0, 7.0),
        ],
        columns=["stop", "configuration", "metric", "x_uniform", *SPEEDUP],
    )
    fig = quality_figure(curves, nets, {"eps": 0.02, "level": 0.8, "radius": 2.0})
    panels = fig.axes
    assert [ax.get_title() for ax in panels] == [
        "within 2% of A*",
        "within 2% of the exact optimum",
    ]
    for ax in panels:
        assert ax.get_xscale() == ax.get_yscale() == "log"
        assert "mass within 2 px" in ax.get_xlabel() and "x a uniform map's" in ax.get_xlabel()
    assert "speed-up over RRT*" in panels[0].get_ylabel()
    for ax in panels:  # one curve per envelope of the panel's own stop rule, its q joined
        assert [t.get_text() for t in ax.get_legend().get_texts()] == [
            "NRRT*, path envelope",
            "VNRRT*, vertex envelope",
        ]
        drawn = [line for line in ax.get_lines() if line.get_marker() == "o"]
        assert [len(line.get_xdata()) for line in drawn] == [3, 3]
        assert [line.get_color() for line in drawn] == ["C0", "C1"]  # path, vertex
    stars = [line for line in panels[0].get_lines() if line.get_marker() == "*"]
    # the informed network is not placed on curves of plain samplers
    assert [(s.get_xdata()[0], s.get_ydata()[0]) for s in stars] == [(2.5, 1.3), (2.5, 1.31)]
    assert not [line for line in panels[1].get_lines() if line.get_marker() == "*"]
    labels = {t.get_text(): t for t in panels[0].texts}
    assert set(labels) == {"VNRRT* [vertexnet]", "M-VNRRT* τ=0.5 [vertexnet]"}
    offsets = {t.xyann[1] for t in labels.values()}
    assert len(offsets) == 2  # two stars at one place: their labels stacked, not overlaid
    assert "whiskers: 80% CI" in fig._suptitle.get_text()


def test_regime_heatmap_cells_colour_bar_and_significance_marks():
    cells = pd.DataFrame(
        [
            ("eta=5", "nrrt_star", 4.0, 3.0, 5.0),
            ("eta=5", "vnrrt_star", 0.5, 0.3, 0.9),
            ("eta=20", "nrrt_star", 2.0, 0.9, 3.0),
            ("eta=20", "vnrrt_star", 1.0, 0.8, 1.3),
            ("eta=20", "vnrrt_star@q0.5", 1.1, 0.8, 1.3),  # one cell's extra: not a column
        ],
        columns=["regime", "configuration", "speedup", "ci_low", "ci_high"],
    ).assign(stop="optimal")
    fig = regime_figure(cells, "optimal", {"eps": 0.05, "level": 0.9})
    ax, bar = fig.axes
    assert "within 5% of A*" in ax.get_title() and "90% CI" in ax.get_title()
    assert "log2 speed-up" in bar.get_ylabel()
    (image,) = [c for c in ax.get_children() if isinstance(c, AxesImage)]
    np.testing.assert_allclose(image.get_array(), [[2.0, -1.0], [1.0, 0.0]])
    assert [t.get_text() for t in ax.texts] == ["4.00*", "0.50*", "2.00", "1.00"]
    assert [t.get_text() for t in ax.get_xticklabels()] == ["NRRT*", "VNRRT*"]
    assert [t.get_text() for t in ax.get_yticklabels()] == ["eta=5", "eta=20"]


def _budget_summary() -> dict:
    """A summary of two budgets (:mod:`vnrrt.studies.training_budget.summary`'s shape)."""
    keys, ratio_keys = (
        ["rrt_star", "nrrt_star", "vnrrt_star", "m_vnrrt_star@0.6"],
        ["vnrrt_star", "m_vnrrt_star@0.6"],
    )
    stops = ["initial", "optimal"]

    def cell(v):
        return {"speedup": v, "ci_low": v * 0.8, "ci_high": v * 1.25}

    budgets = []
    for images, grow in ((4800, 1.0), (38400, 1.5)):
        over = {
            s: {"iterations": {k: cell(grow * (j + 1)) for j, k in enumerate(keys[1:])}}
            for s in stops
        }
        ratios = {s: {"iterations": {k: cell(grow) for k in ratio_keys}} for s in stops}
        nets = {
            n: {
                "heatmap": {
                    "mass_near_interior": {"ratio": 2.0 * grow},
                    "mass_near_path": {"ratio": 5.0},
                }
            }
            for n in ("vertexnet", "nrrtnet")
        }
        budgets.append({"images": images, "speedups": over, "ratios": ratios, "networks": nets})
    settings = {
        "keys": keys,
        "ratio_keys": ratio_keys,
        "stops": stops,
        "eps": 0.02,
        "level": 0.8,
        "train_seed": 1,
        "heatmap": {"radius": 2.0},
    }
    return {"settings": settings, "budgets": budgets, "metrics": ["iterations"]}


def test_budget_figure_lines_per_planner_and_stop_with_bands_and_masses():
    fig = budget_figure(_budget_summary(), "iterations")
    shown = [ax for ax in fig.axes if ax.get_visible()]
    assert [ax.get_title() for ax in shown] == [
        "over RRT*, initial solution",
        "over RRT*, within 2% of A*",
        "VNRRT* / NRRT* (paired)",
        "M-VNRRT* τ=0.6 / NRRT* (paired)",
        "heatmap mass within 2 px, x a uniform map's",
    ]
    for ax in shown:
        assert ax.get_xscale() == ax.get_yscale() == "log" and ax.get_xlabel() == (
            "training images seen"
        )
        assert _visible_tick_labels(ax.xaxis) == ["4,800", "38,400"]
    planners = shown[0]
    assert [line.get_label() for line in planners.get_lines()[:3]] == [
        "NRRT*",
        "VNRRT*",
        "M-VNRRT* τ=0.6",
    ]
    assert len(planners.collections) == 3  # a CI band per line
    np.testing.assert_allclose(planners.get_lines()[1].get_ydata(), [2.0, 3.0])
    assert [line.get_label() for line in shown[2].get_lines()[:2]] == [
        "initial solution",
        "within 2% of A*",
    ]
    masses = [line.get_label() for line in shown[4].get_lines()]
    assert masses == [
        "vertexnet: near the interior vertices",
        "vertexnet: near the path",
        "nrrtnet: near the interior vertices",
        "nrrtnet: near the path",
    ]
    assert "80% CI" in fig._suptitle.get_text() and "training seeds 1" in fig._suptitle.get_text()


def test_validation_figure_rows_and_colour_bars():
    k, n = 2, 16
    rgb = np.zeros((k, n, n, 3))
    target = np.zeros((k, n, n))
    target[:, 3, 4] = 1
    probs = np.random.default_rng(0).random((k, n, n))
    fig = prediction_figure(rgb, target, target, probs)
    bars = [ax for ax in fig.axes if ax.get_label() == "<colorbar>"]
    panels = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
    assert len(panels) == 3 * k and len(bars) == k
    assert [ax.get_title() for ax in panels[:3]] == [
        "input",
        "ground truth",
        f"predicted (max {probs[0].max():.2f})",
    ]


def test_a_plan_panel_draws_tree_path_and_endpoints():
    g = _grid()
    result = plan(g, (2.5, 2.5), (21.5, 21.5), "rrt_star", seed=0, keep_tree=True)
    _, ax = plt.subplots()
    plot_plan(ax, g, result, (2.5, 2.5), (21.5, 21.5))
    assert ax.get_title().startswith("RRT*: cost")
    assert len(ax.collections) == 1  # the tree
    assert len(ax.collections[0].get_segments()) == result.tree_size - 1
    np.testing.assert_array_equal(ax.get_lines()[0].get_xydata(), result.path)
    assert {"start", "goal"} <= _marker_labels(ax)
    np.testing.assert_array_equal(_obstacle_image(ax).get_array(), g != 0)
