"""The report renderer on a synthetic trial table: censored cells, fallbacks, comparability,
the paper's rows, display names and plain-text cells."""

import numpy as np
import pandas as pd
import yaml

from vnrrt.evaluation.config import StatsConfig
from vnrrt.evaluation.table import COLUMNS, conform
from vnrrt.studies.paper_comparison.networks_report import MetricSettings, networks_section
from vnrrt.studies.paper_comparison.paper_noise import ratio_interval
from vnrrt.studies.paper_comparison.report import ReportInputs, build_report
from vnrrt.studies.paper_comparison.summary import analyze
from vnrrt.studies.paper_comparison.tables import cell
from vnrrt.studies.paper_tables import load_paper_tables

METRICS = MetricSettings(radius=3.0, tau=0.5, ap_radius=1.0, endpoint_radius=3.0)


def synthetic_trials() -> pd.DataFrame:
    """NRRT* takes ~2x as long as VNRRT*; M-VNRRT* fails every 4th trial at a 5 s budget and
    falls back to uniform sampling on two; map_1 and 20 random instances of 10 maps."""
    rng = np.random.default_rng(1)
    rows = []
    configs = [
        ("rrt_star", np.nan, "", 3.0),
        ("nrrt_star", np.nan, "nrrtnet", 2.0),
        ("vnrrt_star", np.nan, "vertexnet", 1.0),
        ("m_vnrrt_star", 0.5, "vertexnet", 1.0),
    ]
    seq = 0
    for stop in ("initial", "optimal"):
        for planner, tau, source, scale in configs:
            key = planner if tau != tau else f"{planner}@{tau:g}"
            for inst in range(21):
                map_set = "map_1" if inst == 0 else "random"
                for trial in range(8 if inst == 0 else 1):
                    t = scale * rng.uniform(0.5, 1.5) * 1e-3
                    fail = planner == "m_vnrrt_star" and (trial + inst) % 4 == 0
                    rows.append(
                        dict.fromkeys(COLUMNS, np.nan)
                        | dict(
                            seq=seq,
                            instance=inst,
                            map_set=map_set,
                            map=f"m{inst}",
                            cluster=(inst - 1) // 2,
                            key=key,
                            planner=planner,
                            tau=tau,
                            source=source,
                            stop=stop,
                            trial=trial,
                            seed=trial,
                            success=not fail,
                            stop_reason="max_seconds" if fail else "solved",
                            fallback_uniform=planner == "m_vnrrt_star" and inst == 3,
                            reference_length=100.0,
                            cost=100 + t,
                            iterations=int(1e6 * t),
                            tree_size=500,
                            collision_checks=900,
                            time_to_first=t / 10,
                            time_to_stop=5.0 if fail else t,
                            setup_time=1e-4,
                        )
                    )
                    seq += 1
    return conform(pd.DataFrame(rows), "synthetic")


def test_cells_show_censoring_and_fallbacks():
    s = {
        "n": 10,
        "successes": 7,
        "budget_hits": 3,
        "fallbacks": 2,
        "mean": 1.5,
        "std": 0.5,
        "median": 1.0,
        "ci_low": 1.0,
        "ci_high": 2.0,
        "censored": True,
        "median_exact": True,
    }
    assert cell(s) == "1 (>=1.5±0.5) 7/10, fallback 2"
    assert cell({**s, "median_exact": False}).startswith(">=1 ")
    assert cell(None) == "—"
    assert cell({**s, "mean": float("nan")}) == "no success (0/10)"


