"""Reports as MLflow artifacts (vnrrt.tracking.report_artifacts), the MLflow names of the study
(vnrrt.names slugs, the evaluation run's claim keys) and the lineage helpers
(vnrrt.tracking.lineage):
figures logged under the paths a report uses, links swapped for UI links, the HTML with its
figures inline, DVC's hash as a dataset digest."""

import base64
import hashlib
import re
from pathlib import Path

import pytest
from mlflow import MlflowClient

from vnrrt.names import map_set_slug, stop_slug
from vnrrt.studies.paper_comparison.run_text import claim_key, planner_key
from vnrrt.tracking import lineage
from vnrrt.tracking.report_artifacts import figure_paths, log_report, to_html, with_links

PNG = base64.b64decode(
    "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mNk+M9QDwADhgGAWjR9awAAAABJRU5ErkJggg=="
)
TEXT = """# A report

See [the other report](other.md) and [a site](https://example.org).

| a | b |
| --- | --- |
| 1 | 2 |

![curve](figures/x/curve.png)
![remote](https://example.org/a.png)
"""


def write_report(tmp_path):
    (tmp_path / "figures" / "x").mkdir(parents=True)
    (tmp_path / "figures" / "x" / "curve.png").write_bytes(PNG)
    report = tmp_path / "report.md"
    report.write_text(TEXT)
    return report


def test_figures_are_the_local_images_and_only_listed_links_change():
    assert figure_paths(TEXT) == ["figures/x/curve.png"]
    swapped = with_links(TEXT, {"other.md": "#/experiments/1/runs/abc/artifacts/other.md"})
    assert "[the other report](#/experiments/1/runs/abc/artifacts/other.md)" in swapped
    assert "[a site](https://example.org)" in swapped and "![curve](figures/x/curve.png)" in swapped


def test_the_html_has_the_table_and_the_figure_inline(tmp_path):
    report = write_report(tmp_path)
    page = to_html(report.read_text(), tmp_path, "report")
    assert "<table>" in page and "<td>2</td>" in page
    (src,) = re.findall(r'<img src="(data:image/png;base64,[^"]+)"', page)
    assert base64.b64decode(src.split(",", 1)[1]) == PNG
    assert '<img src="https://example.org/a.png"' in page  # a URL stays a URL


def test_a_logged_report_has_its_figures_under_the_paths_it_uses(tmp_path):
    report = write_report(tmp_path)
    client = MlflowClient(f"sqlite:///{tmp_path / 'mlflow.db'}")
    exp = client.create_experiment("e", artifact_location=(tmp_path / "art").as_uri())
    run = client.create_run(exp).info.run_id
    written = log_report(client, run, report, {"other.md": "#/x"})
    assert written == ["figures/x/curve.png", "report.md", "report.html"]
    listed = {a.path for a in client.list_artifacts(run, "figures/x")}
    assert listed == {"figures/x/curve.png"}
    logged = client.download_artifacts(run, "report.md", str(tmp_path / "down"))
    assert "[the other report](#/x)" in Path(logged).read_text()
    (tmp_path / "figures" / "x" / "curve.png").unlink()
    with pytest.raises(FileNotFoundError, match="shows figures/x/curve.png"):
        log_report(client, run, report)


def test_a_file_dataset_digest_is_the_md5_dvc_records(tmp_path):
    f = tmp_path / "instances.npz"
    f.write_bytes(b"some bytes" * 1000)
    dataset = lineage.file_dataset(f, "instances")
    assert dataset.digest == hashlib.md5(f.read_bytes()).hexdigest() and dataset.name == "instances"
    assert dataset.source.to_dict() == {"uri": str(f.resolve())}


def test_metric_name_parts_say_map_set_stop_rule_and_planner():
    assert stop_slug("optimal", 0.01) == "within_1pct_of_astar"
    assert stop_slug("optimal_any_angle", 0.005) == "within_0.5pct_of_exact_optimum"
    assert stop_slug("initial", 0.05) == "initial_solution"
    assert (map_set_slug("random"), map_set_slug("map_3")) == ("random_maps", "map_3")
    assert planner_key("m_vnrrt_star@0.5{max}") == "m_vnrrt_star_tau0.5_max"
    assert planner_key("nrrt_star+informed") == "nrrt_star_informed"
    row = {"table": "optimal_time", "column": "map_3", "planner": "m_vnrrt_star@0.5",
           "baseline": "nrrt_star"}  # fmt: skip
    assert claim_key(row) == "optimal_time.map_3.m_vnrrt_star_tau0.5_vs_nrrt_star"


def test_ui_links_are_relative_to_the_page():
    assert lineage.run_link("3", "abc") == "#/experiments/3/runs/abc"
    assert lineage.model_version_link("models:/vnrrt-vertexnet/2") == (
        "#/models/vnrrt-vertexnet/versions/2"
    )
    assert lineage.artifact_url("abc", "figures/a b.png") == (
        "get-artifact?path=figures%2Fa+b.png&run_uuid=abc"
    )
