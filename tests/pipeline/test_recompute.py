"""The committed CPU-scale results bundle (reports/cpu/results, made by an earlier version of
the pipeline, with that run's folders in its params.yaml) recomputes the committed reports
byte for byte with this code: the reports in git are what the code makes of the tables."""

import pytest

from tests.conftest import REPO
from vnrrt.pipeline.recompute import recompute

CPU = REPO / "reports" / "cpu"


@pytest.mark.slow
def test_the_committed_bundle_recomputes_the_committed_cpu_reports(tmp_path):
    recompute(CPU / "results", tmp_path)
    for made, again in (
        ("paper_comparison.md", "paper_comparison.md"),
        ("sampling_ideas.md", "sampling_ideas.md"),
        ("metrics/headline.json", "headline.json"),
    ):
        assert (CPU / made).read_bytes() == (tmp_path / again).read_bytes(), made
