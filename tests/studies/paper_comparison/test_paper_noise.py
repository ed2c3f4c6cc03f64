"""The paper's own intervals: the delta method against a parametric simulation (an independent
computation) and against a case with a known answer; the paper's claims from its tables."""

import math

import pytest

from vnrrt.studies.paper_comparison.paper_noise import (
    claim_interval,
    ratio_interval,
    simulated_interval,
)
from vnrrt.studies.paper_tables import load_paper_tables


def test_a_precise_ratio_has_a_narrow_interval_around_it():
    iv = ratio_interval((20.0, 1.0, 10_000), (10.0, 0.5, 10_000), 0.95)
    assert iv.improvement == pytest.approx(1.0)
    assert 0.99 < iv.low + 1 < 2.0 < iv.high + 1 < 2.01 and iv.significant


def test_the_known_answer_of_the_log_ratio():
    """se(log R)^2 = (s_b/m_b)^2/n_b + (s_p/m_p)^2/n_p: with CVs 1 and n 100 each,
    se = sqrt(0.02), so the 95% interval of R is 2 exp(+-1.95996 sqrt(0.02))."""
    iv = ratio_interval((4.0, 4.0, 100), (2.0, 2.0, 100), 0.95)
    half = 1.959964 * math.sqrt(0.02)
    assert iv.low == pytest.approx(2 * math.exp(-half) - 1, rel=1e-5)
    assert iv.high == pytest.approx(2 * math.exp(half) - 1, rel=1e-5)


@pytest.mark.parametrize(
    ("base", "plan"),
    [((19.38, 6.262, 1000), (3.71, 1.158, 1000)), ((2.0, 1.5, 400), (1.6, 1.0, 300))],
)
def test_the_delta_method_agrees_with_a_parametric_simulation(base, plan):
    iv = ratio_interval(base, plan, 0.9)
    lo, hi = simulated_interval(base, plan, 0.9)
    assert iv.low == pytest.approx(lo, abs=0.02 * (1 + abs(lo)))
    assert iv.high == pytest.approx(hi, abs=0.02 * (1 + abs(hi)))


def test_the_papers_claims_from_its_own_tables(repo):
    paper = load_paper_tables(repo / "data/paper/tables.yaml")
    got = {c["text"][:40]: claim_interval(paper, c, 0.95) for c in paper["claims"]}
    for claim, iv in zip(paper["claims"], got.values(), strict=True):
        assert iv.improvement == pytest.approx(claim["quoted"], abs=5e-4)  # the quoted value
    vn = got["VNRRT* converges to optimal paths 76.82%"]
    assert (round(vn.low, 2), round(vn.high, 2)) == (-0.51, 5.41)  # n = 100 random maps
    assert not vn.significant
    assert got["M-VNRRT* (tau=0.5) is 422.37% faster tha"].significant


def test_bad_inputs_are_refused():
    with pytest.raises(ValueError, match="positive means"):
        ratio_interval((0.0, 1.0, 10), (1.0, 1.0, 10), 0.95)
