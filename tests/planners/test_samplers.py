"""Sampler distributions: heatmap (NRRT*/VNRRT*), masked (M-VNRRT*) and uniform."""

import numpy as np
import pytest
from scipy import stats

from vnrrt.grid import GridError
from vnrrt.planners import PlannerConfig, draw, heatmap_sampler, make_sampler, uniform_sampler

N = 200_000


def pixel_counts(samples, shape):
    cells = np.floor(samples).astype(int)
    return np.bincount(cells[:, 1] * shape[1] + cells[:, 0], minlength=shape[0] * shape[1])


@pytest.fixture(scope="module")
def heat():
    rng = np.random.default_rng(5)
    hm = rng.random((9, 11))
    hm[rng.random((9, 11)) < 0.3] = 0.0  # some zero-weight pixels
    return hm


def test_heatmap_draws_match_input_chi_square(heat):
    s = heatmap_sampler(heat, heat.shape, mix=1.0)
    counts = pixel_counts(draw(s, N, seed=1), heat.shape)
    assert counts[heat.ravel() == 0].sum() == 0  # zero weight, never drawn
    pos = heat.ravel() > 0
    expected = heat.ravel()[pos] / heat.sum() * N
    assert stats.chisquare(counts[pos], expected).pvalue > 1e-3


def test_points_are_uniform_inside_pixels(heat):
    pts = draw(heatmap_sampler(heat, heat.shape, mix=1.0), 20_000, seed=2)
    frac = pts - np.floor(pts)
    for a in range(2):
        assert stats.kstest(frac[:, a], "uniform").pvalue > 1e-3


def test_mix_is_one_half():
    hot = np.zeros((20, 20))
    hot[4, 7] = 1.0
    pts = draw(heatmap_sampler(hot, hot.shape, mix=0.5), N, seed=3)
    in_hot = np.count_nonzero((np.floor(pts) == [7, 4]).all(axis=1))
    p = 0.5 + 0.5 / hot.size  # heatmap draws plus uniform draws landing there
    assert stats.binomtest(in_hot, N, p).pvalue > 1e-3


def test_uniform_covers_map_evenly():
    shape = (6, 8)
    pts = draw(uniform_sampler(shape), N, seed=4)
    assert pts.min() >= 0 and (pts[:, 0] < 8).all() and (pts[:, 1] < 6).all()
    counts = pixel_counts(pts, shape)
    assert stats.chisquare(counts).pvalue > 1e-3


@pytest.mark.parametrize("tau", [0.5, 0.9])
def test_masked_never_below_tau(heat, tau):
    s = heatmap_sampler(heat, heat.shape, mix=1.0, tau=tau)
    counts = pixel_counts(draw(s, N, seed=6), heat.shape)
    assert counts[heat.ravel() < tau].sum() == 0
    kept = heat.ravel() >= tau
    expected = heat.ravel()[kept] / heat.ravel()[kept].sum() * N
    assert stats.chisquare(counts[kept], expected).pvalue > 1e-3


def test_masked_falls_back_to_uniform_when_empty(heat):
    s = make_sampler("m_vnrrt_star", heat.shape, heat, config=PlannerConfig(tau=2.0))
    assert s.fallback_uniform and s.draws().mix == 0.0 and s.mix == 0.5 and s.tau == 2.0
    assert not make_sampler("vnrrt_star", heat.shape, heat).fallback_uniform


def test_same_seed_same_draws(heat):
    s = heatmap_sampler(heat, heat.shape)
    assert np.array_equal(draw(s, 100, seed=9), draw(s, 100, seed=9))
    assert not np.array_equal(draw(s, 100, seed=9), draw(s, 100, seed=10))


@pytest.mark.parametrize(
    "bad",
    [np.ones((9, 10)), np.full((9, 11), np.nan), -np.ones((9, 11)), np.ones((9, 11), complex)],
)
def test_bad_heatmaps_are_refused(bad):
    with pytest.raises(GridError):
        heatmap_sampler(bad, (9, 11))


@pytest.mark.parametrize(
    ("weights", "why"),
    [
        ([1e308, 0.5e308, 1e308], "the raw total overflows: every draw landed in the last pixel"),
        ([0.6e308] * 5 + [0.0], "the raw total overflows midway"),
        ([5e-324, 5e-324, 5e-324], "subnormal weights: the draw rounded to a multiple of one"),
    ],
)
def test_numerically_hostile_weights_are_drawn_in_proportion(weights, why):
    """Finite weights whose total overflows (or is subnormal) are scaled by a power of two
    before they are summed: the pixel frequencies follow the weights' proportions."""
    hm = np.array([weights], dtype=np.float64)
    s = heatmap_sampler(hm, hm.shape, mix=1.0)
    assert np.isfinite(s.cdf).all() and s.cdf[-1] > 0.5, why
    counts = pixel_counts(draw(s, 60_000, seed=11), hm.shape)
    share = hm.ravel() / hm.ravel().max()  # the proportions, computed without overflow
    pos = share > 0
    assert counts[~pos].sum() == 0
    expected = share[pos] / share[pos].sum() * counts.sum()
    assert stats.chisquare(counts[pos], expected).pvalue > 1e-3, why


@pytest.mark.parametrize("tau", [None, 0.5, 0.9])
def test_probability_maps_keep_their_draws_bit_for_bit(tau):
    """A probability map (a network's float32 sigmoid output, values in [0, 1]) is summed as
    it is: the cdf equals the plain cumulative sum of its weights, so the draws of every
    existing seed are unchanged by the scaling of hostile weights."""
    rng = np.random.default_rng(4)
    logits = rng.normal(-3.0, 3.0, (200, 200))
    hm = (1 / (1 + np.exp(-logits))).astype(np.float32)
    s = heatmap_sampler(hm, hm.shape, mix=0.5, tau=tau)
    flat = hm.astype(np.float64).ravel()
    raw = np.cumsum(flat if tau is None else np.where(flat >= tau, flat, 0.0))
    assert np.array_equal(s.cdf, raw) and s.cdf[-1] == raw[-1]
    ones = heatmap_sampler(np.ones((200, 200)), (200, 200))
    assert np.array_equal(ones.cdf, np.arange(1.0, 40_001.0))  # max 1: not rescaled either