def test_report_on_a_synthetic_table(repo):
    paper = load_paper_tables(repo / "data/paper/tables.yaml")
    st = StatsConfig(bootstrap=300, level=0.95)
    turns = {i: i % 5 for i in range(21)}  # random 1..20: 4 of 0, 8 of 1-2, 8 of 3+
    summary = analyze(synthetic_trials(), paper, 0.01, st, {"vertexnet": 15.0, "nrrtnet": 14.0},
                      turns)  # fmt: skip
    assert summary["strata"]["random"] == {"line of sight": 4, "1-2 turns": 8, "3+ turns": 8}
    optima = {"map_1": {"astar": 110.0, "exact": 100.0, "taut": 101.0}}
    settings = yaml.safe_load((repo / "data/paper/settings.yaml").read_text())
    values = {e["key"]: 0.5 for e in settings["settings"] if e.get("key")}
    trainings = {"vertexnet": {"steps": 10, "batch_size": 8, "train_images": 80,
                               "fit_seconds": 60.0, "network": {"encoder": "resnet18",
                               "params_total": 1234, "weights": "none"}}}  # fmt: skip
    text = build_report(
        ReportInputs(
            summary,
            paper,
            optima,
            {"nrrt_star": "nrrtnet", "vnrrt_star": "vertexnet", "m_vnrrt_star@0.5": "vertexnet"},
            "synthetic",
            {},
            METRICS,
            settings,
            values,
            trainings,
        )
    )
    assert "| NRRT* | paper | 36.48±37.57" in text and "<br>" not in text
    assert "fallback" in text and ">=" in text  # M-VNRRT*'s censored failures are shown
    line = next(
        ln
        for ln in text.splitlines()
        if ln.startswith("| VNRRT* converges to optimal paths 76.82%")
    )
    assert "different map" not in line  # random maps are comparable
    assert "same direction" in line or "reproduced" in line  # ours: ~2x, paper 1.77x
    level = summary["claims"]["corrected_level"]  # Bonferroni over the claims with data
    iv = ratio_interval((19.38, 62.62, 100), (10.96, 62.67, 100), level)  # Table 3, random
    assert f"[{iv.low:+.1%}, {iv.high:+.1%}] (n.s.)" in line  # the paper's own interval
    assert "compatible with the paper's data" in line
    assert "| heatmap draw probability | 0.5 (`planner.mix`)" in text
    assert "| vertexnet (synthetic) | resnet18 U-Net" in text and "from scratch" in text
    map3 = next(ln for ln in text.splitlines() if "on Map 3" in ln)
    assert "no data" in map3  # no map_3 in this table
    assert "| ours: exact continuous optimum | 100 |" in text
    inference = next(ln for ln in text.splitlines() if ln.startswith("| VNRRT* | optimal |"))
    assert "| 15 |" in inference  # VertexNet's inference per map beside its planning time
    rows = {
        r["planner"]: r
        for r in summary["claims"]["rows"]
        if r["table"] == "optimal_time" and r["column"] == "random" and r["baseline"] == "nrrt_star"
    }
    vn = rows["vnrrt_star"]["time_to_stop"]
    assert 1.6 < vn["speedup"] < 2.4 and vn["instances"] == 20 and vn["clusters"] == 10
    per = rows["vnrrt_star"]["strata"]
    assert [per[n]["instances"] for n in ("line of sight", "1-2 turns", "3+ turns")] == [4, 8, 8]
    assert "### The claims per turning-point stratum" in text
    assert "| 3+ turns | 0 | 8 |" in text  # the mix: map_1 (0 turns) and the random maps
    assert "The paper's mix is unknown for its random maps" in text
    assert "### Each claim under both estimands" in text and "robustness" in text
    assert "paired, correlation 0.9" in text


def test_networks_table_shows_shares_and_multiples_of_uniform():
    m = {"test/interior_recall": 0.25, "test/interior_ap": 0.12,
         "test/mass_near_interior": 0.2, "test/mass_near_interior_uniform": 0.01,
         "test/mass_near_interior_tau0_9": 0.05}  # fmt: skip
    text = "\n".join(networks_section({"vertexnet": m}, METRICS))
    row = next(ln for ln in text.splitlines() if ln.startswith("| vertexnet | test |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[2:5] == ["0.25", "0.12", "—"]
    assert cells[5] == "0.2 (20.0x)" and cells[-1] == "0.05 (5.0x)"
    assert "tau 0.9 mask" in text and networks_section({}, METRICS) == []
